"""Motion that sees while it moves (recorders/sim/motion.py): turning while driving along
a path, and the look-around turn toward unknown space only."""

from __future__ import annotations

import math

import numpy as np

from sgtool.mapping.grid import FREE, UNKNOWN, OccupancyGrid
from sgtool.recorders.sim.motion import drive_while_turning, sweep
from sgtool.recorders.sim.navigation import follow_poses, wrap_angle

STEP, TURN = 0.05, math.radians(9.0)


def _on_polyline(p, pts) -> bool:
    for a, b in zip(pts, pts[1:], strict=False):
        ab = np.subtract(b, a)
        t = np.clip(np.dot(np.subtract(p, a), ab) / np.dot(ab, ab), 0, 1)
        if math.dist(p, np.add(a, t * ab)) < 1e-9:
            return True
    return False


def test_turns_while_driving_round_a_gentle_corner() -> None:
    start = (0.0, 0.0, 0.0)
    way = [(2.0, 0.0), (3.5, 1.0)]  # a 34 degree corner
    poses = drive_while_turning(start, way, STEP, TURN)
    pts = [(0.0, 0.0), *way]
    prev = start
    stops = 0
    for p in poses:
        assert _on_polyline(p[:2], pts)
        assert math.dist(p[:2], prev[:2]) <= STEP + 1e-9
        assert abs(wrap_angle(p[2] - prev[2])) <= TURN + 1e-9
        stops += math.dist(p[:2], prev[:2]) < 1e-12
        prev = p
    assert stops == 0  # never stops to turn
    assert math.dist(poses[-1][:2], way[-1]) < 1e-9
    # the stop-and-turn follower spends frames turning on the spot at the corner
    old = follow_poses(start, way, STEP, TURN)
    assert len(poses) < len(old)
    assert sum(math.dist(a[:2], b[:2]) < 1e-12 for a, b in zip([start, *old], old,
                                                                 strict=False)) > 0


def test_turns_on_the_spot_only_when_the_path_leaves_behind() -> None:
    poses = drive_while_turning((0.0, 0.0, 0.0), [(-1.0, 0.0), (-1.0, -1.0)], STEP, TURN,
                                final_yaw=math.pi / 2)
    assert math.dist(poses[-1][:2], (-1.0, -1.0)) < 1e-9
    assert abs(wrap_angle(poses[-1][2] - math.pi / 2)) < 1e-9
    # about (180 - 50) / 9 frames on the spot at the start, then it drives
    still = 0
    for p in poses:
        if math.dist(p[:2], (0.0, 0.0)) > 1e-12:
            break
        still += 1
    assert 14 <= still <= 16
    assert drive_while_turning((1.0, 1.0, 0.3), [], STEP, TURN) == []


def _grid(unknown_cols: slice | None) -> OccupancyGrid:
    g = np.full((81, 81), FREE, dtype=np.int8)
    if unknown_cols is not None:
        g[:, unknown_cols] = UNKNOWN
    return OccupancyGrid(g, (-4.05, -4.05), 0.1)


def test_the_look_around_turns_toward_unknown_space_only() -> None:
    hfov = math.radians(90.0)
    # everything known within 3 m: no turn
    assert sweep(_grid(None), (0.0, 0.0, 0.0), hfov) == 0.0
    # unknown only behind (x < -1 m), robot facing +x: within 3 m its bearings span
    # about 110..250 degrees, so the turn ends when the far end is 45 degrees inside the
    # view: about 250 - 45 = 205 degrees, less than a full turn
    a = sweep(_grid(slice(0, 30)), (0.0, 0.0, 0.0), hfov)
    assert math.radians(195) < abs(a) < math.radians(215)
    # facing the unknown: nothing to turn for
    assert sweep(_grid(slice(0, 30)), (0.0, 0.0, math.pi), math.radians(170.0)) == 0.0
    # unknown to the left (y > 1 m) is reached by turning left, the shorter way
    g = np.full((81, 81), FREE, dtype=np.int8)
    g[51:, :] = UNKNOWN
    left = sweep(OccupancyGrid(g, (-4.05, -4.05), 0.1), (0.0, 0.0, 0.0), hfov)
    assert 0 < left < math.pi
    # off the map is unknown: a robot at the edge of its map turns toward the outside
    assert sweep(_grid(None), (3.9, 0.0, math.pi), hfov) != 0.0


def test_an_action_ends_when_its_navigation_brings_the_target_into_view() -> None:
    # open = navigate then open: when the drive stops because the target came into view,
    # the open is not attempted (from wherever the robot stopped, out of reach)
    from types import SimpleNamespace

    from sgtool.recorders.sim.execution import execute_live
    from sgtool.recorders.sim.live_skills import IN_VIEW
    from sgtool.recorders.sim.skill_plan import SkillCall

    def never(*a):
        raise AssertionError("opened after the target came into view")

    skills = SimpleNamespace(navigate=lambda goal: ("success", IN_VIEW, 1.5),
                             body=SimpleNamespace(open=never))
    sim = SimpleNamespace(tick_index=0, travelled_m=0.0)
    ex = execute_live(sim, skills, (SkillCall("navigate", (1.0, 2.0)), SkillCall("open", 5)),
                      None)
    assert (ex.outcome, ex.reason, ex.cut) == ("success", IN_VIEW, False)
