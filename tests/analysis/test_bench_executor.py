"""The bench on the executor: tasks grouped by house, a task that fails after its retry is
listed in the result and its summary (the other houses are still scored), and the command
then writes nothing (no tables that pass for a result) and exits with one line; a bad
planner option stops the run before any episode."""

from __future__ import annotations

import dataclasses
import json
import sys

import pytest
from click.testing import CliRunner

import sgtool.analysis.bench as bench
from sgtool.analysis.bench import BenchConfig, bench_tasks, prepare_houses, run_benchmark
from sgtool.cli import cli
from sgtool.errors import SgtoolError

SMALL = dict(planners=("random", "greedy"), houses=2, episodes=2, seeds=1, rooms=(4, 6),
             preset="default")


def test_tasks_are_grouped_by_house_and_split_when_workers_outnumber_houses():
    cfg = BenchConfig(planners=("random", "greedy", "sbert"), houses=2)
    ids = [t.id for t in bench_tasks(cfg, prepare_houses(cfg))]
    assert ids == ["house-0/random+greedy+sbert", "house-1/random+greedy+sbert"]
    cfg = BenchConfig(planners=("random", "greedy", "sbert"), houses=1, workers=3)
    ids = [t.id for t in bench_tasks(cfg, prepare_houses(cfg))]
    assert ids == ["house-0/random", "house-0/greedy", "house-0/sbert"]
    cfg = BenchConfig(planners=("random", "greedy", "sbert"), houses=2, workers=3)
    ids = [t.id for t in bench_tasks(cfg, prepare_houses(cfg))]
    assert ids == ["house-0/random+greedy", "house-0/sbert", "house-1/random+greedy",
                   "house-1/sbert"]


@pytest.fixture
def house_one_breaks(monkeypatch):
    real = bench.cached_house
    calls: list[str] = []

    def flaky(ref, *a, **kw):
        calls.append(ref.id)
        if ref.id == "house-1":
            raise RuntimeError("the house fell down")
        return real(ref, *a, **kw)

    monkeypatch.setattr(bench, "cached_house", flaky)
    return calls


def test_a_failing_task_is_retried_once_then_listed(house_one_breaks, tmp_path):
    # from Python a failed task is an error, not a result without that house
    with pytest.raises(SgtoolError, match=r"1 of 2 bench task\(s\) failed after a retry; "
                       "the first: house-1/random\\+greedy: RuntimeError: the house fell"):
        run_benchmark(BenchConfig(**SMALL))
    house_one_breaks.clear()
    res = run_benchmark(BenchConfig(**SMALL), partial=True)  # the others' episodes
    assert house_one_breaks == ["house-0", "house-1", "house-1"]  # one retry
    assert res.failed == ("house-1/random+greedy: RuntimeError: the house fell down "
                          "(after 2 attempts)",)
    assert {r.house for r in res.results} == {"house-0"} and len(res.results) == 4
    r = CliRunner().invoke(cli, ["bench", "--houses", "2", "--episodes", "2", "--seeds", "1",
                                 "--rooms", "4-6", "--preset", "default", "--planners",
                                 "random,greedy", "--no-progress", "-o", str(tmp_path / "out")])
    assert r.exit_code == 2
    assert r.stderr.strip().splitlines() == [
        f"sgtool: error: 1 task(s) failed after a retry, nothing written to {tmp_path}/out; "
        "the first: house-1/random+greedy: RuntimeError: the house fell down (after 2 "
        "attempts)"]
    assert not (tmp_path / "out").exists()  # no folder of tables that looks like a result
    # the library's outputs still list the failed tasks
    bench.write_outputs(res, tmp_path / "lib")
    md = (tmp_path / "lib/summary.md").read_text()
    assert ("Failed tasks (retried once; their episodes are in no table): 1\n- house-1/"
            "random+greedy: RuntimeError: the house fell down (after 2 attempts)\n") in md
    assert json.loads((tmp_path / "lib/summary.json").read_text())["failed_tasks"] == list(
        res.failed)


def test_a_bad_planner_option_stops_the_run_before_any_episode(house_one_breaks):
    with pytest.raises(SgtoolError, match="planner 'greedy' does not take option"):
        run_benchmark(BenchConfig(**SMALL, planner_options={"greedy": {"bogus": 1}}))
    assert house_one_breaks == []


def test_a_task_gives_the_same_results_whatever_its_worker_ran_before():
    """The shared priors' score memo is emptied per task (their batches, and so the last
    bits of their scores, belong to the task): a house run after another in one process
    ends with the memo it has when run first, and the same results."""
    import copy

    from sgtool.analysis.bench import run_task
    from sgtool.results import results_digest
    from sgtool.semantics.priors import default_priors

    cfg = BenchConfig(planners=("scout",), houses=2, episodes=2, seeds=1, rooms=(4, 6),
                      preset="default")
    first, second = bench_tasks(cfg, prepare_houses(cfg))
    alone = run_task(second.args)
    memo_alone = copy.deepcopy(default_priors()._memo._memo)
    run_task(first.args)
    assert default_priors()._memo._memo != memo_alone  # the other house scored other names
    after_other = run_task(second.args)
    assert default_priors()._memo._memo == memo_alone
    assert results_digest(after_other) == results_digest(alone)
    assert {r.house for r in alone} == {"house-1"} and len(alone) == 2


def test_a_task_gives_the_same_episodes_after_a_larger_draw_of_the_same_house():
    """The episode draw depends on how many are drawn, so a process that benched a house
    with more episodes before must not hand out the first N of that draw: it gave other
    queries than a fresh process (a local bench then differed from the same bench on
    Ray's fresh workers)."""
    from sgtool.analysis.bench import run_task
    from sgtool.results import results_digest

    small = BenchConfig(planners=("random",), houses=1, episodes=2, seeds=1, rooms=(4, 6),
                        preset="default")
    large = dataclasses.replace(small, episodes=5)
    (task,) = bench_tasks(small, prepare_houses(small))
    (larger,) = bench_tasks(large, prepare_houses(large))
    fresh = run_task(task.args)
    run_task(larger.args)
    assert results_digest(run_task(task.args)) == results_digest(fresh)


def test_a_plug_in_redefined_between_runs_runs_anew(monkeypatch):
    """A notebook redefines its plug-in between two runs in one process: the second run
    uses the new definition (planners are built per run, not per process), as a fresh
    process would."""
    import types

    from sgtool.analysis.bench import run_benchmark
    from sgtool.planning.registry import make_planner

    mod = types.ModuleType("lab_planners")
    monkeypatch.setitem(sys.modules, "lab_planners", mod)
    cfg = BenchConfig(planners=("lab_planners:Lab",), houses=1, episodes=3, seeds=1,
                      rooms=(4, 5), preset="default")
    mod.Lab = lambda **o: make_planner("random", **o)
    first = run_benchmark(cfg, progress=False).digest
    mod.Lab = lambda **o: make_planner("greedy", **o)
    second = run_benchmark(cfg, progress=False).digest
    greedy = run_benchmark(BenchConfig(planners=("greedy",), houses=1, episodes=3, seeds=1,
                                       rooms=(4, 5), preset="default"), progress=False)
    assert first != second
    assert [(r.success, r.steps) for r in run_benchmark(cfg, progress=False).results] == \
        [(r.success, r.steps) for r in greedy.results]


def test_options_are_recorded_as_the_planner_takes_them():
    """scout.delta=1 from Python was recorded as "1", from the command line as "1.0" (the
    parsed float): summary.json differed, and eval of the two runs on a machine without
    a plug-in called them other options."""
    from sgtool.planning.registry import parse_option

    cli = BenchConfig(planners=("scout",),
                      planner_options={"scout": {"delta": parse_option("scout", "delta", "1")}})
    py = BenchConfig(planners=("scout",), planner_options={"scout": {"delta": 1}})
    assert py.settings()["planner_options"] == cli.settings()["planner_options"] == {
        "scout": {"delta": "1.0"}}


def test_the_config_keeps_its_own_options():
    """A sweep that changes its options dict for the next point leaves the finished
    run's configuration (and summary) as it ran."""
    opts = {"scout": {"delta": 0.2}}
    cfg = BenchConfig(planners=("scout",), planner_options=opts)
    opts["scout"]["delta"] = 0.9
    opts["greedy"] = {}
    assert cfg.planner_options == {"scout": {"delta": 0.2}}
    # a value that is itself a dict or list (a Python-only option) too: it was shared
    nested = {"mine": {"weights": {"a": 1.0}, "order": [1, 2]}}
    cfg = BenchConfig(planners=("scout",), planner_options=nested)
    nested["mine"]["weights"]["a"] = 99.0
    nested["mine"]["order"].append(3)
    assert cfg.planner_options == {"mine": {"weights": {"a": 1.0}, "order": [1, 2]}}
    # the caller's objects stay theirs: a client or a callback is used, not a copy of it
    client, seen = object(), []
    cfg = BenchConfig(planners=("scout",), planner_options={
        "mine": {"client": client, "on_exchange": seen.append, "clients": [client]}})
    mine = cfg.planner_options["mine"]
    assert mine["client"] is client and mine["clients"][0] is client
    mine["on_exchange"](1)
    assert seen == [1]
    with pytest.raises(SgtoolError, match=r"^planner_options\['scout'\]: give \{option: "
                       r"value\}, got 0.2$"):
        BenchConfig(planners=("scout",), planner_options={"scout": 0.2})
