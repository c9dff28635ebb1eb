"""Rewrite an MCAP file into valid variants the specification allows and sgtool's own
writer never makes: messages of some channels (or the last ones) outside chunks (with a
full summary), records of an application's opcode (0x80-0xFF) between records and inside
chunks, schema, channel and data-end records with fields a newer writer appends, small
chunks, an empty chunk, definitions outside chunks, chunk indexes without message
indexes, statistics without counts per channel, messages in another order. Every variant
holds the same schemas, channels, messages, attachments and metadata as its source."""

from __future__ import annotations

import struct
import zlib
from collections import defaultdict
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from pathlib import Path

import mcap.records as R
import zstandard
from mcap.data_stream import RecordBuilder
from mcap.opcode import Opcode
from mcap.reader import make_reader

MAGIC = bytes([137, 77, 67, 65, 80, 48, 13, 10])
def extension(opcode: int) -> bytes:
    """A record of an application's ``opcode`` (0x80-0xFF): 7 bytes of its own."""
    return struct.pack("<BQ", opcode, 7) + b"\x07" * 7


@dataclass
class Variant:
    """What to change: ``loose`` topics are written outside chunks; ``extension`` puts an
    application's record after every data-section record (``"data"``) or before every
    message in a chunk (``"chunk"``); ``extend`` appends bytes to every schema, channel
    and data-end record; ``chunk_messages`` messages per chunk; ``order`` reorders the
    messages before they are written; ``loose_last`` writes that many last messages
    outside chunks; ``empty_chunk`` writes a chunk of no message (times 0) first;
    ``outside`` writes schema and channel records outside chunks; ``message_indexes``
    False writes chunk indexes without them; ``channel_counts`` False leaves the
    statistics' counts per channel empty ("not available")."""

    loose: frozenset[str] = frozenset()
    loose_last: int = 0
    empty_chunk: bool = False
    outside: bool = False
    message_indexes: bool = True
    channel_counts: bool = True
    extension: str = ""
    extension_opcode: int = 0xFF
    extend: int = 0
    chunk_messages: int = 50
    order: Callable[[list[R.Message]], list[R.Message]] | None = None


def _bytes(rec: object, extend: int = 0) -> bytes:
    b = RecordBuilder()
    rec.write(b)  # type: ignore[attr-defined]
    out = b.end()
    if not extend:
        return out
    opcode, length = struct.unpack_from("<BQ", out, 0)
    return struct.pack("<BQ", opcode, length + extend) + out[9:] + b"\xab" * extend


@dataclass
class _Writer:
    path: Path
    v: Variant
    out: bytearray = field(default_factory=bytearray)
    chunk: list[bytes] = field(default_factory=list)
    index: dict[int, list[tuple[int, int]]] = field(default_factory=dict)
    times: list[int] = field(default_factory=list)
    defined: set[tuple[str, int]] = field(default_factory=set)
    chunk_indexes: list[R.ChunkIndex] = field(default_factory=list)

    def top(self, rec_bytes: bytes) -> int:
        at = len(self.out)
        self.out += rec_bytes
        if self.v.extension == "data":
            self.out += extension(self.v.extension_opcode)
        return at

    def define(self, schemas: dict, ch: object, sink: Callable[[bytes], object]) -> None:
        sid = ch.schema_id  # type: ignore[attr-defined]
        if sid and ("s", sid) not in self.defined:
            sink(_bytes(schemas[sid], self.v.extend))
            self.defined.add(("s", sid))
        if ("c", ch.id) not in self.defined:  # type: ignore[attr-defined]
            sink(_bytes(ch, self.v.extend))
            self.defined.add(("c", ch.id))  # type: ignore[attr-defined]

    def flush(self) -> None:
        if not self.chunk:
            return
        data = b"".join(self.chunk)
        packed = zstandard.ZstdCompressor().compress(data)
        rec = _bytes(_chunk(min(self.times), max(self.times), data, packed))
        start = self.top(rec)
        offsets, mi = {}, bytearray()
        for cid, entries in sorted(self.index.items()) if self.v.message_indexes else ():
            offsets[cid] = len(self.out) + len(mi)
            mi += _bytes(R.MessageIndex(channel_id=cid, records=entries))
        self.out += mi
        self.chunk_indexes.append(R.ChunkIndex(
            message_start_time=min(self.times), message_end_time=max(self.times),
            chunk_start_offset=start, chunk_length=len(rec), message_index_offsets=offsets,
            message_index_length=len(mi), compression="zstd", compressed_size=len(packed),
            uncompressed_size=len(data)))
        self.chunk, self.index, self.times = [], {}, []


def _chunk(start: int, end: int, data: bytes, packed: bytes) -> object:
    return R.Chunk(message_start_time=start, message_end_time=end,
                 uncompressed_size=len(data), uncompressed_crc=zlib.crc32(data),
                 compression="zstd", data=packed)


def rewrite(src: Path, dst: Path, v: Variant) -> Path:
    """``src`` rewritten as variant ``v`` into ``dst`` (module doc)."""
    with open(src, "rb") as f:
        r = make_reader(f)
        header = r.get_header()
        summary = r.get_summary()
        assert summary is not None
        messages = [m for _, _, m in r.iter_messages(log_time_order=False)]
        attachments = list(r.iter_attachments())
        metadata = list(r.iter_metadata())
    schemas, channels = dict(summary.schemas), dict(summary.channels)
    if v.order is not None:
        messages = v.order(messages)
    w = _Writer(dst, v)
    w.out += MAGIC
    w.top(_bytes(R.Header(profile=header.profile, library=header.library)))
    if v.empty_chunk:
        packed = zstandard.ZstdCompressor().compress(b"")
        rec = _bytes(_chunk(0, 0, b"", packed))
        w.chunk_indexes.append(R.ChunkIndex(
            message_start_time=0, message_end_time=0, chunk_start_offset=w.top(rec),
            chunk_length=len(rec), message_index_offsets={}, message_index_length=0,
            compression="zstd", compressed_size=len(packed), uncompressed_size=0))
    stats = R.Statistics(message_count=0, schema_count=len(schemas), channel_count=len(channels),
                       attachment_count=len(attachments), metadata_count=len(metadata),
                       chunk_count=0, message_start_time=min(m.log_time for m in messages),
                       message_end_time=max(m.log_time for m in messages),
                       channel_message_counts=defaultdict(int))
    for i, m in enumerate(messages):
        ch = channels[m.channel_id]
        stats.message_count += 1
        stats.channel_message_counts[m.channel_id] += 1
        if ch.topic in v.loose or i >= len(messages) - v.loose_last:
            w.flush()
            w.define(schemas, ch, w.top)
            w.top(_bytes(m))
            continue
        w.define(schemas, ch, w.top if v.outside else w.chunk.append)
        if v.extension == "chunk":
            w.chunk.append(extension(v.extension_opcode))
        at = sum(len(b) for b in w.chunk)
        w.index.setdefault(m.channel_id, []).append((m.log_time, at))
        w.chunk.append(_bytes(m))
        w.times.append(m.log_time)
        if len(w.times) >= v.chunk_messages:
            w.flush()
    w.flush()
    att_idx = []
    for a in attachments:
        rec = _bytes(a)
        att_idx.append(R.AttachmentIndex(offset=w.top(rec), length=len(rec),
                                       log_time=a.log_time, create_time=a.create_time,
                                       data_size=len(a.data), name=a.name,
                                       media_type=a.media_type))
    meta_idx = []
    for md in metadata:
        rec = _bytes(md)
        meta_idx.append(R.MetadataIndex(offset=w.top(rec), length=len(rec), name=md.name))
    stats.chunk_count = len(w.chunk_indexes)
    if not v.channel_counts:
        stats.channel_message_counts = {}
    w.out += _bytes(R.DataEnd(data_section_crc=0), v.extend)
    start = len(w.out)
    groups: list[tuple[int, Iterable[object]]] = [
        (Opcode.SCHEMA, schemas.values()), (Opcode.CHANNEL, channels.values()),
        (Opcode.STATISTICS, [stats]), (Opcode.CHUNK_INDEX, w.chunk_indexes),
        (Opcode.ATTACHMENT_INDEX, att_idx), (Opcode.METADATA_INDEX, meta_idx)]
    offsets = []
    for opcode, recs in groups:
        at = len(w.out)
        for rec in recs:
            w.out += _bytes(rec)
        if len(w.out) > at:
            offsets.append(R.SummaryOffset(group_opcode=opcode, group_start=at,
                                         group_length=len(w.out) - at))
    offset_start = len(w.out)
    for so in offsets:
        w.out += _bytes(so)
    w.out += _bytes(R.Footer(summary_start=start, summary_offset_start=offset_start,
                           summary_crc=0))
    w.out += MAGIC
    dst.write_bytes(bytes(w.out))
    return dst


def channel_ids(path: Path, topic: str) -> set[int]:
    """The ids of the channels of ``topic`` in the MCAP file ``path`` (its summary's)."""
    with open(path, "rb") as f:
        summary = make_reader(f).get_summary()
    assert summary is not None
    return {cid for cid, c in summary.channels.items() if c.topic == topic}


def without(src: Path, dst: Path, topic: str) -> Path:
    """``src`` with every message of ``topic`` left out (its channel kept)."""
    gone = channel_ids(src, topic)
    return rewrite(src, dst, Variant(order=lambda ms: [m for m in ms
                                                       if m.channel_id not in gone]))
