"""Checks on the path of a log before it is opened.

Every reader of a log seeks (to the footer, the summary, the chunks) or maps the file into
memory, so the input must be a regular file: a pipe (``sgtool info <(cat log.mcap)``), a
terminal or a device is refused in one line that says how to go on, rather than failing
inside the MCAP reader.
"""

from __future__ import annotations

import mmap
import os
import stat
import struct
from pathlib import Path

from sgtool.errors import LogFormatError
from sgtool.files import quoted
from sgtool.log.mcap_records import MAGIC, FileBytes

_FOOTER = struct.Struct("<BQQQI")  # opcode 0x02, record length 20, two offsets and a CRC
_TAIL = 1 << 20  # how far from the end a footer followed by bytes is looked for


def appended_end(buf: FileBytes, size: int) -> int | None:
    """Where a complete log ends in a file of ``size`` bytes that does not end with the
    MCAP magic but holds, within its last MiB, a footer record followed by the closing
    magic (bytes appended to a closed log): the offset just after that magic, else None.
    Only the pattern is checked; the caller decides whether the log before it reads."""
    if size >= len(MAGIC) and bytes(buf[size - len(MAGIC):size]) == MAGIC:
        return None
    start = max(size - _TAIL, 0)
    tail = bytes(buf[start:size])
    at = tail.rfind(MAGIC)
    while at >= _FOOTER.size:
        opcode, length, *_ = _FOOTER.unpack_from(tail, at - _FOOTER.size)
        if opcode == 0x02 and length == 20:
            return start + at + len(MAGIC)
        at = tail.rfind(MAGIC, 0, at)
    return None


def unended_problem(path: Path, size: int) -> str:
    """The one line for a file of ``size`` bytes that does not end with the MCAP magic:
    bytes appended after a complete log's footer (:func:`appended_end`), or a file cut
    short or still being written; both name the recovery."""
    recover = (f"`sgtool doctor {quoted(path)} --recover OUT.mcap` copies what is readable "
               "into a valid log")
    with open(path, "rb") as f, mmap.mmap(f.fileno(), 0, access=mmap.ACCESS_READ) as buf:
        end = appended_end(buf, size)
    if end is not None:
        extra = size - end
        return (f"{path}: {extra} byte{'' if extra == 1 else 's'} after the end of the "
                f"MCAP file (its footer and closing magic end at byte {end}): bytes "
                f"appended to a complete log; {recover}")
    return (f"{path}: the file ends without the MCAP footer (truncated, or still being "
            f"written); {recover}")


def file_ends(path: Path) -> tuple[bytes, int, bytes]:
    """(its first 9 bytes, its size, its last 37 bytes: a footer record and the closing
    magic) of the file ``path`` (fewer bytes when it is shorter)."""
    with open(path, "rb") as f:
        head = f.read(9)
        size = f.seek(0, os.SEEK_END)
        f.seek(max(size - _FOOTED, 0))
        tail = f.read(_FOOTED) if size >= 16 else b""
    return head, size, tail


_FOOTED = 1 + 8 + 20 + len(MAGIC)  # footer record (opcode, length, 20 bytes) and magic


def _footed(tail: bytes) -> bool:
    """Whether ``tail`` ends with a footer record and the closing magic."""
    return (len(tail) >= _FOOTED and tail[-8:] == MAGIC and tail[-_FOOTED] == 0x02
            and int.from_bytes(tail[-_FOOTED + 1:-_FOOTED + 9], "little") == 20)


def rerun_problem(path: Path, head: bytes) -> str | None:
    """The one line for a Rerun recording (its file magic ``RRF0``..``RRF2``: what
    ``sgtool view -o`` writes) given where an sgtool log is read, else None."""
    if not head.startswith(b"RRF"):
        return None
    return (f"{path} is a Rerun recording (.rrd), not an sgtool log: open it with "
            f"`rerun {quoted(path)}`, and give sgtool the .mcap log it was made from")


def opening_damaged(head: bytes, size: int, tail: bytes) -> bool:
    """Whether a file of ``size`` bytes whose first bytes ``head`` (9 or more) do not
    start with the MCAP magic is an MCAP file with a damaged opening magic: it ends with a
    footer record and the closing magic (``tail``: its last bytes, :func:`file_ends`), a
    header record follows the opening, or the opening is off by a few bytes (not any other
    file, such as a text file that happens to end with the magic bytes)."""
    near = len(head) >= 8 and sum(a != b for a, b in zip(head[:8], MAGIC, strict=True)) <= 3
    return size >= 17 and not head.startswith(b"RRF") and (
        near or _footed(tail) or head[8:9] == b"\x01")


def magic_problem(path: Path) -> tuple[int, str | None]:
    """The size of the MCAP file ``path`` and the one line when it does not start and end
    with the MCAP magic (None when it does): not an MCAP file; one whose opening magic is
    damaged (:func:`opening_damaged`); or :func:`unended_problem`'s."""
    head, size, tail = file_ends(path)
    opening = head[:8]
    if opening != MAGIC:
        rerun = rerun_problem(path, head)
        if rerun is not None:
            return size, rerun
        return size, (f"{path}: not an MCAP file (it does not start with the MCAP magic bytes)"
                      if not opening_damaged(head, size, tail) else
                      f"{path}: its opening MCAP magic bytes are damaged (the rest reads as "
                      f"MCAP); `sgtool doctor {quoted(path)} --recover OUT.mcap` "
                      "recovers what is readable")
    return size, None if tail[-8:] == MAGIC else unended_problem(path, size)


def require_regular_file(path: Path) -> None:
    """:class:`LogFormatError` unless ``path`` is a regular file (it must exist)."""
    mode = os.stat(path).st_mode
    if not stat.S_ISREG(mode):
        what = ("a pipe" if stat.S_ISFIFO(mode) else "a socket" if stat.S_ISSOCK(mode)
                else "a device" if stat.S_ISCHR(mode) or stat.S_ISBLK(mode)
                else "a folder" if stat.S_ISDIR(mode) else "a special file")
        raise LogFormatError(f"{path} is {what}, not a file: sgtool reads a log by seeking "
                             "in it; save it to a file first (e.g. `cat ... > log.mcap`)")
