"""Paths on the robot's own map (sgtool.mapping.live_paths), on hand-built grids.

The grid: 10 cm cells, two rooms (free) side by side with a wall between them. The wall has
a 1 m gap whose cells are unknown (a corridor the robot has not seen), and the rooms are
also joined by a long known detour along the bottom. A planner on the live map must take
the detour; with the detour walled off the goal is unreachable; an unknown sliver within
the optimistic margin of free floor is usable.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from support.path_lengths import path_length

from sgtool.mapping.grid import FREE, OCCUPIED, UNKNOWN, OccupancyGrid
from sgtool.mapping.live_paths import (
    VIEW_DIRECTIONS,
    descend,
    front_goal,
    nearest_along_floor,
    nearest_reachable,
    point_goal,
    stand_goal,
    traversable,
    view_goal,
)
from sgtool.mapping.occupancy import geodesic_distances

RES = 0.1


def two_rooms(detour: bool = True) -> OccupancyGrid:
    """Rows 0..39 (y 0..4 m), cols 0..49 (x 0..5 m): a wall at cols 24-25 from row 8 up,
    with an unknown 1 m gap at rows 26-35; below row 8 a known free corridor (the detour)
    unless ``detour`` is False (then the wall goes down to the border)."""
    g = np.full((40, 50), FREE, np.int8)
    g[0, :] = g[-1, :] = OCCUPIED
    g[:, 0] = g[:, -1] = OCCUPIED
    g[(1 if not detour else 8):, 24:26] = OCCUPIED
    g[26:36, 22:28] = UNKNOWN  # the unseen corridor through the wall (and its mouths)
    return OccupancyGrid(g, (0.0, 0.0), RES)


A, B = (1.0, 3.0), (4.0, 3.0)  # left and right room, level with the gap


def test_an_unseen_corridor_is_not_used() -> None:
    occ = traversable(two_rooms(), robot_radius=0.2, optimistic=0.2)
    dist = geodesic_distances(occ, A)
    path = descend(occ, dist, B)
    assert path is not None
    assert path[0] == pytest.approx((1.05, 3.05)) and path[-1] == pytest.approx((4.05, 3.05))
    # the straight way through the gap is 3 m; the detour dips below row 8 (y < 0.8 m)
    assert min(y for _, y in path) < 0.8
    assert path_length(path) > 5.0
    assert math.isclose(path_length(path), dist[30, 40], rel_tol=1e-9)
    # no cell of the path is unknown
    r = [int(y / RES) for _, y in path]
    c = [int(x / RES) for x, _ in path]
    assert not (two_rooms().grid[r, c] == UNKNOWN).any()


def test_without_the_detour_the_goal_is_unreachable() -> None:
    occ = traversable(two_rooms(detour=False), robot_radius=0.2, optimistic=0.2)
    dist = geodesic_distances(occ, A)
    assert not math.isfinite(dist[30, 40])
    assert descend(occ, dist, B) is None
    assert point_goal(occ, dist, B, snap=1.0) is None  # nothing reachable within 1 m of B


def test_the_optimistic_margin_at_frontiers() -> None:
    g = two_rooms().grid.copy()
    grid = OccupancyGrid(g, (0.0, 0.0), RES)
    # the gap's mouth cells (cols 22-23) lie 0.1-0.2 m from free floor: usable with a
    # 0.2 m margin, not with none; the wall's own unknown cells (cols 24-25) never are
    wide = traversable(grid, robot_radius=0.0, optimistic=0.2)
    none = traversable(grid, robot_radius=0.0, optimistic=0.0)
    assert not wide.blocked[30, 22] and not wide.blocked[30, 23]
    assert none.blocked[30, 22] and none.blocked[30, 23]
    assert wide.blocked[30, 24] and wide.blocked[30, 25]
    # bumps: a point marks its cell as an obstacle, grown by the radius between cell
    # centres: the cells 0.1 m and 0.14 m away are blocked, the cell 0.2 m away is not
    bumped = traversable(grid, robot_radius=0.2, optimistic=0.2,
                         obstacles=np.array([[1.05, 2.05]]))
    assert bumped.blocked[20, 10] and bumped.blocked[20, 11] and bumped.blocked[21, 11]
    assert not bumped.blocked[20, 12] and not bumped.blocked[22, 10]
    assert not traversable(grid, 0.2, 0.2).blocked[20, 10]


def test_goals_on_the_live_map() -> None:
    occ = traversable(two_rooms(), robot_radius=0.2, optimistic=0.2)
    dist = geodesic_distances(occ, A)
    # a frontier's cluster: the gap's left mouth is reachable, the right mouth only the
    # long way round: the nearest along the floor is on the left
    cells = np.array([[2.25, 3.05], [2.25, 3.15], [2.75, 3.05]])
    goal = nearest_reachable(occ, dist, cells)
    assert goal == pytest.approx((2.25, 3.05))
    # cells inside the wall: the reachable cell within the snap radius nearest the robot
    wall = np.array([[2.45, 2.05]])
    g2 = nearest_reachable(occ, dist, wall, snap=0.5)
    assert g2 is not None and g2[0] < 2.4 and math.dist(g2, wall[0]) <= 0.5 + 1e-9
    assert nearest_reachable(occ, dist, wall, snap=0.0) is None
    # a stand for a thing in the wall: within reach, at most `slack` beyond the nearest
    stand = stand_goal(occ, dist, (2.45, 1.55), reach=1.0, slack=0.1)
    assert stand is not None and stand[0] < 2.45
    d_best = min(math.dist((2.45, 1.55), occ.grid.center_of(r, c))
                 for r, c in zip(*np.nonzero(np.isfinite(dist)), strict=True))
    assert math.dist(stand, (2.45, 1.55)) <= d_best + 0.1 + 1e-9
    assert stand_goal(occ, dist, (2.45, 1.55), reach=0.1) is None


def kitchen_row(neighbours: bool = True) -> OccupancyGrid:
    """A 4 x 4 m room (10 cm cells, walls round it) with a 0.8 x 0.8 m fridge against its
    top wall (x 1.6..2.4, y 3.1..3.9), and with ``neighbours`` a counter on either side of
    it along the wall (x 0.1..1.6 and 2.4..3.9, 0.6 m deep)."""
    g = np.full((40, 40), FREE, np.int8)
    g[0, :] = g[-1, :] = OCCUPIED
    g[:, 0] = g[:, -1] = OCCUPIED
    g[31:39, 16:24] = OCCUPIED  # the fridge
    if neighbours:
        g[33:39, 1:16] = OCCUPIED
        g[33:39, 24:39] = OCCUPIED
    return OccupancyGrid(g, (0.0, 0.0), RES)


@pytest.mark.parametrize("neighbours", [True, False])
def test_a_container_is_looked_into_from_in_front_of_it(neighbours) -> None:
    """With its back to the wall (and counters at its sides, or free floor there), the
    open fan round the fridge faces the room: the view point is straight in front of it at
    the asked distance, even for a robot standing off to its side."""
    occ = traversable(kitchen_row(neighbours), robot_radius=0.25)
    fridge = (2.0, 3.5)
    dist = geodesic_distances(occ, (0.6, 2.2))  # beside the fridge, by the left counter
    v = view_goal(occ, dist, fridge, 1.4)
    assert v is not None
    # in front (within one ray's spacing of straight down the room), not at the robot's
    # side, at the distance asked (to a cell)
    bearing = math.degrees(math.atan2(v[1] - fridge[1], v[0] - fridge[0]))
    assert abs(bearing - -90.0) <= 360.0 / VIEW_DIRECTIONS
    assert abs(math.dist(v, fridge) - 1.4) <= RES


def test_a_free_standing_container_is_looked_into_from_the_nearest_side() -> None:
    """Open all round (a box in the middle of the room): the view point nearest the robot
    along the floor; boxed in (no ray leaves it): None."""
    g = np.full((40, 40), FREE, np.int8)
    g[0, :] = g[-1, :] = OCCUPIED
    g[:, 0] = g[:, -1] = OCCUPIED
    g[18:22, 18:22] = OCCUPIED  # a 0.4 m box at (2, 2)
    occ = traversable(OccupancyGrid(g, (0.0, 0.0), RES), robot_radius=0.25)
    dist = geodesic_distances(occ, (3.5, 2.0))  # east of it
    v = view_goal(occ, dist, (2.0, 2.0), 1.0)
    assert v is not None and v[0] > 2.9 and abs(v[1] - 2.0) <= RES
    g[10:30, 10] = g[10:30, 30] = g[10, 10:31] = g[30, 10:31] = OCCUPIED  # a ring round it
    occ = traversable(OccupancyGrid(g, (0.0, 0.0), RES), robot_radius=0.25)
    dist = geodesic_distances(occ, (3.5, 2.0))
    assert view_goal(occ, dist, (2.0, 2.0), 1.0) is None


def test_a_container_is_opened_from_in_front_of_it() -> None:
    """The fridge of kitchen_row without counters, the robot at its left side: the nearest
    stand within reach is beside it (its side board towards the robot); the front stand
    is within reach and within 30 degrees of straight in front of it, facing the room.
    Boxed in (no open fan): None, and the caller stands as before."""
    occ = traversable(kitchen_row(False), robot_radius=0.25)
    fridge = (2.0, 3.5)
    dist = geodesic_distances(occ, (0.6, 3.5))  # left of the fridge, level with it
    side = stand_goal(occ, dist, fridge, reach=0.95, slack=0.3)
    assert side is not None
    assert abs(math.degrees(math.atan2(side[1] - fridge[1], side[0] - fridge[0]))) > 120
    front = front_goal(occ, dist, fridge, reach=0.95, slack=0.3)
    assert front is not None and math.dist(front, fridge) <= 0.95 + 1e-9
    bearing = math.degrees(math.atan2(front[1] - fridge[1], front[0] - fridge[0]))
    assert abs(bearing - -90.0) <= 30.0 + 1e-9
    g = kitchen_row(False).grid.copy()
    g[26, 11:30] = g[26:39, 11] = g[26:39, 29] = OCCUPIED  # walled in, the robot outside
    boxed = traversable(OccupancyGrid(g, (0.0, 0.0), RES), robot_radius=0.25)
    d2 = geodesic_distances(boxed, (0.6, 3.5))
    assert front_goal(boxed, d2, fridge, reach=0.95) is None


def cabinet_against_a_wall() -> OccupancyGrid:
    """6 x 5 m (10 cm cells): room B below the wall y = 3.0, room A above it, a doorway at
    x 5.0..5.9. In room A a cabinet stands with its back to that wall (x 2.6..3.4, y
    3.1..3.6, centre (3.0, 3.35)) between two counters along it (0.6 m deep, x 0.1..4.6),
    and two chairs (x 2.0 and 4.0, y 4.1..4.3) narrow the floor in front of it."""
    g = np.full((50, 60), FREE, np.int8)
    g[0, :] = g[-1, :] = OCCUPIED
    g[:, 0] = g[:, -1] = OCCUPIED
    g[30, :50] = OCCUPIED  # the wall, its doorway at columns 50..58
    g[31:36, 26:34] = OCCUPIED  # the cabinet
    g[31:37, 1:26] = g[31:37, 34:46] = OCCUPIED  # the counters
    g[41:43, 19:21] = g[41:43, 39:41] = OCCUPIED  # the chairs
    return OccupancyGrid(g, (0.0, 0.0), RES)


def test_a_stand_at_a_container_stays_in_its_room() -> None:
    """Round the cabinet of :func:`cabinet_against_a_wall` the widest open fan runs
    through the wall behind it into room B (the wall and the robot's margin are left
    within exit_within), so the
    front stand and the view fall in room B, where the cabinet cannot be opened or seen
    into. Within room A's cells (labelled by the point nearest along the floor, through
    the doorway for room B) both face its front."""
    occ = traversable(cabinet_against_a_wall(), robot_radius=0.25)
    cabinet = (3.0, 3.35)
    dist = geodesic_distances(occ, (1.0, 4.5))  # in room A
    labels = nearest_along_floor(occ, np.array([[3.0, 4.6], [3.0, 1.5]]))
    r, c = occ.grid.cell_of(5.5, 2.0)
    assert labels[r, c] == 1  # room B's floor below the doorway
    r, c = occ.grid.cell_of(5.5, 4.5)
    assert labels[r, c] == 0
    assert labels[occ.blocked].max() == -1
    room_a = labels != 1
    for within, side in ((None, -1.0), (room_a, 1.0)):
        stand = front_goal(occ, dist, cabinet, reach=0.95, slack=0.3, within=within)
        view = view_goal(occ, dist, cabinet, 1.4, within=within)
        assert stand is not None and view is not None
        assert np.sign(stand[1] - 3.0) == side and np.sign(view[1] - 3.0) == side
    assert stand_goal(occ, dist, cabinet, 0.95, 0.3, room_a)[1] > 3.0  # type: ignore[index]
