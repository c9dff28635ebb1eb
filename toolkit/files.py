"""Atomic file output: a file appears at its final path complete, or not at all.

Every file sgtool writes outside a log (results, summaries, house specs, weights, figures,
golden expectations) goes through :func:`atomic_write` or :func:`atomic_output`: the bytes
go to a temporary file with a unique name in the same folder, are flushed and fsync'ed, get
the mode a plain ``open`` would give (umask applied), and are renamed over the final path.
An error, Ctrl-C or a concurrent writer never leaves a half-written file at the final path;
the temporary file is removed on any exception. Two processes writing the same path each
use their own temporary file, and the last rename wins with a complete file.
"""

from __future__ import annotations

import contextlib
import os
import tempfile
from collections.abc import Iterator
from pathlib import Path
from typing import IO


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


@contextlib.contextmanager
def atomic_output(path: str | os.PathLike[str], suffix: str = ".partial") -> Iterator[Path]:
    """Yield a temporary path beside ``path``; on a clean exit it is renamed to ``path``.

    For writers that need a path (a library that opens the file itself); the temporary
    file exists (empty) when the block starts. The parent folder is created.
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, name = tempfile.mkstemp(prefix=f".{path.name}.", suffix=suffix, dir=path.parent)
    os.close(fd)
    tmp = Path(name)
    try:
        yield tmp
        with open(tmp, "rb+") as fh:
            os.fsync(fh.fileno())
        os.chmod(tmp, 0o666 & ~_umask())  # mkstemp makes 0600; give the usual mode
        os.replace(tmp, path)
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
