"""How `sgtool run-bench` runs its episodes (sgtool.analysis.closed_loop_bench_run.
EpisodeRunner), on one small house at 64x48 with two steps per episode: a partial log a
killed run left is removed before its episode runs again, a worker that does not see the
output folder sends its log back for the driver to write (the same logs and rows as a run
in the folder), and run.json says which episodes ran now."""

from __future__ import annotations

import json
import re
from dataclasses import replace
from pathlib import Path

import pytest
from click.testing import CliRunner

from sgtool.analysis.closed_loop_bench import ClosedLoopBenchConfig, run_closed_loop_bench
from sgtool.analysis.closed_loop_bench_run import EpisodeRunner
from sgtool.analysis.executor import FolderMark, LocalExecutor
from sgtool.cli import cli
from sgtool.datasets.generator import generate_house
from sgtool.house.io import save_house
from sgtool.recorders.sim import CameraConfig
from sgtool.recorders.sim.closed_loop import ClosedLoopOptions

ARGS = ["run-bench", "--planners", "random", "--houses", "0", "--episodes", "1",
        "--resolution", "64x48", "--max-steps", "2", "--frames", "120", "--no-progress"]


@pytest.fixture(scope="module")
def house_file(tmp_path_factory) -> Path:
    p = tmp_path_factory.mktemp("houses") / "small.json"
    save_house(generate_house(6, rooms=(4, 4)), p)
    return p


def _messages(path: Path) -> list[tuple[str, int, bytes]]:
    """A log's messages, the measured decision time zeroed (the only wall clock in it)."""
    from mcap.reader import make_reader

    with open(path, "rb") as f:
        return [(c.topic, m.log_time,
                 re.sub(rb'"decision_time_s":[0-9.e-]+', b'"decision_time_s":0', m.data))
                for _, c, m in make_reader(f).iter_messages()]


def test_a_partial_log_of_a_killed_run_is_removed_and_run_json_says_what_ran(
        house_file, tmp_path) -> None:
    out = tmp_path / "rb"
    stale = out / "logs/none/random/small/ep-000.mcap.k1lled00.partial"
    stale.parent.mkdir(parents=True)
    stale.write_bytes(b"half a log")  # what a SIGKILL mid-episode leaves
    res = CliRunner().invoke(cli, [*ARGS, "--house", str(house_file), "-o", str(out)])
    assert res.exit_code == 0, res.output
    assert sorted(p.name for p in stale.parent.iterdir()) == ["ep-000.mcap"]
    run = json.loads((out / "run.json").read_text())
    assert run["executor"] == "local"
    [ep] = run["episodes"]
    assert ep["log"] == "logs/none/random/small/ep-000.mcap" and ep["ran"] is True
    assert ep["seconds"] > 0 and ep["node"] == "" and ep["sent"] is False
    # resumed: read back, not run
    again = CliRunner().invoke(cli, [*ARGS, "--house", str(house_file), "-o", str(out)])
    assert again.exit_code == 0, again.output
    [ep] = json.loads((out / "run.json").read_text())["episodes"]
    assert ep["ran"] is False and ep["seconds"] is None


def test_a_worker_that_does_not_see_the_folder_sends_its_log_back(
        house_file, tmp_path, monkeypatch, capsys) -> None:
    cfg = ClosedLoopBenchConfig(
        planners=("random", "greedy"), houses=0, house_files=(str(house_file),), episodes=1,
        options=ClosedLoopOptions(camera=CameraConfig(width=64, height=48), max_steps=2,
                                  frames=120))
    here = tmp_path / "here"
    here.mkdir()
    direct = run_closed_loop_bench(cfg, here, runner=EpisodeRunner(None, here))
    capsys.readouterr()
    again = run_closed_loop_bench(cfg, here, runner=EpisodeRunner(None, here, progress=True))
    # read back, not run, with a bar while the logs are checked
    assert [(r.task, r.seconds) for r in again.rows] == [(r.task, None) for r in direct.rows]
    assert "checking logs there" in capsys.readouterr().err
    away = tmp_path / "away"
    away.mkdir()
    stale = away / "logs/none/greedy/small/ep-000.mcap.k1lled00.partial"
    stale.parent.mkdir(parents=True)
    stale.write_bytes(b"half a log")
    # and the driver's copy of a log sent back, the driver killed while it wrote it
    unsent = away / "logs/none/greedy/small/.ep-000.mcap.k1lled01.partial"
    unsent.write_bytes(b"half a log sent back")
    # every worker is "on another machine": it runs into a folder of its own
    monkeypatch.setattr(FolderMark, "here", lambda self: False)
    runner = EpisodeRunner(LocalExecutor(1), away)
    shipped = run_closed_loop_bench(cfg, away, runner=runner)
    assert not stale.exists() and not unsent.exists()
    logs = sorted(p.relative_to(away) for p in away.rglob("*.mcap"))
    assert logs == sorted(p.relative_to(here) for p in here.rglob("*.mcap"))
    assert len(logs) == 2 and not list(away.rglob("*.partial"))
    for rel in logs:  # written by the driver from the bytes sent back
        assert _messages(away / rel) == _messages(here / rel)
    for a, b in zip(shipped.rows, direct.rows, strict=True):
        assert a.task.output == away / b.task.output.relative_to(here)
        # the folder's log, relative to it (not the worker's)
        assert away / a.result.source == a.task.output
        assert replace(a.result, wall={}, source="") == replace(b.result, wall={}, source="")
        assert (a.frames, a.failures) == (b.frames, b.failures)
    assert runner.nodes == {r.task.output: "" for r in shipped.rows}
    assert runner.sent == {r.task.output for r in shipped.rows}


def test_ctrl_c_on_an_executor_removes_the_partial_logs_of_unfinished_tasks(tmp_path) -> None:
    """A Ray worker cancelled by force cannot remove its partial log: on Ctrl-C the driver
    removes those of the tasks not finished."""
    from sgtool.analysis.closed_loop_bench import tasks_of

    cfg = ClosedLoopBenchConfig(planners=("random",), houses=1, episodes=1,
                                options=ClosedLoopOptions(max_steps=2))
    (task,) = tasks_of(cfg, tmp_path / "logs")
    task.output.parent.mkdir(parents=True)

    class Killed:
        """An executor whose worker was writing when Ctrl-C came."""

        def run(self, fn, items, **kw):
            (task.output.parent / f"{task.output.name}.abcd1234.partial").write_bytes(b"x")
            raise KeyboardInterrupt

    runner = EpisodeRunner(Killed(), tmp_path)  # type: ignore[arg-type]
    with pytest.raises(KeyboardInterrupt):
        runner(lambda t: t, [task])
    assert not list(task.output.parent.glob("*.partial"))
