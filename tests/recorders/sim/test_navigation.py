"""Navigation helpers of the simulator (pure): per-frame poses, string pulling, goals in
front of containers, open panels in the occupancy, hinged panel geometry."""

from __future__ import annotations

import math

import numpy as np
from support.small_house import small_house

from sgtool.mapping.occupancy import OccupancyMap, astar, geodesic_distances, world_to_cell
from sgtool.recorders.sim import articulation as art
from sgtool.recorders.sim import navigation as nav
from sgtool.recorders.sim.navigation import with_occupied


def line_is_free(grid, a, b) -> bool:
    """The sight check one segment at a time (the reference of nav.lines_are_free): every
    quarter-cell sample of a-b, both ends included, in a free cell of the grid."""
    n = max(2, int(math.ceil(math.dist(a, b) / (grid.resolution / 4))) + 1)
    t = np.linspace(0.0, 1.0, n)
    x = a[0] + (b[0] - a[0]) * t
    y = a[1] + (b[1] - a[1]) * t
    col = np.floor((x - grid.origin[0]) / grid.resolution + 1e-9).astype(int)
    row = np.floor((y - grid.origin[1]) / grid.resolution + 1e-9).astype(int)
    rows, cols = grid.shape
    if (row < 0).any() or (col < 0).any() or (row >= rows).any() or (col >= cols).any():
        return False
    return not grid.blocked[row, col].any()


def test_follow_poses_turns_then_drives_in_bounded_steps() -> None:
    poses = nav.follow_poses((0.0, 0.0, 0.0), [(0.0, 1.0), (1.0, 1.0)], step=0.1,
                             turn_step=math.radians(30), final_yaw=math.pi)
    # 90 deg left in 3 turns, 10 drive steps, 90 deg right in 3, 10 steps, 180 deg in 6
    assert len(poses) == 3 + 10 + 3 + 10 + 6
    assert np.allclose(poses[2], (0.0, 0.0, math.pi / 2))
    assert np.allclose(poses[12], (0.0, 1.0, math.pi / 2))
    assert np.allclose(poses[25][:2], (1.0, 1.0))
    assert math.isclose(abs(poses[-1][2]), math.pi)
    assert math.isclose(nav.travelled((0.0, 0.0, 0.0), poses), 2.0)
    assert nav.turn_poses((0, 0, 3.0), -3.0, 0.1)[0][2] > 3.0  # the short way, through pi


def test_smoothed_path_is_free_and_shorter() -> None:
    h = small_house(door="open")
    occ = nav.occupancy_with(h, {"door_0": "open"}, [], nav.RobotConfig())
    path = astar(occ, (1.0, 2.5), (6.0, 0.5))
    assert path is not None
    smooth = nav.smooth_path(occ, path)
    assert smooth[0] == path[0] and smooth[-1] == path[-1]
    assert len(smooth) < len(path) / 5
    for a, b in zip(smooth, smooth[1:], strict=False):
        assert line_is_free(occ, a, b)
    length = sum(math.dist(a, b) for a, b in zip(smooth, smooth[1:], strict=False))
    raw = sum(math.dist(a, b) for a, b in zip(path, path[1:], strict=False))
    assert length <= raw + 1e-9


def test_open_panels_block_the_floor_they_swing_into() -> None:
    h = small_house(door="open")
    robot = nav.RobotConfig()
    d = h.doors[0]
    p = art.door_panel(d, -1, 1)
    fp = p.footprint(1.0)
    without = nav.occupancy_with(h, {"door_0": "open"}, [], robot)
    with_panel = nav.occupancy_with(h, {"door_0": "open"}, [fp], robot)
    r, c = world_to_cell(without, fp[0], fp[1])
    assert not without.occupied[r, c] and with_panel.occupied[r, c]
    closed = nav.occupancy_with(h, {"door_0": "closed"}, [], robot)
    r, c = world_to_cell(closed, 4.0, 1.5)
    assert closed.occupied[r, c] and not without.occupied[r, c]


def test_door_panel_hinges_and_sides() -> None:
    h = small_house()
    d = h.doors[0]  # centre (4, 1.5), along +y (yaw pi/2): left of it is -x
    assert art.side_of_door(d, 3.0, 1.5) == 1 and art.side_of_door(d, 5.0, 1.5) == -1
    for end in (-1, 1):
        for side in (-1, 1):
            p = art.door_panel(d, end, side)
            (x, y, _), yaw = p.pose(0.0)
            assert np.allclose((x, y), d.center)  # closed: fills the opening
            (x, y, _), yaw = p.pose(1.0)
            hinge_y = 1.5 + end * 0.45
            assert math.isclose(y, hinge_y, abs_tol=1e-4)  # yaw is stored to 4 decimals
            assert math.isclose(x, 4.0 - side * 0.45, abs_tol=1e-4)  # swung to that side


def test_container_panels_close_the_front_and_open_outwards() -> None:
    h = small_house()
    cab = h.furniture_by_id()["furn_0"]  # front faces +y, at y = 0.35 + 0.25
    (single,) = art.container_panels(cab)
    (x, y, z), yaw = single.pose(0.0)
    assert math.isclose(x, 1.0, abs_tol=1e-9) and 0.58 < y < 0.6
    (x, y, _), yaw = single.pose(1.0)
    assert math.isclose(x, 1.0 - 0.4, abs_tol=0.02) and y > 0.6 + 0.3
    fridge = h.furniture_by_id()["furn_2"]  # front faces -x
    (p,) = art.container_panels(fridge, hinge=1)
    (x, y, _), _ = p.pose(1.0)
    assert x < 6.15 - 0.3
    wide = art.container_panels(h.furniture_by_id()["furn_1"])  # 1 m wide: double doors
    assert len(wide) == 2 and all(math.isclose(q.width, 0.5) for q in wide)


def test_approach_goal_stands_square_in_front() -> None:
    h = small_house()
    robot = nav.RobotConfig()
    occ = nav.occupancy_with(h, {"door_0": "closed"}, [], robot)
    geo = geodesic_distances(occ, (3.0, 2.5))
    cab = h.furniture_by_id()["furn_0"]
    box = (cab.center[0], cab.center[1], cab.size[0], cab.size[1], cab.yaw)
    x, y = nav.approach_goal(occ, geo, box, robot, front=box)
    lx, ly = cab.to_local(x, y)
    assert ly > cab.size[1] / 2 and abs(lx) <= cab.size[0] / 2 - 0.15 + 1e-9
    d = art.point_box_distance(x, y, box)
    assert robot.approach[0] <= d <= robot.approach[1]


def _string_pull_one_by_one(grid, pts):
    """smooth_path as it was: one line_is_free per later point, farthest first."""
    if len(pts) <= 2:
        return list(pts)
    out, i = [pts[0]], 0
    while i < len(pts) - 1:
        j = next((k for k in range(len(pts) - 1, i + 1, -1)
                  if line_is_free(grid, pts[i], pts[k])), i + 1)
        out.append(pts[j])
        i = j
    return out


def test_batched_sight_checks_equal_one_line_at_a_time() -> None:
    """lines_are_free samples each segment as line_is_free does (the same answers), and
    smooth_path's batches keep the farthest visible point: random grids and point sets,
    cells off the grid and degenerate segments included."""
    from sgtool.mapping.occupancy import OccupancyMap

    rng = np.random.default_rng(0)
    for _ in range(150):
        occ = rng.random((40, 50)) < rng.uniform(0.0, 0.3)
        origin = (float(rng.uniform(-2, 2)), float(rng.uniform(-2, 2)))
        grid = OccupancyMap.of_occupied(occ, origin, 0.05, 0.0, False)
        m = int(rng.integers(2, 60))
        pts = [(float(x), float(y))
               for x, y in zip(rng.uniform(-2.5, 3, m), rng.uniform(-2.5, 2.5, m), strict=True)]
        pts.append(pts[-1])  # a zero-length segment
        free = nav.lines_are_free(grid, pts[0], pts[1:])
        assert list(free) == [line_is_free(grid, pts[0], b) for b in pts[1:]]
        assert nav.smooth_path(grid, pts) == _string_pull_one_by_one(grid, pts)


def test_house_maps_are_kept_per_spec_and_door_states() -> None:
    """occupancy_with keeps the house map of a spec and door states: the same states give
    the same map, other states their own (a closed door blocks, an open one does not), and
    extra footprints never change the kept map."""
    h = small_house(door="closed")
    robot = nav.RobotConfig()
    closed = nav.occupancy_with(h, {"door_0": "closed"}, [], robot)
    opened = nav.occupancy_with(h, {"door_0": "open"}, [], robot)
    assert nav.occupancy_with(h, {"door_0": "closed"}, [], robot) is closed
    assert opened.blocked.sum() < closed.blocked.sum()
    boxed = nav.occupancy_with(h, {"door_0": "open"}, [(1.0, 2.5, 0.4, 0.4, 0.0)], robot)
    assert boxed.blocked.sum() > opened.blocked.sum()
    again = nav.occupancy_with(h, {"door_0": "open"}, [], robot)
    assert again is opened and np.array_equal(again.blocked, opened.blocked)
    other = small_house(door="closed")  # an equal spec, another object: its own entry
    assert np.array_equal(nav.occupancy_with(other, {"door_0": "closed"}, [], robot).blocked,
                          closed.blocked)


def test_with_occupied_equals_the_map_grown_from_scratch() -> None:
    """Adding occupied cells to a map grows only the window around them by the radius; the
    blocked and occupied cells equal those of the map built from scratch (random grids,
    radii and added blocks, a base without an occupied cell included)."""
    rng = np.random.default_rng(0)
    for trial in range(200):
        shape = (int(rng.integers(5, 60)), int(rng.integers(5, 60)))
        occ0 = rng.random(shape) < rng.uniform(0.0, 0.3)
        radius = float(rng.choice([0.0, 0.05, 0.12, 0.2, 0.33]))
        base = OccupancyMap.of_occupied(occ0, (0.3, -1.2), 0.05, radius, bool(trial % 2))
        occ = occ0.copy()
        for _ in range(int(rng.integers(0, 4))):
            r, c = int(rng.integers(0, shape[0])), int(rng.integers(0, shape[1]))
            occ[r:r + int(rng.integers(1, 6)), c:c + int(rng.integers(1, 6))] = True
        got = with_occupied(base, occ)
        want = OccupancyMap.of_occupied(occ, base.origin, 0.05, radius, base.closed_doors_free)
        assert np.array_equal(got.blocked, want.blocked), trial
        assert np.array_equal(got.occupied, want.occupied), trial
        assert (got.origin, got.robot_radius, got.closed_doors_free) == \
            (want.origin, want.robot_radius, want.closed_doors_free)
