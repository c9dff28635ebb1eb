"""Atomic file output: a file appears at its final path complete, or not at all.

Every file sgtool writes outside a log (results, summaries, house specs, weights, figures,
golden expectations) goes through :func:`atomic_write` or :func:`atomic_output`: the bytes
go to a temporary file with a unique name in the same folder, are flushed and fsync'ed, get
the mode a plain ``open`` would give (umask applied), and are renamed over the final path.
An error, Ctrl-C or a concurrent writer never leaves a half-written file at the final path;
the temporary file is removed on any exception. Two processes writing the same path each
use their own temporary file, and the last rename wins with a complete file.

:func:`temp_beside` makes such a unique temporary file for writers that manage it
themselves (the log writer); :class:`OutputError` is the one-line user error for a
destination that cannot be written (read-only, missing, full), made by
:func:`output_error` from the :class:`OSError`.
"""

from __future__ import annotations

import contextlib
import errno
import os
import tempfile
from collections.abc import Iterator
from pathlib import Path
from typing import IO

from sgtool.errors import SgtoolError

# OSError numbers that a user's environment causes (a destination that is read-only,
# missing, full, not writable): reported as one line, never as a traceback
ENVIRONMENT_ERRNOS = frozenset({
    errno.EACCES, errno.EPERM, errno.EROFS, errno.ENOSPC, errno.EDQUOT, errno.ENOENT,
    errno.ENOTDIR, errno.EISDIR, errno.EEXIST, errno.EFBIG, errno.ENAMETOOLONG, errno.EIO,
    errno.ENXIO, errno.ETXTBSY, errno.EMFILE, errno.ENFILE, errno.ELOOP, errno.EXDEV,
    errno.ENOTEMPTY, errno.EBUSY,
})


# errors of a write that say the destination is full or failing, whatever file they name
FULL_ERRNOS = frozenset({errno.ENOSPC, errno.EDQUOT, errno.EFBIG, errno.EIO})


class OutputError(SgtoolError):
    """An output could not be written (read-only folder, missing folder, full disk)."""


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def is_environment_error(e: BaseException) -> bool:
    """True for an :class:`OSError` a user's environment causes (see ``ENVIRONMENT_ERRNOS``)."""
    return isinstance(e, OSError) and e.errno in ENVIRONMENT_ERRNOS


def concerns(e: OSError, *paths: str | os.PathLike[str]) -> bool:
    """Is ``e`` a failure to write one of ``paths``: it names one of them, or names no file
    and says that the destination is full or failing (a buffered write)?"""
    if e.filename is not None:
        return str(e.filename) in {str(p) for p in paths}
    return e.errno in FULL_ERRNOS


def output_error(e: OSError, path: str | os.PathLike[str] | None = None,
                 note: str = "nothing was written") -> OutputError:
    """The one-line :class:`OutputError` for ``e`` while writing ``path`` (or the file the
    error names): ``cannot write PATH: No space left on device (nothing was written)``."""
    where = path if path is not None else (e.filename or "the output")
    reason = e.strerror or type(e).__name__
    return OutputError(f"cannot write {where}: {reason}" + (f" ({note})" if note else ""))


def temp_beside(path: str | os.PathLike[str], suffix: str = ".partial",
                hidden: bool = True) -> tuple[int, Path]:
    """A new, uniquely named, empty file in the folder of ``path`` (``.NAME.XXXXXXXX`` +
    ``suffix``, or ``NAME.XXXXXXXX`` + ``suffix`` when not ``hidden``) with the mode a
    plain ``open`` would give; returns its open descriptor and path. Two callers never get
    the same name."""
    path = Path(path)
    prefix = f".{path.name}." if hidden else f"{path.name}."
    fd, name = tempfile.mkstemp(prefix=prefix, suffix=suffix, dir=path.parent)
    try:
        os.fchmod(fd, 0o666 & ~_umask())  # mkstemp makes 0600; give the usual mode
    except BaseException:
        os.close(fd)
        os.unlink(name)
        raise
    return fd, Path(name)


@contextlib.contextmanager
def atomic_output(path: str | os.PathLike[str], suffix: str = ".partial") -> Iterator[Path]:
    """Yield a temporary path beside ``path``; on a clean exit it is renamed to ``path``.

    For writers that need a path (a library that opens the file itself); the temporary
    file exists (empty) when the block starts. The parent folder is created.
    """
    path = Path(path)
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = temp_beside(path, suffix)
    except OSError as e:
        raise output_error(e, path) from None
    os.close(fd)
    try:
        yield tmp
        with open(tmp, "rb+") as fh:
            os.fsync(fh.fileno())
        os.chmod(tmp, 0o666 & ~_umask())  # a library may have made its own file anew
        os.replace(tmp, path)
    except OSError as e:
        tmp.unlink(missing_ok=True)
        if concerns(e, tmp, path):
            raise output_error(e, path) from None
        raise
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise


@contextlib.contextmanager
def atomic_open(path: str | os.PathLike[str], mode: str = "w") -> Iterator[IO]:
    """``open(path, mode)`` ("w", "wb", "wt") that becomes ``path`` only on a clean exit."""
    if mode not in ("w", "wt", "wb"):
        raise ValueError(f"atomic_open writes a new file; mode {mode!r}")
    with atomic_output(path) as tmp:
        encoding = None if "b" in mode else "utf-8"
        with open(tmp, mode, encoding=encoding) as fh:
            yield fh
            fh.flush()


def atomic_write(path: str | os.PathLike[str], data: str | bytes) -> Path:
    """Write ``data`` (text is UTF-8) to ``path`` atomically; return the path."""
    with atomic_open(path, "wb") as fh:
        fh.write(data.encode("utf-8") if isinstance(data, str) else data)
    return Path(path)
