"""The robot's own exploration when the graph offers the planner nothing (issue 17), on the
small 4-room house of test_closed_loop at 96x72.

Checked: a start whose graphs offer nothing while the robot stands at its start pose (the
condition of a cluttered start room: no room, region or frontier node, reproduced by
emptying the scene graphs built near the start) ends at step 1 without the fallback and
reaches a room with it, the fallback's actions logged as ``explore`` of grid frontiers
with reason "fallback: no actionable node", decided on no graph, their frames and metres
counted; a planner that gives up with goals on offer ends the episode; one that gives up
after every goal on offer failed (made so) hands over to the fallback, which stops as
soon as the graph offers a node it did not offer before, and that episode's log replays
into the same scene graphs byte for byte; the fallback is deterministic and uses the
robot's side only (the true map made to raise); with no grid frontier it goes to open
edges of the robot's map.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from click.testing import CliRunner
from support.pinned_houses import pinned_house
from support.scripted_planner import Scripted
from support.seed0_episodes import seed0_episode

from sgtool.cli import cli
from sgtool.datasets.episodes import list_episodes
from sgtool.log import LogReader
from sgtool.mapping.grid import FREE, OCCUPIED, UNKNOWN, OccupancyGrid
from sgtool.mapping.live_paths import traversable
from sgtool.mapping.occupancy import geodesic_distances
from sgtool.planning.base import Action
from sgtool.planning.candidates import actionable
from sgtool.planning.registry import make_planner
from sgtool.recorders.sim import CameraConfig
from sgtool.recorders.sim import closed_loop as cl
from sgtool.recorders.sim.closed_loop import ClosedLoopOptions, run_episode
from sgtool.recorders.sim.fallback_explore import (
    GAVE_UP,
    MARKED,
    FallbackOptions,
    FallbackRun,
    is_fallback,
    new_candidates,
    next_edge,
    open_edges,
)
from sgtool.scenegraph.builder import SceneGraphBuilder
from sgtool.scenegraph.frontiers import find_frontiers

OPTS = ClosedLoopOptions(camera=CameraConfig(width=96, height=72), frames=900)
GRAPH = "/sgtool/scene_graph"


@pytest.fixture(scope="module")
def house():
    return pinned_house("generated-6-rooms-4")  # its closed door (support.pinned_houses)


def _open_start(house) -> tuple[int, object]:
    """An episode whose start room has a way out (episode 0's door is closed)."""
    for k in range(len(list_episodes(house, seed=0))):
        idx, ep = seed0_episode(house, k)
        if ep.start.room != seed0_episode(house, 0)[1].start.room:
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
        m.setattr(cl.Fallback, "explore", lambda self, why, known=(), **kw: FallbackRun(0))
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
    decided = next(i for i, a in enumerate(acts) if a["planner"] is not None)
    fallback = [a for a in acts[:decided] if is_fallback(a.get("reason"))]
    assert fallback and acts[1:decided] == fallback  # before the first decision
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


def test_giving_up_with_goals_on_offer_ends_the_episode(house, tmp_path) -> None:
    """done() while the graph offers goals that never failed is the planner's choice: the
    episode ends (no exploration on the planner's behalf)."""
    idx, ep = _open_start(house)
    p = Scripted([lambda g: Action("done")] * 40)
    out = tmp_path / "gave_up.mcap"
    rep = run_episode(house, ep, p, out, OPTS, episode_index=idx)
    assert actionable(p.graphs[0])
    assert (rep.success, rep.end, rep.steps) == (False, "gave_up", 1)
    acts = _actions(out)
    assert acts[-1]["message"] == cl.DONE_MESSAGE  # the executor's, beside the planner's reason
    assert not any(is_fallback(a.get("reason")) for a in acts)
    assert cl.give_up_handed_over(["room:1"], {"room:1", "door:2"})
    assert not cl.give_up_handed_over(["room:1", "door:2"], {"room:1"})


def test_giving_up_after_every_goal_failed_hands_over(house, tmp_path,
                                                      monkeypatch) -> None:
    """Every goal on offer failed before (made so here): the give-up is handed over."""
    monkeypatch.setattr(cl, "give_up_handed_over", lambda offered, failed: True)
    idx, ep = _open_start(house)
    p = Scripted([Action("done")] + [lambda g: Action("done")] * 40)
    out = tmp_path / "gave_up.mcap"
    rep = run_episode(house, ep, p, out, OPTS, episode_index=idx)
    acts = _actions(out)
    assert (acts[1]["skill"], acts[1]["outcome"]) == ("done", "success")
    assert "gave up while the robot's map has reachable frontiers" in acts[1]["message"]
    assert p.feedbacks[0].message == acts[1]["message"]
    handed = [a for a in acts[2:] if is_fallback(a.get("reason"))]
    assert handed and handed[0]["reason"].startswith("fallback: the planner gave up")
    assert handed[0]["travelled_m"] > 0 and handed[0]["graph_time_ns"] is None
    # the hand-over stopped when the graph offered something new to the planner
    assert len(p.graphs) > 1 and new_candidates(p.graphs[1], actionable(p.graphs[0]))
    assert rep.steps == len(p.graphs)  # every give-up was a step; the fallback's are not
    # the episode ends: found, out of frames, or a give-up with no frontier left
    assert rep.end in ("found", "frames", "gave_up")
    if rep.end == "gave_up":
        assert acts[-1]["message"] == cl.DONE_MESSAGE
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

    monkeypatch.setattr(cl, "give_up_handed_over", lambda offered, failed: True)

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


def _nearest_frontier(g) -> Action:
    fs = [c for c in actionable(g) if c.kind == "frontier"]
    if not fs:
        return Action("done")
    return Action("explore", min(fs, key=lambda c: (c.distance, c.node_id)).node_id)


def test_an_explore_that_shows_nothing_new_goes_on(house, tmp_path) -> None:
    """After a planner's explore whose graph offers no object, door or room it was not
    offered before, the planner chooses again among the frontiers only (it is shown
    nothing else) and the robot explores there, at most ``explore_on`` times, each an
    action with reason WENT_ON that is no step; it stops at the first graph that offers
    something new. With ``explore_on`` 0 there is none."""
    idx, ep = _open_start(house)
    runs = {}
    for on in (0, 3):
        p = Scripted([_nearest_frontier] * 30)
        out = tmp_path / f"on{on}.mcap"
        rep = run_episode(house, ep, p, out, dataclasses.replace(OPTS, max_steps=5,
                                                                 explore_on=on),
                          episode_index=idx)
        runs[on] = (p, _actions(out), rep)
    p0, acts0, rep0 = runs[0]
    assert not any(a["reason"].startswith(cl.WENT_ON) for a in acts0)
    assert len(p0.graphs) == rep0.steps
    p2, acts2, rep2 = runs[3]
    decided = [a for a in acts2 if a["graph_time_ns"] is not None]
    assert len(decided) == len(p2.graphs)  # every decision is logged, went-on ones too
    on = [k for k, a in enumerate(decided) if a["reason"].startswith(cl.WENT_ON)]
    assert on, "some explore of the nearest frontier showed nothing new"
    assert rep2.steps == len(p2.graphs) - len(on)  # going on is no step
    for k in on:
        # only frontiers were on offer, and the explore before it showed nothing new
        assert {c.kind for c in actionable(p2.graphs[k])} == {"frontier"}
        assert decided[k]["skill"] == "explore"
        prev = k - 1
        while prev in on:
            prev -= 1
        assert k - prev <= 3  # at most explore_on in a row
        assert decided[prev]["skill"] == "explore" and decided[prev]["outcome"] == "success"
        base = [c for c in actionable(p2.graphs[prev]) if c.kind != "frontier"]
        assert not new_candidates(p2.graphs[k], base, frontiers=False)
    # a run of went-on legs shorter than explore_on ended because something new was on
    # offer (or no frontier was left, or the target came into view)
    checked = 0
    for k in on:
        run = 1 + (k - 1 in on) + (k - 1 in on and k - 2 in on)
        if k + 1 in on or k + 1 >= len(decided) or run >= 3 or \
                decided[k]["outcome"] != "success":
            continue
        start = k - run
        base = [c for c in actionable(p2.graphs[start]) if c.kind != "frontier"]
        assert new_candidates(p2.graphs[k + 1], base, frontiers=False) or \
            not any(c.kind == "frontier" for c in actionable(p2.graphs[k + 1]))
        checked += 1
    assert checked >= 1


def test_bump_marks_that_wall_off_every_goal_are_forgotten(house, tmp_path,
                                                           monkeypatch) -> None:
    """Bump marks can wall off every goal while leaving the robot more floor than the
    sealed rule guards (a room whose open door frame it brushed): then the closed loop
    drops them, the planner is offered the graph's goals again and the closing Episode
    record counts it; without that the episode ends there."""
    import numpy as np

    from sgtool.log.records import Episode as LoggedEpisode
    from sgtool.mapping.occupancy import OccupancyMap
    from sgtool.recorders.sim.live_skills import LiveNavConfig, LiveSkills

    idx, ep = _open_start(house)
    real_map = LiveSkills.live_map

    def walled(self, refresh):
        occ = real_map(self, refresh)
        if occ is None or not self.bumps:
            return occ
        # with a bump mark, only a disc of 0.3 m around the robot is floor (the sealed
        # rule off): what the marks across a door frame do to a small room
        h, w = occ.shape
        x = occ.origin[0] + (np.arange(w) + 0.5) * occ.resolution
        y = occ.origin[1] + (np.arange(h) + 0.5) * occ.resolution
        X, Y = np.meshgrid(x, y)
        bx, by = self.body.base[:2]
        far = np.hypot(X - bx, Y - by) > 0.3
        return OccupancyMap(occ.grid, occ.blocked | far, occ.robot_radius)

    monkeypatch.setattr(LiveSkills, "live_map", walled)
    real_observe = cl._Search.observe

    def observe(self):
        if self.steps == 1 and self.skills is not None and not self.skills.bumps:
            self.skills.bumps.append((-50.0, -50.0))  # a contact (its place is moot here)
            self.skills._planned = None
        return real_observe(self)

    monkeypatch.setattr(cl._Search, "observe", observe)
    ends = {}
    for forget in (False, True):
        with monkeypatch.context() as m:
            if not forget:
                m.setattr(LiveSkills, "forget_bumps", lambda self: 0)
            p = Scripted([_nearest_frontier, lambda g: Action("done")])
            out = tmp_path / f"forget{forget}.mcap"
            opts = dataclasses.replace(OPTS, max_steps=2, explore_on=0,
                                       live=LiveNavConfig(sealed_m2=0.0))
            rep = run_episode(house, ep, p, out, opts, episode_index=idx)
            with LogReader(out) as r:
                closing = [e for _, e in r.records(LoggedEpisode) if e.status != "started"]
            ends[forget] = (rep, p, closing[0].extras)
    rep, p, extra = ends[False]  # walled off: nothing on offer, the planner gives up
    assert rep.end == "gave_up" and not actionable(p.graphs[1])
    assert "bumps_forgotten" not in extra
    rep, p, extra = ends[True]  # the marks dropped: the goals are on offer again
    assert actionable(p.graphs[1])  # (its done() on them then ends the episode)
    assert extra["bumps_forgotten"] == 1


def _pocket_grid() -> OccupancyGrid:
    """A walled 2 x 3 m room at 5 cm, its floor seen but for an unknown pocket of 0.3 m^2
    (12 x 10 cells) in the middle: under the scene graph's ``min_pocket`` (0.5 m^2), so
    the frontier rule finds nothing there."""
    g = np.full((60, 40), FREE, dtype=np.int8)
    g[24:36, 15:25] = UNKNOWN
    g[:, 0] = g[:, -1] = g[0, :] = g[-1, :] = OCCUPIED
    return OccupancyGrid(g, (0.0, 0.0), 0.05)


def test_open_edges_where_the_frontier_rule_finds_none() -> None:
    grid = _pocket_grid()
    start = (1.0, 0.5)
    assert find_frontiers(grid, start) == []
    occ = traversable(grid, 0.2, 0.25)
    dist = geodesic_distances(occ, start)
    edges = open_edges(occ, dist, 6)
    assert len(edges) == 1  # the ring of reachable cells round the pocket (and in it)
    rows, cols = edges[0][:, 0], edges[0][:, 1]
    assert np.isfinite(dist[rows, cols]).all()
    assert rows.min() == 23 and rows.max() == 36 and cols.min() == 14 and cols.max() == 25
    pick = next_edge(occ, dist, [], 0.5, 0.3)
    assert pick is not None
    goal, cell = pick
    r, c = (int(v) for v in occ.grid.cell_of(*cell))
    assert goal.label == f"edge:{r}-{c}" and goal.kind == "cells"
    assert dist[r, c] == dist[rows, cols].min() and r == 23  # the side facing the robot
    # a place looked around from (or gone to) within ``forget``: no edge left to go to
    assert next_edge(occ, dist, [cell], 0.5, 0.3) is None
    assert open_edges(occ, dist, len(rows) + 1) == []  # shorter than min_edge: none
    # seen floor all round, no unknown: no edge
    seen = OccupancyGrid(np.where(grid.grid == UNKNOWN, FREE, grid.grid), (0.0, 0.0), 0.05)
    occ2 = traversable(seen, 0.2, 0.25)
    assert open_edges(occ2, geodesic_distances(occ2, start), 1) == []


def test_with_no_grid_frontier_the_hand_over_goes_to_open_edges(house, tmp_path,
                                                                monkeypatch) -> None:
    """The frontier rule made to find nothing (a cluttered room: its unknown pockets are
    under ``min_pocket``): a planner that gives up hands over to the fallback, which goes
    to open edges of the robot's map, logged as ``explore`` of ``edge:`` goals."""
    from sgtool.recorders.sim import fallback_explore as fe

    monkeypatch.setattr(fe, "next_frontier", lambda *a, **k: None)
    monkeypatch.setattr(cl, "give_up_handed_over", lambda offered, failed: True)
    idx, ep = _open_start(house)
    out = tmp_path / "edges.mcap"
    rep = run_episode(house, ep, Scripted([lambda g: Action("done")] * 40), out, OPTS,
                      episode_index=idx)
    acts = _actions(out)
    edges = [a for a in acts if str(a["target"]).startswith("edge:")]
    assert edges and all(is_fallback(a["reason"]) and a["skill"] == "explore"
                         for a in edges)
    assert all(a["graph_time_ns"] is None and a["planner"] is None for a in edges)
    assert edges[0]["travelled_m"] > 0
    assert not any(str(a["target"]).startswith("frontier:") and is_fallback(a["reason"])
                   for a in acts)  # no grid frontier was offered
    assert rep.travelled_m >= sum(a["travelled_m"] for a in edges) - 1e-3  # logged: 4 d.p.


def test_a_cluttered_room_is_explored_not_given_up(tmp_path) -> None:
    """House 5 of the closed-loop bench (8-16 rooms, symsearch; pinned as generated
    before the generator kept container fronts clear), episode 4 at 160x120: the random
    planner opens the door out of the start room into a bedroom whose floor is fringed
    with glimpses of a bed; the episode once ended ``gave_up`` after 4 steps (the graph
    offered nothing and no frontier was reachable). It finds the magazine; any open edge
    it goes to is the fallback's."""
    from sgtool.analysis.bench_houses import bench_episodes

    spec = pinned_house("generated-5-rooms-8-16-symsearch")
    ep = bench_episodes(spec, 6, "symsearch")[4]
    assert ep.query == "magazine"
    out = tmp_path / "magazine.mcap"
    rep = run_episode(spec, ep, make_planner("random"), out,
                      ClosedLoopOptions(camera=CameraConfig(width=160, height=120)),
                      house_id="house-5", episode_index=4)
    assert rep.end == "found" and rep.success
    edges = [a for a in _actions(out) if str(a["target"]).startswith("edge:")]
    assert all(is_fallback(a["reason"]) for a in edges)


@pytest.mark.parametrize("marks_wall", [False, True])
def test_a_give_up_is_the_marks_only_when_they_withheld_goals(house, tmp_path, monkeypatch,
                                                              marks_wall):
    """A give-up while bump marks stand and goals are withheld as unreachable is handed
    over only when the marks withheld them (the map without them reaches them): a mark
    far off, walling nothing, let any give-up with a goal out of reach (unknown space, a
    closed door) go on (a review). Here the map is blocked beyond 1.5 m of the start,
    always, or only while a mark stands."""
    from sgtool.log.records import Episode as LoggedEpisode
    from sgtool.mapping.occupancy import OccupancyMap
    from sgtool.recorders.sim.live_skills import LiveSkills
    from sgtool.recorders.sim.reachability import UNREACHABLE

    idx, ep = _open_start(house)
    real_map, real_init = LiveSkills.live_map, LiveSkills.__init__
    start: list[tuple[float, float]] = []

    def far_blocked(self, refresh):  # noqa: ANN001, ANN202
        occ = real_map(self, refresh)
        if occ is None or (marks_wall and not (self.bumps or self.held)):
            return occ
        h, w = occ.shape
        x = occ.origin[0] + (np.arange(w) + 0.5) * occ.resolution
        y = occ.origin[1] + (np.arange(h) + 0.5) * occ.resolution
        xx, yy = np.meshgrid(x, y)
        far = np.hypot(xx - start[0][0], yy - start[0][1]) > 1.5
        return OccupancyMap(occ.grid, occ.blocked | far, occ.robot_radius)

    def init(self, *a, **k):  # noqa: ANN001, ANN002, ANN003, ANN202
        real_init(self, *a, **k)
        start.append(tuple(self.body.base[:2]))
        self.held.append((-50.0, -50.0))  # a contact far off: it walls nothing off
        self.held_from.append(start[0])

    monkeypatch.setattr(LiveSkills, "live_map", far_blocked)
    monkeypatch.setattr(LiveSkills, "__init__", init)
    out = tmp_path / "x.mcap"
    rep = run_episode(house, ep, Scripted([Action("done")] * 6), out,
                      dataclasses.replace(OPTS, max_steps=3, explore_on=0), episode_index=idx)
    with LogReader(out) as r:
        closing = [e for _, e in r.records(LoggedEpisode) if e.status != "started"][0]
    assert closing.extras["withheld"].get(UNREACHABLE, 0) > 0
    if marks_wall:  # the mark withheld the far goals: dropped, and the episode goes on
        assert rep.steps > 1 and closing.extras["bumps_forgotten"] >= 1
        with LogReader(out) as r:
            reasons = [a["message"] for _, a in r.records("action") if a["skill"] == "done"]
        assert any(w.startswith(MARKED) for w in reasons), reasons
        assert not any(
            w.startswith(GAVE_UP) for w in reasons)
    else:  # it withheld nothing: the give-up is the planner's and ends the episode
        assert rep.end == "gave_up" and rep.steps == 1
        assert "bumps_forgotten" not in closing.extras
