"""Diagnosing and recovering MCAP files that were cut short or damaged.

:func:`scan` walks the file record by record without trusting it
(:mod:`sgtool.log.file_walk`) and cross-checks what it read (:mod:`sgtool.log.file_check`):
it tells a *complete* file (header, data, summary and footer all there, every CRC the file
carries right: chunks, attachments, summary, data section; every index and the statistics
agreeing with the records; CRCs over every message) from an *unverified* one (the same, but
the writer wrote no CRC over some chunks, so damage inside their messages cannot be
seen: many ROS 2 recordings), a *truncated* one (the bytes stop inside or after a record
with no footer: a killed recorder, a full disk, a copy cut short) and a *corrupt* one
(anything else). :func:`recover` writes every readable message (with its schemas,
channels, attachments and metadata) to a new, indexed MCAP file and never writes over its
input. It keeps every intact byte: channels whose definition is damaged in the data section
are read with their summary copies, a damaged header or record is skipped up to the next
valid record, the readable prefix of a cut or damaged compressed chunk is decoded; and it
says what was lost (messages per channel and their time range, from the indexes and the
statistics).
"""

from __future__ import annotations

import io
import mmap
import os
import struct
from collections import Counter
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import IO, Literal

from mcap.records import Attachment, Channel, Message, Metadata, Schema, Statistics
from mcap.writer import CompressionType, Writer

from sgtool.errors import LogFormatError, SgtoolError
from sgtool.files import atomic_open
from sgtool.log import schemas as S
from sgtool.log.file_check import SummaryState, check, expected_messages, summary_state
from sgtool.log.file_walk import Item, Layout, data_crc_matches, walk
from sgtool.log.log_file import (
    appended_end,
    file_ends,
    opening_damaged,
    require_regular_file,
    rerun_problem,
)
from sgtool.log.mcap_records import MAGIC
from sgtool.log.message_check import message_problem
from sgtool.output_check import check_log_output

Status = Literal["complete", "unverified", "truncated", "corrupt"]
_OUTSIDE_CHUNKS = -1  # the key of messages outside chunks among the per-chunk counts
_CRC_FLAG = "_Writer__enable_crcs"  # the mcap writer's private switch of chunk CRCs


@dataclass
class Diagnosis:
    path: str
    size: int
    status: Status = "complete"
    problems: list[str] = field(default_factory=list)
    readable_messages: int = 0
    lost_chunks: int = 0
    channels: int = 0
    attachments: int = 0
    last_good_offset: int = 0  # byte offset after the last record read whole
    first_time_ns: int | None = None
    last_time_ns: int | None = None
    salvaged_messages: int = 0  # read from damaged chunks: not covered by a CRC
    # readable messages no CRC covers (damaged chunks, chunks without a CRC, outside
    # chunks without a data-section CRC): each decoded and checked (message_check) first
    unverified_messages: int = 0
    dropped_messages: int = 0  # they fail their check (damaged, or written malformed): not copied
    lost_messages: int = 0  # that the indexes or statistics know of
    lost_unknown: bool = False  # some damaged or cut data had no index: more may be lost
    lost: dict[str, dict[str, int | None]] = field(default_factory=dict)  # per topic
    checks: dict[str, str] = field(default_factory=dict)  # CRC -> ok | mismatch | ...

    def as_dict(self) -> dict[str, object]:
        return dict(self.__dict__)


def _mapped(f: io.BufferedReader, size: int) -> mmap.mmap:
    return mmap.mmap(f.fileno(), size, access=mmap.ACCESS_READ)


def _diagnose(buf: mmap.mmap, diag: Diagnosis, writer: _Copier | None) -> None:
    """Walk ``buf``, copy what is readable to ``writer``, fill ``diag``. Bytes appended
    after a complete log (:func:`~sgtool.log.log_file.appended_end`) are the only problem
    named when the log before them reads without damage; else the whole file is walked."""
    end = appended_end(buf, diag.size)
    if end is not None:
        before = Layout(end)
        for _ in walk(buf, before):
            pass
        if before.corrupt or before.truncated or before.problems:
            end = None
    lay = Layout(diag.size if end is None else end)
    if writer is not None:
        writer.layout = lay
    unknown = _consume(walk(buf, lay), diag, writer,
                       lambda: lay.header is None or lay.header.profile == S.PROFILE
                       or _names_sgtool_metadata(buf))
    read = {c.offset: Counter((cid, t) for cid, t, _ in c.messages if cid not in unknown)
            for c in lay.chunks}
    read[_OUTSIDE_CHUNKS] = Counter((cid, t) for cid, t, _ in lay.loose if cid not in unknown)
    state = summary_state(buf, lay)
    diag.checks = _checks(buf, lay, state)
    problems = list(lay.problems) + diag.problems
    if end is not None:
        extra = diag.size - end
        problems.insert(0, f"{extra} byte{'' if extra == 1 else 's'} after the closing magic "
                        f"at byte {end}: appended to a closed log (its footer and magic end there)")
    if not lay.corrupt and not lay.truncated:
        problems += check(buf, lay, state)
    diag.problems = problems
    diag.last_good_offset = lay.last_good_offset
    diag.status = ("corrupt" if lay.corrupt or (problems and not lay.truncated)
                   else "truncated" if lay.truncated else _verified(lay))
    diag.lost_chunks = sum(not c.intact for c in lay.chunks)
    _account_losses(buf, lay, state, read, diag)


def _verified(lay: Layout) -> Status:
    """"complete" when CRCs cover every message, else "unverified": every record reads and
    every index agrees, but damage inside the messages of a chunk without a CRC (the
    writer wrote none), or of messages outside chunks without a data section CRC, cannot be
    seen."""
    if lay.data_end is not None and lay.data_end.record.data_section_crc:
        return "complete"
    covered = all(c.header.uncompressed_crc or not c.messages for c in lay.chunks) \
        and not lay.loose
    return "complete" if covered else "unverified"


def _checks(buf: mmap.mmap, lay: Layout, state: SummaryState) -> dict[str, str]:
    chunks = [c for c in lay.chunks if c.header.uncompressed_crc]
    out = {"chunks": f"{sum(c.intact for c in chunks)} of {len(lay.chunks)} verified"
           if chunks else "no CRCs written" if lay.chunks else "no chunks"}
    out["summary"] = ("absent" if not state.present else "not written"
                      if not state.crc_checked else "ok" if state.crc_ok else "mismatch")
    if lay.data_end is not None:
        crc = lay.data_end.record.data_section_crc
        out["data"] = ("not written" if not crc else "ok" if data_crc_matches(
            buf, lay, lay.data_end.offset, crc) else "mismatch")
    return out


def _account_losses(buf: mmap.mmap, lay: Layout, state: SummaryState,
                    read: dict[int, Counter[tuple[int, int]]], diag: Diagnosis) -> None:
    """What the indexes (and the statistics) say is missing from what was read."""
    expected = expected_messages(buf, lay, state)
    lost: Counter[tuple[int, int]] = Counter()
    for off, entries in expected.items():
        lost += Counter(entries) - read.get(off, Counter())
    diag.lost_unknown = any(not c.intact and c.offset not in expected for c in lay.chunks)
    if lay.truncated and not state.trusted:
        diag.lost_unknown = True
    names = {**{c.id: c.topic for c in _summary_channels(lay)},
             **{c.id: c.topic for c in lay.channels.values()}}
    per: dict[str, dict[str, int | None]] = {}
    for (cid, t), n in sorted(lost.items()):
        e = per.setdefault(names.get(cid, f"channel {cid}"),
                           {"messages": 0, "first_ns": t, "last_ns": t})
        e["messages"] = int(e["messages"] or 0) + n
        e["last_ns"] = t
    stats = [r.record for r in lay.summary_records() if isinstance(r.record, Statistics)]
    if state.trusted and stats:
        got: Counter[int] = Counter()
        for c in read.values():
            for (cid, _), n in c.items():
                got[cid] += n
        for cid, n in stats[0].channel_message_counts.items():
            missing = int(n) - got[cid]
            name = names.get(cid, f"channel {cid}")
            if missing > int(per.get(name, {}).get("messages") or 0):
                e = per.setdefault(name, {"messages": 0, "first_ns": None, "last_ns": None})
                e["messages"] = missing
    diag.lost = per
    diag.lost_messages = sum(int(e["messages"] or 0) for e in per.values())


def scan(path: str | os.PathLike[str]) -> Diagnosis:
    """Read the whole file and say whether it is complete, truncated or corrupt."""
    p = Path(path)
    if not p.exists():
        raise LogFormatError(f"{p}: no such file")
    require_regular_file(p)
    opening = _require_magic(p)
    diag = Diagnosis(str(p), p.stat().st_size, problems=[opening] if opening else [])
    with open(p, "rb") as f, _mapped(f, diag.size) as buf:
        _diagnose(buf, diag, None)
    return diag


def _require_magic(p: Path) -> str | None:
    """A file that does not even start like an MCAP file is not a damaged log: say so. One
    whose opening magic bytes are damaged but that is an MCAP file otherwise (its closing
    magic, a header record after the opening one, or the opening bytes off by a few) is:
    the problem to name (None when the opening magic is intact)."""
    head, size, tail = file_ends(p)
    if head[:8] == MAGIC:
        return None
    rerun = rerun_problem(p, head)
    if rerun is not None:
        raise LogFormatError(rerun)
    if opening_damaged(head, size, tail):
        return (f"the opening magic bytes are damaged ({head[:8].hex(' ')} instead of "
                f"{MAGIC.hex(' ')})")
    raise LogFormatError(f"{p}: not an MCAP file (it does not start with the MCAP magic "
                         "bytes): there is no log to check or recover")


def _summary_channels(lay: Layout) -> list[Channel]:
    return [r.record for r in lay.summary_records() if isinstance(r.record, Channel)]


def _names_sgtool_metadata(buf: mmap.mmap) -> bool:
    """Whether ``buf`` holds a metadata record named as sgtool names its own (opcode 0x0C,
    its length, then the name): an sgtool log whose header was damaged or rewritten
    (a recovery that lost the header writes none)."""
    name = struct.pack("<I", len(S.METADATA_NAME)) + S.METADATA_NAME.encode()
    at = buf.find(name)
    while at != -1:
        if at >= 9 and buf[at - 9] == 0x0C:
            return True
        at = buf.find(name, at + 1)
    return False


def _consume(items: Iterator[Item], diag: Diagnosis, writer: _Copier | None,
             sgtool_log: Callable[[], bool] = lambda: True) -> set[int]:
    """Count (and copy) the records of ``items``; messages whose channel is defined
    nowhere before them wait for the summary copies. Returns the ids of channels defined
    nowhere (their messages are lost). Messages are checked as an sgtool log's when
    ``sgtool_log()`` says the file is one (its header's profile, asked at the first
    message; a file whose header is lost counts as one), else only as parsing
    (:func:`~sgtool.log.message_check.message_problem`)."""
    schemas: dict[int, Schema] = {}
    channels: dict[int, Channel] = {}
    spare_schemas: dict[int, Schema] = {}
    spare_channels: dict[int, Channel] = {}
    orphans: list[Item] = []
    seen_channels: set[int] = set()

    dropped: Counter[str] = Counter()
    first_drop: dict[str, str] = {}
    malformed: Counter[str] = Counter()  # intact bytes that fail their check as written
    first_malformed: dict[str, str] = {}

    own: list[bool] = []  # whether the file is an sgtool log, once asked

    def take(it: Item, ch: Channel) -> None:
        r = it.record
        schema = schemas.get(ch.schema_id) or spare_schemas.get(ch.schema_id)
        if not own:
            own.append(sgtool_log())
        problem = message_problem(schema, ch, r.data, own[0])
        if problem is not None:
            count, first = (malformed, first_malformed) if it.covered else (dropped, first_drop)
            count[ch.topic] += 1
            first.setdefault(ch.topic, f"at {int(r.log_time)} ns: {problem}")
            return
        if not it.covered:
            diag.unverified_messages += 1
        seen_channels.add(ch.id)
        diag.readable_messages += 1
        diag.salvaged_messages += it.source == "salvaged"
        t = int(r.log_time)
        diag.first_time_ns = t if diag.first_time_ns is None else min(diag.first_time_ns, t)
        diag.last_time_ns = t if diag.last_time_ns is None else max(diag.last_time_ns, t)
        if writer is not None:
            writer.message(schema, ch, r, it.covered)

    for it in items:
        r = it.record
        if isinstance(r, Schema):
            (spare_schemas if it.source == "summary" else schemas).setdefault(r.id, r)
        elif isinstance(r, Channel):
            (spare_channels if it.source == "summary" else channels).setdefault(r.id, r)
        elif isinstance(r, Message):
            ch = channels.get(r.channel_id)
            if ch is None:
                orphans.append(it)
            else:
                take(it, ch)
        elif isinstance(r, Attachment) and it.source == "data":
            diag.attachments += 1
            if writer is not None:
                writer.attachment(r)
        elif isinstance(r, Metadata) and it.source == "data":
            if writer is not None:
                writer.metadata(r)
    unknown: Counter[int] = Counter()
    taken: Counter[int] = Counter()
    for it in orphans:
        cid = it.record.channel_id
        ch = channels.get(cid) or spare_channels.get(cid)
        if ch is None:
            unknown[cid] += 1
        else:
            taken[cid] += 1
            take(it, ch)
    for cid, n in sorted(taken.items()):
        diag.problems.append(f"{n} messages of channel {cid} read with the summary's copy "
                             "of its definition (the data section's is damaged)")
    for cid, n in sorted(unknown.items()):
        diag.problems.append(f"{n} messages of channel {cid}, defined nowhere, skipped")
    for topic, n in sorted(dropped.items()):
        diag.problems.append(f"{n} messages of {topic[:80]} that no CRC covers dropped: they "
                             f"fail their check (the first {first_drop[topic]})")
    for topic, n in sorted(malformed.items()):
        diag.problems.append(f"{n} messages of {topic[:80]} were written malformed (their CRC "
                             f"holds, their content fails its check: the first "
                             f"{first_malformed[topic]}); --recover leaves them out")
    diag.dropped_messages = sum(dropped.values()) + sum(malformed.values())
    if writer is not None:  # channels without messages are kept too
        for _, ch in sorted({**spare_channels, **channels}.items()):
            writer.channel(schemas.get(ch.schema_id) or spare_schemas.get(ch.schema_id), ch)
    diag.channels = len(seen_channels)
    return set(unknown)


class _Copier:
    """Re-writes records into a fresh, indexed MCAP file with the input's header (read
    by the walk before any record is copied), renumbering nothing.

    A message that no CRC covered in the input goes into a chunk written without a CRC
    (the chunk in progress is closed when that changes): the copy's CRCs vouch only for
    what the input's did, so ``sgtool doctor`` calls a copy holding such messages
    "unverified", never "complete". The ``mcap`` writer has no per-chunk switch: this
    sets its private flag (checked to be there)."""

    def __init__(self, out: IO[bytes]) -> None:
        self.out = out
        self.layout: Layout | None = None
        self._w: Writer | None = None
        self.schema_ids: dict[int, int] = {}
        self.channel_ids: dict[int, int] = {}
        self._crcs = True  # the chunk in progress gets a CRC

    @property
    def w(self) -> Writer:
        if self._w is None:
            h = self.layout.header if self.layout is not None else None
            self._w = Writer(self.out, compression=CompressionType.ZSTD)
            if not isinstance(getattr(self._w, _CRC_FLAG, None), bool):
                raise SgtoolError("this version of the mcap package cannot write chunks "
                                  "without a CRC; recovery needs it")
            self._w.start(profile=h.profile if h else "",
                          library=h.library if h else "sgtool doctor")
        return self._w

    def channel(self, schema: Schema | None, ch: Channel) -> None:
        if ch.id not in self.channel_ids:
            sid = 0
            if schema is not None:
                if schema.id not in self.schema_ids:
                    self.schema_ids[schema.id] = self.w.register_schema(
                        schema.name, schema.encoding, schema.data
                    )
                sid = self.schema_ids[schema.id]
            self.channel_ids[ch.id] = self.w.register_channel(
                ch.topic, ch.message_encoding, sid, dict(ch.metadata)
            )

    def message(self, schema: Schema | None, ch: Channel, m: Message, covered: bool) -> None:
        """Copy ``m``; ``covered``: a CRC covered it in the input (class doc)."""
        self.channel(schema, ch)
        if covered != self._crcs:
            self._crc_chunks(covered)
        self.w.add_message(
            self.channel_ids[ch.id], m.log_time, m.data, m.publish_time, m.sequence
        )

    def _crc_chunks(self, on: bool) -> None:
        self.w.flush()  # the chunk in progress keeps its setting
        setattr(self.w, _CRC_FLAG, on)
        self._crcs = on

    def finish(self) -> None:
        """Close the last chunk and write the summary (with its CRC)."""
        if not self._crcs:
            self._crc_chunks(True)
        self.w.finish()

    def attachment(self, a: Attachment) -> None:
        self.w.add_attachment(a.create_time, a.log_time, a.name, a.media_type, a.data)

    def metadata(self, m: Metadata) -> None:
        self.w.add_metadata(m.name, dict(m.metadata))


def recover(path: str | os.PathLike[str], out: str | os.PathLike[str],
            overwrite: bool = False) -> Diagnosis:
    """Copy every readable message of ``path`` into ``out`` (a valid, indexed MCAP file).

    Messages are written in the order they were found; the MCAP index of the new file lets
    readers iterate them in log-time order. ``out`` is written atomically and must not be
    the input file; it passes the one output check (:func:`sgtool.output_check.check_log_output`,
    its errors naming ``--recover``, the option of ``sgtool doctor`` that gives it) before
    anything is read.
    """
    src, dst = Path(path), Path(out)
    if not src.exists():
        raise LogFormatError(f"{src}: no such file")
    require_regular_file(src)
    if dst.exists() and os.path.samefile(src, dst):
        raise SgtoolError(f"refusing to write the recovered log over its input {src}")
    check_log_output(dst, force=overwrite, option="--recover")
    opening = _require_magic(src)
    diag = Diagnosis(str(src), src.stat().st_size, problems=[opening] if opening else [])
    with open(src, "rb") as f, _mapped(f, diag.size) as buf, atomic_open(dst, "wb") as o:
        copier = _Copier(o)
        _diagnose(buf, diag, copier)
        copier.finish()
    return diag
