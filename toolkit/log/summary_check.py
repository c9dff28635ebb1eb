"""Checks a reader makes before it trusts the summary section of an MCAP file.

The summary (statistics, chunk, attachment and metadata indexes) says where everything is;
damaged, it makes a reader seek to nonsense, allocate gigabytes or print a time span of
years. :func:`check_summary` verifies the summary CRC (when the writer wrote one) and that
every offset and length it holds lies inside the file; :func:`read_attachment` reads one
attachment and checks its CRC; :class:`BoundedReader` clamps every read to the file.
"""

from __future__ import annotations

import io
import zlib
from typing import IO

from mcap.opcode import Opcode
from mcap.records import Attachment, AttachmentIndex, ChunkIndex, Footer
from mcap.summary import Summary

from sgtool.errors import LogFormatError, SgtoolError
from sgtool.files import quoted
from sgtool.log.mcap_records import FOOTER_RECORD_SIZE, RecordError, footer_at_end, parse_body


class BoundedReader(io.BufferedReader):
    """A buffered file whose reads never ask for more bytes than the file holds after the
    current position (a damaged length field gives a short read, not a MemoryError)."""

    def __init__(self, raw: io.FileIO, size: int) -> None:
        super().__init__(raw)
        self._size = size
        self._path = raw.name

    def check_open(self) -> None:
        """A read after :meth:`close` (a LogReader used after its ``with`` block) is one
        line saying so, not a damaged-data error."""
        if self.closed:
            raise SgtoolError(f"{self._path}: read after its LogReader was closed (read "
                              "inside its `with` block)")

    def seek(self, pos: int, whence: int = 0) -> int:
        self.check_open()
        return super().seek(pos, whence)

    def read(self, n: int | None = -1) -> bytes:
        self.check_open()
        if n is None or n < 0:
            return super().read()
        return super().read(max(0, min(n, self._size - self.tell())))


def _tail(f: IO[bytes], size: int) -> bytes:
    """The footer and closing magic, after 8 bytes standing for the file's magic."""
    n = min(size, 8 + FOOTER_RECORD_SIZE)
    f.seek(size - n)
    return b"\0" * (16 + FOOTER_RECORD_SIZE - n) + f.read(n)


def read_footer(f: IO[bytes], size: int) -> Footer | None:
    """The footer record at the end of the file, None when there is none."""
    tail = _tail(f, size)
    found = footer_at_end(tail, len(tail))
    return None if found is None else found[1]


def check_summary(f: IO[bytes], size: int, summary: Summary,
                  footer: Footer | None = None) -> None:
    """:class:`LogFormatError` when the summary CRC is wrong or an index points outside
    the file or contradicts the others; ``footer``: the file's, when read already."""
    footer = footer or read_footer(f, size)
    if footer is not None and footer.summary_crc and footer.summary_start:
        start = int(footer.summary_start)
        end = size - 8 - FOOTER_RECORD_SIZE + 9 + 16
        if not 8 <= start <= end:
            raise LogFormatError(f"the footer's summary start {start} is outside the file")
        f.seek(start)
        crc = 0
        left = end - start
        while left > 0:
            block = f.read(min(left, 1 << 20))
            if not block:
                break
            crc = zlib.crc32(block, crc)
            left -= len(block)
        if crc != footer.summary_crc:
            raise LogFormatError("the summary section is damaged (its CRC does not match: "
                                 "statistics, indexes or summary copies are wrong)")
    for ci in summary.chunk_indexes:
        if (ci.chunk_start_offset + ci.chunk_length > size
                or ci.message_start_time > ci.message_end_time
                or any(o + 9 > size for o in ci.message_index_offsets.values())):
            raise LogFormatError(f"a chunk index (chunk at byte {ci.chunk_start_offset}, "
                                 f"{ci.chunk_length} bytes) does not fit the file")
    for ai in summary.attachment_indexes:
        if ai.offset + ai.length > size or ai.data_size > ai.length:
            raise LogFormatError(f"the attachment index of {ai.name!r} does not fit the file")
    for mi in summary.metadata_indexes:
        if mi.offset + mi.length > size:
            raise LogFormatError(f"the metadata index of {mi.name!r} does not fit the file")
    st = summary.statistics
    chunks = [c for c in summary.chunk_indexes if not maybe_empty(c)]
    if st is not None and st.message_count and chunks:
        span = (min(c.message_start_time for c in chunks),
                max(c.message_end_time for c in chunks))
        # messages outside chunks may widen the statistics' range, never narrow it
        if st.message_start_time > span[0] or st.message_end_time < span[1]:
            raise LogFormatError(f"the statistics say messages from {st.message_start_time} "
                                 f"to {st.message_end_time} ns, the chunk indexes "
                                 f"{span[0]} to {span[1]} ns")


def maybe_empty(ci: ChunkIndex) -> bool:
    """The chunk ``ci`` indexes may hold no message: the MCAP specification gives such a
    chunk the times 0 and 0, and it has no message index."""
    return not ci.message_index_offsets and ci.message_start_time == ci.message_end_time == 0


def read_attachment(f: IO[bytes], ai: AttachmentIndex, where: str) -> Attachment:
    """The attachment ``ai`` points to, its CRC checked; :class:`LogFormatError` when it
    is not there or damaged."""
    f.seek(int(ai.offset))
    data = f.read(int(ai.length))
    try:
        if len(data) != ai.length or data[0] != Opcode.ATTACHMENT:
            raise RecordError("no attachment record there")
        a = parse_body(Opcode.ATTACHMENT, data[9:])
    except RecordError as e:
        raise LogFormatError(f"{where}: attachment {ai.name!r} at byte {ai.offset} is "
                             f"damaged ({e}); `sgtool doctor {quoted(where)}` says what is "
                             "readable") from None
    if a.name != ai.name:
        raise LogFormatError(f"{where}: the attachment at byte {ai.offset} is {a.name!r}, "
                             f"its index says {ai.name!r}")
    return a
