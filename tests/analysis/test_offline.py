"""``sgtool eval``: metrics from MCAP logs written with sgtool.log's writer and from bench
JSONL; planners replayed against logged decisions; episode cutting in multi-episode and
unfinished logs."""

from __future__ import annotations

import json

import pytest
from click.testing import CliRunner
from support.symbolic_fixtures import three_rooms

from sgtool.analysis.bench import BenchConfig, run_benchmark, write_outputs
from sgtool.analysis.offline import (
    EvalInputError,
    load_results,
    read_log_episodes,
    replay_decisions,
)
from sgtool.cli import cli
from sgtool.house.io import load_house
from sgtool.log.writer import LogWriter
from sgtool.planning.registry import make_planner
from sgtool.recorders.symbolic_environment import SymbolicHouse, run_episode


@pytest.fixture(scope="module")
def house() -> SymbolicHouse:
    return SymbolicHouse(load_house(three_rooms()))


@pytest.fixture(scope="module")
def greedy_log(house, tmp_path_factory):
    path = tmp_path_factory.mktemp("logs") / "greedy.mcap"
    with LogWriter(path, seed=2) as log:
        res = run_episode(house, make_planner("greedy"), "sweater", ["obj_5"], seed=2,
                          episode_index=0, seen=False, house_id="three", log=log)
    return path, res


def test_metrics_from_a_log_match_the_run(greedy_log):
    path, res = greedy_log
    (ep,) = read_log_episodes(path)
    assert len(ep.decisions) == res.steps
    assert all(d.graph is not None for d in ep.decisions)
    r = ep.result()
    assert (r.success, r.steps, r.n_open, r.seed, r.seen, r.planner, r.query, r.house) == (
        res.success, res.steps, res.n_open, 2, False, "greedy", "sweater", "three")
    assert r.travelled_m == pytest.approx(res.travelled_m, abs=1e-3)
    assert r.shortest_m == pytest.approx(res.shortest_m, abs=1e-3)
    assert [(s.skill, s.target, s.outcome) for s in r.trace] == \
        [(s.skill, s.target, s.outcome) for s in res.trace]
    # its repr names it in a line (it printed every decision's graph: megabytes)
    assert repr(ep) == (f"LoggedEpisode(source={str(path)!r}, index=0, planner='greedy', "
                        f"query='sweater', decisions={res.steps}, closed=True)")


def test_planner_against_its_own_log_agrees(greedy_log):
    path, res = greedy_log
    eps = read_log_episodes(path)
    same = replay_decisions(make_planner("greedy"), eps)
    assert same.decisions == res.steps and same.skipped == 0
    assert same.rate("agree") == 1.0 and same.rate("invalid") == 0.0
    assert same.rate("room") == 1.0
    other = replay_decisions(make_planner("scout"), eps, name="scout")
    assert other.decisions == res.steps and other.rate("invalid") == 0.0
    assert 0.0 <= other.rate("agree") <= other.rate("target") <= 1.0


def test_done_naming_no_node_of_the_graph_is_not_in_graph(greedy_log):
    """A planner answering done(obj:99999) names no node, as navigate(obj:99999) would:
    both count as "not in graph"; a done without a target (giving up) does not."""
    from sgtool.planning.base import Action

    class Says:
        def __init__(self, skill, target):
            self.name, self.skill, self.target = "says", skill, target

        def reset(self, query, seed=0):
            pass

        def decide(self, graph):
            return Action(self.skill, self.target)

        def feedback(self, fb):
            pass

    eps = read_log_episodes(greedy_log[0])
    for skill, target, invalid in (("done", "obj:99999", 1.0), ("navigate", "obj:99999", 1.0),
                                   ("done", None, 0.0)):
        assert replay_decisions(Says(skill, target), eps).rate("invalid") == invalid


def records_log(path, records):  # type: ignore[no-untyped-def]
    """A log of sgtool records only, one per nanosecond in the order given."""
    with LogWriter(path) as log:
        for t, (kind, data) in enumerate(records):
            log.write_record(kind, t, data)
    return path


def test_multi_episode_and_unfinished_logs(tmp_path, house):
    path = records_log(tmp_path / "two.mcap", [
        ("episode", {"kind": "search", "status": "started", "query": "cup", "planner": "x"}),
        ("action", {"skill": "open", "target": "door:0", "outcome": "success",
                    "travelled_m": 2.0}),
        ("episode", {"kind": "search", "status": "success", "steps": 1, "travelled_m": 2.0,
                     "shortest_m": 1.0}),
        ("episode", {"kind": "search", "status": "started", "query": "mug", "planner": "x",
                     "steps": 0, "travelled_m": 0.0, "frames": 0}),  # as the closed loop
        ("action", {"skill": "explore", "target": "room:1", "outcome": "success",
                    "travelled_m": 3.0}),
        ("action", {"skill": "open", "target": "obj:1", "outcome": "invalid",
                    "travelled_m": 0.0}),
    ])  # the run was killed: no closing record
    a, b = read_log_episodes(path)
    ra, rb = a.result(), b.result()
    assert (ra.query, ra.success, ra.steps, ra.n_open, ra.shortest_m) == ("cup", True, 1, 1, 1.0)
    assert (rb.query, rb.success, rb.steps, rb.travelled_m, rb.n_invalid, rb.end) == (
        "mug", False, 2, 3.0, 1, "ended")
    assert (ra.episode, rb.episode) == (0, 1)
    # eval says that the second was cut short, not only that it failed
    notes: list[str] = []
    load_results([path], notes)
    assert notes == [f"{path}: episode 1 has no closing record (the run was interrupted or "
                     "killed): scored from the actions logged until it stopped, as a "
                     "failure"]
    # no scene graphs: a planner has nothing to decide on
    rep = replay_decisions(make_planner("greedy"), [a, b])
    assert rep.decisions == 0 and rep.skipped == 3


def test_load_results_rejects_other_files(tmp_path):
    bad = tmp_path / "x.bin"
    bad.write_bytes(b"\x00\x01garbage")
    with pytest.raises(EvalInputError, match="neither an MCAP log"):
        load_results([bad])
    with pytest.raises(EvalInputError, match="no such file"):
        load_results([tmp_path / "missing.mcap"])


def test_eval_cli_on_logs_and_bench_output(tmp_path, greedy_log):
    path, res = greedy_log
    runner = CliRunner()
    r = runner.invoke(cli, ["eval", str(path), "--planner", "greedy,random"])
    assert r.exit_code == 0, r.output
    assert "Metrics recomputed from 1 episode(s)" in r.output
    assert "Planners against the logged decisions" in r.output
    row = next(ln for ln in r.output.splitlines() if ln.startswith("| greedy") and "%" in ln)
    assert "100.0%" in row
    # bench output: eval recomputes the bench summary exactly
    bench = run_benchmark(BenchConfig(planners=("random", "greedy"), houses=1, episodes=2,
                                      seeds=2))
    write_outputs(bench, tmp_path / "b")
    r = runner.invoke(cli, ["eval", str(tmp_path / "b" / "episodes.jsonl"), "--json",
                            "-o", str(tmp_path / "e.json")])
    assert r.exit_code == 0, r.output
    got = json.loads(r.output)
    want = json.loads((tmp_path / "b" / "summary.json").read_text())["planners"]
    for p in ("random", "greedy"):
        for k in ("sr", "spl", "steps", "auc_e_distance", "auc_e_steps"):
            assert got["planners"][p][k]["mean"] == want[p][k]["mean"]
    assert json.loads((tmp_path / "e.json").read_text()) == got
    r = runner.invoke(cli, ["eval", str(tmp_path / "b" / "episodes.jsonl"), "-p", "greedy"])
    assert r.exit_code == 2 and "needs logged decisions" in r.output


def test_bench_logs_round_trip_through_eval(tmp_path):
    """Episodes recorded by `sgtool bench --log-dir` give back the bench's own records."""
    cfg = BenchConfig(planners=("greedy",), houses=1, episodes=2, seeds=1, rooms=(5, 6),
                      log_dir=str(tmp_path / "logs"))
    bench = run_benchmark(cfg)
    logs = sorted((tmp_path / "logs").rglob("*.mcap"))
    assert len(logs) == 2
    results, logged = load_results(logs)
    assert [(r.query, r.success, r.steps, r.n_open, r.end, r.seen) for r in results] == \
        [(r.query, r.success, r.steps, r.n_open, r.end, r.seen) for r in bench.results]
    assert [r.travelled_m for r in results] == pytest.approx(
        [r.travelled_m for r in bench.results], abs=1e-3)
    rep = replay_decisions(make_planner("greedy"), logged)
    assert rep.decisions == sum(r.steps for r in bench.results) and rep.rate("agree") == 1.0


def test_seen_is_filled_as_bench_does_when_a_log_lacks_it(tmp_path):
    """Seen = a training query of the shipped priors, as `sgtool bench` counts it: an
    unseen query of the split and a house file's own name ("yoga mat") are unseen."""
    from sgtool.analysis.bench_priors import training_vocabulary
    from sgtool.datasets.split import unseen_queries

    unseen = unseen_queries()[0]
    path = tmp_path / "q.mcap"
    with LogWriter(path) as log:
        for t, q in enumerate((sorted(training_vocabulary(None))[0], unseen, "yoga mat")):
            log.write_record("episode", 2 * t, {"kind": "search", "status": "started",
                                                "query": q})
            log.write_record("episode", 2 * t + 1, {"kind": "search", "status": "failure"})
    results, _ = load_results([path])
    assert [r.seen for r in results] == [True, False, False]


def test_a_ros2_mcap_with_sgtool_topic_names_is_called_foreign(tmp_path):
    """A bag exported from a derived log (`sgtool export bag`) keeps sgtool's topic names;
    eval says it is a ROS 2 recording, not that an sgtool record is damaged."""
    from mcap.writer import Writer

    path = tmp_path / "exported.mcap"
    with open(path, "wb") as f:
        w = Writer(f)
        w.start(profile="ros2", library="test")
        sid = w.register_schema("std_msgs/msg/String", "ros2msg", b"string data")
        cid = w.register_channel("/sgtool/scene_graph", "cdr", sid)
        w.add_message(cid, log_time=1, data=b"\x00\x01\x00\x00\x03\x00\x00\x00{}\x00",
                      publish_time=1)
        w.finish()
    with pytest.raises(EvalInputError, match=r"is a ROS 2 recording .*not an sgtool log"):
        load_results([path])


def test_eval_says_when_planners_ran_on_different_episodes(tmp_path):
    """Rows of planners run on different episodes are not comparable as they stand: eval
    says so, with the counts."""
    from sgtool.results import EpisodeResult, write_jsonl

    rows = [EpisodeResult(planner=p, seed=0, house="h", episode=e, query="mug",
                          success=True, steps=2, travelled_m=3.0, shortest_m=2.0)
            for p, eps in (("a", (0, 1, 2)), ("b", (0, 1))) for e in eps]
    f = tmp_path / "episodes.jsonl"
    write_jsonl(rows, f)
    r = CliRunner().invoke(cli, ["eval", str(f)])
    assert r.exit_code == 0, r.output
    assert "sgtool: note: the planners ran on different episodes (a 3, b 2; 2 in common)" \
        in r.output
    write_jsonl(rows[:2] + rows[3:], f)  # the same two episodes each: nothing to say
    assert "different episodes" not in CliRunner().invoke(cli, ["eval", str(f)]).output


def test_a_closing_record_without_steps_is_no_cut_short_episode(tmp_path):
    """``steps`` is optional in a closing record: an episode closed by one is complete
    (eval says nothing), only a missing closing record is a run cut short."""
    path = records_log(tmp_path / "one.mcap", [
        ("episode", {"kind": "search", "status": "started", "query": "cup", "planner": "x"}),
        ("action", {"skill": "navigate", "target": "obj:1", "outcome": "success",
                    "travelled_m": 2.0}),
        ("episode", {"kind": "search", "status": "success"}),
    ])
    notes: list[str] = []
    (r,), (e,) = load_results([path], notes)
    assert notes == [] and e.closed and r.success


def _mistake(how: str):
    """A decision with one mistake: it raises, returns None or names no skill."""
    from sgtool.planning.base import Action

    def decide(graph):
        if how == "raises":
            raise RuntimeError("bug in my planner")
        return None if how == "none" else Action("fly", None)

    return decide


@pytest.mark.parametrize("how, why", [
    ("none", r"decide\(\) returned None, not an sgtool.Action"),
    ("skill", r"decide\(\) returned an Action with skill 'fly'; the skills are"),
    ("raises", r"decide\(\) raised RuntimeError: bug in my planner"),
])
def test_a_planner_object_is_held_to_the_plug_in_contract(greedy_log, how, why):
    """replay_decisions holds a user's object to what run_one holds it to: a wrong return,
    an unknown skill or an exception is one line naming the planner, not a traceback or
    a disagreement scored."""
    from support.scripted_planner import Scripted

    from sgtool.errors import SgtoolError

    mine = Scripted([_mistake(how)])  # a user's planner object, not a plug-in name
    mine.name = "mine"
    with pytest.raises(SgtoolError, match=f"planner 'mine': {why}"):
        replay_decisions(mine, read_log_episodes(greedy_log[0]))
