"""Putting a finished output in place without replacing one another run wrote meanwhile.

A command checks at its start that an output it was not told to overwrite (no ``--force``)
does not exist (:func:`sgtool.output_check.check_output`, which calls :func:`expect_new`);
a second run given the same path may write it before the first finishes. :func:`publish`
moves such an output into place only while the path is still free (a hard link, which fails
when it exists), so neither run's file is silently replaced; other outputs are renamed over
whatever is there, as before. A finished output that could not be published is kept in
sight beside the path (:func:`keep_in_sight`).
"""

from __future__ import annotations

import errno
import os
from pathlib import Path

# the paths of this process's outputs that must still be new when published
_NEW_ONLY: set[str] = set()


def expect_new(path: str | os.PathLike[str], new: bool = True) -> None:
    """``path`` must (``new``: no ``--force``) or need not still be new when the output
    is moved into place."""
    (_NEW_ONLY.add if new else _NEW_ONLY.discard)(os.path.abspath(path))


def publish(tmp: str | os.PathLike[str], path: str | os.PathLike[str]) -> None:
    """Move the finished ``tmp`` to ``path``: one rename, or, for a path that must be new
    (:func:`expect_new`), a hard link that fails with :class:`FileExistsError` (naming
    ``path``) when ``path`` appeared meanwhile; once in place, the path is this run's (a
    second write of it replaces it)."""
    key = os.path.abspath(path)
    if key not in _NEW_ONLY:
        os.replace(tmp, path)
        return
    _move_to_new(tmp, path)
    _NEW_ONLY.discard(key)


def keep_in_sight(tmp: str | os.PathLike[str]) -> Path:
    """Where a finished output that could not be published is kept: a hidden temporary
    ``.NAME`` renamed to ``NAME`` beside it (never over a file; left hidden if that fails)."""
    tmp = Path(tmp)
    if not tmp.name.startswith("."):
        return tmp
    kept = tmp.with_name(tmp.name[1:])
    try:
        _move_to_new(tmp, kept)
    except OSError:
        return tmp
    return kept


def _move_to_new(tmp: str | os.PathLike[str], path: str | os.PathLike[str]) -> None:
    """Move ``tmp`` to ``path`` unless ``path`` exists (:class:`FileExistsError` naming
    ``path``): a hard link, or, where there are none (FAT, some network file systems), a
    rename after a check."""
    try:
        os.link(tmp, path)
    except FileExistsError:  # (it names tmp: filename, path: filename2)
        raise FileExistsError(errno.EEXIST, os.strerror(errno.EEXIST), str(path)) from None
    except OSError:  # no hard links here
        if os.path.lexists(path):
            raise FileExistsError(errno.EEXIST, os.strerror(errno.EEXIST), str(path)) from None
        os.replace(tmp, path)
    else:
        os.unlink(tmp)
