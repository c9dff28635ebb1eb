"""Paths on the robot's own map: where it may drive on a grid it is still building (pure).

The live map is the bird's-eye grid of the voxel map (:mod:`sgtool.mapping.bev`: free,
occupied, unknown). :func:`traversable` turns it into an
:class:`~sgtool.mapping.occupancy.OccupancyMap`, the grid the house planners use, so the
existing geodesics and A* run on it unchanged:

- a known obstacle blocks every cell whose centre is closer than the robot radius to the
  obstacle cell's centre: the obstacle is taken at its cell's centre, as the house
  generator's clearance and the simulator's contact check take it (the contact check lets
  the base come half a cell closer still). Measured to the cell's nearer edge instead
  (:func:`~sgtool.mapping.occupancy.inflate` with the full radius), every observed
  obstacle grew by half a cell on top of the voxels' own rounding, and the robot's map
  closed passages of generated houses that the robot fits through;
- an unknown cell is not traversable, except within ``optimistic`` metres of known free
  floor: the short optimistic margin that lets a path end at (and slightly into) a
  frontier, whose far side the camera sees on the way;
- everything outside the grid is unknown.

Goals on the live map (all pick among cells with a finite geodesic distance ``dist`` from
the robot, ties by the lowest row, then column):

- :func:`nearest_reachable`: of a set of world points (a frontier's cluster), the cell
  nearest along the floor; points whose own cell is blocked fall back to the reachable
  cells within ``snap`` metres of them;
- :func:`point_goal`: the reachable cell nearest (straight line) to a point, within ``snap``;
- :func:`stand_goal`: a place to stand at an object known only by its position: the
  reachable cells nearest to it, of which the one nearest along the floor;
- :func:`front_goal`: a place to stand at a container to open or look into it, within
  reach in front of its opening (the middle of its open fan, :func:`open_fan`, as below);
- :func:`view_goal`: a place to look into a container from: ``distance`` m from it, in
  the middle of the widest fan of directions in which the map is open from the
  container's own blocked cells out to that distance (a piece stands with its back to a
  wall and its sides often against others, so the open fan faces its front).

These take ``within``, a bool grid of the cells a stand (and a fan's ray) may end in: the
closed loop gives the cells of the container's own room (:func:`nearest_along_floor`
labels each cell with the Voronoi node nearest along the floor), since a ray leaves a
piece standing against a wall through the wall as easily as through its front.

:func:`descend` reads a shortest cell path off a distance field (steepest descent from
the goal to the robot), so one Dijkstra run serves both the goal choice and the path.
"""

from __future__ import annotations

import hashlib
import itertools
import math
from collections.abc import Sequence

import numpy as np
from scipy import ndimage
from scipy.sparse.csgraph import dijkstra

from sgtool.mapping.grid import OccupancyGrid
from sgtool.mapping.occupancy import OccupancyMap, free_cell_graph, inflate

_SQRT2 = math.sqrt(2.0)
_STEPS = ((0, 1), (0, -1), (1, 0), (-1, 0), (1, 1), (1, -1), (-1, 1), (-1, -1))


def traversable(grid: OccupancyGrid, robot_radius: float, optimistic: float = 0.25,
                obstacles: np.ndarray | None = None) -> OccupancyMap:
    """The live grid as a map to plan on (module doc): ``blocked`` = cells whose centre is
    closer than ``robot_radius`` to a known obstacle cell's centre, plus unknown cells
    farther than ``optimistic`` m from known free floor. ``obstacles`` (world x, y; e.g.
    where the robot bumped into something) mark their cells as obstacles too."""
    if optimistic < 0:
        raise ValueError("optimistic margin must be >= 0")
    occupied = grid.occupied
    if obstacles is not None and len(obstacles):
        occ_map = OccupancyMap(grid, occupied)
        rows, cols = _cells_of(occ_map, obstacles)
        occupied = occupied.copy()
        occupied[rows, cols] = True
    # inflate measures to the obstacle cell's edge: half a cell less is to its centre
    blocked = inflate(occupied, max(robot_radius - grid.resolution / 2.0, 0.0),
                      grid.resolution)
    unknown = grid.unknown
    if unknown.any():
        free = grid.free
        if free.any():
            to_free = ndimage.distance_transform_edt(~free, sampling=grid.resolution)
            far = to_free > optimistic + 1e-9
        else:
            far = np.ones(grid.shape, bool)
        blocked |= unknown & far
    return OccupancyMap(grid, blocked, robot_radius)


def _grid_cells(occ: OccupancyMap, points: np.ndarray
                ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(rows, cols, on the grid) of every point (world x, y)."""
    pts = np.asarray(points, dtype=np.float64).reshape(-1, 2)
    rows = np.floor((pts[:, 1] - occ.origin[1]) / occ.resolution).astype(np.int64)
    cols = np.floor((pts[:, 0] - occ.origin[0]) / occ.resolution).astype(np.int64)
    ok = (rows >= 0) & (rows < occ.shape[0]) & (cols >= 0) & (cols < occ.shape[1])
    return rows, cols, ok


def _cells_of(occ: OccupancyMap, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    rows, cols, ok = _grid_cells(occ, points)
    return rows[ok], cols[ok]


def _centre(occ: OccupancyMap, r: int, c: int) -> tuple[float, float]:
    return (occ.origin[0] + (c + 0.5) * occ.resolution,
            occ.origin[1] + (r + 0.5) * occ.resolution)


def _argmin(occ: OccupancyMap, score: np.ndarray) -> tuple[float, float] | None:
    flat = score.ravel()
    if flat.size == 0 or not np.isfinite(flat).any():
        return None
    r, c = divmod(int(np.argmin(flat)), occ.shape[1])
    return _centre(occ, r, c)


def nearest_reachable(occ: OccupancyMap, dist: np.ndarray, points: np.ndarray,
                      snap: float = 0.5) -> tuple[float, float] | None:
    """The cell of ``points`` (world x, y) nearest the robot along the floor; when none of
    their own cells is reachable, the reachable cell within ``snap`` m of them nearest
    along the floor. None when nothing qualifies."""
    rows, cols = _cells_of(occ, points)
    if rows.size == 0:
        return None
    mask = np.zeros(occ.shape, bool)
    mask[rows, cols] = True
    hit = _argmin(occ, np.where(mask, dist, np.inf))
    if hit is not None or snap <= 0:
        return hit
    near = ndimage.distance_transform_edt(~mask, sampling=occ.resolution) <= snap + 1e-9
    return _argmin(occ, np.where(near, dist, np.inf))


def point_goal(occ: OccupancyMap, dist: np.ndarray, xy: Sequence[float],
               snap: float) -> tuple[float, float] | None:
    """The reachable cell nearest (straight line) to ``xy`` within ``snap`` m, None when
    there is none."""
    X, Y = _centres(occ)
    d = np.hypot(X - xy[0], Y - xy[1])
    return _argmin(occ, np.where(np.isfinite(dist) & (d <= snap + 1e-9), d, np.inf))


def stand_goal(occ: OccupancyMap, dist: np.ndarray, xy: Sequence[float], reach: float,
               slack: float = 0.3, within: np.ndarray | None = None
               ) -> tuple[float, float] | None:
    """Where to stand to work on a thing at ``xy``: of the reachable cells within ``reach``
    m of it (and ``within``, a bool grid, when given), those at most ``slack`` m farther
    than the nearest one, the one nearest along the floor. None when no such cell is
    within ``reach``."""
    X, Y = _centres(occ)
    d = np.hypot(X - xy[0], Y - xy[1])
    ok = np.isfinite(dist) & (d <= reach + 1e-9)
    return _stand_among(occ, dist, d, ok if within is None else ok & within, slack)


def _stand_among(occ: OccupancyMap, dist: np.ndarray, d: np.ndarray, ok: np.ndarray,
                 slack: float) -> tuple[float, float] | None:
    """Of the cells ``ok``, those at most ``slack`` farther (``d``: m from the thing) than
    the nearest one, the one nearest along the floor (``dist``); None when none is ok."""
    if not ok.any():
        return None
    best = float(d[ok].min())
    return _argmin(occ, np.where(ok & (d <= best + slack + 1e-9), dist, np.inf))


VIEW_DIRECTIONS = 36  # directions tried round a container by view_goal (10 degrees apart)


def view_goal(occ: OccupancyMap, dist: np.ndarray, xy: Sequence[float], distance: float,
              exit_within: float = 0.8, within: np.ndarray | None = None
              ) -> tuple[float, float] | None:
    """Where to look into a container at ``xy`` from (module doc): of
    :data:`VIEW_DIRECTIONS` rays from ``xy``, a ray is *open* when, after leaving the
    blocked cells round ``xy`` within ``exit_within`` m (the container and the robot-radius
    margin about it), every cell it crosses out to ``distance`` m is free and the cell at
    ``distance`` is reachable. The result is the end of the ray bisecting the widest
    circular run of open rays (when that ray is not open itself, the end of the run's
    middle ray; of equally wide runs, the one whose end is nearest along the floor; all
    rays open: the nearest end of any). None when no ray is open. With ``within`` (a bool
    grid) a ray whose end cell is outside it is not open either."""
    fan = open_fan(occ, dist, xy, distance, exit_within, within)
    return None if fan is None else _centre(occ, *fan[1])


def open_fan(occ: OccupancyMap, dist: np.ndarray, xy: Sequence[float], distance: float,
             exit_within: float = 0.8, within: np.ndarray | None = None
             ) -> tuple[float, tuple[int, int]] | None:
    """The bisector (radians) of the widest run of open rays round ``xy`` out to
    ``distance`` and the cell :func:`view_goal` takes on it (its rules, ``within``
    included); None when no ray is open."""
    n = VIEW_DIRECTIONS
    radii = np.arange(0.0, distance + 1e-9, occ.resolution / 2.0)
    if radii.size == 0 or radii[-1] < distance - 1e-9:
        radii = np.append(radii, distance)

    def end_of(angle: float) -> tuple[int, int] | None:
        rows, cols = _cells_of(occ, np.stack([xy[0] + radii * math.cos(angle),
                                              xy[1] + radii * math.sin(angle)], axis=1))
        if rows.size != radii.size:  # leaves the grid
            return None
        blocked = occ.blocked[rows, cols]
        free = np.flatnonzero(~blocked)
        if free.size == 0 or radii[free[0]] > exit_within + 1e-9 \
                or blocked[free[0]:].any() or not math.isfinite(dist[rows[-1], cols[-1]]) \
                or (within is not None and not within[rows[-1], cols[-1]]):
            return None
        return int(rows[-1]), int(cols[-1])

    ends = [end_of(2.0 * math.pi * k / n) for k in range(n)]
    open_ = [e is not None for e in ends]
    if not any(open_):
        return None
    if all(open_):
        runs = [(k, 1) for k in range(n)]
    else:  # from a closed ray round the circle: each group of open rays is a run
        start = open_.index(False)
        around = [(start + i) % n for i in range(n)]
        runs = []
        for is_open, group in itertools.groupby(around, key=lambda i: open_[i]):
            if is_open:
                g = list(group)
                runs.append((g[0], len(g)))
    widest = max(length for _, length in runs)
    best: tuple[float, int, int, float] | None = None
    for first, length in runs:
        if length != widest:
            continue
        angle = 2.0 * math.pi * (first + (length - 1) / 2.0) / n
        end = end_of(angle) or ends[(first + (length - 1) // 2) % n]
        assert end is not None
        key = (float(dist[end]), end[0], end[1], angle)
        if best is None or key[:3] < best[:3]:
            best = key
    assert best is not None
    return math.remainder(best[3], 2.0 * math.pi), (best[1], best[2])


def front_goal(occ: OccupancyMap, dist: np.ndarray, xy: Sequence[float], reach: float,
               slack: float = 0.3, half_angle: float = math.radians(30.0),
               within: np.ndarray | None = None) -> tuple[float, float] | None:
    """Where to stand to open or look into a container at ``xy``, in front of its opening:
    :func:`stand_goal`'s rule (within ``reach``, at most ``slack`` farther than the
    nearest such cell, then nearest along the floor) over the reachable cells whose
    bearing from ``xy`` lies within ``half_angle`` of the bisector of its open fan
    (:func:`open_fan` out to ``reach``: a piece stands with its back to a wall and its
    sides often against others, so the fan faces its front), and within ``within`` (a
    bool grid) when given, for the fan's rays too. None when there is no fan or no such
    cell (then :func:`stand_goal` is the way to stand).

    From 60 degrees off a cabinet's front its side board hides the inside; from in front
    the camera sees in."""
    fan = open_fan(occ, dist, xy, reach, within=within)
    if fan is None:
        return None
    X, Y = _centres(occ)
    dx, dy = X - xy[0], Y - xy[1]
    d = np.hypot(dx, dy)
    off = np.abs(np.remainder(np.arctan2(dy, dx) - fan[0] + math.pi, 2.0 * math.pi) - math.pi)
    ok = np.isfinite(dist) & (d <= reach + 1e-9) & (off <= half_angle + 1e-9)
    return _stand_among(occ, dist, d, ok if within is None else ok & within, slack)


def nearest_along_floor(occ: OccupancyMap, points: np.ndarray) -> np.ndarray:
    """For every cell, the index of the point of ``points`` (world x, y; e.g. the nodes of
    a Voronoi graph) nearest to it along the floor (the free cells of ``occ``, 8-connected
    as the geodesics); -1 for a blocked cell and one no point reaches. Points whose own
    cell is blocked or off the grid take no part; of points sharing a cell, the first.
    Kept on ``occ`` per set of points: read the grid, never change it."""
    pts = np.asarray(points, dtype=np.float64).reshape(-1, 2)
    key = ("nearest_along_floor", hashlib.sha256(pts.tobytes()).hexdigest())
    cached = occ._cache.get(key)
    if cached is not None:
        return cached
    out = np.full(occ.shape, -1, dtype=np.int64)
    occ._cache[key] = out  # filled in below; read it, never change it
    g, index, flat = free_cell_graph(occ)
    rows, cols, on = _grid_cells(occ, pts)
    source_of: dict[int, int] = {}
    for i in np.flatnonzero(on):
        node = int(index[rows[i], cols[i]])
        if node >= 0:
            source_of.setdefault(node, int(i))
    if not source_of or flat.size == 0:
        return out
    sources = sorted(source_of)
    _, _, reached = dijkstra(g, directed=True, indices=sources, min_only=True,
                             return_predecessors=True)
    lookup = np.full(flat.size, -1, dtype=np.int64)
    lookup[sources] = [source_of[n] for n in sources]
    ok = reached >= 0
    labels = np.full(flat.size, -1, dtype=np.int64)
    labels[ok] = lookup[reached[ok]]
    out.ravel()[flat] = labels
    return out


def _centres(occ: OccupancyMap) -> tuple[np.ndarray, np.ndarray]:
    rows, cols = occ.shape
    x = occ.origin[0] + (np.arange(cols) + 0.5) * occ.resolution
    y = occ.origin[1] + (np.arange(rows) + 0.5) * occ.resolution
    return np.meshgrid(x, y)


def descend(occ: OccupancyMap, dist: np.ndarray, goal: Sequence[float]
            ) -> list[tuple[float, float]] | None:
    """A shortest path (cell centres, robot's cell first, goal's last) read off ``dist``,
    the geodesic distances from the robot (:func:`~sgtool.mapping.occupancy.
    geodesic_distances` on ``occ``); None when the goal's cell is unreachable. Each step
    goes to the neighbour whose distance plus the step length equals the cell's own
    (steepest descent; diagonals only past two free cells, as the graph)."""
    r = int(math.floor((goal[1] - occ.origin[1]) / occ.resolution))
    c = int(math.floor((goal[0] - occ.origin[0]) / occ.resolution))
    if not occ.in_bounds(r, c) or not math.isfinite(dist[r, c]):
        return None
    blocked, res = occ.blocked, occ.resolution
    h, w = occ.shape
    path = [(r, c)]
    for _ in range(h * w):
        d = dist[r, c]
        if d <= 1e-12:
            break
        nxt = None
        for dr, dc in _STEPS:
            rr, cc = r + dr, c + dc
            if not (0 <= rr < h and 0 <= cc < w) or blocked[rr, cc]:
                continue
            if dr and dc and (blocked[r + dr, c] or blocked[r, c + dc]):
                continue
            step = res * (_SQRT2 if dr and dc else 1.0)
            if abs(dist[rr, cc] + step - d) <= 1e-7:
                nxt = (rr, cc)
                break
        if nxt is None:  # cannot happen on a distance field of this grid
            return None
        r, c = nxt
        path.append(nxt)
    path.reverse()
    return [_centre(occ, pr, pc) for pr, pc in path]

