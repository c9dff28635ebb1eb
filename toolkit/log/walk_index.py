"""An index of an MCAP file built from its records, for files whose summary does not say
everything a reader needs.

The MCAP specification makes every part of the summary optional: a valid file may have
no summary section at all, no statistics, no chunk, attachment or metadata indexes,
channels repeated without their schemas, or messages in the data section outside any chunk
(which no index points to). :func:`needs_walk` says whether a summary is enough to read a
file through it; when it is not, :func:`walk_log` reads the file once, record by record
(:mod:`sgtool.log.file_walk`, which trusts nothing), and gives the summary the file would
have had (schemas, channels, statistics, chunk, attachment and metadata indexes) with every
message in log-time order. Damage found on the way is a one-line
:class:`~sgtool.errors.LogFormatError` pointing to ``sgtool doctor``.
"""

from __future__ import annotations

import mmap
from dataclasses import dataclass
from pathlib import Path
from typing import IO

from mcap.opcode import Opcode
from mcap.records import (
    AttachmentIndex,
    Channel,
    ChunkIndex,
    Footer,
    Message,
    Metadata,
    MetadataIndex,
    Schema,
    Statistics,
)
from mcap.summary import Summary

from sgtool.errors import LogFormatError
from sgtool.files import quoted
from sgtool.log.file_walk import ChunkFacts, Layout, walk
from sgtool.log.mcap_records import head
from sgtool.log.summary_check import maybe_empty, read_footer

Entry = tuple[Schema | None, Channel, Message]


@dataclass
class WalkedLog:
    """What a walk of the whole file found: the summary it stands for, every message
    (log-time order, ties in file order) and the metadata records by name."""

    summary: Summary
    messages: list[Entry]
    metadata: dict[str, dict[str, str]]


def needs_walk(summary: Summary | None) -> bool:
    """True when ``summary`` cannot answer for the file alone: it is absent, has no
    statistics or no message counts per channel (an empty map: "not available"), names
    schemas it lacks, counts messages on channels it lacks, indexes a chunk without
    message indexes, or counts more chunks, attachments or metadata records than it
    indexes (so messages outside chunks, or records no index points to, exist)."""
    if summary is None or summary.statistics is None:
        return True
    st = summary.statistics
    if st.message_count and not any(st.channel_message_counts.values()):
        return True
    if st.message_count and any(not c.message_index_offsets and not maybe_empty(c)
                                for c in summary.chunk_indexes):
        return True
    if any(c.schema_id and c.schema_id not in summary.schemas
           for c in summary.channels.values()):
        return True
    if any(n and cid not in summary.channels for cid, n in st.channel_message_counts.items()):
        return True
    return (st.chunk_count != len(summary.chunk_indexes)
            or (st.message_count > 0 and not summary.chunk_indexes)
            or st.attachment_count != len(summary.attachment_indexes)
            or st.metadata_count != len(summary.metadata_indexes))


def loose_messages(f: IO[bytes], size: int, summary: Summary,
                   footer: Footer | None = None) -> bool:
    """True when the data section holds a message (or bytes that are no record) outside
    what ``summary`` indexes: its chunks with the message indexes after them, attachments
    and metadata. Statistics count such messages, no index points to them, so a reader
    going by the indexes alone would lose them. Only the bytes between indexed records are
    read (the header, definitions outside chunks, the data end, as a rule); ``footer``:
    the file's, when read already."""
    footer = footer or read_footer(f, size)
    if footer is None or not footer.summary_start:
        return True
    spans = sorted([(int(c.chunk_start_offset), int(c.chunk_start_offset + c.chunk_length
                                                    + c.message_index_length))
                    for c in summary.chunk_indexes]
                   + [(int(a.offset), int(a.offset + a.length))
                      for a in summary.attachment_indexes]
                   + [(int(m.offset), int(m.offset + m.length))
                      for m in summary.metadata_indexes])
    pos, end = 8, int(footer.summary_start)
    for start, stop in [*spans, (end, end)]:
        while pos < start:  # the records of a gap, read one by one
            f.seek(pos)
            h = head(f.read(9), 0, 9)
            if h is None or h[0] == Opcode.MESSAGE or pos + 9 + h[1] > start:
                return True
            pos += 9 + h[1]
        pos = max(pos, stop)
    return False


def walk_log(path: Path, size: int) -> WalkedLog:
    """Read the whole file at ``path`` (``size`` bytes) and index it (module doc)."""
    lay = Layout(size)
    with open(path, "rb") as f, mmap.mmap(f.fileno(), size, access=mmap.ACCESS_READ) as buf:
        items = list(walk(buf, lay))
    if lay.corrupt or lay.truncated:
        why = lay.problems[0] if lay.problems else "damaged records"
        raise LogFormatError(f"{path}: {why}; `sgtool doctor {quoted(path)}` says what is readable "
                             "and --recover copies it")
    schemas: dict[int, Schema] = {}
    channels: dict[int, Channel] = {}
    for it in sorted(items, key=lambda it: it.source != "data"):  # data section first
        r = it.record
        if isinstance(r, Schema):
            schemas.setdefault(r.id, r)
        elif isinstance(r, Channel):
            channels.setdefault(r.id, r)
    messages: list[Entry] = []
    for it in items:
        m = it.record
        if not isinstance(m, Message):
            continue
        ch = channels.get(m.channel_id)
        if ch is None:
            raise LogFormatError(f"{path}: a message at {m.log_time} ns names channel "
                                 f"{m.channel_id}, defined nowhere; `sgtool doctor {quoted(path)}` "
                                 "says what is readable")
        messages.append((schemas.get(ch.schema_id), ch, m))
    messages.sort(key=lambda e: int(e[2].log_time))
    summary = Summary()
    summary.schemas = schemas
    summary.channels = channels
    summary.chunk_indexes = [_chunk_index(c) for c in lay.chunks]
    data = [r for r in lay.top if not lay.in_summary(r.offset)]
    summary.attachment_indexes = [
        AttachmentIndex(offset=r.offset, length=9 + r.length, log_time=r.record.log_time,
                        create_time=r.record.create_time, data_size=len(r.record.data),
                        name=r.record.name, media_type=r.record.media_type)
        for r in data if r.opcode == Opcode.ATTACHMENT]
    meta = [r for r in data if r.opcode == Opcode.METADATA]
    summary.metadata_indexes = [MetadataIndex(offset=r.offset, length=9 + r.length,
                                              name=r.record.name) for r in meta]
    summary.statistics = _statistics(messages, summary, len(lay.chunks))
    metadata: dict[str, dict[str, str]] = {}
    for r in meta:
        rec: Metadata = r.record
        metadata[rec.name] = dict(rec.metadata)
    return WalkedLog(summary, messages, metadata)


def _chunk_index(c: ChunkFacts) -> ChunkIndex:
    h = c.header
    return ChunkIndex(
        message_start_time=h.message_start_time, message_end_time=h.message_end_time,
        chunk_start_offset=c.offset, chunk_length=9 + c.length,
        message_index_offsets={cid: raw.offset for cid, raw in c.indexes.items()},
        message_index_length=sum(9 + raw.length for raw in c.indexes.values()),
        compression=h.compression, compressed_size=c.compressed_size,
        uncompressed_size=h.uncompressed_size)


def _statistics(messages: list[Entry], summary: Summary, chunks: int) -> Statistics:
    counts: dict[int, int] = {}
    for _, ch, _ in messages:
        counts[ch.id] = counts.get(ch.id, 0) + 1
    times = [int(m.log_time) for _, _, m in messages]
    return Statistics(
        message_count=len(messages), schema_count=len(summary.schemas),
        channel_count=len(summary.channels),
        attachment_count=len(summary.attachment_indexes),
        metadata_count=len(summary.metadata_indexes), chunk_count=chunks,
        message_start_time=min(times, default=0), message_end_time=max(times, default=0),
        channel_message_counts=counts)
