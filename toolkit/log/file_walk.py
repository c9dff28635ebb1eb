"""Walking an MCAP file record by record without trusting it.

:func:`walk` yields every readable schema, channel, message, attachment and metadata record
of a file (those inside chunks, and messages outside them) and fills a :class:`Layout`
with where everything was and what went wrong. It never stops at damage: a record that
does not parse is skipped up to the next valid record (resynchronisation), a record whose
length field is damaged is read up to where the next record starts, a chunk whose
compressed data is cut or damaged gives the messages decoded before the damage
(``salvaged``), and the records after the data section (summary copies of schemas and
channels, indexes, statistics) are kept for the cross-checks of
:mod:`sgtool.log.file_check`.
"""

from __future__ import annotations

import zlib
from collections.abc import Generator, Iterator
from dataclasses import dataclass, field
from typing import Any, Literal

from mcap.opcode import Opcode
from mcap.records import Channel, Chunk, Footer, Header, Message, MessageIndex, Schema

from sgtool.log.mcap_records import (
    MAGIC,
    FileBytes,
    Raw,
    RecordError,
    chunk_prefix,
    decompress,
    footer_at_end,
    head,
    inner_records,
    next_record_start,
    parse_body,
    read_record,
    trailing_is_damage,
)

Source = Literal["data", "summary", "salvaged"]
_MAX_CHUNK = 1 << 31  # uncompressed bytes one chunk may decode to


@dataclass
class ChunkFacts:
    """A chunk record found at ``offset`` and what could be read of it."""

    offset: int
    length: int  # body length of the record
    header: Chunk  # its header fields (``data`` emptied)
    compressed_size: int
    decoded: int = 0  # uncompressed bytes decoded
    messages: list[tuple[int, int, int]] = field(default_factory=list)  # channel, time, offset
    intact: bool = False  # CRC (when written) right, every record read
    salvaged: bool = False  # messages kept from a damaged chunk, not covered by its CRC
    indexes: dict[int, Raw] = field(default_factory=dict)  # message indexes after it


@dataclass
class Layout:
    """Where the records of a file are and what is wrong with them."""

    size: int
    header: Header | None = None
    footer: tuple[int, Footer] | None = None
    chunks: list[ChunkFacts] = field(default_factory=list)
    # messages of the data section outside any chunk (the specification allows them):
    # channel, log time, offset
    loose: list[tuple[int, int, int]] = field(default_factory=list)
    top: list[Raw] = field(default_factory=list)  # records outside chunks, in file order
    data_end: Raw | None = None
    schemas: dict[int, Any] = field(default_factory=dict)  # of the data section, by id
    channels: dict[int, Any] = field(default_factory=dict)
    problems: list[str] = field(default_factory=list)
    corrupt: bool = False
    truncated: bool = False
    last_good_offset: int = 8
    trusted_summary_start: int | None = None
    # data-section CRCs checked: the offset of the data end record -> its CRC matched
    # (one pass over the bytes per offset, whoever asks: :func:`data_crc_matches`)
    data_crcs: dict[int, bool] = field(default_factory=dict)

    def define(self, rec: Schema | Channel) -> None:
        """Note a schema or channel of the data section (the first definition of an id)."""
        (self.schemas if isinstance(rec, Schema) else self.channels).setdefault(rec.id, rec)

    def damaged(self, problem: str) -> None:
        self.corrupt = True
        self.problems.append(problem)

    def summary_records(self) -> list[Raw]:
        """The records after the data end (or after the footer's summary start)."""
        start = self._summary_start()
        return [r for r in self.top if start is not None and r.offset >= start]

    def _summary_start(self) -> int | None:
        """The data end record's end, else the footer's summary start when its CRC
        vouches for it (a damaged footer must not turn data records into summary ones)."""
        if self.data_end is not None:
            return self.data_end.end
        return self.trusted_summary_start

    def in_summary(self, pos: int) -> bool:
        start = self._summary_start()
        return start is not None and pos >= start


@dataclass(frozen=True)
class Item:
    """A record read by :func:`walk`; ``covered``: a message whose bytes a CRC vouches
    for, that of its chunk or, outside chunks, the data section's
    (:func:`data_section_verified`); False for the messages of a damaged chunk or of a
    chunk written without a CRC."""

    record: Any  # Schema | Channel | Message | Attachment | Metadata
    source: Source
    covered: bool = False


def walk(buf: FileBytes, lay: Layout) -> Iterator[Item]:
    """Every readable record of ``buf`` (a whole MCAP file); ``lay`` says the rest."""
    size = lay.size
    lay.footer = footer_at_end(buf, size)
    end = lay.footer[0] if lay.footer is not None else size
    if lay.footer is not None:
        f = lay.footer[1]
        if 8 <= f.summary_start <= end and f.summary_crc and f.summary_crc == zlib.crc32(
                bytes(buf[f.summary_start:end + 9 + 16])):
            lay.trusted_summary_start = int(f.summary_start)
    loose_covered = data_section_verified(buf, lay)
    pos = 8
    while pos < end:
        if pos == size - 8 and bytes(buf[pos:size]) == MAGIC:
            lay.damaged(f"closing magic at byte {pos} without a footer before it")
            pos = size
            break
        raw: Raw | None
        try:
            raw = read_record(buf, pos, end)
            if trailing_is_damage(buf, raw, end):
                raise RecordError(f"{raw.trailing} bytes after its fields look like damage")
        except RecordError as e:
            raw = yield from _after_damage(buf, pos, end, lay, str(e))
            if raw is None:
                break
        if raw.opcode == Opcode.CHUNK:
            yield from _chunk(raw.offset, raw.length, raw.record, lay)
        else:
            yield from _top(raw, lay, loose_covered)
        pos = raw.end
        lay.last_good_offset = pos
    if lay.footer is not None and pos == end:
        lay.last_good_offset = size
    elif not lay.truncated and not lay.corrupt:
        lay.truncated = True
        lay.problems.append("no footer: the file was not closed (writer killed or still "
                            "writing)")


def _after_damage(buf: FileBytes, pos: int, end: int, lay: Layout, why: str
                  ) -> Generator[Item, None, Raw | None]:
    """Handle bytes at ``pos`` that are not a record: read what can be read of them and
    return the next valid record (None: nothing valid follows)."""
    h = head(buf, pos, end)
    found = next_record_start(buf, pos + 1, end)
    limit = found.offset if found is not None else end
    if h is None:
        lay.truncated = True
        lay.problems.append(f"file ends inside a record header at byte {pos}")
        return None
    opcode, length = h
    runs_past = length > end - pos - 9
    if found is not None and runs_past and lay.footer is None and opcode == Opcode.CHUNK:
        ch = chunk_prefix(buf, pos, end)
        if ch is not None and not ch.compression:
            found = None  # the records of the cut chunk's own uncompressed body: a cut
    if found is None and runs_past and lay.footer is None:
        lay.truncated = True
        lay.problems.append(f"file ends inside a record (opcode 0x{opcode:02x}, {length} "
                            f"bytes) at byte {pos}")
        if opcode == Opcode.CHUNK:
            ch = chunk_prefix(buf, pos, end)
            if ch is not None:
                yield from _chunk(pos, end - pos - 9, ch, lay, cut=True)
        return None
    # damage: perhaps only the length field, so try the bytes up to the next record
    fixed = None
    if opcode in (Opcode.CHUNK, Opcode.HEADER, Opcode.SCHEMA, Opcode.CHANNEL,
                  Opcode.METADATA, Opcode.ATTACHMENT) and limit - pos - 9 >= 0:
        try:
            fixed = Raw(pos, opcode, limit - pos - 9, parse_body(opcode, buf[pos + 9:limit]))
        except RecordError:
            fixed = None
    resumed = f"resumed at byte {found.offset}" if found is not None else "nothing follows"
    if fixed is not None:
        lay.damaged(f"record at byte {pos} (opcode 0x{opcode:02x}) has a damaged length "
                    f"field ({why}); read it up to the next record")
        if fixed.opcode == Opcode.CHUNK:
            yield from _chunk(pos, fixed.length, fixed.record, lay)
        else:
            yield from _top(fixed, lay)
    elif opcode == Opcode.CHUNK and (ch := chunk_prefix(buf, pos, limit)) is not None:
        lay.damaged(f"chunk at byte {pos} is damaged ({why}); {resumed}")
        yield from _chunk(pos, limit - pos - 9, ch, lay, cut=True)
    else:
        lay.damaged(f"damaged record at byte {pos} ({why}); {resumed}")
    return found


def data_section_verified(buf: FileBytes, lay: Layout) -> bool:
    """The data end record (right before the summary section, or before the footer when
    there is none) holds a data-section CRC, and the bytes before it match it: every
    record of the data section, messages outside chunks included, is as written."""
    if lay.footer is None:
        return False
    foff, f = lay.footer
    pos = (int(f.summary_start) if f.summary_start else foff) - 13  # opcode, length, crc
    if pos < 8 or pos + 13 > foff or buf[pos] != Opcode.DATA_END or int.from_bytes(
            bytes(buf[pos + 1:pos + 9]), "little") != 4:
        return False
    crc = int.from_bytes(bytes(buf[pos + 9:pos + 13]), "little")
    return crc != 0 and data_crc_matches(buf, lay, pos, crc)


def data_crc_matches(buf: FileBytes, lay: Layout, end: int, crc: int) -> bool:
    """The bytes before ``end`` (a data end record's offset) match the data-section CRC
    ``crc``; computed once per offset and kept in ``lay``."""
    if end not in lay.data_crcs:
        lay.data_crcs[end] = zlib.crc32(memoryview(buf)[:end]) == crc
    return lay.data_crcs[end]


def _top(raw: Raw, lay: Layout, loose_covered: bool = False) -> Iterator[Item]:
    lay.top.append(raw)
    op, rec = raw.opcode, raw.record
    if op == Opcode.HEADER:
        if raw.offset == 8:
            lay.header = rec
        else:
            lay.damaged(f"a header record at byte {raw.offset}")
    elif op == Opcode.DATA_END:
        lay.data_end = raw
    elif op == Opcode.FOOTER:
        lay.damaged(f"a footer record at byte {raw.offset}, not at the end of the file")
    elif op == Opcode.MESSAGE_INDEX:
        if lay.chunks and not lay.in_summary(raw.offset):
            lay.chunks[-1].indexes.setdefault(rec.channel_id, raw)
    elif op == Opcode.MESSAGE:
        if lay.in_summary(raw.offset):
            lay.damaged(f"a message record in the summary section at byte {raw.offset}")
        else:
            lay.loose.append((int(rec.channel_id), int(rec.log_time), raw.offset))
            yield Item(rec, "data", covered=loose_covered)
    elif op in (Opcode.SCHEMA, Opcode.CHANNEL, Opcode.ATTACHMENT, Opcode.METADATA):
        summary = lay.in_summary(raw.offset)
        if not summary and op in (Opcode.SCHEMA, Opcode.CHANNEL):
            lay.define(rec)
        yield Item(rec, "summary" if summary else "data")


def _chunk(offset: int, length: int, chunk: Chunk, lay: Layout, cut: bool = False
           ) -> Iterator[Item]:
    facts = ChunkFacts(offset, length, Chunk(
        message_start_time=chunk.message_start_time, message_end_time=chunk.message_end_time,
        uncompressed_size=chunk.uncompressed_size, uncompressed_crc=chunk.uncompressed_crc,
        compression=chunk.compression, data=b""), len(chunk.data))
    lay.chunks.append(facts)
    data, err, whole = decompress(chunk, min(int(chunk.uncompressed_size), _MAX_CHUNK)
                           if not cut and chunk.compression == "" else _MAX_CHUNK)
    facts.decoded = len(data)
    where = f"chunk at byte {offset}"
    if whole and not cut:
        if chunk.uncompressed_crc and zlib.crc32(data) != chunk.uncompressed_crc:
            lay.damaged(f"{where}: CRC does not match its contents, so none of its "
                        "messages can be trusted (the damage cannot be located)")
            return
        records, problems = inner_records(data, complete=True)
        if len(data) != chunk.uncompressed_size:
            problems.append(f"{len(data)} bytes decoded (CRC right), its header says "
                            f"{chunk.uncompressed_size}")
        for p in problems:
            lay.damaged(f"{where}: {p}")
        facts.intact = not problems
    else:
        if err is not None:
            lay.damaged(f"{where}: {err}")
        elif not cut:
            lay.damaged(f"{where}: its compressed data ends early")
        records, _ = inner_records(data, complete=False)
        facts.salvaged = True
    for r in records:
        rec = r.record
        if isinstance(rec, Message):
            facts.messages.append((int(rec.channel_id), int(rec.log_time), r.offset))
            yield Item(rec, "salvaged" if facts.salvaged else "data",
                       covered=not facts.salvaged and bool(chunk.uncompressed_crc))
        else:
            lay.define(rec)
            yield Item(rec, "data")


def message_index_at(buf: FileBytes, offset: int, size: int) -> MessageIndex | None:
    """The message index record at ``offset`` (from a chunk index), None when there is
    none there."""
    try:
        raw = read_record(buf, int(offset), size)
    except (RecordError, ValueError, OverflowError):
        return None
    return raw.record if raw.opcode == Opcode.MESSAGE_INDEX else None
