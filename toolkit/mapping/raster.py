"""Rasterising plane shapes onto a regular grid: which cells a polygon or an oriented box
covers, and the cell <-> world coordinates that decide it.

A grid is anything with ``origin`` (world x, y of the lower-left corner of cell [0, 0]),
``resolution`` (metres per cell) and ``shape`` (rows = y, cols = x), such as
:class:`~sgtool.mapping.grid.OccupancyGrid` or :class:`~sgtool.mapping.occupancy.OccupancyMap`;
the centre of cell (r, c) is
``origin + ((c + 0.5) * resolution, (r + 0.5) * resolution)``. The ``fill_*`` functions
OR a shape into a boolean array of the grid's shape, looking only at a window of cells
around the shape's bounding box.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Protocol

import numpy as np

from sgtool.house.geometry import Point, signed_area

_TOL = 1e-6


class Grid(Protocol):
    """What rasterising needs of a grid (see the module docstring)."""

    @property
    def origin(self) -> tuple[float, float]: ...

    @property
    def resolution(self) -> float: ...

    @property
    def shape(self) -> tuple[int, int]: ...


def world_to_cell(grid: Grid, x: float, y: float) -> tuple[int, int]:
    """(row, col) of the cell holding world point (x, y) (may be out of bounds)."""
    col = math.floor((x - grid.origin[0]) / grid.resolution + 1e-9)
    row = math.floor((y - grid.origin[1]) / grid.resolution + 1e-9)
    return (int(row), int(col))


def cell_to_world(grid: Grid, row: int, col: int) -> tuple[float, float]:
    """World (x, y) of the centre of cell (row, col)."""
    return (grid.origin[0] + (col + 0.5) * grid.resolution,
            grid.origin[1] + (row + 0.5) * grid.resolution)


def cell_centers(grid: Grid, window: tuple[slice, slice] | None = None
                 ) -> tuple[np.ndarray, np.ndarray]:
    """(X, Y) arrays of cell-centre coordinates over ``window`` (default: the whole grid)."""
    rows, cols = window if window is not None else (slice(0, grid.shape[0]),
                                                    slice(0, grid.shape[1]))
    xs = grid.origin[0] + (np.arange(cols.start, cols.stop) + 0.5) * grid.resolution
    ys = grid.origin[1] + (np.arange(rows.start, rows.stop) + 0.5) * grid.resolution
    return np.meshgrid(xs, ys)


def cell_window(grid: Grid, xs: Sequence[float],
                ys: Sequence[float]) -> tuple[slice, slice] | None:
    """(rows, cols) slices of the cells around the bounding box of the points ``xs``,
    ``ys``, one cell of margin on each side; None when it misses the grid."""
    r0, c0 = world_to_cell(grid, min(xs), min(ys))
    r1, c1 = world_to_cell(grid, max(xs), max(ys))
    rows, cols = grid.shape
    r0, c0 = max(r0 - 1, 0), max(c0 - 1, 0)
    r1, c1 = min(r1 + 2, rows), min(c1 + 2, cols)
    if r0 >= r1 or c0 >= c1:
        return None
    return slice(r0, r1), slice(c0, c1)


def fill_polygon(grid: Grid, out: np.ndarray, polygon: Sequence[Point],
                 border: bool = True) -> None:
    """Mark the cells of ``out`` whose centre lies inside ``polygon``. ``border=True``
    counts centres on the border as inside, whatever the winding; ``border=False`` leaves
    them to matplotlib's point-in-path rule (either way)."""
    win = cell_window(grid, [p[0] for p in polygon], [p[1] for p in polygon])
    if win is None:
        return
    from matplotlib.path import Path as MplPath  # imported on first use: start-up time

    X, Y = cell_centers(grid, win)
    pts = np.column_stack([X.ravel(), Y.ravel()])
    # a small radius signed like the winding grows the path, so the border counts as inside
    radius = (1e-6 if signed_area(polygon) > 0 else -1e-6) if border else 0.0
    out[win] |= MplPath(np.asarray(polygon, float)).contains_points(
        pts, radius=radius).reshape(X.shape)


def polygon_mask(grid: Grid, polygon: Sequence[Point], border: bool = True) -> np.ndarray:
    """Bool array of the grid's shape: :func:`fill_polygon` into an empty grid."""
    out = np.zeros(grid.shape, bool)
    fill_polygon(grid, out, polygon, border)
    return out


def _box_frame(grid: Grid, center: Sequence[float], size: Sequence[float], yaw: float,
               pad: float) -> tuple[tuple[slice, slice], np.ndarray, np.ndarray] | None:
    """The window around an oriented box grown by ``pad`` and its cell centres in the
    box's frame (lx along the box's x axis, ly along its y axis)."""
    c, s = math.cos(yaw), math.sin(yaw)
    hx, hy = size[0] / 2.0 + pad, size[1] / 2.0 + pad
    ex = abs(c) * hx + abs(s) * hy
    ey = abs(s) * hx + abs(c) * hy
    win = cell_window(grid, (center[0] - ex, center[0] + ex), (center[1] - ey, center[1] + ey))
    if win is None:
        return None
    X, Y = cell_centers(grid, win)
    dx, dy = X - center[0], Y - center[1]
    return win, c * dx + s * dy, -s * dx + c * dy


def fill_box_overlap(grid: Grid, out: np.ndarray, center: Sequence[float],
                     size: Sequence[float], yaw: float) -> None:
    """Mark the cells whose square overlaps the oriented box (exact for axis-aligned boxes,
    slightly generous for rotated ones); touching the box's edge is not overlapping."""
    c, s = math.cos(yaw), math.sin(yaw)
    # half a cell along the box axes, grown to the cell's extent in that direction
    grow = 0.5 * grid.resolution * (abs(c) + abs(s))
    frame = _box_frame(grid, center, size, yaw, 0.0)
    if frame is None:
        return
    win, lx, ly = frame
    out[win] |= (np.abs(lx) < size[0] / 2.0 + grow - _TOL) & \
        (np.abs(ly) < size[1] / 2.0 + grow - _TOL)


def fill_box_grown(grid: Grid, out: np.ndarray, center: Sequence[float],
                   size: Sequence[float], yaw: float) -> None:
    """Mark the cells whose centre lies within the oriented box grown by half a cell on
    every side (its edge included)."""
    h = grid.resolution / 2
    frame = _box_frame(grid, center, size, yaw, h)
    if frame is None:
        return
    win, lx, ly = frame
    out[win] |= (np.abs(lx) <= size[0] / 2 + h) & (np.abs(ly) <= size[1] / 2 + h)


def fill_box_near(grid: Grid, out: np.ndarray, center: Sequence[float],
                  size: Sequence[float], yaw: float, reach: float) -> None:
    """Mark the cells whose centre lies within ``reach`` of the oriented box (its inside
    and a centre at exactly ``reach`` included): the exact distance from the centre, so
    the cells marked around a box do not depend on how it is turned against the grid. A
    disc of radius ``reach`` on an unmarked centre keeps clear of the box, so a gap of
    ``2 * reach`` or less between two boxes has no unmarked centre at any angle."""
    frame = _box_frame(grid, center, size, yaw, max(reach, 0.0))
    if frame is None:
        return
    win, lx, ly = frame
    ex = np.maximum(np.abs(lx) - size[0] / 2.0, 0.0)
    ey = np.maximum(np.abs(ly) - size[1] / 2.0, 0.0)
    out[win] |= np.hypot(ex, ey) <= reach + _TOL
