"""Messages of an indexed MCAP file in log-time order, read chunk by chunk without a heap.

The ``mcap`` package's :meth:`~mcap.reader.SeekingReader.iter_messages` puts every message
of every chunk through a Python heap to merge chunks by log time. A log written by one
writer (every sgtool log) has chunks that follow each other in time, so the merge is
almost always a concatenation. :func:`ordered_messages` gives exactly the order of
``iter_messages(log_time_order=True)`` (log time, then chunk offset, then position in the
chunk) at a fraction of the cost: chunks are visited by (start time, offset) and the
messages read so far are handed out, sorted, as soon as no chunk still to be read can hold
an earlier one (a single sort of an already sorted list when chunks do not overlap).

Chunk CRCs are checked only with ``verify=True`` (every ``sgtool replay`` unless
``--no-verify``; ``sgtool doctor`` always checks every CRC through
:mod:`sgtool.log.file_check`). Lengths are
checked against the chunk before they are used; any damage raises an exception that the
reader (``LogReader._checked``) turns into its one-line
:class:`~sgtool.errors.LogFormatError` pointing to ``sgtool doctor``.
"""

from __future__ import annotations

import functools
import struct
import sys
import zlib
from collections.abc import Iterator
from typing import IO, Any

from mcap.records import Channel, ChunkIndex, Message, Schema
from mcap.summary import Summary


class ChunkError(ValueError):
    """Damage found in a chunk (the reader words it as a LogFormatError)."""


_MESSAGE = 0x05
_CHUNK_HEAD = struct.Struct("<QQQI")  # start time, end time, uncompressed size, crc
_RECORD_HEAD = struct.Struct("<BQ")
_MESSAGE_HEAD = struct.Struct("<HIQQ")  # channel, sequence, log time, publish time
MAX_CHUNK_BYTES = 1 << 31  # an uncompressed chunk larger than this is damage

Item = tuple[Schema | None, Channel, Message]
_Key = tuple[int, int, int]  # log time, chunk offset, position in the chunk


@functools.cache
def _zstd() -> Any:
    import zstandard

    return zstandard.ZstdDecompressor()


def chunk_records(f: IO[bytes], ci: ChunkIndex, verify: bool,
                  buffers: ChunkBuffers | None = None) -> bytes | memoryview:
    """The uncompressed records of the chunk that ``ci`` points to (CRC checked when
    ``verify`` and the writer wrote one); ``buffers`` as in :func:`chunk_data`."""
    return chunk_data(read_chunk(f, ci), ci, verify, buffers)


class ChunkBuffers:
    """Buffers that zstd chunks are decompressed into and reused once nothing refers to
    them any more: a fresh buffer for every chunk costs more than the decompression when
    the caller allocates images between chunks (the freed pages go back to the system and
    are faulted in again). For callers that take the messages as views
    (``ordered_messages(views=True)``); a buffer stays taken while any view of it lives
    (a bytearray with views cannot change size: :func:`_unexported`; the reference count
    alone would depend on the interpreter's version). Chunks above ``max_bytes`` are
    not pooled (a reader keeps at most ``keep`` buffers while it is open)."""

    def __init__(self, keep: int = 4, max_bytes: int = 32 << 20) -> None:
        self._keep = keep
        self._max_bytes = max_bytes
        self._buffers: list[bytearray] = []

    def take(self, size: int) -> bytearray | None:
        """A buffer of at least ``size`` bytes that nothing refers to, or None when
        ``keep`` buffers are all in use or ``size`` is above ``max_bytes``."""
        if size > self._max_bytes:
            return None
        for i in range(len(self._buffers)):
            # free: no view of it lives, and no one holds it but the list and the call
            if _unexported(self._buffers[i]) and sys.getrefcount(self._buffers[i]) <= 2:
                if len(self._buffers[i]) < size:
                    self._buffers[i] = bytearray(size)
                return self._buffers[i]
        if len(self._buffers) < self._keep:
            self._buffers.append(bytearray(size))
            return self._buffers[-1]
        return None


def _unexported(buf: bytearray) -> bool:
    """No view of ``buf`` lives (a memoryview, or an array made from one): a bytearray
    with views refuses to change size. The first check of a buffer may reallocate it once
    (it has no room to grow yet); later ones do not."""
    try:
        buf.append(0)
    except BufferError:
        return False
    del buf[-1]
    return True


def _zstd_into(data: memoryview, size: int, buffers: ChunkBuffers | None
               ) -> bytes | memoryview:
    """``data`` decompressed (at most ``size`` bytes: more is damage, a shorter result is
    checked by the caller), into a reused buffer when ``buffers`` has one free."""
    buf = buffers.take(size) if buffers is not None else None
    if buf is None:
        return _zstd().decompress(data, max_output_size=size)
    out = memoryview(buf)[:size]
    reader = _zstd().stream_reader(data, read_size=len(data))
    got = 0
    while got < size:
        n = reader.readinto(out[got:])
        if n == 0:
            break
        got += n
    if reader.read(1):
        raise ChunkError(f"more than the {size} bytes the chunk header says")
    return out[:got]


def read_chunk(f: IO[bytes], ci: ChunkIndex) -> bytes:
    """The chunk record that ``ci`` points to, as it is in the file (opcode, length, body;
    :func:`chunk_data` decompresses it). The summary check has already bounded
    ``ci.chunk_length`` by the file size."""
    f.seek(ci.chunk_start_offset)
    record = f.read(ci.chunk_length)
    if len(record) < 9 + _CHUNK_HEAD.size + 4 or record[0] != 0x06:
        raise ChunkError(f"no chunk record at byte {ci.chunk_start_offset}")
    return record


def chunk_data(record: bytes, ci: ChunkIndex, verify: bool,
               buffers: ChunkBuffers | None = None) -> bytes | memoryview:
    """The uncompressed records of a chunk record of :func:`read_chunk` (CRC checked when
    ``verify`` and the writer wrote one); zstd chunks into one of ``buffers`` (a
    ``memoryview`` then) when given and one is free."""
    _, _, size, crc = _CHUNK_HEAD.unpack_from(record, 9)
    pos = 9 + _CHUNK_HEAD.size
    (name_len,) = struct.unpack_from("<I", record, pos)
    if name_len > 16 or pos + 4 + name_len + 8 > len(record):
        raise ChunkError(f"chunk at byte {ci.chunk_start_offset}: bad compression name")
    compression = str(record[pos + 4:pos + 4 + name_len], "ascii", "replace")
    pos += 4 + name_len
    (data_len,) = struct.unpack_from("<Q", record, pos)
    pos += 8
    if data_len > ci.chunk_length or size > MAX_CHUNK_BYTES:
        raise ChunkError(f"chunk at byte {ci.chunk_start_offset}: lengths do not fit")
    if pos + data_len > len(record):
        raise ChunkError(f"chunk at byte {ci.chunk_start_offset} is cut short")
    stored = memoryview(record)[pos:pos + data_len]
    data: bytes | memoryview
    if compression == "zstd":
        data = _zstd_into(stored, size, buffers)
    elif compression == "lz4":
        import lz4.frame

        data = lz4.frame.decompress(stored)
    elif compression:
        raise ChunkError(f"chunk at byte {ci.chunk_start_offset}: unknown compression "
                             f"{compression[:16]!r}")
    else:
        data = bytes(stored)
    if len(data) != size:
        raise ChunkError(f"chunk at byte {ci.chunk_start_offset}: {len(data)} bytes "
                             f"uncompressed, its header says {size}")
    if verify and crc != 0 and zlib.crc32(data) != crc:
        raise ChunkError(f"chunk at byte {ci.chunk_start_offset}: CRC mismatch")
    return data


def _messages_of(data: bytes | memoryview, offset: int, summary: Summary, wanted: set[int] | None,
                 start_ns: int | None, end_ns: int | None, views: bool = False
                 ) -> list[tuple[_Key, Item]]:
    out: list[tuple[_Key, Item]] = []
    payload: bytes | memoryview = memoryview(data) if views else data
    pos, n, index = 0, len(data), 0
    channels, schemas = summary.channels, summary.schemas
    while pos < n:
        op, length = _RECORD_HEAD.unpack_from(data, pos)
        body = pos + 9
        pos = body + length
        if pos > n:
            raise ChunkError(f"chunk at byte {offset}: a record runs past its end")
        if op != _MESSAGE:
            index += 1
            continue
        if length < _MESSAGE_HEAD.size:
            raise ChunkError(f"chunk at byte {offset}: a message record is too short")
        cid, seq, t, pub = _MESSAGE_HEAD.unpack_from(data, body)
        channel = channels[cid]  # KeyError: a message on an undefined channel
        if ((wanted is None or cid in wanted) and (start_ns is None or t >= start_ns)
                and (end_ns is None or t < end_ns)):
            schema = schemas[channel.schema_id] if channel.schema_id else None
            # with views, data is a memoryview where mcap's Message declares bytes
            msg = Message(channel_id=cid, sequence=seq, log_time=t, publish_time=pub,
                          data=payload[body + _MESSAGE_HEAD.size:pos])  # type: ignore[arg-type]
            out.append(((t, offset, index), (schema, channel, msg)))
        index += 1
    return out


def _chunks_of(summary: Summary, topics: list[str] | None, start_ns: int | None,
               end_ns: int | None) -> tuple[set[int] | None, list[ChunkIndex]]:
    """(the channel ids of ``topics``, None for all; the chunks that may hold their
    messages with ``start_ns <= log time < end_ns``), in index order."""
    wanted = None if topics is None else {
        cid for cid, ch in summary.channels.items() if ch.topic in set(topics)}
    return wanted, [ci for ci in summary.chunk_indexes
                    if (wanted is None or not ci.message_index_offsets
                        or wanted & ci.message_index_offsets.keys())
                    and (start_ns is None or ci.message_end_time >= start_ns)
                    and (end_ns is None or ci.message_start_time < end_ns)]


def ordered_messages(f: IO[bytes], summary: Summary, topics: list[str] | None = None, *,
                     start_ns: int | None = None, end_ns: int | None = None,
                     verify: bool = False, views: bool = False,
                     buffers: ChunkBuffers | None = None) -> Iterator[Item]:
    """(schema, channel, message) of the chunked messages on ``topics`` (all when None)
    with ``start_ns <= log time < end_ns``, in the order of the ``mcap`` reader's
    ``iter_messages(log_time_order=True)`` (module doc). With ``views`` a message's
    ``data`` is a read-only ``memoryview`` into its chunk instead of a copy (for callers
    that parse it at once: an image is then copied once, by the parser, not twice), and
    with ``buffers`` too the chunks are decompressed into reused buffers."""
    wanted, chunks = _chunks_of(summary, topics, start_ns, end_ns)
    chunks.sort(key=lambda ci: (ci.message_start_time, ci.chunk_start_offset))
    pending: list[tuple[_Key, Item]] = []
    for j, ci in enumerate(chunks):
        data = chunk_records(f, ci, verify, buffers if views else None)
        pending.extend(_messages_of(data, ci.chunk_start_offset,
                                    summary, wanted, start_ns, end_ns, views))
        pending.sort(key=lambda e: e[0])
        if j + 1 < len(chunks):
            nxt = chunks[j + 1]
            bound = (nxt.message_start_time, nxt.chunk_start_offset, -1)
            cut = len(pending)
            while cut and pending[cut - 1][0] > bound:
                cut -= 1
        else:
            cut = len(pending)
        for _, item in pending[:cut]:
            yield item
        del pending[:cut]


def reversed_messages(f: IO[bytes], summary: Summary, topics: list[str] | None = None, *,
                      start_ns: int | None = None, end_ns: int | None = None,
                      verify: bool = False) -> Iterator[Item]:
    """The messages of :func:`ordered_messages` in exactly the reverse order, read chunk by
    chunk from the chunk that ends last (the ``mcap`` reader's reverse read parses a chunk
    with a record parser of its own, which loses the messages after a schema or channel
    record that a newer writer extended)."""
    wanted, chunks = _chunks_of(summary, topics, start_ns, end_ns)
    chunks.sort(key=lambda ci: (ci.message_end_time, ci.chunk_start_offset), reverse=True)
    pending: list[tuple[_Key, Item]] = []
    for j, ci in enumerate(chunks):
        data = chunk_records(f, ci, verify, None)
        pending.extend(_messages_of(data, ci.chunk_start_offset, summary, wanted, start_ns,
                                    end_ns))
        pending.sort(key=lambda e: e[0], reverse=True)
        cut = len(pending)
        if j + 1 < len(chunks):  # what a chunk still to be read may hold comes after
            nxt = chunks[j + 1]
            bound = (nxt.message_end_time, nxt.chunk_start_offset, sys.maxsize)
            cut = 0
            while cut < len(pending) and pending[cut][0] > bound:
                cut += 1
        for _, item in pending[:cut]:
            yield item
        del pending[:cut]


def chunk_messages(data: bytes | memoryview, ci: ChunkIndex, summary: Summary, views: bool = False
                   ) -> list[Item]:
    """(schema, channel, message) of every message of one chunk (``data``: its
    uncompressed records), in log-time order, ties in chunk order: the order
    :func:`ordered_messages` gives them when no other chunk overlaps this one in time."""
    found = _messages_of(data, ci.chunk_start_offset, summary, None, None, None, views)
    found.sort(key=lambda e: e[0])
    return [item for _, item in found]
