"""The scripts in ``examples/`` run as a user runs them (a subprocess each, small inputs) and
print what they promise; ``my_planner.MyPlanner`` is also checked decision by decision."""

from __future__ import annotations

import gzip
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

import sgtool

REPO = Path(__file__).resolve().parents[1]
EXAMPLES = REPO / "examples"
GOLDEN = REPO / "tests" / "golden"
SCRIPTS = ("replay_rooms.py", "my_planner.py", "benchmark_my_planner.py",
           "import_replay_export.py", "evaluate_logged.py")


def run(script: str, *args: str | Path, cwd: Path = REPO) -> str:
    """The stdout of ``python examples/SCRIPT ARGS``; the test fails with its stderr."""
    env = {**os.environ, "HF_HUB_OFFLINE": "1", "TRANSFORMERS_OFFLINE": "1",
           "MPLBACKEND": "Agg", "PYTHONPATH": str(EXAMPLES)}
    done = subprocess.run([sys.executable, str(EXAMPLES / script), *map(str, args)],
                          capture_output=True, text=True, cwd=cwd, env=env, timeout=300)
    assert done.returncode == 0, f"{script} failed:\n{done.stderr[-3000:]}"
    return done.stdout


def table_rows(text: str) -> dict[str, list[str]]:
    """Markdown table rows of ``text``: first cell -> the other cells (of its first row:
    the results table, not the interval tables after it)."""
    rows: dict[str, list[str]] = {}
    for line in text.splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if line.startswith("|") and not set(cells[0]) <= {"-"}:
            rows.setdefault(cells[0], cells[1:])
    return rows


@pytest.mark.parametrize("script", SCRIPTS)
def test_every_example_says_how_to_run_it(script: str) -> None:
    text = (EXAMPLES / script).read_text()
    assert text.startswith('"""') and "python examples/" + script in text
    assert "argparse" in text
    assert "usage:" in run(script, "--help")


def test_replay_rooms_prints_the_golden_graphs_rooms() -> None:
    """Per refresh, each room with its category and object count: the same as the golden
    graphs of the log's replay (tests/golden/)."""
    out = run("replay_rooms.py", GOLDEN / "house6-tour.mcap", "--classifier", "containment")
    golden = [sgtool.SceneGraph.from_json(line) for line in
              gzip.open(GOLDEN / "house6-tour.graphs.jsonl.gz", "rt").read().splitlines()]
    printed: list[tuple[int, int, set[tuple[str, str, int, bool]]]] = []
    for line in out.splitlines():
        if m := re.fullmatch(r"refresh (\d+) at [\d.]+ s \(\w+, \d+ frames\): (\d+) rooms, "
                             r"(\d+) objects", line):
            assert int(m[1]) == len(printed)
            printed.append((int(m[2]), int(m[3]), set()))
        elif m := re.fullmatch(r"  (room:\d+) +(\w+) +(\d+) objects( +\(unexplored\))?", line):
            printed[-1][2].add((m[1], m[2], int(m[3]), m[4] is None))
    assert f"{len(golden)} refreshes" in out.splitlines()[-1]
    assert len(printed) == len(golden) == 31
    for (rooms, objects, lines), graph in zip(printed, golden, strict=True):
        assert (rooms, objects) == (len(graph.rooms), len(graph.objects))
        assert lines == {(r.id, r.category, sum(o.room == r.id for o in graph.objects),
                          r.explored) for r in graph.rooms}
    # the last refresh: four rooms, the kitchen room:1 holding 29 of the 40 objects (room:0,
    # the corridor's end past the living room's door, was told apart from the start)
    assert ("room:1", "kitchen", 29, True) in printed[-1][2]


def _graph(*, frontier_d: float | None, query_room_objects: bool = False) -> sgtool.SceneGraph:
    """A room with two closed containers (a cabinet 3 m away, a fridge 5 m away) and,
    unless ``frontier_d`` is None, a frontier that far; a mug inside the fridge when asked."""
    regions = [sgtool.RegionNode("region:0.0", "room:0", (0.0, 0.0))]
    dist = {"room:0": 0.0, "region:0.0": 0.0, "obj:1": 3.0, "obj:2": 5.0}
    if frontier_d is not None:
        regions.append(sgtool.RegionNode("frontier:0", "room:0", (frontier_d, 0.0),
                                         kind="frontier", frontier_type="leading out"))
        dist["frontier:0"] = frontier_d
    objects = [sgtool.ObjectNode("obj:1", "cabinet", "region:0.0", "room:0", (3.0, 0.0, 0.0),
                                 state="closed", affordances=("openable",)),
               sgtool.ObjectNode("obj:2", "fridge", "region:0.0", "room:0", (5.0, 0.0, 0.0),
                                 state="closed", affordances=("openable",))]
    if query_room_objects:
        objects.append(sgtool.ObjectNode("obj:3", "mug", "obj:2", "room:0", (5.0, 0.0, 1.0),
                                         relation="inside"))
        dist["obj:3"] = 5.0
    return sgtool.SceneGraph(sgtool.RobotState((0.0, 0.0), room="room:0"),
                             rooms=(sgtool.RoomNode("room:0", "kitchen"),),
                             regions=tuple(regions), objects=tuple(objects), distances=dist)


def test_my_planner_decides_as_its_docstring_says() -> None:
    sys.path.insert(0, str(EXAMPLES))
    try:
        from my_planner import MyPlanner
    finally:
        sys.path.remove(str(EXAMPLES))
    planner: sgtool.Planner = MyPlanner(max_failures=1)
    planner.reset("fridge_magnet")
    # 1. unexplored space first, even farther than the containers
    first = planner.decide(_graph(frontier_d=8.0))
    assert (first.skill, first.target) == ("explore", "frontier:0")
    # 2. then the container most alike the query by name: "fridge" (5 m) over "cabinet" (3 m)
    second = planner.decide(_graph(frontier_d=None))
    assert (second.skill, second.target) == ("open", "obj:2")
    # a failure drops it (max_failures=1): the cabinet is next
    planner.feedback(sgtool.Feedback(second, "failure", "stuck"))
    third = planner.decide(_graph(frontier_d=None))
    assert (third.skill, third.target) == ("open", "obj:1")
    planner.feedback(sgtool.Feedback(third, "invalid"))
    assert planner.decide(_graph(frontier_d=None)).skill == "done"  # nothing left
    # 3. the query in view: done on it
    planner.reset("mug")
    found = planner.decide(_graph(frontier_d=8.0, query_room_objects=True))
    assert (found.skill, found.target) == ("done", "obj:3")


def test_benchmark_my_planner_rows_beside_scout(tmp_path: Path) -> None:
    out = run("benchmark_my_planner.py", "--houses", "2", "--episodes", "3", "-o",
              tmp_path / "bench")
    rows = table_rows(out)
    assert set(rows) >= {"my_planner:MyPlanner", "scout"}
    for name in ("my_planner:MyPlanner", "scout"):
        assert rows[name][-1] == "6 (1 seeds)"  # 2 houses x 3 episodes x 1 seed
    # the printed SR is the share of the written episodes that succeeded
    results = sgtool.read_results(tmp_path / "bench" / "episodes.jsonl")
    mine = [r for r in results if r.planner == "my_planner:MyPlanner"]
    assert len(mine) == 6 and len(results) == 12
    assert rows["my_planner:MyPlanner"][0] == f"{sgtool.success_rate(mine):.3f} ± -"
    assert "my_planner:MyPlanner" in (tmp_path / "bench" / "summary.md").read_text()
    assert "Paired comparisons on the same episodes" in out  # and the intervals


def test_my_planner_script_runs_one_episode() -> None:
    out = run("my_planner.py", "--seed", "3", "--rooms", "4-6").splitlines()
    m = re.fullmatch(r"house 3, find '(.+)': (found|not found) in (\d+) steps, .*", out[0])
    assert m is not None, out[0]
    assert len(out) == 1 + int(m[3])  # one line per step
    assert all(re.fullmatch(r" +\d+ (explore|open|navigate|close|done) +\S+ +\w+", s)
               for s in out[1:])


def _bag_counts(path: Path) -> dict[str, int]:
    from rosbags.highlevel import AnyReader
    from rosbags.typesys import Stores, get_typestore

    counts: dict[str, int] = {}
    with AnyReader([path], default_typestore=get_typestore(Stores.LATEST)) as reader:
        for connection, _, _ in reader.messages():
            counts[connection.topic] = counts.get(connection.topic, 0) + 1
    return counts


def test_import_replay_export_writes_a_readable_bag(tmp_path: Path) -> None:
    from support.rgbd_folders import make_tum_folder

    folder = make_tum_folder(tmp_path / "tum", [1.0 + i / 30 for i in range(24)])
    out = run("import_replay_export.py", folder, "-o", tmp_path / "out",
              "--intrinsics", "60,60,39.5,29.5")
    assert f"imported.mcap: 24 frames from rgbd/tum {folder}" in out
    m = re.search(r"^24 frames, (\d+) refreshes", out, re.MULTILINE)
    assert m is not None, out
    refreshes = int(m[1])
    assert refreshes == 3  # every 10 frames (10, 20) and the end (24)
    with sgtool.LogReader(tmp_path / "out" / "derived.mcap") as log:
        assert log.message_count("/sgtool/scene_graph") == refreshes
    counts = _bag_counts(tmp_path / "out" / "derived_bag")
    assert counts["/camera/depth/image_raw"] == counts["/camera/rgb/image_raw"] == 24
    assert counts["/map/occupancy"] == counts["/sgtool/scene_graph"] == refreshes
    assert f"derived_bag (ros2, zstd): {sum(counts.values())} messages" in out


def test_evaluate_logged_replays_the_logged_decisions(tmp_path: Path) -> None:
    """Logs of a small greedy bench: greedy agrees with every logged decision of its own
    (it is deterministic and sees the same graphs); the metrics are the bench's."""
    config = sgtool.BenchConfig(planners=("greedy",), houses=1, episodes=3, seeds=1,
                                rooms=(4, 6), preset="default", log_dir=str(tmp_path / "logs"))
    bench = sgtool.run_benchmark(config, progress=False)
    logs = sorted((tmp_path / "logs").rglob("*.mcap"))
    assert len(logs) == 3
    out = run("evaluate_logged.py", *logs, "-p", "greedy", "-p", "my_planner:MyPlanner")
    metrics, _, offline = out.partition("Planners against the logged decisions")
    assert offline, out
    decisions = sum(r.steps for r in bench.results)  # one decision per step
    assert table_rows(offline)["greedy"][:3] == [str(decisions), "100.0%", "100.0%"]
    assert table_rows(offline)["my_planner:MyPlanner"][0] == str(decisions)
    row = table_rows(metrics)["greedy"]
    assert row[0] == f"{sgtool.success_rate(bench.results):.3f} ± -"
    assert row[-1] == "3 (1 seeds)"


def test_the_api_guide_runs(tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                            capsys: pytest.CaptureFixture[str]) -> None:
    """docs/api.md's code blocks, in order, in one namespace, from a folder that looks like
    the repository root (the two closed-loop blocks are left out: a PyBullet episode takes a
    minute; tests/recorders/sim covers run_episode, tests/toolkit/commands/test_run_again
    a logged episode run again)."""
    guide = (REPO / "docs" / "api.md").read_text()
    blocks = re.findall(r"```python\n(.*?)```", guide, re.DOTALL)
    assert len(blocks) == 22
    runnable = [b for b in blocks if "run_closed_loop(" not in b]
    assert len(runnable) == len(blocks) - 2
    for name in ("tests", "examples"):
        (tmp_path / name).symlink_to(REPO / name)
    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr(sys, "path", list(sys.path))  # the guide adds examples/ to it
    namespace: dict[str, object] = {"__name__": "api_guide"}
    for block in runnable:
        exec(compile(block, "docs/api.md", "exec"), namespace)  # noqa: S102
    out = capsys.readouterr().out
    assert "my_planner:MyPlanner" in out and "| scout" in out  # the benchmark table
    assert (tmp_path / "results" / "summary.md").is_file()
    assert (tmp_path / "derived_bag").is_dir()
    assert sorted(p.name for p in (tmp_path / "derived_logs").iterdir()) == [
        ".sgtool-output", "house10-start.mcap", "house6-tour.mcap"]
    assert (tmp_path / "derived.rrd").stat().st_size > 0
    assert (tmp_path / "run-bench" / "summary.md").is_file()
    assert "| scout " in (tmp_path / "run-bench" / "run.md").read_text()
    logged = namespace["logged"]  # a run-bench episode read back to run again
    assert isinstance(logged, sgtool.LoggedRun) and logged.planner == "scout"
    assert logged.options.max_steps == 10 and logged.notes == ()
    again = namespace["again"]  # the tables at other budgets, read back (nothing run)
    assert again.results() == namespace["result"].results()  # type: ignore[attr-defined]
    with sgtool.LogReader(tmp_path / "my.mcap") as log:
        assert [r.skill for _, r in log.records(sgtool.ActionRecord)] == ["navigate"]
    no_mugs = namespace["no_mugs"]  # a hand-made graph, read back from its dict form
    assert isinstance(no_mugs, sgtool.SceneGraph)
    assert not any(o.category == "mug" for o in no_mugs.objects)
    recorded = namespace["recorded"]  # the recording block
    assert isinstance(recorded, sgtool.RecordReport) and recorded.frames == 40
    with sgtool.LogReader(tmp_path / "house.mcap") as log:
        assert log.frame_count() == 40
    found = namespace["found"]  # the noise-study block: none, then label_swap 0.05
    assert isinstance(found, sgtool.NoiseStudyResult)
    assert [c.condition.noise for c in found.cells] == ["none", "none,label_swap=0.05"]
    assert (tmp_path / "noise-study" / "results.csv").is_file()
    assert len(list((tmp_path / "noise-cache").rglob("*.mcap"))) == 2
    report = namespace["report"]
    assert isinstance(report, sgtool.OfflineReport) and report.decisions > 0
    checked, what_if = namespace["checked"], namespace["what_if"]  # the golden-logs block
    assert isinstance(checked, sgtool.CheckReport) and checked.exit_code == 0
    assert isinstance(what_if, sgtool.CheckReport) and what_if.exit_code == 1
