"""The robot's own exploration when the graph offers the planner nothing (issue 17), on the
small 4-room house of test_closed_loop at 96x72.

Checked: a start whose graphs offer nothing while the robot stands at its start pose (the
condition of a cluttered start room: no room, region or frontier node, reproduced by
emptying the scene graphs built near the start) ends at step 1 without the fallback and
reaches a room with it, the fallback's actions logged as ``explore`` of grid frontiers
with reason "fallback: no actionable node", decided on no graph, their frames and metres
counted; a planner that gives up while the map has reachable frontiers hands over to the
fallback, which stops as soon as the graph offers a node it did not offer before, and that
episode's log replays into the same scene graphs byte for byte; the fallback is
deterministic and uses the robot's side only (the true map made to raise).
"""

from __future__ import annotations

import dataclasses
import math

import pytest
from click.testing import CliRunner
from support.scripted_planner import Scripted

from sgtool.cli import cli
from sgtool.datasets.generator import generate_house
from sgtool.log import LogReader
from sgtool.planning.base import Action
from sgtool.planning.candidates import actionable
from sgtool.planning.registry import make_planner
from sgtool.recorders.sim import CameraConfig
from sgtool.recorders.sim import closed_loop as cl
from sgtool.recorders.sim.closed_loop import ClosedLoopOptions, pick_episode, run_episode
from sgtool.recorders.sim.fallback_explore import (
    FallbackOptions,
    FallbackRun,
    is_fallback,
    new_candidates,
)
from sgtool.scenegraph.builder import SceneGraphBuilder

OPTS = ClosedLoopOptions(camera=CameraConfig(width=96, height=72), frames=900)
GRAPH = "/sgtool/scene_graph"


@pytest.fixture(scope="module")
def house():
    return generate_house(6, rooms=(4, 4))


def _open_start(house) -> tuple[int, object]:
    """An episode whose start room has a way out (episode 0's door is closed)."""
    for k in range(len(cl.list_episodes(house))):
        idx, ep = pick_episode(house, index=k)
        if ep.start.room != pick_episode(house, index=0)[1].start.room:
            return idx, ep
    raise AssertionError("no episode starts in another room")


def _empty_near_start(monkeypatch, start_xy: tuple[float, float], radius: float = 0.6) -> None:
    """Scene graphs built while the robot is within ``radius`` of its start hold no node:
    what a cluttered start room gives (free floor in pieces, no room, no frontier node)
    while the occupancy grid, and so its frontier cells, is the real one."""
    real = SceneGraphBuilder.refresh

    def refresh(self, t_ns):
        g = real(self, t_ns)
        if math.dist(g.robot.position[:2], start_xy) > radius:
            return g
        return dataclasses.replace(g, rooms=(), regions=(), objects=(), doors=(),
                                   distances={})

    monkeypatch.setattr(SceneGraphBuilder, "refresh", refresh)


def _actions(path) -> list[dict]:
    with LogReader(path) as r:
        return [a for _, a in r.records("action")]


def test_empty_first_graph_reaches_a_room_with_the_fallback(house, tmp_path,
                                                            monkeypatch) -> None:
    idx, ep = _open_start(house)
    _empty_near_start(monkeypatch, (ep.start.x, ep.start.y))
    # without the fallback: nothing to act on, greedy gives up at step 1
    with monkeypatch.context() as m:
        m.setattr(cl.Fallback, "explore", lambda self, why, known=(): FallbackRun(0))
        m.setattr(cl.Fallback, "can_explore", lambda self: False)
        before = run_episode(house, ep, make_planner("greedy"), tmp_path / "before.mcap",
                             OPTS, episode_index=idx)
    assert (before.end, before.steps) == ("gave_up", 1)
    # with it: the robot drives to a grid frontier on its own, then greedy acts on rooms
    p = Scripted([lambda g: Action("explore", g.rooms[0].id if g.rooms else None)])
    out = tmp_path / "after.mcap"
    rep = run_episode(house, ep, p, out, dataclasses.replace(OPTS, max_steps=1),
                      episode_index=idx)
    first = p.graphs[0]
    assert first.rooms and actionable(first), "the planner's first graph offers a room"
    acts = _actions(out)
    assert acts[0]["skill"] == "look_around"
    fallback = [a for a in acts if is_fallback(a.get("reason"))]
    assert fallback and acts[1:1 + len(fallback)] == fallback  # before the first decision
    for a in fallback:
        assert a["skill"] == "explore" and a["target"].startswith("frontier:")
        assert a["reason"].startswith("fallback: no actionable node")
        assert a["graph_time_ns"] is None and a["planner"] is None
    assert fallback[0]["outcome"] == "success" and fallback[0]["travelled_m"] > 0.3
    assert rep.travelled_m >= sum(a["travelled_m"] for a in fallback)
    assert rep.steps == 1 and acts[len(fallback) + 1]["target"] == first.rooms[0].id
    # greedy through the same start: more than the one step of giving up
    again = run_episode(house, ep, make_planner("greedy"), tmp_path / "greedy.mcap", OPTS,
                        episode_index=idx)
    assert again.steps > 1 and again.end != "gave_up" or again.success


def test_giving_up_with_frontiers_left_hands_over(house, tmp_path) -> None:
    idx, ep = _open_start(house)
    p = Scripted([Action("done")] + [lambda g: Action("done")] * 40)
    out = tmp_path / "gave_up.mcap"
    rep = run_episode(house, ep, p, out, OPTS, episode_index=idx)
    acts = _actions(out)
    assert (acts[1]["skill"], acts[1]["outcome"]) == ("done", "success")
    assert "gave up while the robot's map has reachable frontiers" in acts[1]["reason"]
    assert p.feedbacks[0].message == acts[1]["reason"]
    handed = [a for a in acts[2:] if is_fallback(a.get("reason"))]
    assert handed and handed[0]["reason"].startswith("fallback: the planner gave up")
    assert handed[0]["travelled_m"] > 0 and handed[0]["graph_time_ns"] is None
    # the hand-over stopped when the graph offered something new to the planner
    assert len(p.graphs) > 1 and new_candidates(p.graphs[1], actionable(p.graphs[0]))
    assert rep.steps == len(p.graphs)  # every give-up was a step; the fallback's are not
    # the episode ends: found, out of frames, or a give-up with no frontier left
    assert rep.end in ("found", "frames", "gave_up")
    if rep.end == "gave_up":
        assert acts[-1]["reason"] == cl.DONE_MESSAGE
    # replay rebuilds the live scene graphs byte for byte
    derived = tmp_path / "replayed.mcap"
    r = CliRunner().invoke(cli, ["replay", str(out), "-o", str(derived)])
    assert r.exit_code == 0, r.output
    with LogReader(out) as a, LogReader(derived) as b:
        live = [bytes(m.data) for _, _, m in a.raw_messages([GRAPH])]
        assert live and live == [bytes(m.data) for _, _, m in b.raw_messages([GRAPH])]
    # deterministic: the same run again logs the same actions
    again = tmp_path / "again.mcap"
    run_episode(house, ep, Scripted([Action("done")] + [lambda g: Action("done")] * 40),
                again, OPTS, episode_index=idx)
    strip = [{k: v for k, v in a.items() if k != "decision_time_s"} for a in acts]
    assert strip == [{k: v for k, v in a.items() if k != "decision_time_s"}
                     for a in _actions(again)]


def test_fallback_uses_the_robot_side_only(house, tmp_path, monkeypatch) -> None:
    """The hand-over runs with the simulator's ground truth made to raise."""
    from sgtool.recorders.sim.simulation import Simulation

    idx, ep = _open_start(house)

    def refuse(*a, **k):
        raise AssertionError("the robot side read the ground truth")

    for name in ("occupancy", "navigate", "explore", "closed_doors_on_way", "room_of_base"):
        monkeypatch.setattr(Simulation, name, refuse)
    p = Scripted([Action("done"), lambda g: Action("done")])
    rep = run_episode(house, ep, p, tmp_path / "guarded.mcap",
                      dataclasses.replace(OPTS, max_steps=2), episode_index=idx)
    assert rep.steps >= 1
    assert any(is_fallback(a.get("reason")) for a in _actions(tmp_path / "guarded.mcap"))


def test_fallback_options_bound_a_hand_over() -> None:
    assert FallbackOptions().max_goals >= 1 and FallbackOptions().forget > 0
    assert is_fallback("fallback: no actionable node") and not is_fallback("stopped: x")
    assert not is_fallback(None)
