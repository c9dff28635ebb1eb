"""Bird's-eye occupancy from voxel columns, and the distance fields built on it."""

from __future__ import annotations

import numpy as np
import pytest
from support.bev_reference import occupancy_from_keys
from support.synthetic_world import camera_pose

from sgtool.mapping.bev import (
    BevConfig,
    ColumnGrid,
    classify_keys,
    columns_between,
    estimate_floor_level,
    floor_fans,
    line_of_sight,
)
from sgtool.mapping.esdf import distance_field
from sgtool.mapping.grid import FREE, OCCUPIED, UNKNOWN
from sgtool.mapping.holes import fill_holes_parts
from sgtool.mapping.occupancy import inflate
from sgtool.mapping.voxels import pack

RES = 0.05
CFG = BevConfig(floor_z=0.0, margin=2, snap=1, max_hole=0.0)


def keys_of(cells: list[tuple[int, int, int]]) -> np.ndarray:
    a = np.asarray(cells, dtype=np.int64)
    return np.sort(pack(a[:, 0], a[:, 1], a[:, 2], 0))


def value(occ, ix: int, iy: int) -> int:  # noqa: ANN001
    return occ.value_at((ix + 0.5) * RES, (iy + 0.5) * RES)


def test_column_classes() -> None:
    keys = keys_of([
        (0, 0, 0),  # floor only -> free
        (1, 0, 0), (1, 0, 20),  # floor and a voxel at 1 m -> occupied
        (2, 0, 0), (2, 0, 45),  # floor and a lamp at 2.25 m (above the band) -> free
        (3, 0, 2),  # a 10-15 cm thing counts as floor (tolerance 0.1 m -> 2 levels)
        (4, 0, 3),  # above the tolerance: occupied, even without floor under it
        (5, 0, -3),  # below the floor (noise): floor
    ])
    occ = occupancy_from_keys(keys, RES, CFG)
    assert [value(occ, i, 0) for i in range(6)] == [FREE, OCCUPIED, FREE, FREE, OCCUPIED, FREE]
    assert value(occ, 0, 1) == UNKNOWN and value(occ, 7, 0) == UNKNOWN
    assert occ.grid.dtype == np.int8


def test_floor_level_is_estimated_from_the_histogram() -> None:
    # a floor 0.5 m below z = 0 (level -10) with furniture above it
    cells = [(x, y, -10) for x in range(10) for y in range(10)]
    cells += [(x, 0, z) for x in range(3) for z in range(-9, 10)]
    keys = keys_of(cells)
    iz = np.array([c[2] for c in cells])
    lo = int(iz.min())
    assert estimate_floor_level(lo, np.bincount(iz - lo)) == -10
    occ = occupancy_from_keys(keys, RES, BevConfig(margin=2, snap=1, max_hole=0.0))
    assert value(occ, 5, 5) == FREE and value(occ, 1, 0) == OCCUPIED
    assert occ.floor_z == pytest.approx(-0.45)


def test_trajectory_footprint_is_free_but_never_overrides_obstacles() -> None:
    keys = keys_of([(10, 10, 0), (10, 11, 20)])
    occ = occupancy_from_keys(keys, RES, BevConfig(floor_z=0.0, robot_radius=0.1, margin=5,
                                                   snap=1, max_hole=0.0),
                              trajectory=[(10.5 * RES, 10.5 * RES)])
    assert value(occ, 10, 11) == OCCUPIED
    assert value(occ, 12, 10) == FREE  # 2 cells = 0.1 m from the robot
    assert value(occ, 13, 10) == UNKNOWN


def test_small_enclosed_holes_are_filled() -> None:
    grid = np.full((9, 12), FREE, dtype=np.int8)
    grid[2:4, 2:4] = UNKNOWN  # 4 cells enclosed by free: filled
    grid[5:7, 7:9] = UNKNOWN  # 4 cells touching an obstacle: kept
    grid[7, 9] = OCCUPIED
    grid[0, 5] = UNKNOWN  # on the border: kept
    grid[2:5, 7:10] = UNKNOWN  # 9 cells: too big
    filled, parts = fill_holes_parts(grid, 4)
    assert filled == 4 and parts is not None and parts.filled.sum() == 1
    assert (grid[2:4, 2:4] == FREE).all()
    assert (grid[5:7, 7:9] == UNKNOWN).all() and grid[0, 5] == UNKNOWN
    assert (grid[2:5, 7:10] == UNKNOWN).all()


def test_incremental_column_grid_equals_rebuild() -> None:
    rng = np.random.default_rng(0)
    cells = rng.integers(-40, 40, size=(3000, 3))
    cells[:, 2] = rng.integers(-2, 40, size=3000)
    keys = pack(cells[:, 0], cells[:, 1], cells[:, 2], rng.integers(0, 5, size=3000))
    traj = [(0.3, -0.2), (0.5, 0.1)]
    full = occupancy_from_keys(np.sort(keys), RES, CFG, traj, level=0)
    cg = ColumnGrid(RES, CFG)
    for part in np.array_split(keys, 7):
        cg.add(classify_keys(part, 0, RES, CFG), traj)
    inc = cg.occupancy(traj, 0)
    assert inc.origin == full.origin
    np.testing.assert_array_equal(inc.grid, full.grid)


def test_floor_fans_clear_the_blind_zone() -> None:
    """A camera 1 m up, pitched 0.5 rad down, sees the floor from ~1.3 m on; rays ending
    on the floor clear the cells between the robot and there."""
    from support.synthetic_world import BoxWorld, render

    from sgtool.log.frame import CameraIntrinsics

    k = CameraIntrinsics.from_fov(40, 30, 40)
    pose = camera_pose(0.0, 0.0, 0.0, height=1.0, pitch=0.5)
    depth, _ = render(BoxWorld((), floor_instance=1), pose, k)
    fans = floor_fans(depth, pose, k.fx, k.fy, k.cx, k.cy, every=4)
    assert len(fans) == 10
    near = np.hypot(fans[:, 2], fans[:, 3])
    assert near.min() == pytest.approx(1.0 / np.tan(0.5 + np.radians(20)), rel=0.05)
    assert np.allclose(fans[:, 4], 0.0, atol=1e-6)  # float32 depth
    cg = ColumnGrid(RES, CFG)
    cg.carve(fans, level=0)
    occ = cg.occupancy()
    assert FREE in (occ.value_at(0.6, -0.02), occ.value_at(0.6, 0.02))  # blind zone
    assert occ.value_at(-0.5, 0.0) == UNKNOWN  # behind the camera


def test_line_of_sight_through_a_wall() -> None:
    grid = np.full((20, 20), FREE, dtype=np.int8)
    grid[:, 10] = OCCUPIED
    occ = occupancy_from_keys(keys_of([(0, 0, 0)]), RES, CFG)
    occ = type(occ)(grid, (0.0, 0.0), RES)
    blocked = grid == OCCUPIED
    a = np.array([[0.1, 0.5], [0.1, 0.5], [0.1, 0.5]])
    b = np.array([[0.4, 0.5], [0.9, 0.5], [0.5, 0.5]])
    assert line_of_sight(blocked, occ, a, b).tolist() == [True, False, False]
    # the last 0.2 m are not checked: a target sitting on the obstacle is visible
    assert line_of_sight(blocked, occ, a[:1], np.array([[0.52, 0.5]]), skip_end=0.1)[0]


def test_distance_fields_and_inflation() -> None:
    obstacle = np.zeros((11, 11), dtype=bool)
    obstacle[5, 5] = True
    dist, feat = distance_field(obstacle, 0.1, with_features=True)
    assert dist[5, 8] == pytest.approx(0.3)
    assert dist[0, 5] == pytest.approx(0.1)  # the virtual border around the grid
    assert tuple(feat[:, 5, 7]) == (5, 5)
    # inflation (the robot's footprint): cell centres closer than radius + half a cell to
    # the obstacle's centre: 0.2 + 0.05 m takes (5, 7) at 0.2 m and (6, 7) at 0.224 m,
    # not (5, 8) at 0.3 m nor (7, 7) at 0.283 m
    grown = inflate(obstacle, 0.2, 0.1)
    assert grown[5, 7] and grown[6, 7] and grown[6, 6]
    assert not grown[5, 8] and not grown[7, 7]


def test_columns_between_keep_the_columns_reaching_into_the_band() -> None:
    # floor at level 2 (0.1 m voxels): a wall column up to 2.0 m, a table column up to
    # 0.7 m and a lamp hanging at 1.9-2.0 m over a third column
    wall = [(0, 0, z) for z in range(2, 23)]
    table = [(1, 0, z) for z in range(2, 10)]
    lamp = [(2, 0, 21), (2, 0, 22)]
    keys = np.sort(pack(*np.array(wall + table + lamp).T, 0))
    # what reaches from 1.2 m to 1.6 m above the floor: the wall only
    assert columns_between(keys, 2, 0.1, 1.2, 1.6).tolist() == [[0, 0]]
    # from 0.5 m: the table too; the lamp is above the band in both
    assert columns_between(keys, 2, 0.1, 0.5, 1.6).tolist() == [[0, 0], [1, 0]]
    assert columns_between(keys, 2, 0.1, 1.85, 2.0).tolist() == [[0, 0], [2, 0]]
    assert columns_between(keys[:0], 2, 0.1, 1.2, 1.6).shape == (0, 2)
