"""Cross-checks of a walked MCAP file, and what its indexes say was lost.

:func:`check` verifies every CRC the file carries that the walk did not (summary section,
data section) and that the summary, the statistics, the chunk, message, attachment and
metadata indexes and the chunk headers agree with the records they describe: a file is
*complete* only when nothing disagrees. :func:`expected_messages` reads, for each chunk,
the messages its indexes say it holds, which is what :mod:`sgtool.log.recover` compares
with what it could read to say what was lost.
"""

from __future__ import annotations

import zlib
from collections import Counter
from dataclasses import dataclass

from mcap.opcode import Opcode
from mcap.records import (
    AttachmentIndex,
    Channel,
    ChunkIndex,
    MetadataIndex,
    Schema,
    Statistics,
    SummaryOffset,
)

from sgtool.log.file_walk import ChunkFacts, Layout, data_crc_matches, message_index_at
from sgtool.log.mcap_records import FileBytes


@dataclass(frozen=True)
class SummaryState:
    """Whether the summary section is there and whether its CRC was checked and right."""

    present: bool
    crc_checked: bool
    crc_ok: bool

    @property
    def trusted(self) -> bool:
        return self.present and (self.crc_ok or not self.crc_checked)


def summary_state(buf: FileBytes, lay: Layout) -> SummaryState:
    if lay.footer is None or not lay.footer[1].summary_start:
        return SummaryState(False, False, False)
    fo, f = lay.footer
    start = int(f.summary_start)
    if not 8 <= start <= fo:
        return SummaryState(False, False, False)
    if not f.summary_crc:
        return SummaryState(True, False, True)
    ok = zlib.crc32(bytes(buf[start:fo + 9 + 16])) == f.summary_crc
    return SummaryState(True, True, ok)


def check(buf: FileBytes, lay: Layout, state: SummaryState) -> list[str]:
    """Everything that disagrees in a file the walk read without damage (empty: the file
    is complete)."""
    out: list[str] = []
    if lay.header is None:
        out.append("no readable header record")
    if lay.data_end is None:
        out.append("no data end record")
    elif lay.data_end.record.data_section_crc and not data_crc_matches(
            buf, lay, lay.data_end.offset, lay.data_end.record.data_section_crc):
        out.append("the data section CRC does not match its bytes")
    if lay.footer is not None and lay.footer[1].summary_start and not state.present:
        out.append(f"the footer's summary start {lay.footer[1].summary_start} is not in "
                   "the file")
    if state.crc_checked and not state.crc_ok:
        out.append("the summary section CRC does not match its bytes (indexes, statistics "
                   "or summary copies are damaged)")
    summary = lay.summary_records()
    for c in lay.chunks:
        out += _chunk_header(c)
    out += _message_indexes(lay)
    out += _summary_copies(lay, summary)
    out += _statistics(lay, summary)
    out += _chunk_indexes(buf, lay, summary)
    out += _record_indexes(lay, summary)
    out += _summary_offsets(lay, summary)
    return out


def _of(records: list, cls: type) -> list:
    return [r.record for r in records if isinstance(r.record, cls)]


def _chunk_header(c: ChunkFacts) -> list[str]:
    h = c.header
    if not c.messages:
        return []
    times = [t for _, t, _ in c.messages]
    if (min(times), max(times)) != (h.message_start_time, h.message_end_time):
        return [f"chunk at byte {c.offset}: its header says messages from "
                f"{h.message_start_time} to {h.message_end_time} ns, it holds "
                f"{min(times)} to {max(times)} ns"]
    return []


def _message_indexes(lay: Layout) -> list[str]:
    if not any(c.indexes for c in lay.chunks):
        return []  # a file written without message indexes
    out = []
    for c in lay.chunks:
        held: dict[int, set[tuple[int, int]]] = {}
        for cid, t, off in c.messages:
            held.setdefault(cid, set()).add((t, off))
        indexed = {cid: {(int(t), int(o)) for t, o in raw.record.records}
                   for cid, raw in c.indexes.items()}
        if {k: v for k, v in indexed.items() if v} != held:
            out.append(f"chunk at byte {c.offset}: its message indexes do not match the "
                       "messages it holds")
    return out


def _summary_copies(lay: Layout, summary: list) -> list[str]:
    """Summary copies that differ from the data section's definition or are missing from
    it (a writer may define a channel without messages in the summary only), and summary
    channels whose schema is defined nowhere. The summary may repeat the channels without
    their schemas (the specification makes each group optional): readers then take the
    schemas from the data section."""
    out = []
    s_schemas = {s.id for s in _of(summary, Schema)} | set(lay.schemas)
    s_channels = {c.id: c for c in _of(summary, Channel)}
    if s_channels:
        for cid in sorted(set(lay.channels) - set(s_channels)):
            out.append(f"channel {cid} of the data section is missing from the summary")
        for c in s_channels.values():
            if c.schema_id and c.schema_id not in s_schemas:
                out.append(f"summary channel {c.id} ({c.topic!r}) names schema "
                           f"{c.schema_id}, which is defined nowhere")
    for s in _of(summary, Schema):
        d = lay.schemas.get(s.id)
        if d is not None and (d.name, d.encoding, bytes(d.data)) != (s.name, s.encoding,
                                                                bytes(s.data)):
            out.append(f"summary copy of schema {s.id} ({s.name!r}) differs from the data")
    for s in _of(summary, Channel):
        d = lay.channels.get(s.id)
        if d is not None and (d.schema_id, d.topic, d.message_encoding, dict(d.metadata)) != (
                s.schema_id, s.topic, s.message_encoding, dict(s.metadata)):
            out.append(f"summary copy of channel {s.id} ({s.topic!r}) differs from the data")
    return out


def _statistics(lay: Layout, summary: list) -> list[str]:
    stats = _of(summary, Statistics)
    if not stats:
        return []
    st = stats[0]
    msgs = [(cid, t) for c in lay.chunks for cid, t, _ in c.messages]
    msgs += [(cid, t) for cid, t, _ in lay.loose]
    counts = Counter(cid for cid, _ in msgs)
    attachments = sum(r.opcode == Opcode.ATTACHMENT and not lay.in_summary(r.offset)
                      for r in lay.top)
    metadata = sum(r.opcode == Opcode.METADATA and not lay.in_summary(r.offset)
                   for r in lay.top)
    # (schema and channel counts are not compared: writers count them differently)
    want = {
        "message_count": len(msgs), "chunk_count": len(lay.chunks),
        "attachment_count": attachments, "metadata_count": metadata,
    }
    out = [f"statistics: {k} is {getattr(st, k)}, the file holds {v}"
           for k, v in want.items() if getattr(st, k) != v]
    if st.channel_message_counts and \
            {k: v for k, v in st.channel_message_counts.items() if v} != dict(counts):
        out.append("statistics: message counts per channel differ from the file")
    if msgs and (st.message_start_time, st.message_end_time) != (
            min(t for _, t in msgs), max(t for _, t in msgs)):
        out.append(f"statistics: time range {st.message_start_time} .. "
                   f"{st.message_end_time} ns differs from the messages")
    return out


def _chunk_indexes(buf: FileBytes, lay: Layout, summary: list) -> list[str]:
    idx = _of(summary, ChunkIndex)
    if not idx:
        return []
    by_offset = {c.offset: c for c in lay.chunks}
    out = []
    if len(idx) != len(lay.chunks):
        out.append(f"{len(idx)} chunk indexes for {len(lay.chunks)} chunks")
    for ci in idx:
        c = by_offset.get(int(ci.chunk_start_offset))
        if c is None:
            out.append(f"chunk index points to byte {ci.chunk_start_offset}: no chunk there")
            continue
        h = c.header
        if (ci.chunk_length, ci.message_start_time, ci.message_end_time, ci.compression,
                ci.compressed_size, ci.uncompressed_size) != (
                9 + c.length, h.message_start_time, h.message_end_time, h.compression,
                c.compressed_size, h.uncompressed_size):
            out.append(f"chunk index of the chunk at byte {c.offset} disagrees with it")
        for cid, off in ci.message_index_offsets.items():
            raw = c.indexes.get(cid)
            if raw is None or raw.offset != off:
                out.append(f"chunk index of the chunk at byte {c.offset}: no message index "
                           f"of channel {cid} at byte {off}")
        span = sum(9 + r.length for r in c.indexes.values())
        if c.indexes and ci.message_index_length != span:
            out.append(f"chunk index of the chunk at byte {c.offset}: message index length "
                       f"{ci.message_index_length}, the indexes take {span} bytes")
    return out


def _record_indexes(lay: Layout, summary: list) -> list[str]:
    out = []
    data = {r.offset: r for r in lay.top if not lay.in_summary(r.offset)}
    att = [r for r in data.values() if r.opcode == Opcode.ATTACHMENT]
    a_idx = _of(summary, AttachmentIndex)
    if a_idx and len(a_idx) != len(att):
        out.append(f"{len(a_idx)} attachment indexes for {len(att)} attachments")
    for ai in a_idx:
        r = data.get(int(ai.offset))
        a = r.record if r is not None and r.opcode == Opcode.ATTACHMENT else None
        if r is None or a is None or (
                (ai.length, ai.name, ai.media_type, ai.log_time, ai.create_time, ai.data_size)
                != (9 + r.length, a.name, a.media_type, a.log_time, a.create_time, len(a.data))):
            out.append(f"attachment index {ai.name!r} disagrees with the attachment at "
                       f"byte {ai.offset}")
    meta = [r for r in data.values() if r.opcode == Opcode.METADATA]
    m_idx = _of(summary, MetadataIndex)
    if m_idx and len(m_idx) != len(meta):
        out.append(f"{len(m_idx)} metadata indexes for {len(meta)} metadata records")
    for mi in m_idx:
        r = data.get(int(mi.offset))
        if r is None or r.opcode != Opcode.METADATA or (mi.length, mi.name) != (
                9 + r.length, r.record.name):
            out.append(f"metadata index {mi.name!r} disagrees with the record at byte "
                       f"{mi.offset}")
    return out


def _summary_offsets(lay: Layout, summary: list) -> list[str]:
    groups: dict[int, tuple[int, int]] = {}
    for r in summary:
        if r.opcode == Opcode.SUMMARY_OFFSET:
            continue
        start, end = groups.get(r.opcode, (r.offset, r.end))
        groups[r.opcode] = (min(start, r.offset), max(end, r.end))
    out = []
    offsets = [r for r in summary if r.opcode == Opcode.SUMMARY_OFFSET]
    for so in (r.record for r in offsets):
        assert isinstance(so, SummaryOffset)
        g = groups.get(so.group_opcode)
        if g is None and so.group_length == 0:
            continue  # the mcap writer lists empty groups (a log with no attachments)
        if g is None or (so.group_start, so.group_length) != (g[0], g[1] - g[0]):
            out.append(f"summary offset of opcode 0x{so.group_opcode:02x} disagrees with "
                       "the summary")
    if lay.footer is not None and lay.footer[1].summary_offset_start:
        first = offsets[0].offset if offsets else None
        if lay.footer[1].summary_offset_start != first:
            out.append("the footer's summary offset start does not point to the summary "
                       "offsets")
    return out


def expected_messages(buf: FileBytes, lay: Layout, state: SummaryState
                      ) -> dict[int, list[tuple[int, int]]]:
    """For each chunk (by offset) the (channel id, log time) of every message its indexes
    say it holds: from the summary's chunk indexes when the summary is trusted, else from
    the message indexes that follow the chunk. Chunks without an index are absent."""
    out: dict[int, list[tuple[int, int]]] = {}
    if state.trusted:
        for ci in _of(lay.summary_records(), ChunkIndex):
            entries: list[tuple[int, int]] = []
            for cid, off in ci.message_index_offsets.items():
                mi = message_index_at(buf, off, lay.size)
                if mi is not None and mi.channel_id == cid:
                    entries += [(int(cid), int(t)) for t, _ in mi.records]
            out[int(ci.chunk_start_offset)] = entries
    for c in lay.chunks:
        if c.offset not in out and c.indexes:
            out[c.offset] = [(int(cid), int(t)) for cid, raw in c.indexes.items()
                             for t, _ in raw.record.records]
    return out
