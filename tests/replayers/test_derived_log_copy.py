"""Replay copies the input's chunks into the derived log as they are (no recompression)
wherever that keeps the messages and their order; the derived log reads back exactly as
the one written message by message."""

from __future__ import annotations

import pytest
from mcap.reader import make_reader
from mcap.records import Message
from mcap.stream_reader import StreamReader
from support.mcap_variants import Variant, rewrite
from support.paths import GOLDEN

from sgtool.log import LogReader
from sgtool.log import schemas as S
from sgtool.log.recover import scan
from sgtool.replayers.derived_log import ReplayOptions, replay

TOUR = GOLDEN / "house6-tour.mcap"
START = GOLDEN / "house10-start.mcap"
TRIGGERS = {S.RECORDS["instances"].topic, S.RECORDS["action"].topic}


def read_back(path):
    """(topic, log time, bytes) in the order of sgtool's reader, and of the mcap package's."""
    with LogReader(path) as r:
        ours = [(c.topic, m.log_time, bytes(m.data)) for _, c, m in r.raw_messages()]
    with open(path, "rb") as f:
        theirs = [(c.topic, m.log_time, bytes(m.data))
                  for _, c, m in make_reader(f).iter_messages(log_time_order=True)]
    assert ours == theirs
    return ours


def chunk_records(path):
    """The chunk records of a log (bytes) and, per record, the topics of its messages."""
    data = path.read_bytes()
    with LogReader(path) as r:
        return [(data[ci.chunk_start_offset:ci.chunk_start_offset + ci.chunk_length],
                 {c.topic for _, c, _ in items})
                for ci, (_, items) in zip(sorted(r.summary.chunk_indexes,
                                                 key=lambda ci: ci.chunk_start_offset),
                                          r.chunks(), strict=True)]


def test_copied_chunks_give_the_same_derived_log(tmp_path):
    copied, written = tmp_path / "copied.mcap", tmp_path / "written.mcap"
    a = replay(TOUR, copied)
    b = replay(TOUR, written, copy_chunks=False)
    assert (a.frames, a.refreshes) == (b.frames, b.refreshes) == (206, 31)
    assert read_back(copied) == read_back(written)
    assert scan(copied).status == "complete"
    out = copied.read_bytes()
    inputs = chunk_records(TOUR)
    # every input chunk without an instance table or action record is in the output as it
    # is; the others were written message by message (a refresh at their log time must
    # come before them)
    as_is = [rec in out for rec, _ in inputs]
    assert as_is == [not (topics & TRIGGERS) for _, topics in inputs]
    assert 0 < sum(as_is) < len(as_is)
    assert b"".join(rec for rec, _ in inputs[:3]) not in written.read_bytes()
    replay(copied, None, verify=True)  # every chunk CRC of the copy checks


def test_what_is_not_copied(tmp_path):
    # a log with derived channels (replayed before) is written message by message, as is
    # a replay cut short by --max-frames: the same bytes as without copying
    first = tmp_path / "first.mcap"
    replay(TOUR, first, ReplayOptions(max_frames=40))
    replay(TOUR, tmp_path / "first-written.mcap", ReplayOptions(max_frames=40),
           copy_chunks=False)
    assert first.read_bytes() == (tmp_path / "first-written.mcap").read_bytes()
    again, again_written = tmp_path / "again.mcap", tmp_path / "again-written.mcap"
    replay(first, again)
    replay(first, again_written, copy_chunks=False)
    assert again.read_bytes() == again_written.read_bytes()


def test_max_frames_copies_exactly_that_many_frames(tmp_path):
    """--max-frames N: the derived log holds the N frames that were integrated, not the
    start of frame N + 1 (its images and poses arrive before the frame is complete)."""
    out = tmp_path / "cut.mcap"
    report = replay(TOUR, out, ReplayOptions(max_frames=20))
    assert report.frames == 20 and report.truncated
    with LogReader(out) as r:
        assert r.message_count("/camera/depth") == 20
        last_depth = max(d.log_time_ns for d in r.messages(["/camera/depth"]))
        assert max(d.log_time_ns for d in r.messages(["/tf"])) <= last_depth
        assert r.message_count("/camera/rgb") == 20


def test_definitions_outside_the_inputs_chunks_precede_the_copied_ones(tmp_path):
    """An input that defines its channels outside its chunks, a message a chunk: the
    derived log defines every channel before its first message (the MCAP specification;
    the mcap package's streaming reader refuses otherwise) and reads back whole."""
    src = rewrite(TOUR, tmp_path / "outside.mcap", Variant(outside=True, chunk_messages=1))
    out = tmp_path / "derived.mcap"
    report = replay(src, out)
    assert (report.frames, report.refreshes) == (206, 31)
    with open(out, "rb") as f:
        streamed = [m for m in StreamReader(f, validate_crcs=True).records
                    if isinstance(m, Message)]
    assert len(streamed) == len(read_back(out))
    d = scan(out)
    assert d.status == "complete", d.problems


def _ties(first: set[str] | None = None, last: set[str] | None = None):
    """An order of :data:`START`'s messages that puts, among messages of one log time,
    those of topics ``first`` before the others and those of ``last`` after them (MCAP
    orders no such ties)."""
    with LogReader(START) as r:
        topics = {cid: ch.topic for cid, ch in r.summary.channels.items()}

    def rank(m):
        topic = topics[m.channel_id]
        return -1 if first and topic in first else 1 if last and topic in last else 0

    return lambda messages: sorted(messages, key=lambda m: (m.log_time, rank(m)))


@pytest.mark.parametrize("name", ["records first", "transforms last", "ids last"])
def test_messages_of_one_log_time_replay_alike_in_any_order(tmp_path, name):
    """The golden log with the messages of each log time in another order: the same scene
    graphs (an action record before its frame's /tf finished that frame without it)."""
    order = {"records first": _ties(first=TRIGGERS), "transforms last": _ties(last={S.TF}),
             "ids last": _ties(last={S.IDS, S.CALIBRATION})}[name]
    src = rewrite(START, tmp_path / "ties.mcap", Variant(order=order))
    graphs = []
    for log in (START, src):
        got = []
        replay(log, None, on_refresh=lambda r, _s, got=got: got.append(r.graph.to_json()))
        graphs.append(got)
    assert len(graphs[0]) == 15 and graphs[1] == graphs[0]
