"""Rebuild the MCAP project's reader conformance cases from their JSON descriptions.

A description (``../shared/data/mcap-conformance/<Case>/<Case>-<features>.json``) lists the
records a streamed reader yields, in file order, with the records inside a chunk listed in
place of the chunk; the variant's features (``meta.variant.features``) say how the file was
laid out: ``ch`` one chunk holding the data section's schemas, channels and messages
(written after the data section's attachments and metadata, uncompressed), ``mx`` message
indexes after it, ``pad`` three extra bytes (``01 ff ff``) at the end of every record that
may grow (not Message, Chunk, DataEnd or Footer, nor the records inside the chunk). The
summary records (and their offsets and CRCs) are in the description as written.

``build_case`` returns the file bytes; ``check_case_crcs`` confirms them against the
description's own data-section and summary CRCs, which pin every byte.
"""

from __future__ import annotations

import json
import struct
import zlib
from dataclasses import dataclass
from pathlib import Path
from typing import Any

MAGIC = b"\x89MCAP0\r\n"
PAD = b"\x01\xff\xff"
OPCODES = {
    "Header": 0x01, "Footer": 0x02, "Schema": 0x03, "Channel": 0x04, "Message": 0x05,
    "Chunk": 0x06, "MessageIndex": 0x07, "ChunkIndex": 0x08, "Attachment": 0x09,
    "AttachmentIndex": 0x0A, "Statistics": 0x0B, "Metadata": 0x0C, "MetadataIndex": 0x0D,
    "SummaryOffset": 0x0E, "DataEnd": 0x0F,
}
UNPADDED = {"Message", "Chunk", "DataEnd", "Footer"}


@dataclass(frozen=True)
class Case:
    """One described file: its name, features and records (type, field dict) in order."""

    name: str
    features: frozenset[str]
    records: tuple[tuple[str, dict[str, Any]], ...]

    def data_records(self) -> list[tuple[str, dict[str, Any]]]:
        """The records between Header and DataEnd."""
        out = []
        for kind, fields in self.records[1:]:
            if kind == "DataEnd":
                break
            out.append((kind, fields))
        return out

    def count(self, kind: str) -> int:
        """How many records of ``kind`` the data section holds."""
        return sum(1 for k, _ in self.data_records() if k == kind)


def load_case(path: Path) -> Case:
    """Read one JSON description."""
    doc = json.loads(path.read_text())
    records = tuple((r["type"], dict(r["fields"])) for r in doc["records"])
    return Case(path.stem, frozenset(doc["meta"]["variant"]["features"]), records)


def _s(text: str) -> bytes:
    raw = text.encode()
    return struct.pack("<I", len(raw)) + raw


def _b(values: list[str]) -> bytes:
    return bytes(int(v) for v in values)


def _str_map(mapping: dict[str, str]) -> bytes:
    body = b"".join(_s(k) + _s(v) for k, v in mapping.items())
    return struct.pack("<I", len(body)) + body


def _u(fmt: str, *values: str) -> bytes:
    return struct.pack("<" + fmt, *(int(v) for v in values))


def body_of(kind: str, f: dict[str, Any]) -> bytes:
    """The record body (after opcode and length) of one described record, unpadded."""
    if kind == "Header":
        return _s(f["profile"]) + _s(f["library"])
    if kind == "Schema":
        data = _b(f["data"])
        return (_u("H", f["id"]) + _s(f["name"]) + _s(f["encoding"])
                + struct.pack("<I", len(data)) + data)
    if kind == "Channel":
        return (_u("HH", f["id"], f["schema_id"]) + _s(f["topic"]) + _s(f["message_encoding"])
                + _str_map(f["metadata"]))
    if kind == "Message":
        return (_u("HIQQ", f["channel_id"], f["sequence"], f["log_time"], f["publish_time"])
                + _b(f["data"]))
    if kind == "Attachment":
        data = _b(f["data"])
        covered = (_u("QQ", f["log_time"], f["create_time"]) + _s(f["name"])
                   + _s(f["media_type"]) + struct.pack("<Q", len(data)) + data)
        return covered + struct.pack("<I", zlib.crc32(covered))
    if kind == "Metadata":
        return _s(f["name"]) + _str_map(f["metadata"])
    if kind == "DataEnd":
        return _u("I", f["data_section_crc"])
    if kind == "Statistics":
        counts = b"".join(_u("HQ", k, v) for k, v in f["channel_message_counts"].items())
        return (_u("QHIIIIQQ", f["message_count"], f["schema_count"], f["channel_count"],
                   f["attachment_count"], f["metadata_count"], f["chunk_count"],
                   f["message_start_time"], f["message_end_time"])
                + struct.pack("<I", len(counts)) + counts)
    if kind == "ChunkIndex":
        offsets = b"".join(_u("HQ", k, v) for k, v in f["message_index_offsets"].items())
        return (_u("QQQQ", f["message_start_time"], f["message_end_time"],
                   f["chunk_start_offset"], f["chunk_length"])
                + struct.pack("<I", len(offsets)) + offsets
                + _u("Q", f["message_index_length"]) + _s(f["compression"])
                + _u("QQ", f["compressed_size"], f["uncompressed_size"]))
    if kind == "AttachmentIndex":
        return (_u("QQQQQ", f["offset"], f["length"], f["log_time"], f["create_time"],
                   f["data_size"]) + _s(f["name"]) + _s(f["media_type"]))
    if kind == "MetadataIndex":
        return _u("QQ", f["offset"], f["length"]) + _s(f["name"])
    if kind == "SummaryOffset":
        return _u("BQQ", f["group_opcode"], f["group_start"], f["group_length"])
    if kind == "Footer":
        return _u("QQI", f["summary_start"], f["summary_offset_start"], f["summary_crc"])
    raise ValueError(f"unknown record type {kind}")


def record(kind: str, body: bytes, pad: bool) -> bytes:
    """Opcode, length and body (plus the padding a newer writer's fields would take)."""
    if pad and kind not in UNPADDED:
        body += PAD
    return bytes([OPCODES[kind]]) + struct.pack("<Q", len(body)) + body


def build_case(case: Case) -> bytes:
    """The file bytes the description stands for."""
    pad = "pad" in case.features
    chunked = "ch" in case.features
    out = bytearray(MAGIC)
    out += record("Header", body_of(*case.records[0]), pad)
    in_chunk = []
    for kind, fields in case.data_records():
        if chunked and kind in ("Schema", "Channel", "Message"):
            in_chunk.append((kind, fields))
        else:
            out += record(kind, body_of(kind, fields), pad)
    if chunked:
        out += _chunk(in_chunk, pad, "mx" in case.features)
    summary = False
    for kind, fields in case.records[1 + len(case.data_records()):]:
        summary = summary or kind == "Footer"
        out += record(kind, body_of(kind, fields), pad)
    assert summary, "a description ends with a Footer"
    return bytes(out + MAGIC)


def _chunk(records: list[tuple[str, dict[str, Any]]], pad: bool, indexes: bool) -> bytes:
    inner = bytearray()
    per_channel: dict[int, list[tuple[int, int]]] = {}
    times = []
    for kind, fields in records:
        if kind == "Message":
            log_time = int(fields["log_time"])
            times.append(log_time)
            per_channel.setdefault(int(fields["channel_id"]), []).append((log_time, len(inner)))
        inner += record(kind, body_of(kind, fields), False)
    start, end = (min(times), max(times)) if times else (0, 0)
    body = (struct.pack("<QQQI", start, end, len(inner), zlib.crc32(inner)) + _s("")
            + struct.pack("<Q", len(inner)) + inner)
    out = record("Chunk", body, pad)
    if indexes:
        for channel, entries in per_channel.items():
            packed = b"".join(struct.pack("<QQ", t, o) for t, o in entries)
            out += record("MessageIndex",
                          struct.pack("<HI", channel, len(packed)) + packed, pad)
    return out


def check_case_crcs(case: Case, data: bytes) -> None:
    """Raise AssertionError unless ``data`` matches the description's CRCs and offsets."""
    data_end = next(f for k, f in case.records if k == "DataEnd")
    footer = case.records[-1][1]
    summary_start = int(footer["summary_start"])
    end_of_data = data.rindex(bytes([OPCODES["DataEnd"]]) + struct.pack("<Q", 4)
                              + _u("I", data_end["data_section_crc"]))
    assert zlib.crc32(data[:end_of_data]) == int(data_end["data_section_crc"]), case.name
    if summary_start:
        assert summary_start == end_of_data + 13, case.name
    footer_at = len(data) - 8 - 29
    crc_from = summary_start or footer_at
    assert zlib.crc32(data[crc_from:footer_at + 25]) == int(footer["summary_crc"]), case.name


def all_cases(root: Path) -> list[Path]:
    """Every description under ``root``, sorted."""
    return sorted(root.rglob("*.json"))
