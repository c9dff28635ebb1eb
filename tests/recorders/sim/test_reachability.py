"""Reachability on the robot's own map in the graph the planner sees (recorders/sim/
reachability.py).

Checked: the windowed goal cell equals the cell the skill drives to (LiveSkills.select on
the whole grid) for stand, point and frontier goals all over a small map with a wall, a
gap and unknown space; a failed goal is withheld while the same cell would be tried again
and offered once the map moves it; in the closed loop the planner is not offered the room
behind a closed door that its map cannot reach (test_live_navigation's situation), and
the reason is counted into the closing Episode record.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from types import SimpleNamespace

import numpy as np
import pytest
from support.pinned_houses import pinned_house
from support.scripted_planner import Scripted
from support.seed0_episodes import seed0_episode

from sgtool.log import LogReader
from sgtool.mapping.grid import FREE, OCCUPIED, UNKNOWN, OccupancyGrid
from sgtool.mapping.live_paths import traversable
from sgtool.mapping.occupancy import geodesic_distances
from sgtool.planning.base import Action
from sgtool.planning.candidates import actionable
from sgtool.recorders.sim import CameraConfig
from sgtool.recorders.sim.closed_loop import ClosedLoopOptions, run_episode
from sgtool.recorders.sim.live_goals import Goal
from sgtool.recorders.sim.live_skills import HOLD_M, LiveNavConfig, LiveSkills
from sgtool.recorders.sim.navigation import RobotConfig
from sgtool.recorders.sim.reachability import (
    LOOKED,
    UNREACHABLE,
    FailedGoals,
    goal_cell,
    reachable_view,
)


@dataclass
class _Body:  # what LiveSkills reads of the robot for goal choice
    base: tuple[float, float, float]
    config: RobotConfig


def _map():
    g = np.full((40, 60), FREE, dtype=np.int8)
    g[:, 30] = OCCUPIED  # a wall at x = 3.0..3.1 m
    g[18:24, 30] = FREE  # with a 0.6 m gap
    g[:, 50:] = UNKNOWN  # unknown past x = 5 m
    g[5:9, 10:14] = OCCUPIED  # a box
    grid = OccupancyGrid(g, (0.0, 0.0), 0.1)
    occ = traversable(grid, 0.2, 0.25)
    return occ, geodesic_distances(occ, (1.0, 2.0))


def test_goal_cell_is_the_cell_the_skill_drives_to() -> None:
    occ, dist = _map()
    skills = LiveSkills(_Body((1.0, 2.0, 0.0), RobotConfig()), lambda: None)
    rng = np.random.default_rng(3)
    kinds = {"stand": 0, "point": 0, "cells": 0}
    for xy in rng.uniform((-0.5, -0.5), (6.5, 4.5), size=(150, 2)):
        for kind in ("stand", "point"):
            goal = Goal("g", kind, xy[None, :])
            want = skills.select(goal, occ, dist)
            assert goal_cell(skills, goal, occ, dist) == want
            kinds[kind] += want is None
        cells = xy + rng.uniform(-0.4, 0.4, size=(5, 2))
        goal = Goal("f", "cells", cells)
        want = skills.select(goal, occ, dist)
        assert goal_cell(skills, goal, occ, dist) == want
        kinds["cells"] += want is None
    # both outcomes occur for every kind (the box, the unknown and the grid's edge)
    assert all(0 < n < 150 for n in kinds.values()), kinds


def test_a_stand_is_chosen_in_its_objects_room_by_both() -> None:
    """_map's wall parts room L (a Voronoi node at (1.5, 2)) from room R (one at (4, 2)):
    a thing on the wall's line (its stands on either side about as near) is stood at on
    the left, the robot's side, when no room is known; as a thing of room R, on the right,
    through the gap. The windowed goal cell and the skill's cell agree with the rooms as
    without them."""
    occ, dist = _map()
    skills = LiveSkills(_Body((1.0, 2.0, 0.0), RobotConfig()), lambda: None)
    layers = SimpleNamespace(node_rooms=("room:L", "room:R"),
                             voronoi=SimpleNamespace(positions=np.array([[1.5, 2.0],
                                                                         [4.0, 2.0]])))
    thing = np.array([[3.05, 0.8]])
    for room, side in ((None, -1.0), ("room:R", 1.0), ("room:L", -1.0)):
        for kind in ("stand", "front"):
            goal = Goal("obj:1", kind, thing, room)
            cell = skills.select(goal, occ, dist, layers)  # type: ignore[arg-type]
            assert cell is not None and math.copysign(1.0, cell[0] - 3.05) == side, (room, cell)
            if kind == "stand":
                assert goal_cell(skills, goal, occ, dist, layers) == cell  # type: ignore[arg-type]
    rng = np.random.default_rng(5)
    for xy in rng.uniform((-0.5, -0.5), (6.5, 4.5), size=(100, 2)):
        for room in ("room:L", "room:R"):
            goal = Goal("g", "stand", xy[None, :], room)
            assert goal_cell(skills, goal, occ, dist, layers) == \
                skills.select(goal, occ, dist, layers)  # type: ignore[arg-type]


def test_a_failed_goal_waits_until_the_map_moves_it() -> None:
    f = FailedGoals(same=0.5)
    assert not f.blocks("obj:3", (1.0, 1.0))  # never failed
    f.failed("obj:3")
    assert f.blocks("obj:3", (1.0, 1.0))  # the first look records the cell
    assert f.blocks("obj:3", (1.3, 1.2))  # within 0.5 m: the same attempt
    assert not f.blocks("obj:3", (2.0, 1.0))  # the map moved it: tried again
    assert not f.blocks("obj:3", (1.0, 1.0))  # and forgotten until it fails again


def test_a_failed_goal_is_released_once_when_nothing_else_is_left() -> None:
    f = FailedGoals(same=0.5)
    for n in ("door:4", "obj:3"):
        f.failed(n)
        assert f.blocks(n, (1.0, 1.0))
    assert f.release(["obj:3", "door:4", "obj:9"]) == ["door:4", "obj:3"]  # 9 never failed
    assert not f.blocks("door:4", (1.0, 1.0))  # offered again from the same place
    f.failed("door:4")  # and it failed again
    assert f.blocks("door:4", (1.0, 1.0))
    assert f.release(["door:4"]) == []  # released once per episode only
    assert f.blocks("door:4", (1.0, 1.0))


@pytest.fixture(scope="module")
def house():
    return pinned_house("generated-6-rooms-4")  # its closed door (support.pinned_houses)


def test_the_planner_is_not_offered_a_room_its_map_cannot_reach(house, tmp_path) -> None:
    # episode 0 starts in a room whose only door to room:1 is closed (test_live_navigation):
    # the scene graph knows room:1, the robot's map holds no way there
    idx, ep = seed0_episode(house, 0)
    p = Scripted([Action("done")])
    out = tmp_path / "view.mcap"
    run_episode(house, ep, p, out,
                ClosedLoopOptions(camera=CameraConfig(width=160, height=120), max_steps=1),
                episode_index=idx)
    seen = p.graphs[0]
    assert seen.node("room:1") is not None and "room:1" not in seen.distances
    assert "room:1" not in {c.node_id for c in actionable(seen)}
    assert actionable(seen)  # something else is on offer (the fallback did not run)
    with LogReader(out) as r:
        episodes = [e for _, e in r.records("episode")]
    assert episodes[-1]["extra"]["withheld"][UNREACHABLE] >= 1


def test_the_robot_body_holds_no_simulation(house) -> None:
    from sgtool.recorders.sim import Simulation
    from sgtool.recorders.sim.live_skills import PrivilegedAccess, RobotBody

    with Simulation(house, start=0) as sim:
        body = RobotBody(sim)
        with pytest.raises(PrivilegedAccess, match="_sim"):
            body._sim  # noqa: B018 (the old plain attribute)
        with pytest.raises(PrivilegedAccess):
            vars(body)  # no instance dict to look into
        with pytest.raises(PrivilegedAccess):
            body.spy = sim
        assert body.base == sim.base and body.fps == sim.fps
        assert 0 < body.hfov < 3.1


def test_one_dijkstra_run_per_refresh_and_pose() -> None:
    occ, _ = _map()
    body = _Body((1.0, 2.0, 0.0), RobotConfig())
    skills = LiveSkills(body, lambda: None)
    ref = SimpleNamespace(index=4, layers=SimpleNamespace(occupancy=occ.grid))
    first = skills.plan_map(ref)
    assert first is not None and skills.plan_map(ref) is first  # the view, then the skill
    d = first[1]
    assert d[20, 10] == 0.0 and np.isinf(d[6, 11])  # from the robot's cell; the box
    body.base = (2.0, 2.0, 0.0)  # moved: planned afresh
    moved = skills.plan_map(ref)
    assert moved is not first and moved[1][20, 20] == 0.0
    skills.bumps.append((2.5, 2.0))  # a bump changes the map
    assert skills.plan_map(ref) is not moved


def _frontier_refresh(occ, index: int = 1):
    """A refresh of the small map whose graph offers two frontiers: ``region:1`` near
    (4.0, 1.0) and ``region:2`` near (2.0, 3.5)."""
    from sgtool.scenegraph.graph import RegionNode, RobotState, SceneGraph

    graph = SceneGraph(
        robot=RobotState((1.0, 2.0)),
        regions=(RegionNode("region:1", "room:0", (4.0, 1.0), kind="frontier"),
                 RegionNode("region:2", "room:0", (2.0, 3.5), kind="frontier")),
        distances={"region:1": 3.2, "region:2": 1.8})
    layers = SimpleNamespace(occupancy=occ.grid, frontier_ids=[], frontiers=[])
    return SimpleNamespace(index=index, graph=graph, layers=layers)


def test_a_frontier_looked_at_from_its_cell_is_not_offered_again() -> None:
    # the robot went to region:1's cell and looked around there; the frontier stayed in
    # the graph (it cannot be seen from there): before, every planner was offered the same
    # useless explore again (a step each, repeated explores of one frontier in the logs)
    occ, _ = _map()
    body = _Body((1.0, 2.0, 0.0), RobotConfig())
    skills = LiveSkills(body, lambda: None)
    ref = _frontier_refresh(occ)
    view = reachable_view(ref, skills, FailedGoals())
    assert {c.node_id for c in actionable(view.graph)} == {"region:1", "region:2"}
    body.base = (4.0, 1.0, 0.0)
    skills.looked.append((4.0, 1.0))
    view = reachable_view(ref, skills, FailedGoals())
    assert view.withheld == {"region:1": LOOKED}
    assert {c.node_id for c in actionable(view.graph)} == {"region:2"}
    # looking around elsewhere (1 m away) does not withhold it
    skills.looked[:] = [(4.0, 2.0)]
    assert reachable_view(ref, skills, FailedGoals()).withheld == {}


def test_look_around_records_where_it_looked() -> None:
    occ, _ = _map()

    class Turning(_Body):
        hfov = 1.0
        fps = 10.0

        def drive(self, poses):
            self.base = poses[-1]
            return 0.0, False

    body = Turning((1.0, 2.0, 0.0), RobotConfig())
    known = SimpleNamespace(index=1, layers=SimpleNamespace(occupancy=occ.grid))
    skills = LiveSkills(body, lambda: known)
    skills.look_around()  # the refresh never changes: the whole sweep, then recorded
    assert skills.looked == [(1.0, 2.0)]


def test_look_around_keeps_to_the_sight_lines_only_when_asked() -> None:
    occ, _ = _map()

    class Turning(_Body):
        hfov = 1.0
        fps = 10.0
        frames = 0

        def drive(self, poses):
            self.base = poses[-1]
            self.frames += len(poses)
            return 0.0, False

    known = SimpleNamespace(index=1, layers=SimpleNamespace(occupancy=occ.grid))
    asked = []

    def walls(grid):  # the camera sees past nothing: no unknown cell is in sight
        asked.append(grid)
        return np.ones(grid.shape, dtype=bool)

    turns = {}
    for on in (False, True):
        body = Turning((1.0, 2.0, 0.0), RobotConfig())
        skills = LiveSkills(body, lambda: known, LiveNavConfig(sight_lines=on), sight=walls)
        out = skills.look_around()
        turns[on] = (body.frames, out)
    assert turns[False][0] > 0  # off: the whole sweep toward the unknown
    assert turns[True] == (0, ("success", "nothing unknown around", 0.0))
    assert len(asked) == 1  # consulted once, and only with sight_lines on


def test_bump_marks_that_wall_the_robot_in_are_dropped() -> None:
    # contacts all round the robot (at a door frame, a swinging panel): each bump is
    # blocked and grown by the robot's radius, so eight of them ring it in; before, every
    # goal was then unreachable for the rest of the episode (a bayes-search episode ended
    # "gave_up" in a pocket of 83 cells with 9 bumps, 42 goals withheld)
    occ, _ = _map()
    body = _Body((1.0, 2.0, 0.0), RobotConfig())
    skills = LiveSkills(body, lambda: None)
    ref = SimpleNamespace(index=4, layers=SimpleNamespace(occupancy=occ.grid))
    ring = [(1.0 + 0.4 * math.cos(a), 2.0 + 0.4 * math.sin(a))
            for a in np.linspace(0.0, 2.0 * math.pi, 12, endpoint=False)]
    skills.bumps.extend(ring)
    sealed = traversable(occ.grid, 0.2, 0.25, np.array(ring))
    assert np.isfinite(geodesic_distances(sealed, (1.0, 2.0))).sum() * 0.01 < 1.0  # the pocket
    planned = skills.plan_map(ref)
    assert planned is not None
    m, d = planned
    assert 0 < len(skills.bumps) < len(ring)
    assert skills.bumps == ring[len(ring) - len(skills.bumps):]  # the oldest went first
    assert np.isfinite(d[20, 45])  # the far side of the wall's gap is reachable again
    goal = Goal("frontier:1", "point", np.array([[4.5, 2.0]]))
    assert goal_cell(skills, goal, m, d) is not None
    # a bump that does not wall it in stays
    left = list(skills.bumps)
    skills.bumps.append((2.0, 3.0))
    skills.plan_map(SimpleNamespace(index=5, layers=ref.layers))
    assert skills.bumps == [*left, (2.0, 3.0)]


def test_bump_marks_that_wall_off_the_way_past_a_passage_are_dropped() -> None:
    # a mark goes one radius ahead of the move, so scraping a corner of a narrow passage
    # marks the passage itself: grown by the robot's radius it cut the robot off from
    # everything past it for the rest of the episode, though it kept plenty of floor (a
    # voi episode searched 5 rooms of 15 and gave up with the way to the rest marked)
    occ, _ = _map()  # the wall at x = 3 m has a 0.6 m gap at y = 1.8..2.4 m
    ref = SimpleNamespace(index=4, layers=SimpleNamespace(occupancy=occ.grid))
    gap, corner = [(3.05, 1.95), (3.05, 2.25)], (0.5, 3.5)
    for sealed_m2, left in ((2.0, [gap[1], corner]), (0.0, [*gap, corner])):
        skills = LiveSkills(_Body((1.0, 2.0, 0.0), RobotConfig()), lambda: None,
                            LiveNavConfig(sealed_m2=sealed_m2))
        skills.bumps.extend([*gap, corner])
        planned = skills.plan_map(ref)
        assert planned is not None
        m, d = planned
        # the oldest goes, and that opens the passage; the corner's takes < 2 m2 and stays
        assert skills.bumps == left
        assert np.isfinite(d[20, 40]) == (sealed_m2 > 0)  # (4.05, 2.05): past the wall
        assert np.isfinite(d[20, 15])  # the robot's side, either way
        # the map planned on is the one without the dropped mark
        assert np.array_equal(m.blocked, traversable(occ.grid, 0.2, 0.25,
                                                     np.array(left)).blocked)


def test_a_navigate_that_did_not_see_into_its_piece_counts_as_failed() -> None:
    """After a ``navigate`` the closed loop holds the target back from the same place
    when the graph still has it unsearched (its node ``examine``-able, not explored)."""
    from sgtool.recorders.sim.reachability import not_seen_into
    from sgtool.scenegraph.graph import ObjectNode, RobotState, SceneGraph
    from sgtool.scenegraph.stream import Refresh

    def refresh(explored: bool, affordances: tuple[str, ...]) -> Refresh:
        node = ObjectNode("obj:7", "bucket", "region:0", "room:0", (1.0, 1.0, 0.5),
                          affordances=affordances, explored=explored)
        graph = SceneGraph(RobotState((0.0, 0.0)), objects=(node,))
        return Refresh(0, 0, 1, "frames", graph, None)

    assert not_seen_into(refresh(False, ("container", "examine")), "obj:7")
    assert not not_seen_into(refresh(True, ("container", "examine")), "obj:7")
    assert not not_seen_into(refresh(False, ("openable",)), "obj:7")  # nothing to see into
    assert not not_seen_into(refresh(False, ("container", "examine")), "obj:8")
    assert not not_seen_into(None, "obj:7") and not not_seen_into(
        refresh(False, ("examine",)), None)


def test_marks_of_a_way_that_failed_on_contacts_are_held() -> None:
    """A skill that ends on repeated contacts holds its last mark: the way is really
    blocked. Before, the cut-off rule dropped it again at once (it walled off the floor
    past a passage), the next plan was the same path, and a wedged robot spent up to 27
    steps of an episode failing from the same place (a helper's bayes-search episode).
    A held mark stays where a plain one goes; if held marks wall the robot in, they go."""
    occ, _ = _map()  # the wall at x = 3 m has a 0.6 m gap at y = 1.8..2.4 m
    ref = SimpleNamespace(index=4, layers=SimpleNamespace(occupancy=occ.grid))
    gap = [(3.05, 1.95), (3.05, 2.25)]
    for held in (False, True):
        skills = LiveSkills(_Body((1.0, 2.0, 0.0), RobotConfig()), lambda: None,
                            LiveNavConfig(sealed_m2=2.0))
        (skills.held if held else skills.bumps).extend(gap)
        planned = skills.plan_map(ref)
        assert planned is not None
        _, d = planned
        assert np.isfinite(d[20, 40]) != held  # (4.05, 2.05): past the wall
        assert (skills.held, skills.bumps) == ((gap, []) if held else ([], [gap[1]]))
    ring = [(1.0 + 0.4 * math.cos(a), 2.0 + 0.4 * math.sin(a))
            for a in np.linspace(0.0, 2.0 * math.pi, 12, endpoint=False)]
    skills = LiveSkills(_Body((1.0, 2.0, 0.0), RobotConfig()), lambda: None)
    skills.held.extend(ring)  # held marks ringing the robot in: all dropped
    planned = skills.plan_map(ref)
    assert planned is not None and np.isfinite(planned[1][20, 40])
    assert skills.held == [] and skills.bumps == []
    skills.held.append((2.0, 3.0))
    assert skills.forget_bumps() == 1 and skills.held == []
    # held only near where the way failed: 1 m (HOLD_M) away it may be tried again
    body = _Body((1.0, 2.0, 0.0), RobotConfig())
    skills = LiveSkills(body, lambda: None, LiveNavConfig(sealed_m2=2.0))
    skills.held.extend(gap)
    skills.held_from = [(1.0, 2.0)] * len(gap)
    skills.plan_map(ref)
    assert skills.held == gap
    body.base = (1.0 + HOLD_M + 0.1, 2.0, 0.0)
    planned = skills.plan_map(ref)
    assert skills.held == [] and planned is not None and np.isfinite(planned[1][20, 40])


def test_each_held_mark_lasts_near_where_it_was_held() -> None:
    """Two ways failed at two places: each held mark stays while the robot is within
    HOLD_M of where it was held (only the last place counted: a mark 0.45 m from its own
    place went, one 1.6 m from its own stayed; a review)."""
    occ, _ = _map()
    ref = SimpleNamespace(index=4, layers=SimpleNamespace(occupancy=occ.grid))
    body = _Body((1.0, 2.0, 0.0), RobotConfig())
    skills = LiveSkills(body, lambda: None, LiveNavConfig(sealed_m2=2.0))
    a, b = (1.0, 3.0), (2.3, 1.0)
    skills.held, skills.held_from = [a, b], [(1.0, 2.0), (1.8, 2.0)]
    body.base = (0.6, 1.8, 0.0)  # 0.45 m from a's place, 1.25 m from b's
    skills.plan_map(ref)
    assert skills.held == [a] and skills.held_from == [(1.0, 2.0)]
    skills.held, skills.held_from = [a, b], [(1.0, 2.0), (1.9, 2.0)]
    body.base = (2.6, 2.0, 0.0)  # 1.6 m from a's place, 0.7 m from b's
    skills.plan_map(ref)
    assert skills.held == [b] and skills.held_from == [(1.9, 2.0)]
