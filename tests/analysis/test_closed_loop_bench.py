"""`sgtool run-bench` (sgtool.analysis.closed_loop_bench) on one small house, at 64x48 with
two steps per episode: logs per run, the table, resuming, Ctrl-C, the reason classes."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest
from click.testing import CliRunner

from sgtool.analysis import closed_loop_bench as clb
from sgtool.cli import cli
from sgtool.datasets.generator import generate_house
from sgtool.errors import SgtoolError
from sgtool.house.io import load_house, save_house
from sgtool.log.writer import partial_files

ARGS = ["run-bench", "--planners", "random,greedy", "--houses", "0", "--episodes", "1",
        "--resolution", "64x48", "--max-steps", "2", "--frames", "120", "--no-progress"]


def _episodes(task: clb.RunTask) -> list:
    """The episode list a worker draws for the task's house (the worker's memo)."""
    return clb.house_episodes(task)[1]


@pytest.fixture(scope="module")
def house_file(tmp_path_factory) -> Path:
    p = tmp_path_factory.mktemp("houses") / "small.json"
    save_house(generate_house(6, rooms=(4, 4)), p)
    return p


def test_run_bench_writes_a_log_per_run_and_resumes(house_file, tmp_path, monkeypatch) -> None:
    out = tmp_path / "rb"
    stale = tmp_path / ".rb.k1ll3d00.partial"  # a killed --force run's staging folder
    stale.mkdir()
    res = CliRunner().invoke(cli, [*ARGS, "--house", str(house_file), "-o", str(out),
                                   "--step-budget", "30"])
    assert res.exit_code == 0, res.output
    assert f"sgtool: note: {stale} is the unfinished output of a run" in res.output
    logs = sorted(p.relative_to(out).as_posix() for p in out.rglob("*.mcap"))
    assert logs == ["logs/none/greedy/small/ep-000.mcap",
                    "logs/none/random/small/ep-000.mcap"]
    summary = (out / "summary.md").read_text()
    assert "## Closed loop, noise 'none'" in summary and "| random " in summary
    assert "Failed skills/ep" in summary
    # wall-clock figures only in run.md: summary.md is the same bytes for the same run
    assert "Frames/s" not in summary and "Decision" not in summary
    run_md = (out / "run.md").read_text()
    assert "Frames/s" in run_md and "| random " in run_md
    lines = (out / "episodes.jsonl").read_text().splitlines()
    assert len(lines) == 2 and all('"house":"small"' in s for s in lines)
    assert (out / "efficiency_none_steps.png").stat().st_size > 0
    assert (out / "efficiency_none_frames.png").stat().st_size > 0
    # the statistics that separate planners (closed_loop_tables): one house, one episode,
    # so no interval ("[-]"); greedy against the first planner; frames per room
    assert "SR and SPL with bootstrap intervals over houses" in summary
    assert "Paired comparisons over houses" in summary and "| greedy  | random" in summary
    assert "Paired comparisons per house (intervals over its episodes)" in summary
    assert "SR against the frame budget (frames per room)" in summary and "[-]" in summary
    stats = json.loads((out / "summary.json").read_text())["noise"]["none"]
    assert [(d["planner"], d["reference"]) for d in stats["paired"]] == [("greedy", "random")]
    assert stats["paired_per_house"][0]["house"] == "small"
    # the most frames per room an episode used: at most --frames 120 over 4 rooms
    assert 0 < stats["frames"]["max_per_room"] <= 30.0
    # the settings eval re-scores the run by (AUC-E budgets) and compares runs by
    settings = json.loads((out / "summary.json").read_text())["settings"]
    assert settings == {"planners": ["random", "greedy"], "max_steps": 2,
                        "distance_budget": 5000.0, "step_budget": 30.0,
                        "planner_options": {}}
    scored = CliRunner().invoke(cli, ["eval", str(out), "--json"])
    assert scored.exit_code == 0, scored.output
    assert json.loads(scored.stdout)["budgets"]["steps"]["max"] == 30.0
    # a second run reads the logs back instead of running anything
    monkeypatch.setattr(clb, "run_episode", lambda *a, **k: pytest.fail("ran again"))
    again = CliRunner().invoke(cli, [*ARGS, "--house", str(house_file), "-o", str(out),
                                     "--step-budget", "30"])
    assert again.exit_code == 0, again.output
    assert (out / "episodes.jsonl").read_text().splitlines() == lines
    assert "| random " in again.output
    assert (out / "summary.md").read_text() == summary  # the same run, the same bytes
    # the AUC-E budgets are the report's: a report of the same logs on 8 steps
    only8 = CliRunner().invoke(cli, [*ARGS, "--house", str(house_file), "-o", str(out),
                                     "--report-only", "--step-budget", "8"])
    assert only8.exit_code == 0 and "steps: high-level steps, budget max 8" in \
        (out / "summary.md").read_text()
    assert "| random  | 0 " in (out / "run.md").read_text()  # nothing was run now
    # so are the frame budgets of the SR tables; curves of a profile the tables no longer
    # hold (an earlier run's, here made up) go with the report that leaves it out
    (out / "efficiency_mild_steps.png").write_bytes(b"stale")
    (out / "efficiency_steps.png").write_bytes(b"a bench's")  # no profile: not a curve here
    at = CliRunner().invoke(cli, [*ARGS, "--house", str(house_file), "-o", str(out),
                                  "--report-only", "--budgets", "7,14"])
    assert sorted(p.name for p in out.glob("efficiency_*")) == [
        "efficiency_none_distance.png", "efficiency_none_frames.png",
        "efficiency_none_steps.png", "efficiency_steps.png"]
    assert at.exit_code == 0 and "| SR ≤ 7 f/room | SR ≤ 14 f/room |" in at.output, at.output
    at = CliRunner().invoke(cli, [*ARGS, "--house", str(house_file), "-o", str(out),
                                  "--report-only", "--budgets", "18.7,18.8"])  # as given
    assert at.exit_code == 0 and "| SR ≤ 18.7 f/room | SR ≤ 18.8 f/room |" in at.output
    # --report-only on another command's folder says so (and does not advise --force)
    (tmp_path / "sym").mkdir()
    (tmp_path / "sym" / ".sgtool-output").write_text('{"command": "bench", "files": []}')
    other = CliRunner().invoke(cli, [*ARGS, "--house", str(house_file), "-o",
                                     str(tmp_path / "sym"), "--report-only"])
    assert other.exit_code == 2 and "a folder of `sgtool bench`, not of run-bench" in \
        other.output, other.output
    # eval reads a folder as its table; to ask a planner on the run's decisions it says
    # to give the folder's logs, which it then reads
    asked = CliRunner().invoke(cli, ["eval", str(out), "-p", "greedy", "--json"])
    assert asked.exit_code == 2 and f"give {out / 'logs'} for its logs" in asked.output
    asked = CliRunner().invoke(cli, ["eval", str(out / "logs"), "-p", "greedy", "--json"])
    assert asked.exit_code == 0, asked.output
    assert json.loads(asked.stdout)["offline"]["greedy"]["decisions"] > 0
    # by default, quarters of the budget per room: --frames 120 over the house's rooms
    rooms = len(load_house(house_file).rooms)
    assert f"| SR ≤ {120 / rooms:g} f/room |" in summary, summary
    bad = CliRunner().invoke(cli, [*ARGS, "--house", str(house_file), "-o", str(out),
                                   "--report-only", "--budgets", "7,all"])
    assert bad.exit_code == 2 and bad.output.strip() == \
        "sgtool: error: --budgets 7,all: comma-separated frames per room, e.g. 90,100"
    only = CliRunner().invoke(cli, [*ARGS, "--house", str(house_file), "-o", str(out),
                                    "--planners", "random", "--report-only"])
    assert only.exit_code == 0 and "| random " in only.output and "| greedy" not in only.output
    # ... and says which logs it left out
    assert (f"sgtool: note: 1 episode log(s) in {out}/logs are left out of this report "
            "(logs/none/greedy/small/ep-000.mcap)") in only.output
    # other settings do not mix with the logs there
    other = [*ARGS, "--house", str(house_file), "-o", str(out)]
    other[other.index("--max-steps") + 1] = "3"
    res = CliRunner().invoke(cli, other)
    assert res.exit_code == 2 and "was run with other settings" in res.output
    res = CliRunner().invoke(cli, [*ARGS, "--house", str(house_file), "-o", str(out),
                                   "--every", "5"])
    assert res.exit_code == 2 and "graph refresh (--every frames): 10 in the log, 5 now" \
        in res.output
    # nor does another success rule (MoMa-LLM's done rule)
    res = CliRunner().invoke(cli, [*ARGS, "--house", str(house_file), "-o", str(out),
                                   "--success", "done"])
    assert res.exit_code == 2 and "success rule" in res.output
    # a report of a run cut short says so, in the table and in summary.json
    (out / "logs/none/greedy/small/ep-000.mcap").unlink()
    cut = CliRunner().invoke(cli, [*ARGS, "--house", str(house_file), "-o", str(out),
                                   "--report-only"])
    assert cut.exit_code == 0 and "**Incomplete: 1 of 2 episodes have no log**" in \
        (out / "summary.md").read_text(), cut.output
    assert json.loads((out / "summary.json").read_text())["missing_episodes"] == 1


def test_kendall_tau_against_a_symbolic_bench(house_file, tmp_path) -> None:
    """--symbolic DIR reads a `sgtool bench` folder and adds the tau of the two orders (on
    the episodes of the same house, episode and query); --report-only runs nothing."""
    sym = tmp_path / "sym"
    res = CliRunner().invoke(cli, ["bench", "--houses", "0", "--house", str(house_file),
                                   "--episodes", "1", "--seeds", "1", "--planners",
                                   "random,greedy", "--no-progress", "-o", str(sym)])
    assert res.exit_code == 0, res.output
    out = tmp_path / "rb"
    res = CliRunner().invoke(cli, [*ARGS, "--house", str(house_file), "-o", str(out),
                                   "--symbolic", str(sym)])
    assert res.exit_code == 0, res.output
    assert f"Agreement with the symbolic order (--symbolic {sym}; 2 symbolic episodes of " \
        "the same (house, episode, query))" in res.output
    agreement = json.loads((out / "summary.json").read_text())["noise"]["none"][
        "symbolic_agreement"]
    assert agreement["matched_episodes"] == 2
    assert [k["metric"] for k in agreement["kendall"]] == ["spl", "sr"]
    # a report without the symbolic rows says it leaves the agreement out (it did so
    # silently)
    again = CliRunner().invoke(cli, [*ARGS, "--house", str(house_file), "-o", str(out),
                                     "--report-only"])
    assert again.exit_code == 0 and "this one does not (give --with-symbolic or " \
        "--symbolic DIR again to keep it)" in again.output, again.output
    res = CliRunner().invoke(cli, [*ARGS, "--house", str(house_file), "-o", str(out),
                                   "--symbolic", str(sym)])  # (the agreement back)
    assert res.exit_code == 0 and "this one does not" not in res.output, res.output
    again = CliRunner().invoke(cli, [*ARGS, "--house", str(house_file), "-o", str(out)])
    assert again.exit_code == 0 and "this one does not" in again.output, again.output  # (a
    # resumed run with nothing left to run reports too)
    for args, msg in ((["--symbolic", str(tmp_path / "none")], "no episodes.jsonl"),
                      (["--symbolic", str(sym), "--with-symbolic"], "give one of them"),
                      (["--reference", "scout"], "--reference: 'scout' is not one of"),
                      (["--reference", "random", "--all-pairs"],
                       "--reference and --all-pairs: give one")):
        bad = CliRunner().invoke(cli, [*ARGS, "--house", str(house_file), "-o", str(out),
                                       "--report-only", *args])
        assert bad.exit_code == 2 and msg in bad.output and bad.output.count("\n") == 1, \
            bad.output


def test_ctrl_c_leaves_only_complete_logs(house_file, tmp_path, monkeypatch) -> None:
    out = tmp_path / "rb"

    def interrupted(spec, episode, planner, output, *a, **k):
        Path(f"{output}.abcdefgh.partial").write_bytes(b"half a log")
        raise KeyboardInterrupt

    monkeypatch.setattr(clb, "run_episode", interrupted)
    res = CliRunner().invoke(cli, [*ARGS, "--house", str(house_file), "-o", str(out)])
    assert res.exit_code == 130  # as any interrupted command (143 when killed)
    assert res.output.count("\n") == 1 and "interrupted" in res.output
    assert "no episode had finished: no log was kept" in res.output  # (it named OUT/logs)
    first = out / "logs/none/random/small/ep-000.mcap"
    assert not first.exists() and partial_files(first) == []


def test_ctrl_c_while_the_report_is_written_leaves_the_earlier_one_whole(
        house_file, tmp_path, monkeypatch) -> None:
    """Every episode logged, Ctrl-C after the new report's first files were written: the
    earlier report is there as it was, byte for byte (it was a mix of the two before), no
    stage is left, and the note says the same command writes the report from the logs."""
    out = tmp_path / "rb"
    first = CliRunner().invoke(cli, [*ARGS, "--house", str(house_file), "-o", str(out)])
    assert first.exit_code == 0, first.output
    before = {p.name: p.read_bytes() for p in out.iterdir() if p.is_file()}
    write = clb.write_outputs

    def interrupted(res, out_dir, timings=True):
        write(res, out_dir, timings)  # every file of the new report, then Ctrl-C
        raise KeyboardInterrupt

    monkeypatch.setattr(clb, "write_outputs", interrupted)
    res = CliRunner().invoke(cli, [*ARGS, "--house", str(house_file), "-o", str(out),
                                   "--report-only", "--budgets", "7"])
    assert res.exit_code == 130
    assert "interrupted before the report was written" in res.output
    assert "writes them from the logs (nothing runs again)" in res.output
    assert {p.name: p.read_bytes() for p in out.iterdir() if p.is_file()} == before
    assert not [p for p in out.iterdir() if p.name.startswith(".report.")]
    monkeypatch.undo()
    again = CliRunner().invoke(cli, [*ARGS, "--house", str(house_file), "-o", str(out),
                                     "--report-only", "--budgets", "7"])
    assert again.exit_code == 0 and (out / "summary.md").read_bytes() != before["summary.md"]


def test_ctrl_c_as_the_report_goes_in_says_it_is_this_runs(house_file, tmp_path,
                                                          monkeypatch) -> None:
    """A Ctrl-C while the staged report moves in waits for the moves: the note says the
    report is this run's (it said the files were as they were); a stage a killed run left
    is removed by the next report."""
    import os
    import signal

    out = tmp_path / "rb"
    first = CliRunner().invoke(cli, [*ARGS, "--house", str(house_file), "-o", str(out)])
    assert first.exit_code == 0, first.output
    before = (out / "summary.md").read_bytes()
    (out / ".report.abcdefgh.partial").mkdir()  # what SIGKILL leaves
    replace = os.replace

    def interrupted(src, dst, *a, **k):  # type: ignore[no-untyped-def]
        if Path(src).parent.name.startswith(".report.") and Path(dst).parent == out:
            signal.raise_signal(signal.SIGINT)  # a move of the stage's files into OUT
        return replace(src, dst, *a, **k)

    monkeypatch.setattr(os, "replace", interrupted)
    res = CliRunner().invoke(cli, [*ARGS, "--house", str(house_file), "-o", str(out),
                                   "--report-only", "--budgets", "7"])
    assert res.exit_code == 130
    assert "are this run's (they went in as it was interrupted)" in res.output, res.output
    assert (out / "summary.md").read_bytes() != before
    assert not [p for p in out.iterdir() if p.name.startswith(".report.")]


def test_a_full_disk_while_the_report_is_written_names_the_report_s_file(
        house_file, tmp_path, monkeypatch) -> None:
    """The report is written into a hidden stage first; a write that fails there (a full
    disk) names the file of the output folder it was for, not the stage's, and leaves the
    earlier report as it was."""
    import errno
    import os

    from sgtool.files import output_error

    out = tmp_path / "rb"
    first = CliRunner().invoke(cli, [*ARGS, "--house", str(house_file), "-o", str(out)])
    assert first.exit_code == 0, first.output
    before = {p.name: p.read_bytes() for p in out.iterdir() if p.is_file()}

    def full(res, out_dir, timings=True):
        raise output_error(OSError(errno.ENOSPC, os.strerror(errno.ENOSPC)),
                           Path(out_dir) / "summary.md")

    monkeypatch.setattr(clb, "write_outputs", full)
    res = CliRunner().invoke(cli, [*ARGS, "--house", str(house_file), "-o", str(out),
                                   "--report-only", "--budgets", "7"])
    assert res.exit_code == 2
    assert res.output == (f"sgtool: error: cannot write {out / 'summary.md'}: No space left "
                          "on device (nothing was written)\n")
    assert {p.name: p.read_bytes() for p in out.iterdir() if p.is_file()} == before
    assert not [p for p in out.iterdir() if p.name.startswith(".report.")]


def test_user_errors(tmp_path) -> None:
    for args, msg in ((["--planners", "nope"], "unknown planner 'nope'"),
                      (["--houses", "0"], "--houses: must be >= 1"),
                      (["--noise", "loud"], "loud")):
        res = CliRunner().invoke(cli, ["run-bench", *args, "-o", str(tmp_path / "x")])
        assert res.exit_code == 2 and msg in res.output, res.output
        assert "Traceback" not in res.output


def test_reason_classes() -> None:
    assert clb.reason_class("room:1 is unreachable on the robot's map (no known ...)") == \
        "unreachable on the map"
    assert clb.reason_class("obj:3: the way is blocked by an obstacle the robot's map "
                            "does not show") == "contact"
    assert clb.reason_class("(1.00, 2.00) is not on free floor") == "not on free floor"
    assert clb.reason_class("furn_2 is out of reach: 1.20 m") == "out of reach"
    assert clb.reason_class("something new") == "other"


def _messages(path: Path) -> list[tuple[str, int, bytes]]:
    """A log's messages, the decision time (wall clock, logged on purpose) zeroed."""
    import re

    from mcap.reader import make_reader

    with open(path, "rb") as f:
        return [(c.topic, m.log_time,
                 re.sub(rb'"decision_time_s":[0-9.e-]+', b'"decision_time_s":0', m.data))
                for _, c, m in make_reader(f).iter_messages()]


def test_run_bench_on_two_worker_processes_writes_the_same_logs(house_file, tmp_path) -> None:
    """`-w 2` runs the episodes on the local executor: the same logs (every message but the
    measured decision time) and the same records as one after the other in this process."""
    import json

    runs = {}
    for name, extra in (("one", []), ("two", ["-w", "2"])):
        out = tmp_path / name
        res = CliRunner().invoke(cli, [*ARGS, "--house", str(house_file), "-o", str(out),
                                       *extra])
        assert res.exit_code == 0, res.output
        recs = [json.loads(s) for s in (out / "episodes.jsonl").read_text().splitlines()]
        for r in recs:
            r.pop("wall")  # wall clock
            assert (out / r["source"]).is_file() and not Path(r["source"]).is_absolute()
        logs = {p.relative_to(out).as_posix(): _messages(p) for p in out.rglob("*.mcap")}
        runs[name] = (recs, logs)
    assert runs["one"][0] == runs["two"][0] and len(runs["one"][0]) == 2
    assert runs["one"][1] == runs["two"][1] and len(runs["one"][1]) == 2


def test_episodes_are_the_symbolic_benchs() -> None:
    """Episode k of a run of N episodes is episode k of the bench's draw of N (the draw
    depends on N: the first round took the draw of k + 1)."""
    from sgtool.analysis.bench_houses import bench_episodes

    cfg = clb.ClosedLoopBenchConfig(planners=("random",), houses=1, house_seed=0,
                                    episodes=3, rooms=(4, 6))
    tasks = clb.tasks_of(cfg, Path("logs"))
    spec = tasks[0].house.load(cfg.rooms, cfg.preset)
    want = [(e.id, e.query) for e in bench_episodes(spec, 3, "symsearch")]
    assert [(_episodes(t)[t.episode].id, _episodes(t)[t.episode].query)
            for t in tasks] == want
    (first,) = bench_episodes(spec, 1, "symsearch")
    # why the draw size matters (house-0, 4-6 rooms): ep_0 is another episode
    assert first.id == want[0][0] and first.query != want[0][1]


def test_frames_per_room_scales_the_budget_with_the_house(house_file, tmp_path) -> None:
    """--frames-per-room 30 on a 4-room house: a budget of 120 frames, logged as such (and
    the run resumes under the same option); with --frames too it is a one-line error."""
    from sgtool.log.reader import LogReader
    from sgtool.log.records import Episode as LoggedEpisode

    args = [a for a in ARGS]
    i = args.index("--frames")
    args[i:i + 2] = ["--frames-per-room", "30", "--planners", "random"]
    out = tmp_path / "rb"
    res = CliRunner().invoke(cli, [*args, "--house", str(house_file), "-o", str(out)])
    assert res.exit_code == 0, res.output
    with LogReader(out / "logs/none/random/small/ep-000.mcap") as r:
        started = next(e for _, e in r.records(LoggedEpisode) if e.status == "started")
    assert started.extras["frame_budget"] == 30 * 4
    # the frame-budget curves of the summary end at the run's own budget per room
    stats = json.loads((out / "summary.json").read_text())["noise"]["none"]
    assert stats["frames"]["max_per_room"] == 30.0
    assert stats["frames"]["budgets_per_room"] == [8.0, 15.0, 23.0, 30.0]  # 1/4.. rounded up
    again = CliRunner().invoke(cli, [*args, "--house", str(house_file), "-o", str(out)])
    assert again.exit_code == 0, again.output
    both = CliRunner().invoke(cli, [*args, "--frames", "100", "--house", str(house_file),
                                    "-o", str(tmp_path / "x")])
    assert both.exit_code == 2 and both.output.count("\n") == 1
    assert "either --frames or --frames-per-room" in both.output


def test_frame_budget() -> None:
    from sgtool.recorders.sim.frame_budget import FrameBudgetError, frame_budget

    assert frame_budget(None, None, 12) is None
    assert frame_budget(500, None, 12) == 500
    assert frame_budget(None, 400, 13) == 5200
    with pytest.raises(FrameBudgetError, match="not both"):
        frame_budget(500, 400, 12)


def test_a_run_goes_episode_by_episode_and_reports_house_by_house() -> None:
    """Episode k of every house runs before episode k + 1 (a run cut short compares the
    planners over all houses); the outputs list the rows house by house."""
    from types import SimpleNamespace

    cfg = clb.ClosedLoopBenchConfig(planners=("random", "greedy"), houses=2, house_seed=0,
                                    episodes=2, rooms=(4, 6))
    tasks = clb.tasks_of(cfg, Path("logs"))
    ran = [(t.episode, t.house.id, t.planner) for t in tasks]
    assert ran == [(k, h, p) for k in (0, 1) for h in ("house-0", "house-1")
                   for p in ("random", "greedy")]
    rows = sorted((SimpleNamespace(task=t) for t in tasks), key=clb.report_order(cfg, tasks))
    assert [(r.task.house.id, r.task.episode, r.task.planner) for r in rows] == [
        (h, k, p) for h in ("house-0", "house-1") for k in (0, 1) for p in ("random", "greedy")]


def test_a_worker_builds_each_house_once_when_tasks_cycle_through_houses(monkeypatch) -> None:
    cfg = clb.ClosedLoopBenchConfig(planners=("random", "greedy"), houses=2, house_seed=0,
                                    episodes=2, rooms=(4, 6))
    tasks = clb.tasks_of(cfg, Path("logs"))
    built = []
    house_type = type(tasks[0].house)
    monkeypatch.setattr(house_type, "load", lambda self, rooms, preset: built.append(self.id))
    monkeypatch.setattr(clb, "bench_episodes", lambda spec, n, mix: ["ep"] * n)
    monkeypatch.setattr(clb, "_DRAWS", {})
    for t in tasks:  # episode 0 of both houses, then episode 1 of both
        assert _episodes(t) == ["ep", "ep"]
    assert built == ["house-0", "house-1"]


def test_noise_profiles_are_kept_apart(house_file, tmp_path) -> None:
    """A profile from a JSON file in another folder runs into logs/NAME (its name); every
    episode row names its profile, so `sgtool eval` scores them apart; the noise seed is a
    setting of the logs; a report of one profile says which logs it left out."""
    (tmp_path / "nj").mkdir()
    prof = tmp_path / "nj" / "my.json"
    prof.write_text(json.dumps({"profile": "none", "holes": 0.05}))
    out = tmp_path / "rb"
    args = [*ARGS, "--planners", "random", "--house", str(house_file), "-o", str(out)]
    res = CliRunner().invoke(cli, [*args, "--noise", "none", "--noise", str(prof)])
    assert res.exit_code == 0, res.output
    logs = sorted(p.relative_to(out).as_posix() for p in out.rglob("*.mcap"))
    assert logs == ["logs/my/random/small/ep-000.mcap", "logs/none/random/small/ep-000.mcap"]
    rows = [json.loads(s) for s in (out / "episodes.jsonl").read_text().splitlines()]
    assert [r["noise"] for r in rows] == ["none", "my"]
    # the tables and plots name the profile as its logs do
    assert (out / "efficiency_my_steps.png").is_file() and "noise 'my'" in \
        (out / "summary.md").read_text()
    assert set(json.loads((out / "summary.json").read_text())["noise"]) == {"none", "my"}
    ev = CliRunner().invoke(cli, ["eval", str(out / "episodes.jsonl")])
    assert ev.exit_code == 0, ev.output
    assert "random [none]" in ev.output and "random [my]" in ev.output
    assert "2 sensor noise profiles (none, my)" in ev.output
    res = CliRunner().invoke(cli, [*args, "--noise", "none", "--noise-seed", "1"])
    assert res.exit_code == 2 and "noise seed: 0 in the log, 1 now" in res.output
    res = CliRunner().invoke(cli, [*args, "--noise", "none", "--max-depth", "3"])
    assert res.exit_code == 2 and "depth mapped (m): 5.0 in the log, 3.0 now" in res.output
    assert "--max-depth 5 maps as that log did" in res.output
    both = CliRunner().invoke(cli, [*args, "--report-only"])  # as the run was made
    assert both.exit_code == 0 and "noise 'my'" in both.output, both.output
    only = CliRunner().invoke(cli, [*args, "--report-only", "--noise", "none"])
    assert only.exit_code == 0, only.output
    assert f"episode log(s) in {out}/logs are left out of this report (logs/my/" \
        in only.output
    # two files of one profile name would share a folder
    (tmp_path / "my.json").write_text(json.dumps({"holes": 0.1}))
    res = CliRunner().invoke(cli, [*args, "--noise", str(prof), "--noise",
                                   str(tmp_path / "my.json")])
    assert res.exit_code == 2 and "both name the log folder 'my'" in res.output


def test_run_bench_warns_of_an_llm_that_never_answered_usefully(tmp_path) -> None:
    """moma-llm against an endpoint answering every request with a web page: run-bench
    counts its answers per episode (episodes.jsonl) and warns, as bench does."""
    from support.semantics_fixtures import ChatServer

    out = tmp_path / "rb"
    with ChatServer(responder=lambda req: {"text": "<html>a web page</html>"}) as srv:
        r = CliRunner().invoke(cli, ["run-bench", "--planners", "moma-llm", "--houses", "1",
                                     "--episodes", "1", "--resolution", "64x48",
                                     "--max-steps", "2", "--frames", "120", "--no-progress",
                                     "--llm-base-url", srv.base_url, "--llm-model", "m",
                                     "-o", str(out)])
    assert r.exit_code == 0, r.output
    assert "sgtool: warning: moma-llm: none of its" in r.output
    (row,) = [json.loads(s) for s in (out / "episodes.jsonl").read_text().splitlines()]
    n = row["llm_answers"]["requests"]
    assert n > 0 and row["llm_answers"]["valid"] == 0
    # the counts in summary.md, as bench gives them, and in `sgtool eval` of the folder
    line = f"LLM answers of moma-llm: {n} requests, 0 valid, {n} rejected"
    assert line in (out / "summary.md").read_text()
    r = CliRunner().invoke(cli, ["eval", str(out)])
    assert r.exit_code == 0 and line in r.output, r.output


def test_a_noise_profile_spelled_with_spaces_is_the_same_profile() -> None:
    """`--noise "mild, holes=0.05"` (record and run take it) names the folder of
    "mild,holes=0.05"; given both, they are one profile given twice."""
    assert clb.noise_folder("mild, holes = 0.05") == "mild,holes=0.05"
    clb.ClosedLoopBenchConfig("greedy", houses=1, noise="mild, holes=0.05").check()
    with pytest.raises(SgtoolError, match="both name the log folder 'mild,holes=0.05'"):
        clb.ClosedLoopBenchConfig("greedy", houses=1,
                                  noise=("mild,holes=0.05", "mild, holes=0.05")).check()
    # spelled otherwise (another number form, another order): one folder, refused
    with pytest.raises(SgtoolError, match="'mild,holes=0.05' and 'mild,holes=5e-2': both"):
        clb.ClosedLoopBenchConfig("greedy", houses=1,
                                  noise=("mild,holes=0.05", "mild,holes=5e-2")).check()
    with pytest.raises(SgtoolError, match="both name the log folder 'holes=0.05,label_swap"):
        clb.ClosedLoopBenchConfig("greedy", houses=1, noise=(
            "none,holes=0.05,label_swap=0.1", "label_swap=0.1,holes=0.05")).check()


def test_one_profile_spelled_two_ways_resumes_into_one_folder(tmp_path: Path) -> None:
    """A resume that spells the profile otherwise (`holes=0.050`, `none, holes=5e-2`)
    finds the first run's logs: one folder and equal settings, name included."""
    from sgtool.analysis.run_bench_resume import task_settings
    from sgtool.recorders.sim import ClosedLoopOptions

    spellings = ("holes=0.05", "holes=0.050", "none, holes=5e-2", " holes = .05 ")
    assert {clb.noise_folder(s) for s in spellings} == {"holes=0.05"}
    opts = ClosedLoopOptions()
    assert len({json.dumps(task_settings(opts, s, None), sort_keys=True)
                for s in spellings}) == 1
    assert clb.noise_folder("mild,drift_xy=1.0,label_swap=0.1") == \
        "mild,label_swap=0.1,drift_xy=1"


def test_report_only_says_where_the_house_files_went(tmp_path: Path) -> None:
    """A run's house files moved after it ran: --report-only names them and says to give
    --house (a run, not a report, only names them)."""
    cfg = clb.ClosedLoopBenchConfig("greedy", houses=0,
                                    house_files=(str(tmp_path / "gone" / "h.json"),))
    with pytest.raises(SgtoolError, match="no such house spec file\n--report-only: the run's "
                                          "house files are not where it read them; give "
                                          "--house"):
        clb.run_closed_loop_bench(cfg, tmp_path, report_only=True)
    with pytest.raises(SgtoolError, match="no such house spec file$"):
        clb.tasks_of(cfg, tmp_path / "logs")


def test_a_run_made_before_one_spelling_is_found_where_its_logs_are(tmp_path: Path) -> None:
    """A run-bench folder of an earlier sgtool keeps its logs under the profile as typed
    (`none,holes=0.05`): a resume or --report-only finds them there (it looked in
    `holes=0.05` only and ran every episode again), and its logs' recorded profile name
    does not refuse them (faults are compared, not names)."""
    from sgtool.analysis.run_bench_resume import task_settings, with_new_faults
    from sgtool.recorders.sim import ClosedLoopOptions

    logs = tmp_path / "logs"
    (logs / "none,holes=0.05" / "greedy").mkdir(parents=True)
    assert clb.log_path(logs, "none, holes=0.05", "greedy", "house-0", 2) == \
        logs / "none,holes=0.05" / "greedy" / "house-0" / "ep-002.mcap"
    assert clb.log_path(logs, "holes=0.05", "greedy", "house-0", 2).parts[-4] == "holes=0.05"
    from sgtool.recorders.sim.noise import PROFILES

    logged = {**PROFILES["none"].to_dict(), "name": "none,holes=0.05", "holes": 0.05}
    want = task_settings(ClosedLoopOptions(), "holes=0.05", None)["noise"]
    assert with_new_faults(logged) == want


@pytest.mark.parametrize(("budgets", "message"), [
    ((10.0, 10.0), r"--budgets: a budget is given twice \(10, 10\)"),
    ((math.inf,), r"--budgets: frames per room, finite numbers > 0, got inf"),
])
def test_budgets_given_twice_or_infinite_are_one_line(budgets, message) -> None:
    """Two equal budgets printed two identical columns; inf was 'frames per room > 0'."""
    with pytest.raises(SgtoolError, match=message):
        clb.ClosedLoopBenchConfig("greedy", houses=1, budgets=budgets).check()
