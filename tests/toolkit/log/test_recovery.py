"""Crash tolerance: truncated logs recover a growing prefix; a SIGKILLed recorder loses at
most its last second of log time; doctor tells complete, truncated and corrupt apart."""

from __future__ import annotations

import json
import signal
import subprocess
import sys
import textwrap

import pytest
from click.testing import CliRunner
from support.logfixtures import synthetic_frame
from support.paths import TESTS

from sgtool.cli import cli
from sgtool.errors import LogFormatError
from sgtool.log import LogReader, LogWriter
from sgtool.log.recover import recover, scan
from sgtool.log.writer import partial_files

FPS = 20
DT = 1_000_000_000 // FPS


@pytest.fixture(scope="module")
def long_log(tmp_path_factory):
    """6 s of log time at 20 fps; chunks close every second."""
    path = tmp_path_factory.mktemp("logs") / "long.mcap"
    with LogWriter(path, seed=1) as w:
        w.attach_house("{}")
        for i in range(6 * FPS):
            k, rgb, depth, ids, pose, base = synthetic_frame(i)
            w.write_frame(i * DT, rgb=rgb, depth=depth, ids=ids, pose=pose, intrinsics=k,
                          base_pose=base)
    return path


def test_complete_log_scans_complete(long_log):
    d = scan(long_log)
    assert d.status == "complete" and not d.problems
    with LogReader(long_log) as r:
        assert d.readable_messages == r.message_count()


def test_truncation_every_two_percent_recovers_a_growing_prefix(long_log, tmp_path):
    data = long_log.read_bytes()
    with LogReader(long_log) as r:
        total_frames = r.frame_count()
    previous = -1
    frames_seen = []
    for pct in range(2, 100, 2):
        cut = tmp_path / "cut.mcap"
        cut.write_bytes(data[: len(data) * pct // 100])
        with pytest.raises(LogFormatError):  # the only error a reader may raise
            LogReader(cut)
        out = tmp_path / "rec.mcap"
        d = recover(cut, out, overwrite=True)
        assert d.status == "truncated"
        assert d.readable_messages >= previous
        previous = d.readable_messages
        with LogReader(out) as r:
            n = r.frame_count() if r.has("/camera/depth") else 0
            frames = list(r.frames()) if n else []
            assert len(frames) == n
            # a recovered prefix is the first n frames, whole; the readable prefix of a
            # cut chunk may end between the depth image of the last frame and its ids
            assert [f.index for f in frames] == list(range(n))
            assert all(f.rgb is not None and f.ids is not None for f in frames[:-1])
            assert all(f.rgb is not None for f in frames)
        frames_seen.append(n)
    assert frames_seen == sorted(frames_seen)
    assert frames_seen[-1] >= total_frames - FPS  # all but the last second
    assert frames_seen[0] < frames_seen[-1]


def test_a_cut_inside_an_uncompressed_chunk_is_a_truncation(tmp_path):
    """An uncompressed chunk holds whole records in its body: a file cut inside one is
    truncated, not corrupt (the records of the cut chunk are no resumption after damage;
    a ROS 2 bag of a review helper, cut at 10 MB, was called corrupt)."""
    path = tmp_path / "plain.mcap"
    with LogWriter(path, seed=1, compression="none") as w:
        for i in range(3 * FPS):
            k, rgb, depth, ids, pose, base = synthetic_frame(i)
            w.write_frame(i * DT, rgb=rgb, depth=depth, ids=ids, pose=pose, intrinsics=k)
    data = path.read_bytes()
    for pct in (15, 40, 55, 70, 85):
        cut = tmp_path / "cut.mcap"
        cut.write_bytes(data[: len(data) * pct // 100])
        d = scan(cut)
        assert d.status == "truncated", (pct, d.problems)
        assert d.readable_messages > 0


def test_corrupt_chunk_is_reported_and_skipped(long_log, tmp_path):
    from mcap.reader import make_reader

    with open(long_log, "rb") as f:
        summary = make_reader(f).get_summary()
    assert summary is not None
    middle = summary.chunk_indexes[len(summary.chunk_indexes) // 2]
    data = bytearray(long_log.read_bytes())
    data[middle.chunk_start_offset + middle.chunk_length // 2] ^= 0xFF  # inside one chunk
    bad = tmp_path / "bad.mcap"
    bad.write_bytes(bytes(data))
    d = recover(bad, tmp_path / "ok.mcap")
    assert d.status == "corrupt" and d.lost_chunks == 1
    with LogReader(tmp_path / "ok.mcap") as r:
        n = r.frame_count()
    assert 0 < n < 6 * FPS


RECORDER = textwrap.dedent(
    """
    import sys
    sys.path.insert(0, {tests!r})
    from support.logfixtures import synthetic_frame
    from sgtool.log import LogWriter
    DT = {dt}
    w = LogWriter(sys.argv[1], seed=0)
    for i in range(100000):
        k, rgb, depth, ids, pose, base = synthetic_frame(i)
        w.write_frame(i * DT, rgb=rgb, depth=depth, ids=ids, pose=pose, intrinsics=k,
                      base_pose=base)
        print(i, flush=True)
    """
)


def test_sigkilled_recorder_loses_at_most_the_last_second(tmp_path):
    out = tmp_path / "run.mcap"
    script = RECORDER.format(tests=str(TESTS), dt=DT)
    proc = subprocess.Popen([sys.executable, "-c", script, str(out)], stdout=subprocess.PIPE,
                            text=True)
    written = -1
    assert proc.stdout is not None
    for line in proc.stdout:
        written = int(line)
        if written >= 5 * FPS + 7:  # mid-second, mid-chunk
            break
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    partials = partial_files(out)  # OUT.XXXXXXXX.partial beside OUT
    assert len(partials) == 1 and not out.exists()
    partial = partials[0]
    result = CliRunner().invoke(
        cli, ["doctor", str(partial), "--recover", str(tmp_path / "r.mcap")]
    )
    assert result.exit_code == 1, result.output  # it was truncated
    assert "truncated" in result.output
    with LogReader(tmp_path / "r.mcap") as r:
        frames = list(r.frames())
    # frames 0..written were handed to the writer; at most one second of log time is lost
    assert len(frames) >= written + 1 - FPS
    assert [f.index for f in frames] == list(range(len(frames)))
    assert frames[-1].time_ns >= written * DT - 1_000_000_000


def test_doctor_cli_on_complete_and_json(long_log):
    r = CliRunner().invoke(cli, ["doctor", str(long_log), "--json"])
    assert r.exit_code == 0, r.output
    d = json.loads(r.output)
    assert d["status"] == "complete" and d["readable_messages"] > 6 * FPS * 4


def test_doctor_never_overwrites_input(long_log):
    before = long_log.read_bytes()
    r = CliRunner().invoke(cli, ["doctor", str(long_log), "--recover", str(long_log)])
    assert r.exit_code == 2 and "refusing to write the recovered log over its input" in r.output
    assert long_log.read_bytes() == before


def test_damaged_chunks_give_the_documented_error_only(long_log, tmp_path):
    """100 garbage bytes written over the log at 30 places: reading frames either works
    (the bytes hit something not read) or raises LogFormatError pointing to doctor, never
    a decompression or CRC error of the libraries."""
    import random

    data = long_log.read_bytes()
    errors = 0
    for k, off in enumerate(range(200, len(data) - 200, len(data) // 30)):
        bad = tmp_path / "bad.mcap"
        rng = random.Random(k)
        bad.write_bytes(data[:off] + bytes(rng.randrange(256) for _ in range(100))
                        + data[off + 100:])
        try:
            with LogReader(bad) as r:
                sum(1 for _ in r.frames())
        except LogFormatError as e:
            errors += 1
            assert "sgtool doctor" in str(e)
    assert errors >= 20  # most places are chunk data, which CRCs and zstd check


def test_doctor_user_errors(long_log, tmp_path):
    junk = tmp_path / "junk.mcap"
    junk.write_bytes(b"no log here")
    r = CliRunner().invoke(cli, ["doctor", str(junk)])
    assert r.exit_code == 2 and "not an MCAP file" in r.output
    r = CliRunner().invoke(cli, ["doctor", str(junk), "--recover", str(tmp_path / "o.mcap")])
    assert r.exit_code == 2 and not (tmp_path / "o.mcap").exists()
    taken = tmp_path / "taken.mcap"
    taken.write_bytes(b"keep me")
    r = CliRunner().invoke(cli, ["doctor", str(long_log), "--recover", str(taken)])
    assert r.exit_code == 2 and "use --force" in r.output and taken.read_bytes() == b"keep me"
    r = CliRunner().invoke(cli, ["doctor", str(long_log), "--recover", str(taken), "--force"])
    assert r.exit_code == 0 and taken.stat().st_size > 1000


def test_info_on_a_truncated_log_points_to_doctor(long_log, tmp_path):
    cut = tmp_path / "cut.mcap"
    cut.write_bytes(long_log.read_bytes()[: long_log.stat().st_size // 2])
    r = CliRunner().invoke(cli, ["info", str(cut)])
    assert r.exit_code == 2
    assert "without the MCAP footer" in r.output and "--recover" in r.output


def test_the_suggested_command_pastes_whole(long_log, tmp_path):
    """A cut log in a folder with a space: the reader's one line names it as it is and
    suggests `sgtool doctor` with the path quoted, so the command pastes as one word."""
    folder = tmp_path / "my runs"
    folder.mkdir()
    cut = folder / "tour 1.mcap"
    cut.write_bytes(long_log.read_bytes()[:-40])
    with pytest.raises(LogFormatError) as e:
        LogReader(cut)
    assert str(e.value).startswith(f"{cut}: the file ends without the MCAP footer")
    assert f"`sgtool doctor '{cut}' --recover OUT.mcap`" in str(e.value)


def test_a_recovered_log_is_named_mcap(long_log, tmp_path):
    r = CliRunner().invoke(cli, ["doctor", str(long_log), "--recover", str(tmp_path / "x.txt")])
    assert r.exit_code == 2 and "--recover" in r.output and "name it *.mcap" in r.output
    assert not (tmp_path / "x.txt").exists()


def test_bytes_appended_to_a_complete_log_are_not_called_a_cut(long_log, tmp_path):
    """A complete log with bytes appended (a second copy written over a first, a transfer
    that added a line end): the reader says where the log ends, not that it was cut."""
    data = long_log.read_bytes()
    padded = tmp_path / "padded.mcap"
    padded.write_bytes(data + b"\n")
    with pytest.raises(LogFormatError) as e:
        LogReader(padded)
    assert str(e.value).startswith(
        f"{padded}: 1 byte after the end of the MCAP file (its footer and closing magic end "
        f"at byte {len(data)}): bytes appended to a complete log;")
    recovered = tmp_path / "fixed.mcap"
    r = CliRunner().invoke(cli, ["doctor", str(padded), "--recover", str(recovered)])
    assert r.exit_code == 1 and recovered.is_file()
    with LogReader(recovered) as a, LogReader(long_log) as b:
        assert a.message_count() == b.message_count()


def test_doctor_names_bytes_appended_to_a_complete_log(long_log, tmp_path):
    """The diagnosis of a closed log followed by junk reads the log up to its closing magic
    (summary and CRCs checked, nothing lost) and names the appended bytes as its only
    problem; junk that itself holds a footer and magic is not taken for the end of a log
    unless the log before it reads without damage."""
    data = long_log.read_bytes()
    padded = tmp_path / "padded.mcap"
    padded.write_bytes(data + b"junk")
    d = scan(padded)
    whole = scan(long_log)
    assert d.status == "corrupt" and d.lost_messages == 0 and not d.lost_unknown
    assert d.problems == [f"4 bytes after the closing magic at byte {len(data)}: appended "
                          "to a closed log (its footer and magic end there)"]
    assert d.readable_messages == whole.readable_messages and d.checks == whole.checks
    # a file cut inside its data whose tail happens to hold a footer and magic: no "end"
    fake = tmp_path / "fake.mcap"
    fake.write_bytes(data[:len(data) // 2] + data[-37:] + b"x")
    f = scan(fake)
    assert f.status in ("corrupt", "truncated")
    assert not any("appended to a closed log" in p for p in f.problems)
