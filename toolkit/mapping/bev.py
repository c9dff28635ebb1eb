"""Bird's-eye occupancy (free / occupied / unknown) from the voxel map.

MoMa-LLM (paper sec. III-B) analyses "stixels", the voxel columns of the map: the highest
occupied voxel of a column inside a height band above the floor decides the cell; a column
whose highest voxel is floor is free space, any other occupied column is an obstacle. Since
the floor is the lowest thing in a column, that is: a column with a voxel in the band
``(floor + floor_tolerance, floor + band_top]`` is **occupied**; else a column with a floor
voxel (within ``floor_tolerance`` of the floor, or below it) is **free**; else **unknown**.
Things above ``band_top`` (door lintels, lamps, the ceiling) never block: the robot passes
under them.

Three fixes for what a camera cannot see:

- the cells under the robot's footprint along its trajectory are free (the camera never
  sees the floor it stands on);
- the ground cells under camera rays that end on the floor are free (:func:`floor_fans`,
  :meth:`ColumnGrid.carve`): a camera pitched down never sees the floor right in front
  of the robot, and spinning in place would leave a blind ring around it;
- small unknown holes in free space (floor cells that far, grazing rays skipped, a few
  cells wide) become free when they are enclosed by free cells and smaller than
  ``max_hole``; a hole touching an obstacle or the map border stays unknown.

The floor height is taken from the config or estimated as the lowest voxel level holding
at least half as many voxels as the fullest level (floors are the largest horizontal
surfaces a camera sees; the ceiling, when seen, is higher).

The result is an :class:`~sgtool.mapping.grid.OccupancyGrid` (the one grid type: arrays
``[row, col]`` with row = y and col = x, cell (0, 0) has its lower-left corner at
``origin``; 0 free, 100 occupied, -1 unknown, int8, as ROS and Foxglove grids). The grid is aligned
with the voxel lattice (one cell per voxel column) and its origin snapped to whole
``snap`` cells, so it only grows as the map grows and cells keep their indices between
refreshes while the map extent does not change.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from sgtool.mapping.grid import FREE, OCCUPIED, UNKNOWN, OccupancyGrid
from sgtool.mapping.holes import UnknownParts, fill_holes_parts
from sgtool.mapping.voxels import AXIS_BITS, AXIS_MASK, COLUMN_SHIFT, OFFSET, SHIFT_Z


@dataclass(frozen=True)
class BevConfig:
    floor_z: float | None = None  # m; None = estimate from the voxels
    floor_tolerance: float = 0.1  # m above the floor still counted as floor
    band_top: float = 1.6  # m above the floor; higher voxels never block
    robot_radius: float = 0.25  # m; footprint cleared along the trajectory
    max_hole: float = 0.1  # m^2; enclosed unknown holes up to this size become free
    margin: int = 10  # cells of unknown kept around the observed extent
    snap: int = 20  # grid origin at multiples of this many cells


def estimate_floor_level(lowest: int, hist: np.ndarray) -> int | None:
    """Voxel level of the floor from a height histogram (``hist[i]`` voxels at level
    ``lowest + i``): the lowest level with at least half the voxels of the fullest level
    (None without voxels)."""
    if hist.size == 0 or hist.max() <= 0:
        return None
    return lowest + int(np.flatnonzero(hist >= 0.5 * hist.max())[0])


def floor_level(config: BevConfig, resolution: float, lowest: int, hist: np.ndarray) -> int:
    """The configured floor level, or the estimated one (0 without voxels)."""
    if config.floor_z is not None:
        return int(math.floor(config.floor_z / resolution + 1e-9))
    level = estimate_floor_level(lowest, hist)
    return 0 if level is None else level


@dataclass(frozen=True)
class ColumnClasses:
    """Column indices (ix, iy) of occupied and of floor columns."""

    occupied: np.ndarray  # (n, 2) int64
    floor: np.ndarray  # (m, 2) int64


def _unique_columns(col: np.ndarray, presorted: bool) -> np.ndarray:
    if col.size == 0:
        return np.zeros((0, 2), dtype=np.int64)
    if presorted:
        col = col[np.concatenate([[True], col[1:] != col[:-1]])]
    else:
        col = np.unique(col)
    ix = ((col >> AXIS_BITS) & AXIS_MASK) - OFFSET
    iy = (col & AXIS_MASK) - OFFSET
    return np.stack([ix, iy], axis=1)


def floor_levels(config: BevConfig, resolution: float) -> int:
    """Voxel levels above the floor's own that still count as floor: the floor tolerance
    in voxels, at least one (a floor seen from a tilted camera straddles two levels, so a
    voxel coarser than twice the tolerance would map no floor at all)."""
    return max(1, int(round(config.floor_tolerance / resolution)))


def classify_keys(keys: np.ndarray, level: int, resolution: float, config: BevConfig,
                  presorted: bool = False) -> ColumnClasses:
    """Occupied and floor columns of packed voxel keys (:mod:`sgtool.mapping.voxels`;
    sorted keys, as the map stores them, skip a sort)."""
    iz = ((keys >> SHIFT_Z) & AXIS_MASK) - OFFSET
    col = keys >> COLUMN_SHIFT
    tol = floor_levels(config, resolution)
    top = int(round(config.band_top / resolution))
    is_floor = iz <= level + tol
    in_band = (iz > level + tol) & (iz <= level + top)
    return ColumnClasses(_unique_columns(col[in_band], presorted),
                         _unique_columns(col[is_floor], presorted))


def columns_between(keys: np.ndarray, level: int, resolution: float, low: float,
                    high: float, presorted: bool = False) -> np.ndarray:
    """Distinct (ix, iy) voxel columns of packed ``keys`` holding a voxel from ``low`` to
    ``high`` metres above the floor level ``level`` (both ends included, in whole voxels);
    sorted keys, as the map stores them, skip a sort."""
    iz = ((keys >> SHIFT_Z) & AXIS_MASK) - OFFSET
    lo = level + int(math.ceil(low / resolution - 1e-9))
    hi = level + int(math.floor(high / resolution + 1e-9))
    return _unique_columns(keys[(iz >= lo) & (iz <= hi)] >> COLUMN_SHIFT, presorted)


class ColumnGrid:
    """Occupied/floor flags per voxel column over a grid that grows with the map, updated
    with the columns of new voxels only (the incremental half of the BEV)."""

    OCC = np.uint8(1)
    FLOOR = np.uint8(2)
    CARVED = np.uint8(4)

    def __init__(self, resolution: float, config: BevConfig) -> None:
        self.resolution = resolution
        self.config = config
        self.flags = np.zeros((0, 0), dtype=np.uint8)
        self.extent: tuple[int, int, int, int] | None = None  # ix0, iy0, ix1, iy1
        # the robot footprint of the trajectory points seen so far, over ``extent``:
        # (extent, those points, the mask); only new points are stamped while it holds
        self._footprint: tuple[tuple[int, int, int, int], list[tuple[float, float]],
                               np.ndarray] | None = None
        # the last occupancy grid made and its unknown components (see unknown_parts_of)
        self._parts: tuple[np.ndarray, UnknownParts | None] | None = None
        self._track = TrackBox(resolution)  # the trajectory's cell bounds

    def _fit(self, sets: Sequence[np.ndarray], trajectory: Sequence[tuple[float, float]]
             ) -> None:
        self.cover(grid_extent(sets, self.resolution, self.config,
                               track=self._track.of(trajectory)))

    def fitted_extent(self, sets: Sequence[np.ndarray],
                      trajectory: Sequence[tuple[float, float]]) -> tuple[int, int, int, int]:
        """:func:`grid_extent` of ``sets`` and ``trajectory`` (the trajectory's bounds kept
        from the previous calls)."""
        return grid_extent(sets, self.resolution, self.config,
                           track=self._track.of(trajectory))

    def cover(self, want: tuple[int, int, int, int]) -> None:
        """Grow the grid to cover the voxel-index extent ``want`` (keeping the flags)."""
        if self.extent is not None:
            o = self.extent
            want = (min(want[0], o[0]), min(want[1], o[1]), max(want[2], o[2]),
                    max(want[3], o[3]))
            if want == o:
                return
        flags = np.zeros((want[3] - want[1] + 1, want[2] - want[0] + 1), dtype=np.uint8)
        if self.extent is not None and self.flags.size:
            o = self.extent
            flags[o[1] - want[1]:o[3] - want[1] + 1, o[0] - want[0]:o[2] - want[0] + 1] = \
                self.flags
        self.flags, self.extent = flags, want

    def add(self, classes: ColumnClasses,
            trajectory: Sequence[tuple[float, float]] = ()) -> None:
        self._fit([classes.occupied, classes.floor], trajectory)
        assert self.extent is not None
        ix0, iy0 = self.extent[0], self.extent[1]
        for cols, flag in ((classes.occupied, self.OCC), (classes.floor, self.FLOOR)):
            if len(cols):
                self.flags[cols[:, 1] - iy0, cols[:, 0] - ix0] |= flag

    def merge(self, other: ColumnGrid) -> None:
        """Grow to cover ``other`` and add its flags (e.g. a grid of carved cells only)."""
        if other.extent is None:
            return
        self.cover(other.extent)
        assert self.extent is not None
        o, e = other.extent, self.extent
        self.flags[o[1] - e[1]:o[3] - e[1] + 1, o[0] - e[0]:o[2] - e[0] + 1] |= other.flags

    def carve(self, fans: np.ndarray, level: int) -> None:
        """Mark the ground cells under camera rays that end on the floor (see
        :func:`floor_fans`): ``fans`` rows (cam_x, cam_y, end_x, end_y, end_z)."""
        if len(fans) == 0:
            return
        res = self.resolution
        tol = floor_levels(self.config, res)
        ez = np.floor(fans[:, 4] / res).astype(np.int64)
        f = fans[ez <= level + tol]
        if len(f) == 0:
            return
        xy = np.concatenate([f[:, 0:2], f[:, 2:4]])
        self._fit([np.floor(xy / res).astype(np.int64)], ())
        assert self.extent is not None
        vec = f[:, 2:4] - f[:, 0:2]
        length = np.hypot(vec[:, 0], vec[:, 1])
        n = np.ceil(length / res).astype(np.int64) + 1  # samples per ray, one per cell
        ray = np.repeat(np.arange(len(f)), n)
        first = np.concatenate([[0], np.cumsum(n)[:-1]])
        t = (np.arange(int(n.sum())) - first[ray]) / np.maximum(n[ray] - 1, 1)
        x = f[ray, 0] + vec[ray, 0] * t
        y = f[ray, 1] + vec[ray, 1] * t
        c = np.floor(x / res).astype(np.int64) - self.extent[0]
        r = np.floor(y / res).astype(np.int64) - self.extent[1]
        self.flags[r, c] |= self.CARVED

    def occupancy(self, trajectory: Sequence[tuple[float, float]] = (),
                  level: int = 0) -> OccupancyGrid:
        """The occupancy grid (module doc) of the flags plus the trajectory footprint."""
        self._fit([], trajectory)
        assert self.extent is not None
        occ, parts = _occupancy_and_parts(self.flags, self.extent, self.resolution,
                                          self.config, trajectory, level,
                                          self._footprint_of(trajectory))
        self._parts = (occ.grid, parts)
        return occ

    def unknown_parts_of(self, occ: OccupancyGrid) -> UnknownParts | None:
        """The 4-connected components of the unknown cells of ``occ`` when it is the last
        grid :meth:`occupancy` made (the labelling of the hole filling, the filled holes
        taken out: label values may have gaps), else None."""
        if self._parts is None or self._parts[0] is not occ.grid:
            return None
        return self._parts[1]

    def _footprint_of(self, trajectory: Sequence[tuple[float, float]]) -> np.ndarray:
        """:func:`footprint` of ``trajectory`` over the current extent, stamping only the
        points added since the last call when the extent and the earlier points are the
        same (a union of disks: the same cells as stamping them all)."""
        assert self.extent is not None
        points = list(trajectory)
        got = self._footprint
        shape = self.flags.shape
        new = None if got is None or got[0] != self.extent else appended(got[1], points)
        if got is not None and new is not None:
            mask = got[2]
            if new:
                mask = mask | footprint(new, self.extent, shape, self.resolution,
                                        self.config.robot_radius)
        else:
            mask = footprint(points, self.extent, shape, self.resolution,
                             self.config.robot_radius)
        mask.setflags(write=False)
        self._footprint = (self.extent, points, mask)
        return mask


def occupancy_grid(flags: np.ndarray, extent: tuple[int, int, int, int], resolution: float,
                   config: BevConfig, trajectory: Sequence[tuple[float, float]] = (),
                   level: int = 0, stamped: np.ndarray | None = None) -> OccupancyGrid:
    """FREE / OCCUPIED / UNKNOWN from column flags (``ColumnGrid.OCC``/``FLOOR``) over the
    voxel-index ``extent``, with the robot footprint along ``trajectory`` (``stamped``:
    that footprint, when the caller has it) and small holes filled."""
    return _occupancy_and_parts(flags, extent, resolution, config, trajectory, level,
                                stamped)[0]


def _occupancy_and_parts(flags: np.ndarray, extent: tuple[int, int, int, int],
                         resolution: float, config: BevConfig,
                         trajectory: Sequence[tuple[float, float]], level: int,
                         stamped: np.ndarray | None
                         ) -> tuple[OccupancyGrid, UnknownParts | None]:
    """:func:`occupancy_grid` and its unknown components (:func:`fill_holes_parts`)."""
    ix0, iy0 = extent[0], extent[1]
    h, w = flags.shape
    if stamped is None:
        stamped = footprint(trajectory, extent, (h, w), resolution, config.robot_radius) \
            if len(trajectory) else np.zeros((h, w), dtype=bool)
    grid = cell_values(flags, stamped)
    _, parts = fill_holes_parts(grid, int(config.max_hole / resolution**2))
    origin = (ix0 * resolution, iy0 * resolution)
    return OccupancyGrid(grid, origin, resolution, (level + 1) * resolution), parts


# the cell value of every code ``flags | stamped << 3`` (ColumnGrid flags, footprint bit):
# occupied wins, then free (floor, carved or under the robot), else unknown
_STAMPED = np.uint8(8)
_CELL_VALUES = np.array([OCCUPIED if i & ColumnGrid.OCC else
                         FREE if i & (ColumnGrid.FLOOR | ColumnGrid.CARVED | _STAMPED) else
                         UNKNOWN for i in range(16)], dtype=np.int8)


def cell_values(flags: np.ndarray, stamped: np.ndarray) -> np.ndarray:
    """FREE / OCCUPIED / UNKNOWN of column ``flags`` (``ColumnGrid`` bits) and the robot's
    footprint ``stamped`` (bool), in one table look-up."""
    code = flags | (stamped.view(np.uint8) << 3)
    return np.take(_CELL_VALUES, code)


def grid_extent(column_sets: Sequence[np.ndarray], resolution: float, config: BevConfig,
                trajectory: Sequence[tuple[float, float]] = (),
                track: tuple[int, int, int, int] | None = None) -> tuple[int, int, int, int]:
    """Snapped voxel-index extent (ix0, iy0, ix1, iy1) covering columns and trajectory
    (``track``: the trajectory's :func:`track_box`, when the caller has it)."""
    xs: list[int] = []
    ys: list[int] = []
    for cs in column_sets:
        if len(cs):
            xs += [int(cs[:, 0].min()), int(cs[:, 0].max())]
            ys += [int(cs[:, 1].min()), int(cs[:, 1].max())]
    if track is None and len(trajectory):
        track = track_box(trajectory, resolution)
    if track is not None:
        xs += [track[0], track[2]]
        ys += [track[1], track[3]]
    if not xs:
        xs, ys = [0, 0], [0, 0]
    m, s = config.margin, max(1, config.snap)
    ix0 = (min(xs) - m) // s * s
    iy0 = (min(ys) - m) // s * s
    ix1 = -((-(max(xs) + m + 1)) // s) * s - 1
    iy1 = -((-(max(ys) + m + 1)) // s) * s - 1
    return ix0, iy0, ix1, iy1


def track_box(trajectory: Sequence[tuple[float, float]], resolution: float
              ) -> tuple[int, int, int, int] | None:
    """Cell bounds (ix0, iy0, ix1, iy1) of trajectory points (None without points)."""
    if not len(trajectory):
        return None
    t = np.floor(np.asarray(trajectory, dtype=np.float64).reshape(-1, 2) / resolution)
    return (int(t[:, 0].min()), int(t[:, 1].min()), int(t[:, 0].max()), int(t[:, 1].max()))


def appended(seen: list[tuple[float, float]], trajectory: Sequence[tuple[float, float]]
             ) -> list[tuple[float, float]] | None:
    """The points of ``trajectory`` after the prefix ``seen``, None when ``trajectory``
    does not start with ``seen``."""
    n = len(seen)
    if len(trajectory) < n or list(trajectory[:n]) != seen:
        return None
    return list(trajectory[n:])


class TrackBox:
    """:func:`track_box` of a trajectory that grows by appending: kept from one call to
    the next, only the new points are converted (the min and max of the cell indices of
    all points are those of the old bounds and the new points)."""

    def __init__(self, resolution: float) -> None:
        self.resolution = resolution
        self._points: list[tuple[float, float]] = []
        self._box: tuple[int, int, int, int] | None = None

    def of(self, trajectory: Sequence[tuple[float, float]]) -> tuple[int, int, int, int] | None:
        new = appended(self._points, trajectory)
        if new is None:  # not an extension: start afresh
            self._points, self._box = [], None
            new = list(trajectory)
        if new:
            add = track_box(new, self.resolution)
            assert add is not None
            old = self._box or add
            self._box = (min(old[0], add[0]), min(old[1], add[1]), max(old[2], add[2]),
                         max(old[3], add[3]))
            self._points += new
        return self._box


def floor_fans(depth: np.ndarray, pose: np.ndarray, fx: float, fy: float, cx: float,
               cy: float, every: int = 8, min_range: float = 0.1,
               max_range: float = 5.0) -> np.ndarray:
    """The blind zone in front of the camera, as rays: for every ``every``-th image
    column, the bottom-most valid pixel (the nearest ground point the camera sees in that
    direction). Rows (cam_x, cam_y, end_x, end_y, end_z) in the world; at refresh, rays
    ending on the floor clear the ground cells they pass over (:meth:`ColumnGrid.carve`):
    a camera pitched down never sees the floor right in front of the robot, and an
    obstacle there, up to the ray's height, would have been hit instead of the floor."""
    h, w = depth.shape
    cols = np.arange(0, w, every)
    d = depth[:, cols]
    with np.errstate(invalid="ignore"):
        valid = (d >= min_range) & (d < max_range)
    has = valid.any(axis=0)
    if not has.any():
        return np.zeros((0, 5))
    row = h - 1 - np.argmax(valid[::-1], axis=0)
    cols, row = cols[has], row[has]
    z = d[row, np.flatnonzero(has)].astype(np.float64)
    xc = (cols - cx) / fx * z
    yc = (row - cy) / fy * z
    R, t = pose[:3, :3], pose[:3, 3]  # noqa: N806
    ex = R[0, 0] * xc + R[0, 1] * yc + R[0, 2] * z + t[0]
    ey = R[1, 0] * xc + R[1, 1] * yc + R[1, 2] * z + t[1]
    ez = R[2, 0] * xc + R[2, 1] * yc + R[2, 2] * z + t[2]
    k = len(z)
    return np.stack([np.full(k, t[0]), np.full(k, t[1]), ex, ey, ez], axis=1)


def footprint(trajectory: Sequence[tuple[float, float]], extent: tuple[int, int, int, int],
              shape: tuple[int, int], resolution: float, radius: float) -> np.ndarray:
    """Cells within ``radius`` of a trajectory point (disks stamped at its distinct cells)."""
    h, w = shape
    t = np.asarray(trajectory, dtype=np.float64).reshape(-1, 2)
    r = np.floor(t[:, 1] / resolution).astype(np.int64) - extent[1]
    c = np.floor(t[:, 0] / resolution).astype(np.int64) - extent[0]
    cells = np.unique(r * (w + 1) + c)  # distinct (row, col); w + 1 keeps them apart
    r, c = np.divmod(cells, w + 1)
    rad = int(round(radius / resolution))
    dr, dc = np.nonzero(disk(rad))
    rr = (r[:, None] + dr[None, :] - rad).ravel()
    cc = (c[:, None] + dc[None, :] - rad).ravel()
    ok = (rr >= 0) & (rr < h) & (cc >= 0) & (cc < w)
    out = np.zeros((h, w), dtype=bool)
    out[rr[ok], cc[ok]] = True
    return out


def disk(radius: int) -> np.ndarray:
    """Boolean disk structuring element of a radius in cells."""
    r = np.arange(-radius, radius + 1)
    return (r[:, None] ** 2 + r[None, :] ** 2) <= radius * radius


def line_of_sight(blocked: np.ndarray, occ: OccupancyGrid, a: np.ndarray, b: np.ndarray,
                  skip_end: float = 0.0, outside_blocks: bool = True) -> np.ndarray:
    """For segments a[i] -> b[i] (world (k, 2)), True when no ``blocked`` cell lies on
    them (sampled every half cell; the last ``skip_end`` metres before b are not checked,
    so b may sit on an obstacle such as a door panel). Out-of-grid samples block unless
    ``outside_blocks`` is False (space the map has not reached)."""
    a = np.asarray(a, dtype=np.float64).reshape(-1, 2)
    b = np.asarray(b, dtype=np.float64).reshape(-1, 2)
    k = len(a)
    if k == 0:
        return np.zeros(0, dtype=bool)
    vec = b - a
    length = np.hypot(vec[:, 0], vec[:, 1])
    usable = np.maximum(length - skip_end, 0.0)
    n = np.ceil(usable / (occ.resolution / 2.0)).astype(np.int64) + 1  # samples per segment
    seg = np.repeat(np.arange(k), n)
    first = np.concatenate([[0], np.cumsum(n)[:-1]])
    f = (np.arange(int(n.sum())) - first[seg]) * (occ.resolution / 2.0)
    f = np.minimum(f, usable[seg])
    unit = vec / np.maximum(length, 1e-12)[:, None]
    r, c = occ.cell_of(a[seg, 0] + unit[seg, 0] * f, a[seg, 1] + unit[seg, 1] * f)
    inside = occ.inside(r, c)
    hit = np.full(len(seg), outside_blocks, dtype=bool)
    hit[inside] = blocked[r[inside], c[inside]]
    out = np.ones(k, dtype=bool)
    out[seg[hit]] = False
    return out
