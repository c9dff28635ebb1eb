"""The one check of an output file name a writing command or exporter is given, before any
work: not a folder, the right suffix, an existing folder that takes a new file, and no
existing file unless ``force``. Each failure is one :class:`~sgtool.errors.SgtoolError`
line naming the option; nothing is left behind."""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path

from sgtool.errors import SgtoolError
from sgtool.publish import expect_new


def check_output(path: str | os.PathLike[str], *, force: bool = False, option: str = "-o",
                 suffixes: Sequence[str] = (), what: str = "output",
                 force_flag: str = "--force") -> Path:
    """The one check of an output file name a command may write, before any work: it is
    not a folder, it has one of ``suffixes`` (when given), its folder exists and takes a new
    file (a probe file is made there and removed), and it does not exist unless ``force``
    (and is never a device, FIFO or socket, which the atomic rename would replace).
    Each failure is one :class:`SgtoolError` line (``force_flag`` names how to
    overwrite); nothing is left behind."""
    if not os.fspath(path):  # ("" would be the working folder)
        raise SgtoolError(f"{option} '': an empty path; give a file name")
    p = Path(path)
    if p.is_dir():
        raise SgtoolError(f"{option} {p} is a folder; give a file name")
    if suffixes and p.suffix.lower() not in suffixes:
        raise SgtoolError(f"{option} {p}: the {what} must end in {' or '.join(suffixes)}")
    if not p.parent.exists():
        raise SgtoolError(f"{option} {p}: folder {p.parent} does not exist")
    if p.exists() and not force:
        raise SgtoolError(f"{p} exists; not overwriting it (use {force_flag})")
    if p.exists() and not p.is_file():  # a device, FIFO or socket: a rename would replace it
        raise SgtoolError(f"{option} {p} is not a regular file (a device, pipe or socket): "
                          "outputs are written beside it and renamed into place, which would "
                          "replace it; give a file's path")
    _probe_folder(p)
    # (a link to a missing file is replaced, as before: it is no run's output)
    expect_new(p, new=not force and not p.is_symlink())
    return p


def check_log_output(path: str | os.PathLike[str], *, force: bool = False,
                     option: str = "-o",
                     inputs: Sequence[str | os.PathLike[str] | None] = ()) -> Path:
    """:func:`check_output` of an MCAP log to write (``*.mcap``), which must not be one of
    the command's ``inputs`` (files it reads; None: not given)."""
    if not os.fspath(path):  # ("" would be the working folder)
        raise SgtoolError(f"{option} '': an empty path; give a file name")
    for given in inputs:
        if given and _is_file(given) and Path(given).resolve() == Path(path).resolve():
            raise SgtoolError(f"{option} {path}: the output must not be an input "
                              f"({given})")
    if Path(path).suffix != ".mcap" and not Path(path).is_dir():
        raise SgtoolError(f"{option} {path}: the output is an MCAP log; name it *.mcap")
    return check_output(path, force=force, option=option)


def _is_file(given: str | os.PathLike[str]) -> bool:
    """Whether ``given`` names a file; False when it cannot be looked at (an input that is
    not a path, such as ``--noise none``, in a working folder this user cannot read)."""
    try:
        return Path(given).is_file()
    except OSError:
        return False


def _probe_folder(path: Path) -> None:
    """A one-line error now when the folder of ``path`` takes no new file (read-only, or
    not a folder), rather than after the work."""
    import os

    from sgtool.files import output_error, temp_beside

    try:
        fd, probe = temp_beside(path, ".probe")
    except OSError as e:
        raise output_error(e, path) from None
    os.close(fd)
    probe.unlink(missing_ok=True)
