"""Motion that sees while it moves (recorders/sim/motion.py): turning while driving along
a path, the look-around turn toward unknown space only, and the head's tilt into an
opened container."""

from __future__ import annotations

import math

import numpy as np
import pytest

from sgtool.mapping.grid import FREE, OCCUPIED, UNKNOWN, OccupancyGrid
from sgtool.recorders.sim.motion import drive_while_turning, head_tilts, peek_tilt, sweep
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


def test_the_look_around_ignores_unknown_space_behind_what_it_cannot_see_over() -> None:
    hfov = math.radians(90.0)
    g = np.full((81, 81), FREE, dtype=np.int8)
    g[:, :30] = UNKNOWN  # the room behind a wall 1 m behind the robot (x < -1 m)
    g[:, 30] = OCCUPIED
    grid = OccupancyGrid(g, (-4.05, -4.05), 0.1)
    wall = g == OCCUPIED
    # without blockers the unknown room asks for a turn; a wall the camera cannot see
    # over hides it, so there is nothing to turn for
    assert sweep(grid, (0.0, 0.0, 0.0), hfov) != 0.0
    assert sweep(grid, (0.0, 0.0, 0.0), hfov, blockers=wall) == 0.0
    # the same obstacle low enough to see over (no blocker) hides nothing
    assert sweep(grid, (0.0, 0.0, 0.0), hfov, blockers=np.zeros_like(wall)) == \
        sweep(grid, (0.0, 0.0, 0.0), hfov)
    # a doorway in the wall (|y| < 0.45 m) shows part of the room: turn toward it,
    # about 180 - 45 degrees either way
    g[36:45, 30] = FREE
    wall = g == OCCUPIED
    a = sweep(OccupancyGrid(g, (-4.05, -4.05), 0.1), (0.0, 0.0, 0.0), hfov, blockers=wall)
    assert math.radians(110) < abs(a) < math.radians(160)


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


def test_peek_tilt_aims_at_half_the_height_of_the_container_node() -> None:
    # a cabinet node at 0.465 m (0.93 m tall) seen from 0.76 m by a camera at 1.2 m:
    # the axis meets (x, y, 0.2325)
    tilt = peek_tilt(1.2, 15.0, (0.0, 0.0), (0.76, 0.0, 0.465))
    assert tilt == pytest.approx(math.degrees(math.atan2(1.2 - 0.2325, 0.76)))
    assert 51.0 < tilt < 52.5
    # far away the configured tilt sees it already; very close the head stops at its limit
    assert peek_tilt(1.2, 15.0, (0.0, 0.0), (3.0, 0.0, 0.4)) is None
    assert peek_tilt(1.2, 15.0, (1.0, 1.0), (1.0, 1.05, 0.3), max_tilt=70.0) == 70.0


def test_head_tilts_step_to_the_goal_and_back() -> None:
    down = head_tilts(15.0, 51.85, 9.0)
    assert len(down) == 5 and down[-1] == 51.85 and 15.0 not in down
    steps = np.diff([15.0, *down])
    assert np.all(steps > 0) and np.all(steps <= 9.0 + 1e-9)
    up = head_tilts(51.85, 15.0, 9.0)
    assert up[-1] == 15.0 and len(up) == 5
    assert head_tilts(15.0, 15.0, 9.0) == []
    with pytest.raises(ValueError):
        head_tilts(15.0, 30.0, 0.0)
