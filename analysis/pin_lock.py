"""The lock of a pin folder (``sgtool golden``): one process at a time changes its index."""

from __future__ import annotations

import contextlib
import os
import stat
from collections.abc import Iterator
from pathlib import Path

from sgtool.errors import SgtoolError


@contextlib.contextmanager
def pins_locked(root: Path, shared: bool = False) -> Iterator[None]:
    """Hold the lock of the pin folder ``root`` (an advisory lock on a file of this user's
    in a folder of them in the system's temporary folder, named after ``root``'s resolved
    path; nothing is added to ``root``): one process at a time reads, changes and writes its index;
    ``shared``: a reader's lock (checks read the index and the graphs it names together,
    never half of a pin being written). Where there are no advisory locks (not POSIX),
    nothing is held."""
    import hashlib
    import tempfile

    try:
        import fcntl
    except ImportError:  # pragma: no cover - not POSIX
        yield
        return
    key = hashlib.sha256(str(root.resolve()).encode()).hexdigest()[:20]
    user = os.getuid() if hasattr(os, "getuid") else 0
    locks = Path(tempfile.gettempdir()) / f"sgtool-pin-locks-{user}"  # one folder of them,
    try:  # not a file per pin folder in the temp folder
        locks.mkdir(mode=0o700, exist_ok=True)
        st = locks.lstat()
        if not stat.S_ISDIR(st.st_mode) or st.st_uid != user:
            raise PermissionError("not a folder of this user's")
        fh = open(locks / f"{key}.lock", "a+b")  # noqa: SIM115 - closed below
    except OSError as e:
        raise SgtoolError(
            f"cannot lock the pin folder {root}: its lock folder {locks} is unusable "
            f"({getattr(e, 'strerror', None) or e}); remove it, or set TMPDIR to a folder "
            "of your own") from None
    with fh:
        fcntl.flock(fh, fcntl.LOCK_SH if shared else fcntl.LOCK_EX)
        try:
            yield
        finally:
            fcntl.flock(fh, fcntl.LOCK_UN)
