"""The MCAP project's reader conformance cases (issue 34): every file the specification
allows is read whole. Each case is rebuilt from its JSON description
(tests/support/mcap_conformance.py, its bytes pinned by the description's own CRCs) and
must be "complete" for ``sgtool doctor`` ("unverified" where the writer wrote no CRC),
give the described counts in ``sgtool info``, read every message through ``LogReader``,
and come out of ``doctor --recover`` with every message, schema, channel, attachment and
metadata record equal to the description. Seven cases are committed
(tests/toolkit/log/conformance/) and always run; the whole set (416 cases, padding variants
included) runs when ../shared/data/mcap-conformance is there.
"""

from __future__ import annotations

import os
from collections import Counter
from pathlib import Path
from typing import Any

import pytest
from click.testing import CliRunner
from mcap.reader import NonSeekingReader
from support.mcap_conformance import all_cases, build_case, check_case_crcs, load_case

from sgtool.cli import cli
from sgtool.errors import LogFormatError
from sgtool.log.inspect import summarize
from sgtool.log.reader import LogReader
from sgtool.log.recover import recover, scan
from sgtool.log.walk_index import needs_walk

COMMITTED = Path(__file__).parent / "conformance"


def _data(values: list[str]) -> bytes:
    return bytes(int(v) for v in values)


def _described(case: Any) -> dict[str, Counter]:
    """What the data section of a description holds, as comparable tuples (ids left out:
    a recovered file may number schemas and channels anew)."""
    recs = case.data_records()
    schemas = {f["id"]: f for k, f in recs if k == "Schema"}
    channels = {f["id"]: f for k, f in recs if k == "Channel"}

    def schema_of(ch: dict[str, Any]) -> tuple | None:
        s = schemas.get(ch["schema_id"])
        return None if s is None else (s["name"], s["encoding"], _data(s["data"]))

    def channel(ch: dict[str, Any]) -> tuple:
        return (ch["topic"], ch["message_encoding"], tuple(sorted(ch["metadata"].items())),
                schema_of(ch))

    return {
        "schemas": Counter(schema_of(c) for c in channels.values() if schema_of(c)),
        "channels": Counter(channel(c) for c in channels.values()),
        "messages": Counter(
            (channel(channels[f["channel_id"]]), int(f["sequence"]), int(f["log_time"]),
             int(f["publish_time"]), _data(f["data"])) for k, f in recs if k == "Message"),
        "attachments": Counter(
            (f["name"], f["media_type"], int(f["log_time"]), int(f["create_time"]),
             _data(f["data"])) for k, f in recs if k == "Attachment"),
        "metadata": Counter((f["name"], tuple(sorted(f["metadata"].items())))
                            for k, f in recs if k == "Metadata"),
    }


def _recovered(path: Path) -> dict[str, Counter]:
    """The same view of a file (a rebuilt case or its recovered copy), read by the ``mcap``
    package's streaming reader."""
    with open(path, "rb") as f:
        msgs = list(NonSeekingReader(f).iter_messages(log_time_order=False))
    with open(path, "rb") as f:
        atts = list(NonSeekingReader(f).iter_attachments())
    with open(path, "rb") as f:
        meta = list(NonSeekingReader(f).iter_metadata())

    def schema(s: Any) -> tuple | None:
        return None if s is None else (s.name, s.encoding, bytes(s.data))

    def channel(s: Any, c: Any) -> tuple:
        return (c.topic, c.message_encoding, tuple(sorted(c.metadata.items())), schema(s))

    summary_channels = _all_channels(path)
    return {
        "schemas": Counter(schema(s) for s, _ in summary_channels if s is not None),
        "channels": Counter(channel(s, c) for s, c in summary_channels),
        "messages": Counter((channel(s, c), m.sequence, m.log_time, m.publish_time,
                             bytes(m.data)) for s, c, m in msgs),
        "attachments": Counter((a.name, a.media_type, a.log_time, a.create_time,
                                bytes(a.data)) for a in atts),
        "metadata": Counter((m.name, tuple(sorted(m.metadata.items()))) for m in meta),
    }


def _all_channels(path: Path) -> list[tuple[Any, Any]]:
    """(schema, channel) of every channel record the file defines (once per id)."""
    from mcap.records import Channel, Schema
    from mcap.stream_reader import StreamReader

    schemas: dict[int, Any] = {}
    channels: dict[int, Any] = {}
    with open(path, "rb") as f:
        for rec in StreamReader(f, skip_magic=False).records:
            if isinstance(rec, Schema):
                schemas.setdefault(rec.id, rec)
            elif isinstance(rec, Channel):
                channels.setdefault(rec.id, rec)
    return [(schemas.get(c.schema_id), c) for _, c in sorted(channels.items())]


def check_case(json_path: Path, work: Path) -> dict[str, int]:
    """Run every check on one case; returns its message counts (written, recovered)."""
    case = load_case(json_path)
    data = build_case(case)
    check_case_crcs(case, data)
    path, out = work / f"{case.name}.mcap", work / f"{case.name}-recovered.mcap"
    path.write_bytes(data)
    want = _described(case)
    n_messages = sum(want["messages"].values())
    assert _recovered(path) == want, case.name  # the mcap package reads the rebuilt file so

    d = scan(path)
    crc = int(next(f for k, f in case.records if k == "DataEnd")["data_section_crc"])
    assert d.status == ("complete" if crc else "unverified"), (case.name, d.problems)
    assert d.readable_messages == n_messages and not d.problems, case.name
    assert d.checks["chunks"] == ("1 of 1 verified" if "ch" in case.features
                                  else "no chunks"), case.name

    s = summarize(path)
    assert s["messages"] == n_messages, case.name
    assert len(s["channels"]) == sum(want["channels"].values()), case.name
    assert sorted(c["messages"] for c in s["channels"]) == sorted(
        Counter(m[0] for m in want["messages"].elements()).get(ch, 0)
        for ch in want["channels"].elements()), case.name
    assert sorted(c["schema"] for c in s["channels"] if c["schema"]) == sorted(
        sch[0] for sch in want["schemas"].elements()), case.name
    assert len(s["attachments"]) == sum(want["attachments"].values()), case.name
    assert len(s["metadata"]) == sum(want["metadata"].values()), case.name

    with LogReader(path, check_version=False) as r:
        got = [(m.sequence, m.log_time, bytes(m.data)) for _, _, m in r.raw_messages()]
        assert {a.name for a in r.iter_attachments()} == {
            a[0] for a in want["attachments"]}, case.name
        assert sum(len(items) for _, items in r.chunks()) == n_messages, case.name
    assert Counter(got) == Counter((m[1], m[2], m[4]) for m in want["messages"].elements()
                                   ), case.name
    assert [t for _, t, _ in got] == sorted(t for _, t, _ in got), case.name

    rd = recover(path, out)
    assert rd.status == d.status and rd.readable_messages == n_messages, case.name
    assert _recovered(out) == want, case.name
    # the copy vouches for what the input vouched for: its unverified messages stay so
    assert scan(out).status == d.status, case.name
    return {"written": n_messages, "recovered": rd.readable_messages}


@pytest.mark.parametrize("json_path", sorted(COMMITTED.glob("*.json")), ids=lambda p: p.stem)
def test_committed_case(json_path, tmp_path):
    counts = check_case(json_path, tmp_path)
    # the committed file is what the builder makes of its description, byte for byte
    assert json_path.with_suffix(".mcap").read_bytes() == (tmp_path / (
        json_path.stem + ".mcap")).read_bytes()
    assert counts["recovered"] == counts["written"]


def test_committed_cases_cover_what_sgtool_once_refused():
    """Messages outside chunks without a summary, channels repeated without their schemas,
    padded records, records no index points to: each is among the committed cases, and
    each needs the walk (the summary alone does not say everything)."""
    names = {p.stem for p in COMMITTED.glob("*.json")}
    assert {"OneMessage", "TenMessages-ch-chx-mx-pad-rch-st-sum", "OneAttachment-pad-st",
            "OneMetadata-mdx-pad-st-sum"} <= names
    from mcap.reader import make_reader

    with open(COMMITTED / "OneMessage.mcap", "rb") as f:
        assert make_reader(f).get_summary() is None
    with open(COMMITTED / "TenMessages-ch-chx-mx-pad-rch-st-sum.mcap", "rb") as f:
        summary = make_reader(f).get_summary()
    assert summary is not None and summary.channels and not summary.schemas
    assert needs_walk(summary)
    with open(COMMITTED / "OneMessage-ch-chx-mx-pad-rch-rsh-st-sum.mcap", "rb") as f:
        assert not needs_walk(make_reader(f).get_summary())  # a full summary is trusted


def test_all_conformance_cases(shared_data_dir, tmp_path):
    root = shared_data_dir / "mcap-conformance"
    if not root.is_dir():
        pytest.skip(f"{root} is absent")
    cases = all_cases(root)
    assert len(cases) == 416
    totals: Counter[str] = Counter()
    for p in cases:
        totals.update(check_case(p, tmp_path))
        for f in tmp_path.iterdir():
            f.unlink()
    print(f"\n{len(cases)} conformance cases complete; messages recovered "
          f"{totals['recovered']} of {totals['written']}")
    # every Message record of the descriptions, each read and recovered once
    assert totals["recovered"] == totals["written"] == 1768


def test_padding_that_hides_a_record_is_damage(tmp_path):
    """Bytes a newer writer appends are accepted; a length field grown by damage that
    swallows the next record is not taken for them."""
    import struct

    src = (COMMITTED / "OneMessage.mcap").read_bytes()
    # the schema record follows the header (8 + 17 bytes); grow its length over the channel
    pos = 8 + 17
    schema_len = struct.unpack_from("<Q", src, pos + 1)[0]
    channel_len = struct.unpack_from("<Q", src, pos + 9 + schema_len + 1)[0]
    bad = bytearray(src)
    struct.pack_into("<Q", bad, pos + 1, schema_len + 9 + channel_len)
    path = tmp_path / "grown.mcap"
    path.write_bytes(bytes(bad))
    d = scan(path)
    assert d.status == "corrupt"
    assert d.problems == ["record at byte 25 (opcode 0x03) has a damaged length field (47 "
                          "bytes after its fields look like damage); read it up to the next "
                          "record"]
    assert d.readable_messages == 1  # the channel and its message are read all the same


def test_a_pipe_is_refused_in_one_line(tmp_path):
    fifo = tmp_path / "log.fifo"
    os.mkfifo(fifo)
    for fn in (lambda: LogReader(fifo), lambda: summarize(fifo), lambda: scan(fifo),
               lambda: recover(fifo, tmp_path / "out.mcap")):
        with pytest.raises(LogFormatError, match="is a pipe, not a file: sgtool reads a log "
                                                 "by seeking"):
            fn()
    res = CliRunner().invoke(cli, ["info", str(fifo)])
    assert res.exit_code == 2
    assert "is a pipe" in res.output and "Traceback" not in res.output


def test_a_walked_file_reads_by_time_like_an_indexed_one():
    """TenMessages' summary repeats the channel but not its schema: the reader indexes the
    file by a walk, and time ranges, reverse order and counts come out as for an indexed
    file (log times 0..9, two messages at 3 ns)."""
    path = COMMITTED / "TenMessages-ch-chx-mx-pad-rch-st-sum.mcap"
    with LogReader(path, check_version=False) as r:
        assert [d.log_time_ns for d in r.messages()] == [0, 1, 2, 3, 3, 4, 5, 7, 8, 9]
        assert [d.log_time_ns for d in r.messages(start_ns=2, end_ns=5, reverse=True)] == [
            4, 3, 3, 2]
        assert r.time_range() == (0, 9)
        [ch] = r.channels()
        assert (ch.topic, ch.schema_name, ch.schema_encoding, ch.message_count) == (
            "example", "Example", "c", 10)
