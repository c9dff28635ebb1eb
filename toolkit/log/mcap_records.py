"""Parsing MCAP records without trusting them (pure functions over bytes).

Every length is checked against the bytes that are really there before anything is
allocated; a record parses only when its body holds one whole record of its type (no bytes
missing, the attachment CRC right). Bytes after the last field are allowed where the MCAP
specification allows them (fields a newer writer appends: every record but a message, a
chunk, whose records fill it, and the fixed-size footer); :func:`trailing_is_damage` tells
them from a length field grown by damage. A record of an application's own opcode
(0x80-0xFF, which the specification reserves for extensions) is skipped by its length.
:func:`next_record_start` finds the next plausible record after damaged bytes
(resynchronisation), and :func:`decompress` gives the readable prefix of a truncated or
damaged compressed chunk (zstd and lz4 are decoded as streams, so everything before the
damage comes back).
"""

from __future__ import annotations

import io
import mmap
import struct
import zlib
from dataclasses import dataclass
from typing import Any

import numpy as np
from mcap.data_stream import ReadDataStream
from mcap.opcode import Opcode
from mcap.records import (
    Attachment,
    AttachmentIndex,
    Channel,
    Chunk,
    ChunkIndex,
    DataEnd,
    Footer,
    Header,
    Message,
    MessageIndex,
    Metadata,
    MetadataIndex,
    Schema,
    Statistics,
    SummaryOffset,
)

# a whole MCAP file (or its start) in memory: bytes, a view, or a read-only mmap of the file
# (slices of an mmap are bytes)
FileBytes = bytes | memoryview | mmap.mmap

MAGIC = bytes([137, 77, 67, 65, 80, 48, 13, 10])
FOOTER_RECORD_SIZE = 9 + 20
_MIN_LENGTH: dict[int, int] = {Opcode.HEADER: 8, Opcode.FOOTER: 20, Opcode.MESSAGE: 22,
                               Opcode.CHUNK: 40, Opcode.DATA_END: 4}
_CLASSES: dict[int, Any] = {
    Opcode.HEADER: Header, Opcode.FOOTER: Footer, Opcode.SCHEMA: Schema,
    Opcode.CHANNEL: Channel, Opcode.MESSAGE_INDEX: MessageIndex,
    Opcode.CHUNK_INDEX: ChunkIndex, Opcode.ATTACHMENT: Attachment,
    Opcode.ATTACHMENT_INDEX: AttachmentIndex, Opcode.STATISTICS: Statistics,
    Opcode.METADATA: Metadata, Opcode.METADATA_INDEX: MetadataIndex,
    Opcode.SUMMARY_OFFSET: SummaryOffset, Opcode.DATA_END: DataEnd,
}
KNOWN_OPCODES = frozenset(_CLASSES) | {Opcode.MESSAGE, Opcode.CHUNK}
EXTENSION_OPCODES = frozenset(range(0x80, 0x100))  # the specification's, for applications
# records whose size the specification fixes (no fields can be appended)
_FIXED_SIZE = frozenset({Opcode.FOOTER})
CHUNK_OPCODES = frozenset({Opcode.SCHEMA, Opcode.CHANNEL, Opcode.MESSAGE})
# records an extension opcode with its top bit lost is checked against (_check_extension)
_WHOLE_CHECKED = frozenset({Opcode.CHUNK, Opcode.SCHEMA, Opcode.CHANNEL, Opcode.ATTACHMENT,
                            Opcode.METADATA})
_ZSTD_STEP = 16 * 1024  # compressed bytes fed per call: the granularity of a salvage


class RecordError(ValueError):
    """Bytes that are not one valid record of the type their opcode names."""


@dataclass(frozen=True)
class Raw:
    """A record found at ``offset``: ``length`` is its body length (9 header bytes
    before it)."""

    offset: int
    opcode: int
    length: int
    record: Any
    trailing: int = 0  # bytes after the last field the record type defines

    @property
    def end(self) -> int:
        return self.offset + 9 + self.length


def head(buf: FileBytes, pos: int, end: int) -> tuple[int, int] | None:
    """(opcode, body length) of the record at ``pos``, or None when fewer than 9 bytes
    remain before ``end``."""
    if end - pos < 9:
        return None
    opcode, length = struct.unpack_from("<BQ", buf, pos)
    return opcode, length


def parse_body(opcode: int, body: bytes | memoryview) -> Any:
    """The record of ``opcode`` in ``body``; :class:`RecordError` unless ``body`` holds
    one valid record (and only bytes a newer writer may append after it)."""
    return _parse(opcode, body)[0]


def _parse(opcode: int, body: bytes | memoryview) -> tuple[Any, int]:
    """(record, bytes its fields take) of :func:`parse_body`."""
    n = len(body)
    if n < _MIN_LENGTH.get(opcode, 0):
        raise RecordError(f"{n} bytes are too few for opcode 0x{opcode:02x}")
    if opcode == Opcode.CHUNK:
        return _parse_chunk(body, complete=True), n
    if opcode == Opcode.MESSAGE:  # the common records, parsed without a stream
        cid, seq, log_time, publish_time = struct.unpack_from("<HIQQ", body, 0)
        return Message(channel_id=cid, sequence=seq, log_time=log_time,
                       publish_time=publish_time, data=bytes(body[22:])), n
    if opcode == Opcode.MESSAGE_INDEX:
        if n < 6:
            raise RecordError("message index cut short")
        cid, rl = struct.unpack_from("<HI", body, 0)
        if rl % 16 or 6 + rl > n:
            raise RecordError(f"message index of {n} bytes says {rl} bytes of entries")
        return MessageIndex(channel_id=cid, records=list(
            struct.iter_unpack("<QQ", body[6:6 + rl]))), 6 + rl
    stream = ReadDataStream(io.BytesIO(bytes(body)))
    try:
        if opcode in _CLASSES:
            rec = _CLASSES[opcode].read(stream)
        else:
            raise RecordError(f"unknown opcode 0x{opcode:02x}")
    except RecordError:
        raise
    except Exception as e:  # noqa: BLE001 - the mcap parsers raise many kinds on garbage
        raise RecordError(f"{type(e).__name__}: {str(e)[:80]}") from None
    used = stream.count
    if used != n and opcode in _FIXED_SIZE:
        raise RecordError(f"record of {n} bytes holds {used} bytes of fields")
    if opcode == Opcode.ATTACHMENT:
        stored = struct.unpack_from("<I", body, used - 4)[0]
        if stored != 0 and zlib.crc32(bytes(body[: used - 4])) != stored:
            raise RecordError("attachment CRC does not match its bytes")
    return rec, used


def _parse_chunk(body: bytes | memoryview, complete: bool) -> Chunk:
    """A chunk record; with ``complete`` False, ``body`` may stop inside the compressed
    records (a cut file): the chunk holds the bytes that are there."""
    if len(body) < 40:
        raise RecordError("chunk header cut short")
    start, end, usize, crc, clen = struct.unpack_from("<QQQII", body, 0)
    if clen > 16 or 36 + clen + 8 > len(body):
        raise RecordError(f"chunk compression name of {clen} bytes")
    try:
        compression = bytes(body[32:32 + clen]).decode()
    except UnicodeDecodeError:
        raise RecordError("chunk compression name is not text") from None
    rlen = struct.unpack_from("<Q", body, 32 + clen)[0]
    data = body[40 + clen:]
    if complete and rlen != len(data):
        raise RecordError(f"chunk says {rlen} bytes of records, holds {len(data)}")
    if not complete and rlen < len(data):
        raise RecordError(f"chunk says {rlen} bytes of records, holds more")
    return Chunk(message_start_time=start, message_end_time=end, uncompressed_size=usize,
                 uncompressed_crc=crc, compression=compression, data=bytes(data))


def chunk_prefix(buf: FileBytes, pos: int, size: int) -> Chunk | None:
    """The chunk whose record starts at ``pos`` and runs past ``size`` (the file was cut
    inside it), holding the compressed bytes that are there; None when even its header is
    cut or makes no sense."""
    try:
        return _parse_chunk(buf[pos + 9:size], complete=False)
    except RecordError:
        return None


def read_record(buf: FileBytes, pos: int, end: int) -> Raw:
    """The record at ``pos``, which must end by ``end``; :class:`RecordError` otherwise."""
    h = head(buf, pos, end)
    if h is None:
        raise RecordError(f"{end - pos} bytes left: a record needs at least 9")
    opcode, length = h
    if opcode not in KNOWN_OPCODES and opcode not in EXTENSION_OPCODES:
        raise RecordError(f"unknown opcode 0x{opcode:02x}")
    if length > end - pos - 9:
        raise RecordError(f"record of {length} bytes runs past the end ({end - pos - 9} left)")
    if opcode in EXTENSION_OPCODES:  # an application's record: skipped by its length
        _check_extension(opcode, buf[pos + 9:pos + 9 + length])
        return Raw(pos, opcode, length, None)
    rec, used = _parse(opcode, buf[pos + 9:pos + 9 + length])
    return Raw(pos, opcode, length, rec, length - used)


def _check_extension(opcode: int, body: bytes | memoryview) -> None:
    """:class:`RecordError` when the record of application opcode ``opcode`` is rather a
    record whose opcode lost its top bit to damage (0x86: a chunk): its body parses whole,
    not a byte left, as the record of ``opcode & 0x7f``, one of :data:`_WHOLE_CHECKED`
    (records of length-prefixed fields, which a body of other bytes does not fill by
    chance; a message, a data end or an index parses from almost anything)."""
    known = opcode & 0x7F
    if known not in _WHOLE_CHECKED:
        return
    try:
        _, used = _parse(known, body)
    except RecordError:
        return
    if used != len(body):  # not a whole record of that kind: the application's own
        return
    raise RecordError(f"opcode 0x{opcode:02x} holds a whole record of opcode 0x{known:02x} "
                      "(a damaged opcode)")


def trailing_is_damage(buf: FileBytes, raw: Raw, end: int) -> bool:
    """Whether the bytes after the fields of ``raw`` (which a newer writer may append) are
    rather a length field grown by damage: they hold a whole record themselves, or the
    record does not end where the end, the closing magic or another record begins."""
    if not raw.trailing:
        return False
    if next_record_start(buf, raw.end - raw.trailing, raw.end) is not None:
        return True
    return not _plausible_next(buf, raw.end, end, KNOWN_OPCODES)


def _plausible_next(buf: FileBytes, pos: int, end: int, opcodes: frozenset[int]
                    ) -> bool:
    """Is ``pos`` the end of the data, the closing magic, or a record head that fits?"""
    if pos == end or bytes(buf[pos:pos + 8]) == MAGIC:
        return True
    h = head(buf, pos, end)
    return (h is not None and (h[0] in opcodes or h[0] in EXTENSION_OPCODES)
            and h[1] <= end - pos - 9)


def next_record_start(buf: FileBytes, start: int, end: int,
                      opcodes: frozenset[int] = KNOWN_OPCODES) -> Raw | None:
    """The first record at or after ``start`` that parses whole and is followed by the
    end, the closing magic or another plausible record head (so a random byte that looks
    like an opcode is not taken for a record); None when there is none."""
    if end - start < 9:
        return None
    region = np.frombuffer(buf, dtype=np.uint8, count=end - start, offset=start)
    n = len(region) - 8
    ok = np.isin(region[:n], np.fromiter(opcodes, dtype=np.uint8))
    ok &= (region[6:n + 6] == 0) & (region[7:n + 7] == 0) & (region[8:n + 8] == 0)
    for i in np.flatnonzero(ok):
        pos = start + int(i)
        try:
            raw = read_record(buf, pos, end)
        except RecordError:
            continue
        if raw.opcode in opcodes and _plausible_next(buf, raw.end, end, opcodes):
            return raw
    return None


def decompress(chunk: Chunk, limit: int) -> tuple[bytes, str | None, bool]:
    """(uncompressed records of ``chunk``, None, True); when the data is damaged, the
    prefix decoded before the damage and what stopped it; when it is cut short (and not
    damaged), the prefix, None and False. At most ``limit`` bytes come out (a damaged size
    field cannot make it allocate more)."""
    c = chunk.compression
    if c == "":
        return chunk.data[:limit], None, True
    if c == "zstd":
        import zstandard

        dz = zstandard.ZstdDecompressor().decompressobj()
        return _stream(chunk.data, limit, _ZSTD_STEP, dz.decompress, zstandard.ZstdError,
                       lambda: dz.eof, "zstd")
    if c == "lz4":
        import lz4.frame

        dl = lz4.frame.LZ4FrameDecompressor()
        return _stream(chunk.data, limit, _ZSTD_STEP, dl.decompress, RuntimeError,
                       lambda: dl.eof, "lz4")
    return b"", f"unknown compression {c!r}", False


def _stream(data: bytes, limit: int, step: int, feed: Any, error: type[Exception],
            eof: Any, name: str) -> tuple[bytes, str | None, bool]:
    out: list[bytes] = []
    total = 0
    for i in range(0, len(data), step):
        try:
            piece = feed(data[i:i + step])
        except (error, ValueError, EOFError) as e:
            return (b"".join(out), f"{name} data damaged after {i} of {len(data)} bytes "
                    f"({e})", False)
        out.append(piece)
        total += len(piece)
        if total > limit:
            return (b"".join(out)[:limit], f"{name} data decodes to more than {limit} "
                    "bytes", False)
        if eof():
            break
    return b"".join(out), None, bool(eof())


def inner_records(data: bytes, complete: bool) -> tuple[list[Raw], list[str]]:
    """Schema, channel and message records of uncompressed chunk ``data`` (offsets into
    ``data``), and the problems met. Damaged records are skipped up to the next valid one;
    with ``complete`` False (a prefix) a record cut by the end of ``data`` is not a
    problem."""
    out: list[Raw] = []
    problems: list[str] = []
    pos, end = 0, len(data)
    while pos < end:
        try:
            raw = read_record(data, pos, end)
        except RecordError as e:
            h = head(data, pos, end)
            if not complete and (h is None or h[1] > end - pos - 9):
                break  # the prefix ends inside this record
            found = next_record_start(data, pos + 1, end, CHUNK_OPCODES)
            problems.append(f"damaged record at byte {pos} of the chunk ({e}); "
                            + (f"resumed at byte {found.offset}" if found else "rest skipped"))
            if found is None:
                break
            raw = found
        if raw.opcode in CHUNK_OPCODES:
            out.append(raw)
        pos = raw.end
    return out, problems


def footer_at_end(buf: FileBytes, size: int) -> tuple[int, Footer] | None:
    """(offset, footer) of a file that ends with a footer record and the closing magic."""
    pos = size - 8 - FOOTER_RECORD_SIZE
    if pos < 8 or bytes(buf[size - 8:size]) != MAGIC:
        return None
    try:
        raw = read_record(buf, pos, size - 8)
    except RecordError:
        return None
    if raw.opcode != Opcode.FOOTER or raw.end != size - 8:
        return None
    return pos, raw.record
