"""Occupancy grid of a house spec and shortest paths on it.

The grid is what the symbolic benchmark, the episode lister and the scripted recorder plan
on. ``occupied`` marks cells covered by an obstacle: walls, furniture whose box starts below
``max_obstacle_height``, closed doors (unless ``closed_doors_free``), and everything outside
the house (cells whose centre lies in no room polygon), so paths never leave the house.
``blocked`` is where the robot's centre may not be: a cell is blocked when a disc of
``robot_radius`` centred on the cell centre would touch a wall's or closed door's box (the
exact distance from the centre to the box, so a doorway's free cells do not depend on how
the house is turned against the grid: a door wider than the robot's diameter by a cell's
diagonal is passable at any angle, one no wider than the diameter never), would overlap an
occupied cell of furniture or of the outside (:func:`inflate`), or is occupied. Paths run on the
free (not blocked) cells, 8-connected, unit steps of one cell and sqrt(2) cells on
diagonals; a diagonal step needs both cells it cuts past to be free (no corner cutting).
This is the "dilated occupancy map + A*" geodesic of SCOUT's SymSearch (Fig. 5 f).

Arrays are indexed ``[row, col]`` with row = y and col = x; cell ``[0, 0]`` has its lower
left corner at ``origin``; the centre of cell (r, c) is
``origin + ((c + 0.5) * resolution, (r + 0.5) * resolution)``. Rooms, walls, doors and
furniture are rasterised by :mod:`sgtool.mapping.raster` (cell <-> world coordinates too:
``world_to_cell`` and ``cell_to_world`` are importable from here as well).
"""

from __future__ import annotations

import heapq
import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field

import numpy as np
from scipy import ndimage
from scipy.sparse import csr_matrix
from scipy.sparse.csgraph import dijkstra

from sgtool.house.spec import HouseSpec
from sgtool.mapping.grid import FREE, OCCUPIED, OccupancyGrid
from sgtool.mapping.raster import (
    cell_to_world,
    fill_box_near,
    fill_box_overlap,
    fill_polygon,
    world_to_cell,
)

_SQRT2 = math.sqrt(2.0)
_TOL = 1e-6
# (d_row, d_col) of the 8 neighbours; the first four are the axis steps
_STEPS = ((0, 1), (0, -1), (1, 0), (-1, 0), (1, 1), (1, -1), (-1, 1), (-1, -1))


@dataclass(frozen=True, eq=False)
class OccupancyMap:
    """A house's occupancy grid (:class:`~sgtool.mapping.bev.OccupancyGrid`, FREE or
    OCCUPIED cells: the one grid type of the mapping code) with the robot's footprint:
    ``blocked``, the cells the robot's centre may not be in (``occupied`` grown by
    ``robot_radius``; a house's by the exact distance to its boxes: the module docstring)."""

    grid: OccupancyGrid
    blocked: np.ndarray  # bool, occupied grown by robot_radius (class doc)
    robot_radius: float = 0.2
    closed_doors_free: bool = False
    _cache: dict = field(default_factory=dict, repr=False, compare=False)

    @classmethod
    def of_occupied(cls, occupied: np.ndarray, origin: tuple[float, float], resolution: float,
                    robot_radius: float = 0.2, closed_doors_free: bool = False
                    ) -> OccupancyMap:
        """The map of a boolean ``occupied`` mask (blocked cells by :func:`inflate`)."""
        grid = OccupancyGrid(np.where(occupied, OCCUPIED, FREE).astype(np.int8), origin,
                             resolution)
        return cls(grid, inflate(occupied, robot_radius, resolution), robot_radius,
                   closed_doors_free)

    @property
    def origin(self) -> tuple[float, float]:
        return self.grid.origin

    @property
    def resolution(self) -> float:
        return self.grid.resolution

    @property
    def shape(self) -> tuple[int, int]:
        return self.grid.shape

    @property
    def occupied(self) -> np.ndarray:
        """bool [rows=y, cols=x]: cells covered by an obstacle."""
        mask = self._cache.get("occupied")
        if mask is None:
            mask = self._cache["occupied"] = self.grid.occupied
        return mask

    @property
    def free(self) -> np.ndarray:
        """Cells the robot centre may be in (not blocked)."""
        return ~self.blocked

    def in_bounds(self, row: int, col: int) -> bool:
        return 0 <= row < self.shape[0] and 0 <= col < self.shape[1]


# ----------------------------------------------------------------------------------------
# rasterisation
# ----------------------------------------------------------------------------------------
def house_occupancy(spec: HouseSpec, resolution: float = 0.05, robot_radius: float = 0.2,
                    closed_doors_free: bool = False, max_obstacle_height: float = 1.8,
                    margin: float = 0.5) -> OccupancyMap:
    """Rasterise ``spec`` (see the module docstring for what counts as an obstacle).

    ``closed_doors_free=True`` treats closed doors as passable (the robot can open them),
    which is what a planner that may open doors plans on. ``margin`` metres of (occupied)
    outside are kept around the house.
    """
    if resolution <= 0:
        raise ValueError("resolution must be > 0")
    xmin, ymin, xmax, ymax = spec.bounds()
    # whole cells from a multiple of the resolution (1e-9 absorbs float error in x / res)
    ox = math.floor((xmin - margin) / resolution + 1e-9) * resolution
    oy = math.floor((ymin - margin) / resolution + 1e-9) * resolution
    cols = int(math.ceil((xmax + margin - ox) / resolution - 1e-9))
    rows = int(math.ceil((ymax + margin - oy) / resolution - 1e-9))
    grid = OccupancyGrid(np.zeros((rows, cols), np.int8), (round(ox, 9), round(oy, 9)),
                         resolution)
    inside = np.zeros((rows, cols), bool)
    for room in spec.rooms:
        fill_polygon(grid, inside, room.polygon)
    occupied = ~inside
    # (centre, size, yaw) of the walls and closed doors, which make the doorways
    frames = [(((w.a[0] + w.b[0]) / 2.0, (w.a[1] + w.b[1]) / 2.0), (w.length, w.thickness),
               w.yaw) for w in spec.walls]
    if not closed_doors_free:
        frames += [(d.center, (d.width, d.thickness), d.yaw) for d in spec.doors
                   if d.state == "closed"]
    for center, size, yaw in frames:
        fill_box_overlap(grid, occupied, center, size, yaw)
    pieces = np.zeros_like(occupied)
    for f in spec.furniture:
        if f.bottom < max_obstacle_height:
            fill_box_overlap(grid, pieces, f.center[:2], f.size[:2], f.yaw)
    if robot_radius <= 0:
        blocked = occupied | pieces
    else:
        # walls and door frames by their exact distance, not grown from the cells they
        # overlap (those reach up to a cell's diagonal past a turned wall, and growing
        # them adds half a cell more, so a narrow door's passability depended on the
        # house's turn: docs/experiments/houses-nobody-designed.md); furniture is grown
        blocked = inflate(~inside | pieces, robot_radius, resolution) | occupied
        for center, size, yaw in frames:
            fill_box_near(grid, blocked, center, size, yaw, robot_radius)
    occupied |= pieces
    return OccupancyMap(OccupancyGrid(np.where(occupied, OCCUPIED, FREE).astype(np.int8),
                                      grid.origin, resolution),
                        blocked, robot_radius, closed_doors_free)


def inflate(occupied: np.ndarray, radius: float, resolution: float) -> np.ndarray:
    """Cells whose centre is closer than ``radius`` to an occupied cell's square (distance
    between centres < radius + resolution / 2)."""
    if radius <= 0:
        return occupied.copy()
    if occupied.all():
        return occupied.copy()
    dist = ndimage.distance_transform_edt(~occupied, sampling=resolution)
    return dist < radius + resolution / 2.0 - _TOL


def within_cells(mask: np.ndarray, reach: float) -> np.ndarray:
    """Cells whose centre is at most ``reach`` cells from a ``mask`` cell's centre (a
    reach of whole cells included: 0.3 m / 0.05 m is 5.999...); the distance transform
    runs on the mask's bounding box grown by ``reach`` only."""
    out = np.zeros(mask.shape, dtype=bool)
    if not mask.any():
        return out
    reach += 1e-9
    pad = int(math.ceil(reach))
    rows, cols = np.nonzero(mask)
    r0, c0 = max(int(rows.min()) - pad, 0), max(int(cols.min()) - pad, 0)
    r1 = min(int(rows.max()) + pad + 1, mask.shape[0])
    c1 = min(int(cols.max()) + pad + 1, mask.shape[1])
    out[r0:r1, c0:c1] = ndimage.distance_transform_edt(~mask[r0:r1, c0:c1]) <= reach
    return out


# ----------------------------------------------------------------------------------------
# graph search
# ----------------------------------------------------------------------------------------
def free_cell_graph(occ: OccupancyMap) -> tuple[csr_matrix, np.ndarray, np.ndarray]:
    """The 8-connected moves between free cells that cut no corner, as a CSR adjacency
    (weights in metres; cached on the map): (graph, index grid of each cell's node or -1
    when blocked, flat grid index of each node)."""
    cached = occ._cache.get("graph")
    if cached is not None:
        return cached
    free = ~occ.blocked
    rows, cols = free.shape
    index = np.full(free.shape, -1, np.int64)
    flat = np.flatnonzero(free)
    index.ravel()[flat] = np.arange(flat.size)
    src_all, dst_all, w_all = [], [], []
    for dr, dc in _STEPS:
        # cells (r, c) with neighbour (r + dr, c + dc) inside the grid
        rs = slice(max(0, -dr), rows - max(0, dr))
        cs = slice(max(0, -dc), cols - max(0, dc))
        rd = slice(max(0, dr), rows - max(0, -dr))
        cd = slice(max(0, dc), cols - max(0, -dc))
        ok = free[rs, cs] & free[rd, cd]
        if dr and dc:  # no corner cutting: both axis neighbours must be free
            ok &= free[rd, cs] & free[rs, cd]
        src_all.append(index[rs, cs][ok])
        dst_all.append(index[rd, cd][ok])
        w = occ.resolution * (_SQRT2 if dr and dc else 1.0)
        w_all.append(np.full(int(ok.sum()), w))
    n = flat.size
    g = csr_matrix((np.concatenate(w_all), (np.concatenate(src_all), np.concatenate(dst_all))),
                   shape=(n, n))
    occ._cache["graph"] = (g, index, flat)
    return g, index, flat


def nearest_free_cell(occ: OccupancyMap, x: float, y: float,
                      max_snap: float = 0.5) -> tuple[int, int] | None:
    """The free cell nearest to (x, y) (the point's own cell when free), None when none is
    within ``max_snap`` metres."""
    r, c = world_to_cell(occ, x, y)
    if occ.in_bounds(r, c) and not occ.blocked[r, c]:
        return (r, c)
    free = ~occ.blocked
    if not free.any():
        return None
    k = int(math.ceil(max_snap / occ.resolution)) + 1
    r0, r1 = max(r - k, 0), min(r + k + 1, occ.shape[0])
    c0, c1 = max(c - k, 0), min(c + k + 1, occ.shape[1])
    if r0 >= r1 or c0 >= c1:
        return None
    sub = free[r0:r1, c0:c1]
    rr, cc = np.nonzero(sub)
    if rr.size == 0:
        return None
    X = occ.origin[0] + (cc + c0 + 0.5) * occ.resolution
    Y = occ.origin[1] + (rr + r0 + 0.5) * occ.resolution
    d2 = (X - x) ** 2 + (Y - y) ** 2
    i = int(np.lexsort((cc, rr, d2))[0])  # ties: lowest row, then column
    if d2[i] > (max_snap + occ.resolution) ** 2:
        return None
    return (int(rr[i] + r0), int(cc[i] + c0))


def geodesic_distances(occ: OccupancyMap, start_xy: Sequence[float] | Iterable[Sequence[float]],
                       max_snap: float = 0.5) -> np.ndarray:
    """Shortest 8-connected path length (m) from ``start_xy`` to every cell; ``inf`` for
    blocked or unreachable cells. ``start_xy`` is one (x, y) or several (distance to the
    nearest of them). A start in a blocked cell is moved to the nearest free cell within
    ``max_snap`` m; with none there, everything is ``inf``."""
    starts = _as_points(start_xy)
    g, index, flat = free_cell_graph(occ)
    src = []
    for x, y in starts:
        cell = nearest_free_cell(occ, x, y, max_snap)
        if cell is not None:
            src.append(int(index[cell]))
    out = np.full(occ.shape, np.inf)
    if not src or flat.size == 0:
        return out
    d = dijkstra(g, directed=True, indices=sorted(set(src)), min_only=True)
    out.ravel()[flat] = d
    return out


def astar(occ: OccupancyMap, start_xy: Sequence[float], goal_xy: Sequence[float],
          max_snap: float = 0.5) -> list[tuple[float, float]] | None:
    """A shortest 8-connected path from start to goal as world points (cell centres, first
    the start's cell, last the goal's), or None when the goal cannot be reached.

    A* with the octile-distance heuristic (admissible and consistent for these step costs),
    over the cached free-cell graph; ties broken by insertion order, so it is deterministic.
    """
    cs = nearest_free_cell(occ, start_xy[0], start_xy[1], max_snap)
    cg = nearest_free_cell(occ, goal_xy[0], goal_xy[1], max_snap)
    if cs is None or cg is None:
        return None
    g, index, flat = free_cell_graph(occ)
    s, t = int(index[cs]), int(index[cg])
    cols = occ.shape[1]
    indptr, indices, weights = g.indptr, g.indices, g.data
    gr, gc = cg
    res = occ.resolution

    def heuristic(node: int) -> float:
        r, c = divmod(int(flat[node]), cols)
        dr, dc = abs(r - gr), abs(c - gc)
        return res * (max(dr, dc) + (_SQRT2 - 1.0) * min(dr, dc))

    best = {s: 0.0}
    came: dict[int, int] = {}
    heap = [(heuristic(s), 0, s)]
    counter = 1
    closed: set[int] = set()
    while heap:
        _, _, u = heapq.heappop(heap)
        if u == t:
            break
        if u in closed:
            continue
        closed.add(u)
        gu = best[u]
        for k in range(indptr[u], indptr[u + 1]):
            v = int(indices[k])
            nd = gu + float(weights[k])
            if nd < best.get(v, math.inf) - 1e-12:
                best[v] = nd
                came[v] = u
                heapq.heappush(heap, (nd + heuristic(v), counter, v))
                counter += 1
    if t not in best:
        return None
    path = [t]
    while path[-1] != s:
        path.append(came[path[-1]])
    path.reverse()
    return [cell_to_world(occ, *divmod(int(flat[n]), cols)) for n in path]


_NUMBER = (int, float, np.floating, np.integer)


def _as_points(p: Sequence[float] | Iterable[Sequence[float]]) -> list[tuple[float, float]]:
    """One (x, y) point, or several, as a list of points."""
    seq: list[float | Sequence[float]] = list(p)
    if len(seq) == 2 and isinstance(seq[0], _NUMBER) and isinstance(seq[1], _NUMBER):
        return [(float(seq[0]), float(seq[1]))]
    return [_point(q) for q in seq]


def _point(q: float | Sequence[float]) -> tuple[float, float]:
    if isinstance(q, _NUMBER):
        raise TypeError(f"expected an (x, y) point, got the number {q!r}")
    return float(q[0]), float(q[1])
