"""The closed-loop benchmark's config and the Rerun writer as the Python API gives them: a
name alone is a list of one, a set is refused, and every mistake is one SgtoolError line."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any, Protocol

import pytest

import sgtool

LOG = Path(__file__).resolve().parents[1] / "golden" / "house6-tour.mcap"


def test_a_closed_loop_bench_config_takes_a_name_or_a_list() -> None:
    cfg = sgtool.ClosedLoopBenchConfig("scout", noise="mild", house_files="a.json",
                                       rooms=[4, 6])
    assert (cfg.planners, cfg.noise, cfg.house_files, cfg.rooms) == \
        (("scout",), ("mild",), ("a.json",), (4, 6))
    with pytest.raises(sgtool.SgtoolError, match="a set has no order"):
        sgtool.ClosedLoopBenchConfig({"scout", "random"})
    with pytest.raises(sgtool.SgtoolError, match=r"rooms: give \(MIN, MAX\)"):
        sgtool.ClosedLoopBenchConfig("scout", rooms=4)


def test_write_rerun_refuses_in_one_line(tmp_path) -> None:
    log = LOG
    with pytest.raises(sgtool.SgtoolError, match="must not be the input log"):
        sgtool.write_rerun(log, log)
    out = tmp_path / "x.rrd"
    out.write_bytes(b"old")
    with pytest.raises(sgtool.SgtoolError, match=r"exists; .*\(use --force \(overwrite=\)\)"):
        sgtool.write_rerun(log, out)
    with pytest.raises(sgtool.SgtoolError, match="every=0"):
        sgtool.write_rerun(log, tmp_path / "y.rrd", every=0)
    text = tmp_path / "notes.txt"
    text.write_text("not a log")
    with pytest.raises(sgtool.SgtoolError):
        sgtool.write_rerun(text, tmp_path / "z.rrd")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["notes.txt", "x.rrd"]
    assert out.read_bytes() == b"old"


def test_arguments_of_the_wrong_type_are_one_line(tmp_path) -> None:
    """The mistakes a caller of the API makes are one SgtoolError line naming the
    parameter, not an error deep inside a stage (a review hit each of these)."""
    with pytest.raises(sgtool.SgtoolError, match=r"^rooms=5: give \(MIN, MAX\)"):
        sgtool.generate_house(0, rooms=5)
    with pytest.raises(sgtool.SgtoolError, match=r"^rooms=\(4.5, 6\): give \(MIN, MAX\)"):
        sgtool.generate_house(0, rooms=(4.5, 6))
    with pytest.raises(sgtool.SgtoolError, match="^every='x': a whole number, or None$"):
        sgtool.ReplayOptions(every="x")
    with pytest.raises(sgtool.SgtoolError, match="^max_frames=2.5: a whole number"):
        sgtool.ReplayOptions(max_frames=2.5)
    with pytest.raises(sgtool.SgtoolError, match="^max_depth=nan: a finite number"):
        sgtool.ReplayOptions(max_depth=float("nan"))
    with sgtool.LogReader(LOG) as r:
        with pytest.raises(sgtool.SgtoolError, match="^record kind 'nosuch': one of action, "):
            list(r.records("nosuch"))
        with pytest.raises(sgtool.SgtoolError, match="^record kind 5: one of"):
            list(r.records(5))
        assert r.last_record("episode") is not None
    for seed in ("x", 1.5, True):
        with pytest.raises(sgtool.SgtoolError, match=f"^seed={seed!r}: a whole number, or"):
            sgtool.LogWriter(tmp_path / "w.mcap", seed=seed)
    assert not list(tmp_path.iterdir())
    with sgtool.LogWriter(tmp_path / "w.mcap") as w, \
            pytest.raises(ValueError, match="^intrinsics: a CameraIntrinsics, got NoneType$"):
        w.write_frame(0, depth=[[1.0]], pose=[[1.0, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0],
                                             [0, 0, 0, 1]], intrinsics=None)


def test_record_house_takes_a_house_file(tmp_path) -> None:
    pytest.importorskip("pybullet")
    from sgtool.datasets.start_poses import with_start_poses
    from sgtool.recorders.sim import CameraConfig

    house = tmp_path / "h.json"
    sgtool.save_house(with_start_poses(sgtool.generate_house(6, rooms=(4, 4))), house)
    opts = sgtool.RecordOptions(frames=2, camera=CameraConfig(width=32, height=24))
    rep = sgtool.record_house(str(house), tmp_path / "r.mcap", opts)
    assert rep.frames == 2
    with pytest.raises(sgtool.SgtoolError, match="^house: a HouseSpec or a house spec file, "
                       "got int$"):
        sgtool.record_house(5, tmp_path / "x.mcap", opts)  # type: ignore[arg-type]


def test_what_the_cli_refuses_the_api_refuses(tmp_path) -> None:
    """A typo'd planner gave NaN intervals, a negative tolerance 'no difference', an empty
    list an empty pin folder, a file 'no such pin folder'; each is one line now."""
    r = sgtool.EpisodeResult(planner="scout", seed=0, house="h", episode=0, query="cup",
                             success=True, steps=2, travelled_m=3.0, shortest_m=2.0)
    assert sgtool.planner_intervals([r], "scout").episodes == 1
    with pytest.raises(sgtool.SgtoolError, match=r"^planner 'scuot' has no episode in the "
                       r"results \(there: scout\)$"):
        sgtool.planner_intervals([r], "scuot")
    with pytest.raises(sgtool.SgtoolError, match="^planner 'random' has no episode"):
        sgtool.paired_comparison([r], "scout", "random")
    for tol in (-1.0, float("nan")):
        with pytest.raises(sgtool.SgtoolError, match="^tolerance=.*: a finite number >= 0$"):
            sgtool.diff_logs(LOG, LOG, tolerance=tol)
    with pytest.raises(sgtool.SgtoolError, match="^logs: give at least one log to pin$"):
        sgtool.pin_logs([], tmp_path / "pins")
    assert not (tmp_path / "pins").exists()
    text = tmp_path / "text.mcap"
    text.write_text("x")
    with pytest.raises(sgtool.SgtoolError, match="text.mcap is a file, not a pin folder"):
        sgtool.check_pins(text)


def test_an_empty_path_is_no_working_folder(tmp_path, monkeypatch) -> None:
    monkeypatch.chdir(tmp_path)
    with pytest.raises(sgtool.SgtoolError, match="^an empty path: no such file$"):
        sgtool.LogReader("")
    with pytest.raises(sgtool.SgtoolError, match="^an empty path: give a house spec file$"):
        sgtool.load_house("")
    with pytest.raises(sgtool.SgtoolError, match="^-o '': an empty path; give a file name$"):
        sgtool.write_rerun(LOG, "")
    with pytest.raises(sgtool.SgtoolError, match="^output: an empty path; give the derived"):
        sgtool.replay(LOG, "")
    with pytest.raises(sgtool.SgtoolError, match=r"^--dir \(folder=\) '': an empty path"):
        sgtool.pin_logs([LOG], "")
    with pytest.raises(sgtool.SgtoolError, match="^an empty path: give a folder$"):
        sgtool.files.output_dir("")
    assert list(tmp_path.iterdir()) == []


def test_a_first_argument_of_the_wrong_kind_is_one_line(tmp_path) -> None:
    """What a caller passes in the wrong place (a path for a house, a name for an
    episode, None for a result) is named in one line, not an AttributeError deep inside."""
    from sgtool.recorders.sim import CameraConfig

    house = sgtool.generate_house(6, rooms=(4, 4))
    cases = [
        (lambda: sgtool.list_episodes("h.json"), "^spec: a HouseSpec .*, got str$"),
        (lambda: sgtool.pick_episode("h.json"), "^house: a HouseSpec .*, got str$"),
        (lambda: sgtool.make_planner(5), "^planner name: a planner's name .*, got int$"),
        (lambda: sgtool.parse_noise(5), "^--noise: a profile's text .*, got int$"),
        (lambda: CameraConfig(width="x"), "^width='x': a whole number$"),
        (lambda: sgtool.run_benchmark("x"), "^cfg: a BenchConfig, got str$"),
        (lambda: sgtool.write_bench_outputs(None, tmp_path / "b"),
         r"^res: a BenchResult \(of run_benchmark\), got NoneType$"),
        (lambda: sgtool.update_pins(None), "^report: a CheckReport .*, got NoneType$"),
        (lambda: sgtool.diff_graphs(None, None), "^expected: a SceneGraph, got NoneType$"),
        (lambda: sgtool.replay(LOG, on_refresh=5), "^on_refresh: a function, got int$"),
        (lambda: sgtool.replay(LOG, tmp_path / "out.txt"), "name it \\*.mcap$"),
    ]
    for call, message in cases:
        with pytest.raises(sgtool.SgtoolError, match=message):
            call()
    assert sgtool.pick_episode(house)[0] == 0
    assert list(tmp_path.iterdir()) == []
    with pytest.raises(ValueError, match="NaN cost"):
        sgtool.auc_e([float("nan")], [True], 10.0)


def test_run_closed_loop_names_a_wrong_episode() -> None:
    pytest.importorskip("pybullet")
    house = sgtool.generate_house(6, rooms=(4, 4))
    with pytest.raises(sgtool.SgtoolError, match=r"^episode: an Episode \(sgtool.pick_episode"
                       r"\(house\)\), got str$"):
        sgtool.run_closed_loop(house, "mug", sgtool.make_planner("random"), "x.mcap")


def test_progress_takes_false_as_none_and_refuses_true_in_one_line(tmp_path) -> None:
    """progress=False means no progress, as it does for run_benchmark and pin_logs; True
    (no bar of its own there) and an object without update(n) are one line before any
    work, not an AttributeError after an episode."""
    rep = sgtool.replay(LOG, None, sgtool.ReplayOptions(max_frames=5), progress=False)
    assert rep.frames == 5
    with pytest.raises(sgtool.SgtoolError, match=r"^progress=True: an object with update"):
        sgtool.replay(LOG, None, progress=True)
    with pytest.raises(sgtool.SgtoolError, match=r"^progress=5: an object with update"):
        sgtool.export_bag(LOG, tmp_path / "b.bag", progress=5)
    with pytest.raises(sgtool.SgtoolError, match=r"^progress=True: a function, or None"):
        sgtool.write_rerun(LOG, tmp_path / "v.rrd", progress=True)
    with pytest.raises(sgtool.SgtoolError, match=r"^progress=True: an object with update"):
        sgtool.run_closed_loop_bench(sgtool.ClosedLoopBenchConfig("random"), tmp_path / "cl",
                                     progress=True)
    assert not list(tmp_path.iterdir())


def test_float_options_given_as_ints_log_as_floats() -> None:
    """fps=4 and vfov_deg=75 log as the CLI's --fps 4 (4.0) does: the same bytes."""
    from sgtool.recorders.sim import CameraConfig, RecordOptions

    opts = RecordOptions(fps=4, camera=CameraConfig(vfov_deg=75))
    assert isinstance(opts.fps, float) and isinstance(opts.camera.vfov_deg, float)
    with pytest.raises(sgtool.SgtoolError, match="^speed='x': a finite number"):
        sgtool.recorders.sim.RobotConfig(speed="x")


def test_run_closed_loop_bench_refuses_before_any_folder(tmp_path) -> None:
    """Options for a planner not run (a typo) and a plug-in that cannot be built are one
    line before any episode, and leave no output folder (as the symbolic bench does)."""
    out = tmp_path / "cl"
    with pytest.raises(sgtool.SgtoolError, match="'Greedy' is not one of the planners run"):
        sgtool.run_closed_loop_bench(sgtool.ClosedLoopBenchConfig(
            "greedy", planner_options={"Greedy": {"max_failures": 2}}), out)
    with pytest.raises(sgtool.SgtoolError, match="cannot import module 'no_such_module_x'"):
        sgtool.run_closed_loop_bench(sgtool.ClosedLoopBenchConfig(
            ("greedy", "no_such_module_x:Planner")), out)
    assert not out.exists()


def test_more_wrong_arguments_are_one_line() -> None:
    """A bench config's counts as text or fractions, replay of no log, and AUC-E given
    mismatched lists are SgtoolError lines (AUC-E's also a ValueError, as before)."""
    for field, value in (("houses", "2"), ("episodes", 2.5), ("seeds", "1")):
        with pytest.raises(sgtool.SgtoolError, match=f"^{field}={value!r}: a whole number"):
            sgtool.run_benchmark(sgtool.BenchConfig(**{field: value}))
    with pytest.raises(sgtool.SgtoolError, match="^houses='2': a whole number"):
        sgtool.ClosedLoopBenchConfig("greedy", houses="2").check()
    with pytest.raises(sgtool.SgtoolError, match="^log: a log's path, got NoneType$"):
        sgtool.replay(None)
    with pytest.raises(sgtool.SgtoolError, match="differ in length") as e:
        sgtool.auc_e([1.0], [True, False], 10.0)
    assert isinstance(e.value, ValueError)


def test_house_files_that_are_no_paths_are_one_line() -> None:
    """A HouseSpec (run_one takes one, bench takes files) or a name too long for the file
    system: a one-line SgtoolError, not an OSError showing the spec."""
    spec = sgtool.load_house(Path(__file__).parents[2] / "datasets/data/demo_house.json")
    with pytest.raises(sgtool.SgtoolError, match="got a HouseSpec .save it with "
                       "sgtool.save_house"):
        sgtool.BenchConfig(planners=("greedy",), houses=0, house_files=(spec,))
    config = sgtool.BenchConfig(planners=("greedy",), houses=0, episodes=1, seeds=1,
                                house_files=("x" * 300 + ".json",))
    with pytest.raises(sgtool.SgtoolError, match="not a house file or folder .OSError"):
        sgtool.run_benchmark(config)


def test_a_golden_check_runs_on_the_executor_sgtool_exports(tmp_path) -> None:
    """check_pins(executor=sgtool.make_executor(...)): the public way to check logs as
    `golden check -w N` does; a wrong name is one line."""
    log = Path(__file__).parents[1] / "golden" / "house10-start.mcap"
    sgtool.pin_logs([log], tmp_path / "g", sgtool.ReplayOptions(max_frames=20))
    checked = sgtool.check_pins(tmp_path / "g", executor=sgtool.make_executor("local", 1))
    assert checked.exit_code == 0 and [c.status for c in checked.logs] == ["unchanged"]
    with pytest.raises(sgtool.SgtoolError, match="--executor: one of"):
        sgtool.make_executor("cluster")


def test_generated_house_seeds_stay_ones_run_takes_again() -> None:
    """--house-seed near the top with --houses 2: the second house's seed is beyond what
    `sgtool run --seed` takes (its episodes could not be rerun); one line, both benches."""
    top = 2**62
    for config in (sgtool.BenchConfig, sgtool.ClosedLoopBenchConfig):
        with pytest.raises(sgtool.SgtoolError, match=r"--house-seed 4611686018427387904 with "
                           r"--houses 2: the houses' seeds must lie in 0\.\.4611686018427387904"):
            config(planners=("greedy",), houses=2, house_seed=top).check()
        config(planners=("greedy",), houses=1, house_seed=top).check()


def test_a_third_review_s_wrong_arguments_are_one_line(tmp_path) -> None:
    """Wrong types and swapped arguments at the API's entry points are one SgtoolError
    line naming the parameter (a review of the documented API hit each of these)."""
    from support.symbolic_fixtures import three_rooms

    house = sgtool.load_house(three_rooms())
    cases = [
        (lambda: sgtool.BenchConfig(planners=("random",), distance_budget=0).check(),
         r"^--distance-budget \(distance_budget=\): must be > 0"),
        (lambda: sgtool.BenchConfig(planners=("random",), step_budget=float("nan")).check(),
         "^step_budget=nan: a finite number"),
        (lambda: sgtool.BenchConfig(planners=("random",), distance_budget="5k").check(),
         "^distance_budget='5k': a finite number"),
        (lambda: sgtool.BenchConfig(planners=("random",), house_seed="1").check(),
         "^house_seed='1': a whole number"),
        (lambda: sgtool.ClosedLoopBenchConfig("greedy", step_budget=-1).check(),
         r"^--step-budget \(step_budget=\): must be > 0"),
        (lambda: sgtool.ClosedLoopBenchConfig("greedy", options={"max_steps": 3}).check(),
         "^options: a ClosedLoopOptions, got dict"),
        (lambda: sgtool.ClosedLoopOptions(max_steps="3"), "^max_steps='3': a whole number"),
        (lambda: sgtool.ClosedLoopOptions(camera=(96, 72)), r"^camera=\(96, 72\): a CameraConfig"),
        (lambda: sgtool.run_one(house, "greedy", 3), "^query: the target's category name"),
        (lambda: sgtool.run_one(house, "greedy", "sweater", max_steps="5"),
         "^max_steps='5': a whole number"),
        (lambda: sgtool.run_one(house, "greedy", "sweater", start=3), "^start: a region id"),
        (lambda: sgtool.run_one(house, "greedy", "sweater", log="ep.mcap"),
         "^log: an open sgtool.LogWriter"),
        (lambda: sgtool.SymbolicHouse("h.json"), "^spec: a HouseSpec"),
        (lambda: sgtool.load_house(3), "^source: a house spec file's path"),
        (lambda: sgtool.save_house(tmp_path / "h.json", house), "^spec: a HouseSpec"),
        (lambda: sgtool.write_results(tmp_path / "r.jsonl", []), "^path: a file's path"),
        (lambda: sgtool.write_results(str(tmp_path / "r.jsonl"), str(tmp_path / "x")),
         "^results: give the EpisodeResults, then the path"),
        (lambda: sgtool.list_episodes(house, n=-1), "^n=-1: a whole number >= 0"),
        (lambda: sgtool.LogReader(3), "^path: a log's path, got int"),
        (lambda: sgtool.actionable(None), "^graph: a SceneGraph, got NoneType"),
        (lambda: sgtool.run_closed_loop(house, sgtool.list_episodes(house, n=1)[0],
                                        sgtool.make_planner("greedy"), tmp_path / "e.mcap",
                                        {"max_steps": 3}),
         "^options: a ClosedLoopOptions, got dict"),
        (lambda: sgtool.record_house(house, tmp_path / "r.mcap", {"fps": 4}),
         "^options: a RecordOptions, got dict"),
    ]
    for call, message in cases:
        with pytest.raises(sgtool.SgtoolError, match=message):
            call()
    assert not list(tmp_path.iterdir())


def test_a_closed_loop_run_refuses_what_it_could_not_log_before_it_runs(tmp_path) -> None:
    """An output not named *.mcap, and a planner option the log cannot hold (infinity), are
    one line before the simulation starts, and nothing is written."""
    pytest.importorskip("pybullet")
    from support.symbolic_fixtures import three_rooms

    house = sgtool.load_house(three_rooms())
    ep = sgtool.list_episodes(house, n=1)[0]
    with pytest.raises(sgtool.SgtoolError, match="e.txt: the output is an MCAP log"):
        sgtool.run_closed_loop(house, ep, sgtool.make_planner("greedy"), tmp_path / "e.txt")
    with pytest.raises(sgtool.SgtoolError, match="^planner option radius=inf: a finite"):
        sgtool.run_closed_loop(house, ep, sgtool.make_planner("greedy"), tmp_path / "e.mcap",
                               planner_options={"radius": float("inf")})
    assert not list(tmp_path.iterdir())


def test_a_planner_built_from_a_name_is_closed_when_the_run_refuses(tmp_path,
                                                                    monkeypatch) -> None:
    """run_closed_loop builds a planner named to it; when an option it records is refused
    (infinity), that planner is closed all the same (an LLM planner's server, a plug-in's
    files), and nothing is written."""
    pytest.importorskip("pybullet")
    from support.symbolic_fixtures import three_rooms

    (tmp_path / "closing_plugin.py").write_text(
        "from sgtool.planning.planners import GreedyPlanner\n"
        "CLOSED = []\n"
        "class Closing(GreedyPlanner):\n"
        "    def __init__(self, radius=1.0):\n"
        "        super().__init__()\n"
        "    def close(self):\n"
        "        CLOSED.append(self)\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    import closing_plugin  # type: ignore[import-not-found]

    house = sgtool.load_house(three_rooms())
    ep = sgtool.list_episodes(house, n=1)[0]
    with pytest.raises(sgtool.SgtoolError, match="^planner option radius=inf: a finite"):
        sgtool.run_closed_loop(house, ep, "closing_plugin:Closing", tmp_path / "e.mcap",
                               planner_options={"radius": float("inf")})
    assert len(closing_plugin.CLOSED) == 1
    assert not (tmp_path / "e.mcap").exists()


class _Shape(Protocol):
    def area(self) -> float: ...


@dataclass
class _Mine:
    anything: Any = None
    shape: _Shape | None = None
    count: int = 1


def test_typed_fields_leaves_what_isinstance_cannot_check() -> None:
    """A field annotated Any (or a Protocol that is not runtime-checkable) is the class's
    own to check: typed_fields passes it, and still checks its other fields, also of a
    class whose other annotations do not resolve."""
    from sgtool.arg_checks import typed_fields

    typed_fields(_Mine(anything=object(), shape="not checked"))
    with pytest.raises(sgtool.SgtoolError, match="^count='2': a whole number"):
        typed_fields(_Mine(count="2"))

    @dataclass
    class Local:  # "_Local" does not resolve in the module: count is still checked
        inner: _Local | None = None  # noqa: F821
        count: int = 1

    with pytest.raises(sgtool.SgtoolError, match="^count=2.5: a whole number"):
        typed_fields(Local(count=2.5))


def test_outputs_written_from_python_are_sgtools_for_the_shell(tmp_path) -> None:
    """api.md's walk-through: write_bench_outputs into a folder, then the same bench from
    the shell with --force into it: it replaces them (it refused them as not sgtool's,
    the folder having no manifest); a user's file there is kept."""
    from click.testing import CliRunner

    from sgtool.cli import cli

    cfg = sgtool.BenchConfig(planners=("greedy",), houses=1, episodes=1, seeds=1,
                             rooms=(4, 5), preset="default")
    out = tmp_path / "results"
    sgtool.write_bench_outputs(sgtool.run_benchmark(cfg), out)
    (out / "notes.txt").write_text("mine")
    r = CliRunner().invoke(cli, ["bench", "--planners", "greedy", "--houses", "1",
                                 "--episodes", "1", "--seeds", "1", "--rooms", "4-5",
                                 "--preset", "default", "--no-progress", "-o", str(out),
                                 "--force"])
    assert r.exit_code == 0, r.output
    assert (out / "notes.txt").read_text() == "mine" and (out / "summary.md").is_file()
