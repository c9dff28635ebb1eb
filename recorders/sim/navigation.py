"""Where the robot may drive and how: occupancy in the current door states, goals near
targets, smoothed A* paths and the per-frame poses that follow them (pure functions).

Paths are planned on :func:`sgtool.mapping.occupancy.house_occupancy` (walls, furniture,
closed doors, the outside, grown by the robot radius) with the house's *current* door
states, plus the footprints of open door panels (house doors and container doors stick out
into the room when open). A* runs on that grid (8-connected, no corner cutting); the
cell path is shortened by string pulling (keep a waypoint only where the straight line to
the next one would cross a blocked cell), and the base follows it like a differential
drive: turn on the spot to face the next waypoint, then drive straight, in steps of at
most ``speed / fps`` metres and ``turn_speed / fps`` radians per frame.
"""

from __future__ import annotations

import math
import weakref
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
from scipy import ndimage

from sgtool.arg_checks import number
from sgtool.errors import SgtoolError
from sgtool.house.spec import HouseSpec, Room
from sgtool.mapping.grid import FREE, OCCUPIED, OccupancyGrid
from sgtool.mapping.occupancy import OccupancyMap, house_occupancy, inflate
from sgtool.mapping.raster import cell_centers, fill_box_grown, fill_box_near, polygon_mask
from sgtool.recorders.sim.articulation import Box2

Pose2 = tuple[float, float, float]  # x, y, yaw


MAX_SPEED = 5.0  # m/s: --speed of a mobile base


@dataclass(frozen=True)
class RobotConfig:
    """The kinematic mobile base.

    ``reach``: how far (m, from the base centre to the nearest point of an object's
    footprint) the arm opens and closes things; the house generator guarantees a free
    cell within ``reach - radius`` of every container. ``approach``: the distance range
    (m, base centre to footprint) the robot stops at in front of a target, far enough for
    the tilted camera to see low shelves, near enough to reach.
    """

    radius: float = 0.2
    reach: float = 1.0
    approach: tuple[float, float] = (0.55, 0.9)
    speed: float = 0.5  # m/s
    turn_speed: float = math.radians(90.0)  # rad/s
    open_time: float = 1.0  # s to open or close a door
    resolution: float = 0.05  # occupancy cell (m)

    def __post_init__(self) -> None:
        for name in ("radius", "reach", "speed", "turn_speed", "open_time", "resolution"):
            # kept as a float: speed=1 logs as the CLI's --speed 1 (1.0) does
            object.__setattr__(self, name, number(name, getattr(self, name)))
        if not (isinstance(self.approach, tuple | list) and len(self.approach) == 2):
            raise SgtoolError(f"approach={self.approach!r}: a (min, max) pair of metres")
        object.__setattr__(self, "approach", tuple(number("approach", v)
                                                   for v in self.approach))
        for flag, value in (("--speed", self.speed), ("turn_speed", self.turn_speed),
                            ("open_time", self.open_time)):
            if not value > 0:
                raise SgtoolError(f"{flag} {value:g}: must be > 0")
        if self.speed > MAX_SPEED:
            raise SgtoolError(f"--speed {self.speed:g}: at most {MAX_SPEED:g} m/s (a mobile "
                              "robot's base)")
        if not 0 < self.approach[0] < self.approach[1] <= self.reach:
            raise SgtoolError(f"robot approach range {self.approach}: need 0 < min < max "
                              f"<= reach ({self.reach} m)")


# ----------------------------------------------------------------------------------------
# occupancy
# ----------------------------------------------------------------------------------------
def occupancy_with(spec: HouseSpec, door_states: Mapping[str, str], extra: Sequence[Box2],
                   robot: RobotConfig, doors_passable: bool = False) -> OccupancyMap:
    """The house's occupancy with doors in ``door_states`` (spec id -> open/closed) and the
    ``extra`` footprints (open panels) marked occupied; ``doors_passable`` treats closed
    doors as free (for "would it be reachable if the doors were open")."""
    base = _house_map(spec, door_states, robot, doors_passable)
    if not extra:
        return base
    occ = base.occupied.copy()
    near = np.zeros(base.shape, bool)  # cells blocked by the panels, as the house's boxes
    for x, y, sx, sy, yaw in extra:
        fill_box_grown(base, occ, (x, y), (sx, sy), yaw)
        if base.robot_radius > 0:
            fill_box_near(base, near, (x, y), (sx, sy), yaw, base.robot_radius)
    return with_occupied(base, occ, near)


def with_occupied(base: OccupancyMap, occupied: np.ndarray,
                  near: np.ndarray | None = None) -> OccupancyMap:
    """The map of ``occupied`` (``base.occupied`` plus cells), equal to
    ``OccupancyMap.of_occupied(occupied, ...)`` with ``base``'s origin, resolution, radius
    and door rule when ``base`` is such a map; only the window around the added cells is
    grown by the radius (a cell is blocked when it is blocked in ``base`` or near an added
    cell, and every cell near an added cell lies in that window). ``near``: the cells the
    added shapes block, measured to the shapes themselves (``fill_box_near``, as
    :func:`~sgtool.mapping.occupancy.house_occupancy` blocks its boxes), used instead of
    growing the added cells: those reach past a turned shape and would close a doorway
    beside it that the house map leaves open."""
    res, radius = base.resolution, base.robot_radius
    if near is None and not base.occupied.any():  # (the distance transform needs one)
        return OccupancyMap.of_occupied(occupied, base.origin, res, radius,
                                        base.closed_doors_free)
    added = occupied & ~base.occupied
    blocked = base.blocked | added
    if near is not None:
        blocked |= near
    elif added.any():
        rows, cols = np.nonzero(added)
        k = int(math.ceil((radius + res / 2.0) / res)) + 1
        win = (slice(max(int(rows.min()) - k, 0), int(rows.max()) + k + 1),
               slice(max(int(cols.min()) - k, 0), int(cols.max()) + k + 1))
        # the added cells only: the base's own cells are blocked as ``base`` has them
        blocked[win] |= inflate(added[win], radius, res)
    grid = OccupancyGrid(np.where(occupied, OCCUPIED, FREE).astype(np.int8), base.origin, res)
    return OccupancyMap(grid, blocked, radius, base.closed_doors_free)


# the house maps of the last few specs, by door states and robot (house_occupancy is the
# costly part of occupancy_with, asked again at every opening and every new panel layout)
_SPECS_KEPT = 4
_HOUSE_MAPS: dict[int, tuple[weakref.ref[HouseSpec], dict[tuple[Any, ...], OccupancyMap]]] = {}


def _house_map(spec: HouseSpec, door_states: Mapping[str, str], robot: RobotConfig,
               doors_passable: bool) -> OccupancyMap:
    """:func:`house_occupancy` of ``spec`` with the doors in ``door_states``, kept per
    spec (compared by identity: a spec is frozen) for the next call with the same states."""
    states = tuple(door_states.get(d.id, d.state) for d in spec.doors)
    key = (states, robot.resolution, robot.radius, doors_passable)
    entry = _HOUSE_MAPS.get(id(spec))
    if entry is None or entry[0]() is not spec:
        if len(_HOUSE_MAPS) >= _SPECS_KEPT:
            del _HOUSE_MAPS[next(iter(_HOUSE_MAPS))]
        entry = (weakref.ref(spec), {})
        _HOUSE_MAPS[id(spec)] = entry
    maps = entry[1]
    occ = maps.get(key)
    if occ is None:
        doors = tuple(replace(d, state=s) for d, s in zip(spec.doors, states, strict=True))
        occ = house_occupancy(replace(spec, doors=doors), robot.resolution, robot.radius,
                              closed_doors_free=doors_passable)
        if len(maps) > 64:
            maps.clear()
        maps[key] = occ
    return occ


def box_distance_grid(grid: OccupancyMap, box: Box2) -> np.ndarray:
    """Distance (m) from every cell centre to the oriented box (0 inside)."""
    X, Y = cell_centers(grid)
    x, y, sx, sy, yaw = box
    c, s = math.cos(yaw), math.sin(yaw)
    dx, dy = X - x, Y - y
    lx, ly = c * dx + s * dy, -s * dx + c * dy
    ex = np.maximum(np.abs(lx) - sx / 2, 0.0)
    ey = np.maximum(np.abs(ly) - sy / 2, 0.0)
    return np.hypot(ex, ey)


# ----------------------------------------------------------------------------------------
# goals
# ----------------------------------------------------------------------------------------
def approach_goal(grid: OccupancyMap, dist: np.ndarray, box: Box2, robot: RobotConfig,
                  front: Box2 | None = None, within: np.ndarray | None = None
                  ) -> tuple[float, float] | None:
    """Where to stop to work on the object with footprint ``box``: a reachable free cell
    (finite ``dist``, the geodesic distance from the robot) whose distance to the box is in
    ``robot.approach``; when ``front`` (the box of the piece whose front matters) is given,
    cells in front of it (local +y beyond its face) come first, scored by path length plus
    the sideways offset from the front's centre line so the camera looks in square on.
    Falls back to any reachable cell within reach. Only cells of ``within`` (a bool grid:
    the piece's room) when any of them is within reach. None when nothing qualifies."""
    d = box_distance_grid(grid, box)
    ok = np.isfinite(dist)
    if within is not None and (ok & within & (d <= robot.reach - 1e-6)).any():
        ok &= within
    lo, hi = robot.approach
    cand = ok & (d >= lo) & (d <= hi)
    if not cand.any():
        cand = ok & (d <= robot.reach - 1e-6)
        if not cand.any():
            return None
    score = np.where(cand, dist, np.inf)
    if front is not None:
        X, Y = cell_centers(grid)
        x, y, sx, sy, yaw = front
        c, s = math.cos(yaw), math.sin(yaw)
        lx = c * (X - x) + s * (Y - y)
        ly = -s * (X - x) + c * (Y - y)
        ahead = cand & (ly > sy / 2)
        # square on first (within the middle of the front), then anywhere along it
        for half in (max(sx / 2 - 0.15, 0.1), sx / 2 + 0.1):
            in_front = ahead & (np.abs(lx) <= half)
            if in_front.any():
                score = np.where(in_front, dist + 2.0 * np.abs(lx), np.inf)
                break
    return _argmin_cell(grid, score)


def room_mask(grid: OccupancyMap, room: Room) -> np.ndarray:
    """Cells whose centre lies in the room's polygon (centres on its border: either way)."""
    return polygon_mask(grid, room.polygon, border=False)


def room_viewpoint(grid: OccupancyMap, dist: np.ndarray, room: Room,
                   clearance: float = 0.5) -> tuple[float, float] | None:
    """A reachable free cell in ``room`` to look around from: the one nearest the room's
    centroid among those at least ``clearance`` m from any obstacle (any reachable cell of
    the room when none is that clear). None when the room cannot be reached."""
    inside = room_mask(grid, room) & np.isfinite(dist)
    if not inside.any():
        return None
    clear = ndimage.distance_transform_edt(~grid.occupied) * grid.resolution
    good = inside & (clear >= clearance)
    if good.any():
        inside = good
    X, Y = cell_centers(grid)
    cx, cy = room.centroid
    return _argmin_cell(grid, np.where(inside, np.hypot(X - cx, Y - cy), np.inf))


def _argmin_cell(grid: OccupancyMap, score: np.ndarray) -> tuple[float, float] | None:
    flat = score.ravel()
    if not np.isfinite(flat).any():
        return None
    i = int(np.argmin(flat))  # first minimum: lowest row, then column
    r, c = divmod(i, grid.shape[1])
    return (grid.origin[0] + (c + 0.5) * grid.resolution,
            grid.origin[1] + (r + 0.5) * grid.resolution)


# ----------------------------------------------------------------------------------------
# paths
# ----------------------------------------------------------------------------------------
def lines_are_free(grid: OccupancyMap, a: Sequence[float],
                   ends: Sequence[Sequence[float]]) -> np.ndarray:
    """Per end of ``ends``: whether every sample (every quarter cell, both ends included)
    of the segment from ``a`` to it lies in a free cell of the grid, all segments in one
    pass; a segment leaving the grid is not free."""
    counts = [max(2, int(math.ceil(math.dist(a, b) / (grid.resolution / 4))) + 1)
              for b in ends]
    n = np.asarray(counts, dtype=np.int64)
    starts = np.concatenate(([0], np.cumsum(n)[:-1]))
    seg = np.repeat(np.arange(len(counts)), n)
    idx = np.arange(int(n.sum()), dtype=np.int64) - np.repeat(starts, n)
    # np.linspace(0, 1, n): arange(n) * (1 / (n - 1)), the last sample exactly 1
    t = idx * np.repeat(1.0 / (n - 1), n)
    t[starts + n - 1] = 1.0
    e = np.asarray(ends, dtype=np.float64).reshape(-1, 2)
    x = a[0] + (e[seg, 0] - a[0]) * t
    y = a[1] + (e[seg, 1] - a[1]) * t
    col = np.floor((x - grid.origin[0]) / grid.resolution + 1e-9).astype(int)
    row = np.floor((y - grid.origin[1]) / grid.resolution + 1e-9).astype(int)
    rows, cols = grid.shape
    out = (row < 0) | (col < 0) | (row >= rows) | (col >= cols)
    bad = out.copy()
    ok = ~out
    bad[ok] = grid.blocked[row[ok], col[ok]]
    return ~np.logical_or.reduceat(bad, starts)


SMOOTH_BATCH = 16  # later points tried at once by smooth_path (farthest first)


def smooth_path(grid: OccupancyMap, pts: Sequence[tuple[float, float]]
                ) -> list[tuple[float, float]]:
    """String pulling: from each kept point jump to the farthest later point still in
    straight free sight (checked on the blocked grid)."""
    if len(pts) <= 2:
        return list(pts)
    out = [pts[0]]
    i = 0
    while i < len(pts) - 1:
        j = i + 1
        hi = len(pts) - 1
        while hi > i + 1 and j == i + 1:  # batches of candidates, farthest first
            lo = max(i + 2, hi - SMOOTH_BATCH + 1)
            free = lines_are_free(grid, pts[i], [pts[k] for k in range(hi, lo - 1, -1)])
            if free.any():
                j = hi - int(np.argmax(free))
            hi = lo - 1
        out.append(pts[j])
        i = j
    return out


def wrap_angle(a: float) -> float:
    return math.atan2(math.sin(a), math.cos(a))


def turn_poses(pose: Pose2, yaw: float, turn_step: float) -> list[Pose2]:
    """Poses turning on the spot from ``pose`` to heading ``yaw`` (the shorter way), in
    equal steps of at most ``turn_step``; empty when already there."""
    x, y, a = pose
    d = wrap_angle(yaw - a)
    n = int(math.ceil(abs(d) / turn_step - 1e-9))
    return [(x, y, wrap_angle(a + d * k / n)) for k in range(1, n + 1)]


def drive_poses(pose: Pose2, goal: Sequence[float], step: float) -> list[Pose2]:
    """Poses driving straight from ``pose`` to ``goal`` (keeping the heading), in equal
    steps of at most ``step``; empty when already there."""
    x, y, a = pose
    d = math.dist((x, y), goal)
    n = int(math.ceil(d / step - 1e-9))
    return [(x + (goal[0] - x) * k / n, y + (goal[1] - y) * k / n, a) for k in range(1, n + 1)]


def follow_poses(pose: Pose2, waypoints: Sequence[Sequence[float]], step: float,
                 turn_step: float, final_yaw: float | None = None) -> list[Pose2]:
    """Per-frame poses along ``waypoints``: turn to face each one, drive to it; at the end
    turn to ``final_yaw`` when given. Waypoints closer than 1 mm are skipped."""
    out: list[Pose2] = []
    cur = pose
    for w in waypoints:
        if math.dist(cur[:2], w) < 1e-3:
            continue
        heading = math.atan2(w[1] - cur[1], w[0] - cur[0])
        seg = turn_poses(cur, heading, turn_step)
        seg += drive_poses(seg[-1] if seg else cur, w, step)
        out += seg
        cur = out[-1]
    if final_yaw is not None:
        out += turn_poses(cur, final_yaw, turn_step)
    return out


def travelled(pose: Pose2, poses: Sequence[Pose2]) -> float:
    """Summed straight-line distance of a pose sequence starting at ``pose``."""
    total, prev = 0.0, pose
    for p in poses:
        total += math.dist(prev[:2], p[:2])
        prev = p
    return total
