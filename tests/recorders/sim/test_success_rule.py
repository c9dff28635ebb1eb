"""MoMa-LLM's success rule in the closed loop (``sgtool run --success done``): once the target
is in view the planner is asked once more; only ``done(<an object of the query>)`` makes
the episode a success (:func:`sgtool.planning.episode.search_success`)."""

from __future__ import annotations

from pathlib import Path

import pytest
from click.testing import CliRunner

from sgtool.analysis.offline import read_log_episodes, with_success_rule
from sgtool.cli import cli
from sgtool.datasets.generator import generate_house
from sgtool.errors import SgtoolError
from sgtool.log import LogReader
from sgtool.log import schemas as S
from sgtool.planning.base import Action, Feedback
from sgtool.planning.candidates import find_target
from sgtool.planning.episode import CONFIRMED, NOT_CONFIRMED
from sgtool.planning.registry import make_planner
from sgtool.recorders.sim import CameraConfig
from sgtool.recorders.sim.closed_loop import ClosedLoopOptions, pick_episode, run_episode
from sgtool.scenegraph.graph import SceneGraph

OPTS = ClosedLoopOptions(camera=CameraConfig(width=160, height=120))
GRAPH = S.RECORDS["scene_graph"].topic


class _Scout:
    """scout, except that once the graph shows the target it calls done() on it when
    ``confirm``, else done() naming nothing."""

    name = "scout"

    def __init__(self, confirm: bool) -> None:
        self.inner, self.confirm, self.query = make_planner("scout"), confirm, ""

    def reset(self, query: str, seed: int = 0) -> None:
        self.query = query
        self.inner.reset(query, seed=seed)

    def decide(self, graph: SceneGraph) -> Action:
        target = find_target(graph, self.query)
        if target is not None:
            return Action("done", target.id if self.confirm else None)
        return self.inner.decide(graph)

    def feedback(self, fb: Feedback) -> None:
        self.inner.feedback(fb)


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    """The same episode (house seed 6, 4 rooms, episode 0: scout finds it) under the
    observed rule, and under the done rule with and without the confirmation."""
    house = generate_house(6, rooms=(4, 4))
    idx, ep = pick_episode(house, index=0)
    d = tmp_path_factory.mktemp("rule")
    out = {}
    for key, confirm, rule in (("observed", True, "observed"), ("done", True, "done"),
                               ("unconfirmed", False, "done")):
        path = d / f"{key}.mcap"
        rep = run_episode(house, ep, _Scout(confirm), path,
                          ClosedLoopOptions(camera=OPTS.camera, success=rule),
                          episode_index=idx)
        out[key] = (path, rep)
    return out


def _actions(path: Path) -> list[dict]:
    with LogReader(path) as r:
        return [a for _, a in r.records("action")]


def _episodes(path: Path) -> list[dict]:
    with LogReader(path) as r:
        return [e for _, e in r.records("episode")]


def test_done_rule_confirmed(runs) -> None:
    path, rep = runs["done"]
    _, seen = runs["observed"]
    assert (rep.success, rep.end) == (True, "found")
    assert rep.steps == seen.steps  # the confirmation is no step
    acts = _actions(path)
    assert len(acts) == len(_actions(runs["observed"][0])) + 1
    last = acts[-1]
    assert (last["skill"], last["outcome"], last["message"]) == ("done", "success", CONFIRMED)
    assert last["target"].startswith("obj:") and last["travelled_m"] == 0.0
    started, ended = _episodes(path)
    assert started["extra"]["success"] == ended["extra"]["success"] == "done"
    assert (ended["status"], ended["steps"], ended["extra"]["end"]) == (
        "success", rep.steps, "found")
    # the default rule writes no "success" key: its logs stay as they were
    assert "success" not in _episodes(runs["observed"][0])[0]["extra"]
    # offline judging under the done rule agrees with the log
    (logged,) = read_log_episodes(path)
    assert with_success_rule(logged.result(), "done").success


def test_done_rule_unconfirmed(runs) -> None:
    path, rep = runs["unconfirmed"]
    assert (rep.success, rep.end) == (False, NOT_CONFIRMED)
    last = _actions(path)[-1]
    assert last["outcome"] == "failure" and "did not call done()" in last["message"]
    ended = _episodes(path)[-1]
    assert (ended["status"], ended["extra"]["end"]) == ("failure", NOT_CONFIRMED)
    # judged by the observed rule the same log is a find
    (logged,) = read_log_episodes(path)
    assert with_success_rule(logged.result(), "observed").success


def test_done_rule_log_replays_into_the_same_graphs(runs, tmp_path) -> None:
    path, _ = runs["done"]
    derived = tmp_path / "replayed.mcap"
    r = CliRunner().invoke(cli, ["replay", str(path), "-o", str(derived)])
    assert r.exit_code == 0, r.output
    with LogReader(path) as a, LogReader(derived) as b:
        live = [bytes(m.data) for _, _, m in a.raw_messages([GRAPH])]
        again = [bytes(m.data) for _, _, m in b.raw_messages([GRAPH])]
    assert len(live) >= 3 and live == again  # several refreshes, byte for byte


def test_cli_success_option(tmp_path) -> None:
    out = tmp_path / "x.mcap"
    r = CliRunner().invoke(cli, ["run", "-p", "scout", "--seed", "6", "--rooms", "4-4",
                                 "--success", "maybe", "-o", str(out)])
    assert r.exit_code != 0 and "maybe" in r.output and not out.exists()
    with pytest.raises(SgtoolError, match="--success 'maybe'"):
        ClosedLoopOptions(success="maybe").mapping()
