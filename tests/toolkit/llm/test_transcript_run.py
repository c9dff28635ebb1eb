"""A command's transcript: emptied when a run starts, kept when it ends, and put back as it
was when the run is interrupted (the run's other outputs are left as they were too)."""

from __future__ import annotations

import json
import os
import threading

import pytest

from sgtool.errors import SgtoolError
from sgtool.llm.recorded import TranscriptWriter, not_a_transcript, transcript_run

OLD = '{"messages": [], "model": "m", "old": 1}\n'  # an earlier run's exchange


def test_a_finished_run_keeps_its_own_transcript(tmp_path):
    t = tmp_path / "t.jsonl"
    t.write_text(OLD)
    with transcript_run(t):
        assert t.read_text() == ""  # one run per transcript
        w = TranscriptWriter(t)
        w.write({"new": 1})
        w.close()
    assert t.read_text() == '{"new": 1}\n'
    assert sorted(p.name for p in tmp_path.iterdir()) == ["t.jsonl"]


def test_an_interrupted_run_puts_the_previous_transcript_back(tmp_path):
    t = tmp_path / "t.jsonl"
    t.write_text(OLD)
    with pytest.raises(KeyboardInterrupt), transcript_run(t):
        TranscriptWriter(t).write({"new": 1})
        raise KeyboardInterrupt
    assert t.read_text() == OLD
    assert sorted(p.name for p in tmp_path.iterdir()) == ["t.jsonl"]
    fresh = tmp_path / "fresh.jsonl"  # none before: none after
    with pytest.raises(KeyboardInterrupt), transcript_run(fresh):
        raise KeyboardInterrupt
    assert not fresh.exists()


def test_a_killed_run_leaves_the_previous_transcript_in_sight(tmp_path):
    """SIGKILL runs no clean-up: the earlier transcript stays beside the new one under a
    visible name (it was a hidden .t.jsonl.*.partial that no later run mentioned)."""
    import subprocess
    import sys

    t = tmp_path / "t.jsonl"
    t.write_text(OLD)
    code = ("import os, sys\nfrom sgtool.llm.recorded import transcript_run\n"
            "with transcript_run(sys.argv[1]):\n    os.kill(os.getpid(), 9)\n")
    r = subprocess.run([sys.executable, "-c", code, str(t)], check=False)
    assert r.returncode == -9
    (kept,) = [p for p in tmp_path.iterdir() if p != t]
    assert kept.name.startswith("t.jsonl.") and kept.name.endswith(".previous")
    assert kept.read_text() == OLD and t.read_text() == ""


def test_a_failed_run_keeps_what_it_asked(tmp_path):
    """An error (not an interrupt) keeps the run's exchanges: they say what went wrong."""
    t = tmp_path / "t.jsonl"
    t.write_text(OLD)
    with pytest.raises(ValueError), transcript_run(t):
        w = TranscriptWriter(t)
        w.write({"new": 1})
        w.close()
        raise ValueError("the planner failed")
    assert t.read_text() == '{"new": 1}\n'
    assert sorted(p.name for p in tmp_path.iterdir()) == ["t.jsonl"]


def test_a_run_that_fails_before_asking_puts_the_previous_one_back(tmp_path):
    """A setup mistake (a bad option, a URL without http://) fails before the first
    exchange: the earlier run's transcript is not lost to an empty file."""
    t = tmp_path / "t.jsonl"
    t.write_text(OLD)
    with pytest.raises(ValueError), transcript_run(t):
        raise ValueError("a bad option")
    assert t.read_text() == OLD
    assert sorted(p.name for p in tmp_path.iterdir()) == ["t.jsonl"]


def test_a_transcript_is_never_written_over_a_log_or_another_file(tmp_path):
    """A transcript path that names an MCAP log (the input, a recording) or a file that is
    not a JSONL transcript is refused in one line and the file is left as it was."""
    log = tmp_path / "run.mcap"
    log.write_bytes(b"\x89MCAP0\r\n" + b"\0" * 64)
    notes = tmp_path / "notes.md"
    notes.write_text("\n# my notes\nkeep me\n")  # (a blank first line)
    results = tmp_path / "episodes.jsonl"  # JSON lines, but no exchanges
    results.write_text('{"planner": "scout", "success": true}\n')
    for path, why in ((log, "an MCAP log, not a JSONL transcript"),
                      (notes, "exists and is not a JSONL transcript"),
                      (results, "exists and is not a JSONL transcript")):
        before = path.read_bytes()
        with pytest.raises(SgtoolError, match=why):
            with transcript_run(path):
                pass
        with pytest.raises(SgtoolError, match=why):
            TranscriptWriter(path)
        with pytest.raises(SgtoolError, match=why):
            TranscriptWriter(path, append=False)
        assert path.read_bytes() == before
    long = tmp_path / "long.jsonl"  # a first exchange longer than any fixed read
    long.write_text(json.dumps({"model": "m", "messages": [{"role": "user",
                                                           "content": "x" * 200_000}]}) + "\n")
    with TranscriptWriter(long) as w:
        w.write({"new": 1})
    t = tmp_path / "t.jsonl"  # a transcript (or an empty file) is appended to
    t.write_text(OLD)
    with TranscriptWriter(t) as w:
        w.write({"new": 1})
    assert t.read_text() == OLD + '{"new": 1}\n'


def test_a_fifo_is_not_read_to_judge_it(tmp_path):
    """A named pipe (or /dev/stdout) given as the transcript is written as before, never
    opened for reading first (which would wait for a writer forever)."""
    fifo = tmp_path / "t.fifo"
    os.mkfifo(fifo)
    judged = threading.Thread(target=not_a_transcript, args=(fifo,), daemon=True)
    judged.start()
    judged.join(10)
    assert not judged.is_alive()
