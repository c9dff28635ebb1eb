"""Valid MCAP files that sgtool's writer never makes read whole: messages outside chunks
beside a full summary, records of an application's opcode, records with appended fields,
chunks that overlap in time read backwards (tests/support/mcap_variants.py rewrites a
small sgtool log into each; a review found each losing messages)."""

from __future__ import annotations

import dataclasses
import random
from pathlib import Path

import pytest
from mcap.reader import make_reader
from mcap.records import Message
from support.logfixtures import write_log
from support.mcap_variants import Variant, rewrite

from sgtool.log.chunk_stream import ordered_messages, reversed_messages
from sgtool.log.inspect import summarize
from sgtool.log.reader import LogReader
from sgtool.log.recover import scan


def _shuffled(messages: list[Message]) -> list[Message]:
    out = list(messages)
    random.Random(3).shuffle(out)
    return out


def _later(messages: list[Message]) -> list[Message]:
    """The messages half a second later: none at log time 0, an empty chunk's time."""
    return [dataclasses.replace(m, log_time=m.log_time + 500_000_000,
                                publish_time=m.publish_time + 500_000_000) for m in messages]


VARIANTS = {
    "as-is": Variant(),
    "instances outside chunks": Variant(loose=frozenset({"/sgtool/instances"})),
    "frames outside chunks": Variant(loose=frozenset({"/camera/depth", "/tf"})),
    "extension records between records": Variant(extension="data"),
    "extension records in chunks": Variant(extension="chunk"),
    # opcodes whose low bits name a record of the specification's (0x0f: data end, 0x01:
    # header): an application's all the same, read past
    "extension records at 0x8f": Variant(extension="data", extension_opcode=0x8F),
    "extension records at 0x81 in chunks": Variant(extension="chunk", extension_opcode=0x81),
    "extended schemas, channels, data end": Variant(extend=8),
    "shuffled into small chunks": Variant(order=_shuffled, chunk_messages=5),
    # a review's second round: each refused or misread before
    "the last messages outside chunks, past their span": Variant(loose_last=10),
    "an empty chunk, no message at log time 0": Variant(empty_chunk=True, order=_later),
    "statistics without counts per channel": Variant(channel_counts=False),
    "chunks without message indexes": Variant(message_indexes=False),
    "definitions outside chunks, a message a chunk": Variant(outside=True, chunk_messages=1),
}


@pytest.fixture(scope="module")
def source(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return write_log(tmp_path_factory.mktemp("src") / "src.mcap", n=12)


def _content(path: Path) -> list[tuple[str, int, bytes]]:
    """(topic, log time from the first message's, bytes) of every message, sorted."""
    with LogReader(path) as r:
        found = [(ch.topic, int(m.log_time), bytes(m.data)) for _, ch, m in r.raw_messages()]
    first = min(t for _, t, _ in found)
    return sorted((topic, t - first, data) for topic, t, data in found)


@pytest.mark.parametrize("name", sorted(VARIANTS))
def test_a_valid_variant_reads_as_its_source(source: Path, tmp_path: Path, name: str) -> None:
    path = rewrite(source, tmp_path / "v.mcap", VARIANTS[name])
    assert _content(path) == _content(source)
    want = summarize(source)
    got = summarize(path)
    for key in ("messages", "frames", "instances", "actions"):
        assert got.get(key) == want.get(key), (key, got.get(key), want.get(key))
    d = scan(path)
    assert d.status in ("complete", "unverified"), (d.status, d.problems)
    with LogReader(path) as r, LogReader(source) as s:  # the last record, read backwards
        assert r.last_record("instances") == s.last_record("instances")
        assert [f.index for f in r.frames()] == [f.index for f in s.frames()]
        assert len(r.frame_times()) == len(s.frame_times())
        assert [c.message_count for c in r.channels()] == \
            [c.message_count for c in s.channels()]


def test_backwards_is_forwards_reversed(source: Path, tmp_path: Path) -> None:
    """Chunks that overlap in time (messages shuffled into chunks of five): a backwards
    read gives the forwards order reversed, ties included, as the ``mcap`` reader does."""
    path = rewrite(source, tmp_path / "v.mcap", VARIANTS["shuffled into small chunks"])

    def key(items: object) -> list[tuple[int, bytes]]:
        return [(int(m.log_time), bytes(m.data)) for _, _, m in items]  # type: ignore[attr-defined]

    with open(path, "rb") as f:
        reader = make_reader(f)
        summary = reader.get_summary()
        assert summary is not None and len(summary.chunk_indexes) > 10
        fwd = key(ordered_messages(f, summary))
        back = key(reversed_messages(f, summary))
        lib = key(reader.iter_messages(log_time_order=True, reverse=True))
        lo, hi = fwd[5][0], fwd[-5][0]
        window = key(reversed_messages(f, summary, ["/camera/depth"], start_ns=lo, end_ns=hi))
        want = key(ordered_messages(f, summary, ["/camera/depth"], start_ns=lo, end_ns=hi))
    assert back == fwd[::-1] == lib
    assert window == want[::-1] and len(window) > 3


def test_a_chunk_whose_opcode_lost_a_bit_is_damage_not_an_extension(source: Path,
                                                                      tmp_path: Path) -> None:
    """0x06 -> 0x86 (one flipped bit) looks like an application's record; its body is a
    whole chunk, so doctor calls it damage instead of skipping it without a word."""
    with LogReader(source) as r:
        ci = sorted(r.summary.chunk_indexes, key=lambda c: c.chunk_start_offset)[1]
    data = bytearray(source.read_bytes())
    assert data[ci.chunk_start_offset] == 0x06
    data[ci.chunk_start_offset] = 0x86
    bad = tmp_path / "flipped.mcap"
    bad.write_bytes(bytes(data))
    d = scan(bad)
    assert d.status == "corrupt", (d.status, d.problems)
    assert any("a damaged opcode" in p for p in d.problems), d.problems
