"""Replay copies the input's chunks into the derived log as they are (no recompression)
wherever that keeps the messages and their order; the derived log reads back exactly as
the one written message by message."""

from __future__ import annotations

from mcap.reader import make_reader
from support.paths import GOLDEN

from sgtool.log import LogReader
from sgtool.log import schemas as S
from sgtool.log.recover import scan
from sgtool.replayers.derived_log import ReplayOptions, replay

TOUR = GOLDEN / "house6-tour.mcap"
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
