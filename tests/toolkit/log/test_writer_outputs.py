"""Log and file outputs under hostile conditions: two writers on one path, a full disk, a
read-only destination, Ctrl-C. Nothing half-written may appear at the final path, every
failure is one line, and a partial file is kept only when it holds recoverable data."""

from __future__ import annotations

import errno
import os
import shlex
import signal
import tempfile

import pytest
from click.testing import CliRunner
from support.logfixtures import DT, synthetic_frame, write_log
from support.paths import GOLDEN

from sgtool import cli as cli_module
from sgtool.cli import cli
from sgtool.files import OutputError, atomic_write
from sgtool.log import LogReader, LogWriter
from sgtool.log.recover import recover
from sgtool.log.writer import InterruptedWrite, partial_files

ENOSPC = OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))


def frames(w: LogWriter, n: int, start: int = 0) -> None:
    for i in range(start, start + n):
        k, rgb, depth, ids, pose, base = synthetic_frame(i)
        w.write_frame(i * DT, rgb=rgb, depth=depth, ids=ids, pose=pose, intrinsics=k,
                      base_pose=base)


def leftovers(folder) -> list[str]:
    return sorted(p.name for p in folder.iterdir())


def test_two_writers_of_one_path_use_their_own_files_and_the_last_rename_wins(tmp_path):
    out = tmp_path / "run.mcap"
    a = LogWriter(out, seed=1)
    b = LogWriter(out, seed=2)
    assert a.partial_path != b.partial_path
    assert {a.partial_path, b.partial_path} == set(partial_files(out))
    frames(a, 3)
    frames(b, 5)
    a.close()
    with LogReader(out) as r:
        assert r.frame_count() == 3 and r.seed == 1
    b.close()  # the other writer is not hurt by the first rename
    with LogReader(out) as r:
        assert r.frame_count() == 5 and r.seed == 2
    assert leftovers(tmp_path) == ["run.mcap"]


def test_two_processes_writing_one_path_both_finish_with_a_valid_log(tmp_path):
    import subprocess
    import sys
    from pathlib import Path

    tests = Path(__file__).resolve().parents[2]
    script = (
        f"import sys; sys.path.insert(0, {str(tests)!r})\n"
        "from support.logfixtures import write_log\n"
        "write_log(sys.argv[1], n=int(sys.argv[2]))\n"
    )
    out = tmp_path / "run.mcap"
    procs = [subprocess.Popen([sys.executable, "-c", script, str(out), str(n)],
                              stderr=subprocess.PIPE, text=True) for n in (40, 41)]
    errs = [p.communicate()[1] for p in procs]
    assert [p.returncode for p in procs] == [0, 0], errs
    with LogReader(out) as r:
        assert r.frame_count() in (40, 41)  # one complete log, whichever renamed last
    assert leftovers(tmp_path) == ["run.mcap"]


def test_partial_name_is_unique_and_has_the_documented_pattern(tmp_path):
    out = tmp_path / "a[1].mcap"  # glob characters in the name are matched literally
    w = LogWriter(out)
    name = w.partial_path.name
    assert name.startswith("a[1].mcap.") and name.endswith(".partial")
    assert len(name) == len("a[1].mcap.") + 8 + len(".partial")
    assert partial_files(out) == [w.partial_path]
    assert partial_files(tmp_path / "other.mcap") == []
    w.abort()
    assert leftovers(tmp_path) == []


def test_ctrl_c_keeps_a_recoverable_partial_file_and_says_where(tmp_path):
    out = tmp_path / "run.mcap"
    with pytest.raises(InterruptedWrite) as info, LogWriter(out, seed=3) as w:
        frames(w, 25)  # 2.5 s of log time: two closed chunks and an open one
        raise KeyboardInterrupt
    assert isinstance(info.value, KeyboardInterrupt)
    (partial,) = partial_files(out)
    assert info.value.partial == partial and not out.exists()
    assert str(partial) in info.value.note and "sgtool doctor" in info.value.note
    d = recover(partial, tmp_path / "r.mcap")
    assert d.status == "truncated"
    with LogReader(tmp_path / "r.mcap") as r:
        assert r.frame_count() == 25  # the open chunk was flushed on the way out
    assert not info.value.note.endswith("--force)")


def test_the_recover_hint_of_an_overwrite_runs_as_given(tmp_path):
    """Ctrl-C while replacing a log (--force): the earlier log stays, so the hint's
    recover command needs --force too; it runs as printed."""
    out = tmp_path / "run.mcap"
    with LogWriter(out, seed=3) as w:
        frames(w, 3)
    with pytest.raises(InterruptedWrite) as info, LogWriter(out, seed=3, overwrite=True) as w:
        frames(w, 25)
        raise KeyboardInterrupt
    hint = info.value.note.split("recover it with: ")[1].rstrip(")")
    assert hint.endswith(" --force")
    r = CliRunner().invoke(cli, shlex.split(hint)[1:])
    assert r.exit_code in (0, 1), r.output  # 1: a truncated log, recovered
    with LogReader(out) as log:
        assert log.frame_count() == 25


def test_ctrl_c_before_any_message_leaves_nothing(tmp_path):
    out = tmp_path / "run.mcap"
    with pytest.raises(InterruptedWrite, match="nothing written"), LogWriter(out):
        raise KeyboardInterrupt
    assert leftovers(tmp_path) == []


def test_ctrl_c_of_output_that_can_be_made_again_leaves_nothing(tmp_path):
    """``keep_partial=False`` (a replay's derived log): Ctrl-C removes the partial file,
    however much it holds, and the interrupt goes on as it came."""
    out = tmp_path / "derived.mcap"
    with pytest.raises(KeyboardInterrupt) as info, LogWriter(out, keep_partial=False) as w:
        frames(w, 25)
        raise KeyboardInterrupt
    assert not isinstance(info.value, InterruptedWrite)
    assert leftovers(tmp_path) == []


class FullDisk:
    """A file whose writes fail with ENOSPC after ``room`` bytes, like a full disk."""

    def __init__(self, fh, room: int) -> None:
        self._fh, self.room = fh, room

    def write(self, data) -> int:
        self.room -= len(data)
        if self.room < 0:
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
        return self._fh.write(data)

    def __getattr__(self, name):
        return getattr(self._fh, name)


def fill_disk(monkeypatch, room: int) -> None:
    """Files opened through os.fdopen (the log writer's) hold at most ``room`` bytes."""
    real = os.fdopen

    def fdopen(fd, *a, **kw):
        return FullDisk(real(fd, *a, **kw), room)

    monkeypatch.setattr(os, "fdopen", fdopen)


@pytest.fixture
def full_disk(monkeypatch):
    fill_disk(monkeypatch, 20_000)


@pytest.mark.parametrize("short", [40, 20_000])  # fails at close (summary) / mid-frames
def test_full_disk_is_one_line_and_leaves_nothing(tmp_path, monkeypatch, short):
    size = write_log(tmp_path / "ref.mcap", n=30).stat().st_size
    (tmp_path / "ref.mcap").unlink()
    fill_disk(monkeypatch, size - short)
    out = tmp_path / "run.mcap"
    with pytest.raises(OutputError) as info:
        write_log(out, n=30)
    assert str(info.value) == (f"cannot write {out}: No space left on device "
                               "(nothing was written)")
    assert leftovers(tmp_path) == []


def test_replay_on_a_full_disk_is_one_line_without_traceback(tmp_path, full_disk):
    out = tmp_path / "d.mcap"
    r = CliRunner().invoke(cli, ["replay", str(GOLDEN / "house6-tour.mcap"), "-o", str(out),
                                 "--max-frames", "30", "--no-progress"])
    assert r.exit_code == 2, r.output
    assert r.output.strip().splitlines() == [
        f"sgtool: error: cannot write {out}: No space left on device (nothing was written)"]
    assert leftovers(tmp_path) == []


def test_an_input_error_inside_the_writer_is_not_blamed_on_the_output(tmp_path):
    out = tmp_path / "run.mcap"
    missing = tmp_path / "nope.bin"
    with pytest.raises(FileNotFoundError), LogWriter(out) as w:
        frames(w, 2)
        open(missing, "rb")  # noqa: SIM115 - an input that is not there
    assert leftovers(tmp_path) == []


@pytest.fixture
def read_only(monkeypatch):
    """Every new temporary file fails as in a read-only folder (root ignores chmod)."""

    def mkstemp(*a, dir=None, **kw):
        raise OSError(errno.EROFS, os.strerror(errno.EROFS), str(dir))

    monkeypatch.setattr(tempfile, "mkstemp", mkstemp)


@pytest.mark.parametrize("args", [
    ["scenes", "generate", "--seed", "1", "-o", "{d}/h.json"],
    ["replay", str(GOLDEN / "house6-tour.mcap"), "-o", "{d}/d.mcap", "--max-frames", "3",
     "--no-progress"],
    ["view", str(GOLDEN / "house6-tour.mcap"), "-o", "{d}/v.rrd", "--max-frames", "3",
     "--no-voxels"],
    ["doctor", str(GOLDEN / "house6-tour.mcap"), "--recover", "{d}/r.mcap"],
], ids=["scenes-generate", "replay", "view", "doctor-recover"])
def test_read_only_destination_is_one_line(tmp_path, read_only, args):
    args = [a.replace("{d}", str(tmp_path)) for a in args]
    r = CliRunner().invoke(cli, args)
    assert r.exit_code == 2, r.output
    lines = r.output.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("sgtool: error: cannot write ")
    assert "Read-only file system (nothing was written)" in lines[0]
    assert leftovers(tmp_path) == []


def test_an_unwritable_file_in_any_command_is_one_line(tmp_path, monkeypatch):
    from sgtool.results import EpisodeResult, write_jsonl

    eps = write_jsonl([EpisodeResult("greedy", 0, "h", 0, "mug", True, 2, 3.0, 2.5)],
                      tmp_path / "episodes.jsonl")

    def refuse(path, data):
        raise PermissionError(errno.EACCES, os.strerror(errno.EACCES), str(path))

    monkeypatch.setattr("sgtool.files.atomic_write", refuse)
    out = tmp_path / "e.json"
    r = CliRunner().invoke(cli, ["eval", str(eps), "-o", str(out)])
    assert r.exit_code == 2
    assert r.output.strip().splitlines() == [f"sgtool: error: Permission denied: {out}"]
    assert leftovers(tmp_path) == ["episodes.jsonl"]


def test_atomic_write_on_a_full_disk_names_the_final_path(tmp_path, monkeypatch):
    real_fsync = os.fsync

    def fsync(fd):
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    monkeypatch.setattr(os, "fsync", fsync)
    with pytest.raises(OutputError, match=r"cannot write .*x\.json: No space left"):
        atomic_write(tmp_path / "x.json", "{}")
    monkeypatch.setattr(os, "fsync", real_fsync)
    assert leftovers(tmp_path) == []


def test_view_ctrl_c_leaves_nothing_and_exits_130(tmp_path, monkeypatch):
    import sgtool.analysis.rerun_view as rv

    real = rv._export

    def interrupted(rec, r, **kw):
        real(rec, r, **kw)  # everything exported: Ctrl-C just before the file is finished
        raise KeyboardInterrupt

    monkeypatch.setattr(rv, "_export", interrupted)
    log = write_log(tmp_path / "run.mcap")
    r = CliRunner().invoke(cli, ["view", str(log), "-o", str(tmp_path / "v.rrd"),
                                 "--no-voxels"])
    assert r.exit_code == 130
    assert r.output.strip() == "sgtool: interrupted; no output was left half-written"
    assert leftovers(tmp_path) == ["run.mcap"]


def test_view_stops_before_rerun_hangs_on_a_full_disk(tmp_path, monkeypatch):
    import sgtool.analysis.rerun_view as rv

    real = os.statvfs

    class Nearly:
        def __init__(self, st) -> None:
            self.f_frsize, self.f_bavail = st.f_frsize, (rv.FREE_MARGIN - 1) // st.f_frsize

    monkeypatch.setattr(os, "statvfs", lambda p: Nearly(real(p)))
    log = write_log(tmp_path / "run.mcap")
    out = tmp_path / "v.rrd"
    r = CliRunner().invoke(cli, ["view", str(log), "-o", str(out), "--no-voxels"])
    assert r.exit_code == 2
    assert r.output.strip() == (f"sgtool: error: cannot write {out}: No space left on "
                                "device (nothing was written)")
    assert leftovers(tmp_path) == ["run.mcap"]


def test_replay_ctrl_c_leaves_no_partial_log(tmp_path, monkeypatch):
    """A derived log can be made again: Ctrl-C removes its partial file (partial files of
    interrupted replays used to pile up beside the output, each as big as the log)."""
    calls = {"n": 0}
    real = LogWriter._add  # every message but those of input chunks copied as they are

    def add(self, *a, **kw):
        calls["n"] += 1
        if calls["n"] == 100:
            raise KeyboardInterrupt
        return real(self, *a, **kw)

    monkeypatch.setattr(LogWriter, "_add", add)
    out = tmp_path / "d.mcap"
    r = CliRunner().invoke(cli, ["replay", str(GOLDEN / "house6-tour.mcap"), "-o", str(out),
                                 "--no-progress"])
    assert r.exit_code == 130, r.output
    assert r.output.strip() == "sgtool: interrupted; no output was left half-written"
    assert partial_files(out) == [] and not out.exists()


def test_main_ignores_ctrl_c_once_the_command_is_done(tmp_path):
    before = signal.getsignal(signal.SIGINT)
    try:
        cli_module.main(["scenes", "generate", "--seed", "1", "-o", str(tmp_path / "h.json")])
        assert (tmp_path / "h.json").is_file()
        assert signal.getsignal(signal.SIGINT) == signal.SIG_IGN
    finally:
        signal.signal(signal.SIGINT, before)


def test_eval_and_view_never_overwrite_without_force(tmp_path):
    """eval -o and view -o refuse an existing file (the input log included) unless --force,
    and eval never writes over one of its inputs; budgets must be finite and > 0."""
    from sgtool.results import EpisodeResult, write_jsonl

    eps = write_jsonl([EpisodeResult("greedy", 0, "h", 0, "mug", True, 2, 3.0, 2.5)],
                      tmp_path / "episodes.jsonl")
    before = eps.read_bytes()
    r = CliRunner().invoke(cli, ["eval", str(eps), "-o", str(eps)])
    assert r.exit_code == 2 and f"{eps} exists; not overwriting it (use --force)" in r.output
    r = CliRunner().invoke(cli, ["eval", str(eps), "-o", str(eps), "--force"])
    assert r.exit_code == 2 and "the output must not be an input" in r.output
    assert eps.read_bytes() == before
    out = tmp_path / "e.txt"
    assert CliRunner().invoke(cli, ["eval", str(eps), "-o", str(out)]).exit_code == 0
    assert CliRunner().invoke(cli, ["eval", str(eps), "-o", str(out)]).exit_code == 2
    assert CliRunner().invoke(cli, ["eval", str(eps), "-o", str(out), "--force"]).exit_code == 0
    for bad in ("0", "-1", "nan", "inf"):
        r = CliRunner().invoke(cli, ["eval", str(eps), "--distance-budget", bad])
        assert r.exit_code == 2 and len(r.output.strip().splitlines()) == 1, (bad, r.output)
    log = write_log(tmp_path / "run.mcap")
    other = tmp_path / "other.rrd"  # an existing file under the name -o gives
    other.write_bytes(log.read_bytes())
    r = CliRunner().invoke(cli, ["view", str(log), "-o", str(other), "--no-voxels"])
    assert r.exit_code == 2 and "exists; not overwriting it (use --force)" in r.output
    assert other.read_bytes() == log.read_bytes()


def test_a_frame_of_nested_lists_is_written_as_its_arrays(tmp_path):
    """Images and a pose given as nested lists (as a pose already could be) are written as
    the arrays they stand for, not an AttributeError from inside the encoder."""
    from sgtool.log import LogReader, LogWriter

    k, rgb, depth, ids, pose, _ = synthetic_frame(0)
    frames = []
    for name, conv in (("arrays", lambda a: a), ("lists", lambda a: a.tolist())):
        with LogWriter(tmp_path / f"{name}.mcap", seed=1) as w:
            w.write_frame(0, depth=conv(depth), pose=conv(pose), intrinsics=k,
                          rgb=conv(rgb), ids=conv(ids))
        with LogReader(tmp_path / f"{name}.mcap") as r:
            frames += list(r.frames())
    a, b = frames
    assert (a.depth == b.depth).all() and (a.rgb == b.rgb).all() and (a.ids == b.ids).all()
    assert (a.pose == b.pose).all()


@pytest.mark.parametrize("stem", ["a" * 245, "é" * 121])  # 250 and 247 bytes with ".mcap"
def test_an_output_name_near_the_limit_gets_a_temporary_name_that_fits(tmp_path, stem):
    """A name of up to 255 bytes is a name the file system takes: its temporary name
    (``NAME.XXXXXXXX.partial``, 18 bytes longer) is cut to fit, at a character, and is
    still found as the output's partial file."""
    out = tmp_path / f"{stem}.mcap"
    assert len(os.fsencode(out.name)) <= 255
    w = LogWriter(out)
    assert len(os.fsencode(w.partial_path.name)) <= 255
    w.partial_path.name.encode("utf-8")  # cut at a character, not inside one
    assert partial_files(out) == [w.partial_path]
    frames(w, 2)
    w.close()
    assert LogReader(out).frame_count() == 2 and leftovers(tmp_path) == [out.name]
    atomic_write(tmp_path / f"{stem}.json", "{}")
    assert (tmp_path / f"{stem}.json").read_text() == "{}"


def test_two_long_names_that_begin_alike_keep_their_partial_files_apart(tmp_path):
    """Cut to fit, two names differing only past the cut still name their own partial
    files (the cut name carries a hash of the whole one)."""
    a, b = (tmp_path / f"run_{'x' * 236}_{c}.mcap" for c in "AB")
    wa, wb = LogWriter(a), LogWriter(b)
    assert wa.partial_path.name != wb.partial_path.name
    assert partial_files(a) == [wa.partial_path] and partial_files(b) == [wb.partial_path]
    wb.abort()
    assert partial_files(a) == [wa.partial_path] and partial_files(b) == []
    wa.abort()


def test_without_hard_links_a_beaten_output_is_kept_in_sight_too(tmp_path, monkeypatch):
    """A file system without hard links (FAT, some network mounts): the output another run
    wrote meanwhile stays, and this run's is renamed to its visible name."""
    import errno
    import os

    import pytest

    from sgtool.files import OutputError, atomic_write
    from sgtool.output_check import check_output

    def no_links(*args: object) -> None:
        raise PermissionError(errno.EPERM, "Operation not permitted")

    monkeypatch.setattr(os, "link", no_links)
    out = tmp_path / "h.json"
    check_output(out)
    out.write_text("theirs")
    with pytest.raises(OutputError, match="appeared while this run wrote it") as e:
        atomic_write(out, "mine")
    (kept,) = [p for p in tmp_path.iterdir() if p != out]
    assert not kept.name.startswith(".") and kept.read_text() == "mine"
    assert out.read_text() == "theirs" and str(e.value).endswith(f"kept in {kept}")


def test_an_output_another_run_wrote_meanwhile_is_not_replaced_without_force(tmp_path):
    """The no---force check holds to the end: a file that appeared under the output's name
    while the command ran (a second run with the same -o) is kept; this run says so in one
    line and keeps its own finished file beside it, in sight."""
    import pytest

    from sgtool.files import OutputError, atomic_write
    from sgtool.log.writer import LogWriter
    from sgtool.output_check import check_output

    out = tmp_path / "h.json"
    check_output(out)
    out.write_text("theirs")
    with pytest.raises(OutputError, match="appeared while this run wrote it") as e:
        atomic_write(out, "mine")
    kept = [p for p in tmp_path.iterdir() if p != out]
    assert out.read_text() == "theirs" and [p.name[:7] for p in kept] == ["h.json."]
    assert kept[0].read_text() == "mine" and str(e.value).endswith(f"kept in {kept[0]}")
    kept[0].unlink()
    log = tmp_path / "r.mcap"
    check_output(log)
    w = LogWriter(log)
    log.write_text("theirs")
    with pytest.raises(OutputError, match="kept in"):
        w.close()
    assert log.read_text() == "theirs" and len(list(tmp_path.glob("r.mcap.*.partial"))) == 1
    check_output(out, force=True)  # --force: replaced as before
    atomic_write(out, "mine")
    assert out.read_text() == "mine"
    dangling = tmp_path / "d.json"  # a link to a missing file is no run's output: replaced
    dangling.symlink_to(tmp_path / "gone.json")
    check_output(dangling)
    atomic_write(dangling, "mine")
    assert dangling.read_text() == "mine" and not dangling.is_symlink()
