"""Diagnosing and recovering MCAP files that were cut short or damaged.

:func:`scan` walks the file record by record without trusting its summary: it tells a
*complete* file (header, data, footer, closing magic, every chunk readable) from a
*truncated* one (the bytes stop inside or after a record with no footer: a killed
recorder, a full disk, a copy cut short) and a *corrupt* one (bad magic, a chunk whose CRC
or compression fails, a record length that makes no sense while bytes remain).
:func:`recover` writes every complete, readable message (with its schemas, channels,
attachments and metadata) to a new, indexed MCAP file; it never writes over its input.
"""

from __future__ import annotations

import io
import os
import struct
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Literal

from mcap.opcode import Opcode
from mcap.records import Attachment, Channel, Chunk, Footer, Message, Metadata, Schema
from mcap.stream_reader import MAGIC_SIZE, breakup_chunk
from mcap.writer import CompressionType, Writer

from sgtool.errors import LogFormatError, SgtoolError
from sgtool.files import atomic_open

MAGIC = bytes([137, 77, 67, 65, 80, 48, 13, 10])
Status = Literal["complete", "truncated", "corrupt"]

_RECORD_TYPES = {
    Opcode.SCHEMA: Schema,
    Opcode.CHANNEL: Channel,
    Opcode.ATTACHMENT: Attachment,
    Opcode.METADATA: Metadata,
    Opcode.CHUNK: Chunk,
    Opcode.FOOTER: Footer,
}


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

    def as_dict(self) -> dict[str, object]:
        return dict(self.__dict__)


@dataclass(frozen=True)
class _Item:
    record: Schema | Channel | Message | Attachment | Metadata


def _walk(f: io.BufferedReader, size: int, diag: Diagnosis) -> Iterator[_Item]:
    """Yield every readable record; fill ``diag`` with what went wrong."""
    from mcap.data_stream import ReadDataStream

    head = f.read(MAGIC_SIZE)
    if head != MAGIC:
        diag.status = "corrupt"
        diag.problems.append("does not start with the MCAP magic bytes: not an MCAP file")
        return
    pos = MAGIC_SIZE
    diag.last_good_offset = pos
    saw_footer = False
    while True:
        if pos == size:
            break
        if size - pos < 9:
            diag.status = "truncated"
            diag.problems.append(f"file ends inside a record header at byte {pos}")
            return
        f.seek(pos)
        opcode, length = struct.unpack("<BQ", f.read(9))
        body_start = pos + 9
        if length > size - body_start:
            # a record that runs past the end: the writer was cut off while writing it
            diag.status = "truncated"
            diag.problems.append(
                f"file ends inside a record (opcode 0x{opcode:02x}, {length} bytes) at byte {pos}"
            )
            return
        body = f.read(length)
        pos = body_start + length
        cls = _RECORD_TYPES.get(opcode)
        if opcode == Opcode.FOOTER:
            saw_footer = True
            diag.last_good_offset = pos
            tail = f.read(MAGIC_SIZE)
            if tail != MAGIC:
                diag.status = "truncated" if len(tail) < MAGIC_SIZE else "corrupt"
                diag.problems.append("footer is not followed by the closing magic bytes")
            break
        if cls is None:
            diag.last_good_offset = pos
            continue  # data end, indexes, summary records: not needed to recover
        try:
            rec = cls.read(ReadDataStream(io.BytesIO(body)))
        except Exception as e:  # noqa: BLE001 - any parse failure means a damaged record
            diag.status = "corrupt"
            diag.problems.append(f"unreadable {cls.__name__} at byte {pos - length - 9}: {e}")
            if cls is Chunk:
                diag.lost_chunks += 1
            continue
        if isinstance(rec, Chunk):
            try:
                inner = breakup_chunk(rec, validate_crc=True)
            except Exception as e:  # noqa: BLE001
                diag.status = "corrupt"
                diag.lost_chunks += 1
                diag.problems.append(f"chunk at byte {pos - length - 9} is damaged: {e}")
                continue
            for r in inner:
                yield _Item(r)
        else:
            yield _Item(rec)
        diag.last_good_offset = pos
    if not saw_footer and diag.status == "complete":
        diag.status = "truncated"
        diag.problems.append("no footer: the file was not closed (writer killed or still writing)")


def scan(path: str | os.PathLike[str]) -> Diagnosis:
    """Read the whole file and say whether it is complete, truncated or corrupt."""
    p = Path(path)
    if not p.is_file():
        raise LogFormatError(f"{p}: no such file")
    _require_magic(p)
    diag = Diagnosis(str(p), p.stat().st_size)
    with open(p, "rb") as f:
        _consume(_walk(f, diag.size, diag), diag, None)
    return diag


def _require_magic(p: Path) -> None:
    """A file that does not even start like an MCAP file is not a damaged log: say so."""
    with open(p, "rb") as f:
        head = f.read(8)
    if head != bytes([137, 77, 67, 65, 80, 48, 13, 10]):
        raise LogFormatError(f"{p}: not an MCAP file (it does not start with the MCAP magic "
                             "bytes): there is no log to check or recover")


def _consume(items: Iterator[_Item], diag: Diagnosis, writer: _Copier | None) -> None:
    schemas: dict[int, Schema] = {}
    channels: dict[int, Channel] = {}
    for it in items:
        r = it.record
        if isinstance(r, Schema):
            schemas[r.id] = r
        elif isinstance(r, Channel):
            if r.id not in channels and writer is not None:
                writer.channel(schemas.get(r.schema_id), r)
            channels[r.id] = r
            diag.channels = len(channels)
        elif isinstance(r, Message):
            ch = channels.get(r.channel_id)
            if ch is None:
                diag.problems.append(f"message on unknown channel {r.channel_id} skipped")
                continue
            diag.readable_messages += 1
            t = int(r.log_time)
            diag.first_time_ns = t if diag.first_time_ns is None else min(diag.first_time_ns, t)
            diag.last_time_ns = t if diag.last_time_ns is None else max(diag.last_time_ns, t)
            if writer is not None:
                writer.message(schemas.get(ch.schema_id), ch, r)
        elif isinstance(r, Attachment):
            diag.attachments += 1
            if writer is not None:
                writer.attachment(r)
        elif isinstance(r, Metadata):
            if writer is not None:
                writer.metadata(r)


class _Copier:
    """Re-writes records into a fresh, indexed MCAP file, renumbering nothing."""

    def __init__(self, out: io.BufferedWriter, profile: str, library: str) -> None:
        self.w = Writer(out, compression=CompressionType.ZSTD)
        self.w.start(profile=profile, library=library)
        self.schema_ids: dict[int, int] = {}
        self.channel_ids: dict[int, int] = {}

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

    def message(self, schema: Schema | None, ch: Channel, m: Message) -> None:
        self.channel(schema, ch)
        self.w.add_message(
            self.channel_ids[ch.id], m.log_time, m.data, m.publish_time, m.sequence
        )

    def attachment(self, a: Attachment) -> None:
        self.w.add_attachment(a.create_time, a.log_time, a.name, a.media_type, a.data)

    def metadata(self, m: Metadata) -> None:
        self.w.add_metadata(m.name, dict(m.metadata))


def recover(path: str | os.PathLike[str], out: str | os.PathLike[str],
            overwrite: bool = False) -> Diagnosis:
    """Copy every readable message of ``path`` into ``out`` (a valid, indexed MCAP file).

    Messages are written in the order they were found; the MCAP index of the new file lets
    readers iterate them in log-time order. ``out`` is written atomically and must not be
    the input file.
    """
    src, dst = Path(path), Path(out)
    if not src.is_file():
        raise LogFormatError(f"{src}: no such file")
    if dst.exists() and os.path.samefile(src, dst):
        raise SgtoolError(f"refusing to write the recovered log over its input {src}")
    if dst.is_dir():
        raise SgtoolError(f"{dst} is a folder, not a file name")
    if dst.exists() and not overwrite:
        raise SgtoolError(f"{dst} exists; not overwriting it (use --force)")
    _require_magic(src)
    if not dst.parent.exists():
        raise SgtoolError(f"folder {dst.parent} does not exist")
    diag = Diagnosis(str(src), src.stat().st_size)
    with open(src, "rb") as f, atomic_open(dst, "wb") as o:
        f.seek(0)
        header_lib = _header_library(f)
        f.seek(0)
        copier = _Copier(o, profile=header_lib[0], library=header_lib[1])
        _consume(_walk(f, diag.size, diag), diag, copier)
        copier.w.finish()
    return diag


def _header_library(f: io.BufferedReader) -> tuple[str, str]:
    from mcap.data_stream import ReadDataStream
    from mcap.records import Header

    try:
        if f.read(MAGIC_SIZE) != MAGIC:
            return "", "sgtool doctor"
        opcode, length = struct.unpack("<BQ", f.read(9))
        if opcode != Opcode.HEADER or length > 1 << 20:
            return "", "sgtool doctor"
        h = Header.read(ReadDataStream(io.BytesIO(f.read(length))))
        return h.profile, h.library
    except Exception:  # noqa: BLE001
        return "", "sgtool doctor"
