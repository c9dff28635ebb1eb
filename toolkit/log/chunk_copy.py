"""Chunks of one MCAP file copied into another as they are: no decompression, no
recompression.

Replay writes every input message into the derived log. Decoding each chunk to read it is
needed anyway; recompressing its messages is not: :func:`append_chunk` writes the input's
chunk record byte for byte, then the input's message index records (their offsets are
relative to the chunk, so they stay valid), and adds a chunk index pointing at the new
place, and the chunk's messages to the statistics. The ``mcap`` package's writer has no
such call, so this module writes those records beside it, into the same stream, and updates
the writer's chunk index list, statistics and running data-section CRC (its private state:
:func:`writer_supported` checks that it is there; otherwise replay writes message by
message).
``tests/toolkit/log/test_chunk_copy.py`` reads every copy back and through ``sgtool
doctor``'s checks).

A copied chunk keeps the input's channel and schema ids, sequence numbers, publish times
and CRC: the derived log must then give its input channels the input's ids
(:func:`ids_problem`), and the chunk must be compressed as the derived log asks. A damaged
chunk must never be copied (the derived log would carry the damage under a CRC that no
longer matches): :meth:`~sgtool.log.reader.LogReader.chunks`, which decompresses every
chunk it hands out anyway, always checks the stored CRC of the uncompressed records (when
the writer stored one), and a mismatch is the reader's one-line "damaged data" error that
points to ``sgtool doctor``, whatever ``verify`` says.
"""

from __future__ import annotations

import contextlib
import struct
import zlib
from collections.abc import Iterator
from dataclasses import dataclass
from typing import IO, Any

from mcap.records import ChunkIndex
from mcap.summary import Summary
from mcap.writer import Writer

_CHUNK = 0x06
_MESSAGE_INDEX = 0x07
_RECORD_HEAD = struct.Struct("<BQ")
_INDEX_HEAD = struct.Struct("<HI")  # channel id, length of the (time, offset) pairs
_PAIR = 16


@dataclass(frozen=True)
class RawChunk:
    """One chunk of a file as it is: ``record`` the chunk record (opcode, length, body),
    ``message_indexes`` the message index records that follow it, ``counts`` messages per
    channel id as those indexes list them."""

    index: ChunkIndex
    record: bytes
    message_indexes: bytes
    counts: dict[int, int]


def raw_chunk(f: IO[bytes], ci: ChunkIndex, record: bytes) -> RawChunk | None:
    """The chunk ``ci`` of ``f`` (``record``: its chunk record, already read) with its
    message indexes, or None when they are not one run of well-formed records right after
    the chunk, each pointed to by ``ci`` (then the chunk is written message by message)."""
    start = ci.chunk_start_offset + ci.chunk_length
    f.seek(start)
    data = f.read(ci.message_index_length)
    if (len(record) != ci.chunk_length or len(data) != ci.message_index_length
            or len(record) < _RECORD_HEAD.size
            or _RECORD_HEAD.unpack_from(record) != (_CHUNK, len(record) - _RECORD_HEAD.size)):
        return None
    counts: dict[int, int] = {}
    offsets: dict[int, int] = {}
    pos = 0
    while pos < len(data):
        if pos + 9 + _INDEX_HEAD.size > len(data):
            return None
        op, length = _RECORD_HEAD.unpack_from(data, pos)
        cid, pairs = _INDEX_HEAD.unpack_from(data, pos + 9)
        if (op != _MESSAGE_INDEX or length != _INDEX_HEAD.size + pairs or pairs % _PAIR
                or pos + 9 + length > len(data) or cid in offsets):
            return None
        offsets[cid] = start + pos
        counts[cid] = pairs // _PAIR
        pos += 9 + length
    if offsets != ci.message_index_offsets:
        return None
    return RawChunk(ci, record, data, {c: n for c, n in counts.items() if n})


def ids_problem(summary: Summary) -> str | None:
    """Why the chunks of a file with this summary cannot be copied into a new log whose
    writer numbers schemas and channels 1, 2, ... in the order they are registered, or
    None: the ids must be 1..N, every channel's schema known."""
    if not summary.chunk_indexes:
        return "the log has no chunks"
    if sorted(summary.schemas) != list(range(1, len(summary.schemas) + 1)):
        return "schema ids are not 1..N"
    if sorted(summary.channels) != list(range(1, len(summary.channels) + 1)):
        return "channel ids are not 1..N"
    if any(ch.schema_id and ch.schema_id not in summary.schemas
           for ch in summary.channels.values()):
        return "a channel names an unknown schema"
    return None


def in_sequence(chunks: list[ChunkIndex]) -> bool:
    """The chunks, in file order, follow each other in log time (each starts at or after
    the end of the one before): reading them one after the other gives log-time order."""
    ordered = sorted(chunks, key=lambda ci: ci.chunk_start_offset)
    return all(b.message_start_time >= a.message_end_time for a, b in
               zip(ordered, ordered[1:], strict=False))


def writer_supported(writer: Writer) -> bool:
    """``writer`` (an ``mcap`` package writer) has the private state :func:`append_chunk`
    updates (module doc)."""
    private: Any = writer
    return (isinstance(getattr(private, "_Writer__chunk_indices", None), list)
            and hasattr(private, "_Writer__chunk_builder")
            and callable(getattr(private, "_Writer__flush", None))
            and hasattr(private, "_Writer__statistics")
            and isinstance(getattr(private, "_Writer__enable_data_crcs", None), bool)
            and isinstance(getattr(private, "_Writer__data_section_crc", None), int))


@contextlib.contextmanager
def outside_chunks(writer: Writer) -> Iterator[None]:
    """Within the block, ``writer`` writes schema and channel records into the data
    section, outside chunks, at once: a copied chunk may need them (its input defined
    them outside its chunks), and the writer's chunk in progress, which holds no message
    yet, is written only after a copied chunk (the MCAP specification wants a channel
    before its first message)."""
    private: Any = writer
    builder = private._Writer__chunk_builder
    private._Writer__chunk_builder = None
    try:
        yield
    finally:
        private._Writer__chunk_builder = builder
        private._Writer__flush()


def append_chunk(writer: Writer, stream: IO[bytes], chunk: RawChunk) -> None:
    """Write ``chunk`` (record and message indexes) at the end of ``writer``'s output
    ``stream``, after finishing the writer's own chunk in progress; index it and count its
    messages in the writer's statistics and its bytes in the data-section CRC (module
    doc)."""
    writer.flush()
    start = stream.tell()
    stream.write(chunk.record)
    index_start = stream.tell()
    stream.write(chunk.message_indexes)
    ci = chunk.index
    shift = index_start - (ci.chunk_start_offset + ci.chunk_length)
    private: Any = writer
    if private._Writer__enable_data_crcs:
        private._Writer__data_section_crc = zlib.crc32(
            chunk.message_indexes, zlib.crc32(chunk.record, private._Writer__data_section_crc))
    private._Writer__chunk_indices.append(ChunkIndex(
        message_start_time=ci.message_start_time, message_end_time=ci.message_end_time,
        chunk_start_offset=start, chunk_length=ci.chunk_length,
        message_index_offsets={c: o + shift for c, o in ci.message_index_offsets.items()},
        message_index_length=ci.message_index_length, compression=ci.compression,
        compressed_size=ci.compressed_size, uncompressed_size=ci.uncompressed_size))
    stats = private._Writer__statistics
    stats.chunk_count += 1
    if chunk.counts:
        if stats.message_count == 0:
            stats.message_start_time = ci.message_start_time
        else:
            stats.message_start_time = min(stats.message_start_time, ci.message_start_time)
        stats.message_end_time = max(stats.message_end_time, ci.message_end_time)
    for cid, n in chunk.counts.items():
        stats.channel_message_counts[cid] += n
        stats.message_count += n
