"""A read-only folder for tests of output errors, also when the tests run as root (who
writes into read-only folders): then the folder's new entries are refused the way the
kernel refuses them for a user (``tempfile.mkdtemp``/``mkstemp`` and ``os.mkdir`` in it
raise ``PermissionError``)."""

from __future__ import annotations

import errno
import os
import tempfile
from pathlib import Path
from typing import Any

import pytest


def make_read_only(folder: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Make ``folder`` read-only (mode 0555; undo with ``folder.chmod(0o755)``)."""
    folder.chmod(0o555)
    if os.geteuid() != 0:
        return
    inside = folder.resolve()

    def refused(where: Any) -> bool:
        return where is not None and Path(where).resolve() == inside

    def denied(where: Any) -> PermissionError:
        return PermissionError(errno.EACCES, os.strerror(errno.EACCES), str(where))

    real_mkdtemp, real_mkstemp, real_mkdir = tempfile.mkdtemp, tempfile.mkstemp, os.mkdir

    def mkdtemp(*args: Any, dir: Any = None, **kw: Any) -> str:
        if refused(dir):
            raise denied(dir)
        return real_mkdtemp(*args, dir=dir, **kw)

    def mkstemp(*args: Any, dir: Any = None, **kw: Any) -> Any:
        if refused(dir):
            raise denied(dir)
        return real_mkstemp(*args, dir=dir, **kw)

    def mkdir(path: Any, *args: Any, **kw: Any) -> None:
        if refused(Path(path).parent):
            raise denied(path)
        real_mkdir(path, *args, **kw)

    monkeypatch.setattr(tempfile, "mkdtemp", mkdtemp)
    monkeypatch.setattr(tempfile, "mkstemp", mkstemp)
    monkeypatch.setattr(os, "mkdir", mkdir)
