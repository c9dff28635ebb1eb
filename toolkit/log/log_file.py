"""Checks on the path of a log before it is opened.

Every reader of a log seeks (to the footer, the summary, the chunks) or maps the file into
memory, so the input must be a regular file: a pipe (``sgtool info <(cat log.mcap)``), a
terminal or a device is refused in one line that says how to go on, rather than failing
inside the MCAP reader.
"""

from __future__ import annotations

import os
import stat
from pathlib import Path

from sgtool.errors import LogFormatError


def require_regular_file(path: Path) -> None:
    """:class:`LogFormatError` unless ``path`` is a regular file (it must exist)."""
    mode = os.stat(path).st_mode
    if not stat.S_ISREG(mode):
        what = ("a pipe" if stat.S_ISFIFO(mode) else "a socket" if stat.S_ISSOCK(mode)
                else "a device" if stat.S_ISCHR(mode) or stat.S_ISBLK(mode)
                else "a folder" if stat.S_ISDIR(mode) else "a special file")
        raise LogFormatError(f"{path} is {what}, not a file: sgtool reads a log by seeking "
                             "in it; save it to a file first (e.g. `cat ... > log.mcap`)")
