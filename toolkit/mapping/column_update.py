"""Bring a BEV column grid up to date after voxels were removed, without rebuilding it.

A :class:`~sgtool.mapping.bev.ColumnGrid` only ORs flags in: a column is occupied (floor)
when any of its voxels is in the height band (at the floor). When an instance's voxels are
dropped (a door that opened), only the columns that held them can lose a flag, so only
those are classified again, from the map's current keys (the keys of one column are one
run of the sorted keys). The carved flags are kept: they come from camera rays, not from
voxels.

A grid rebuilt from scratch also fits its extent to the columns left, so it can be
smaller than the updated one: :func:`fresh_extent` gives the extent the rebuild would
have, and the caller rebuilds when it differs (then the grid's shape would differ too).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from sgtool.mapping.bev import ColumnGrid, classify_keys
from sgtool.mapping.voxels import AXIS_BITS, AXIS_MASK, COLUMN_SHIFT, OFFSET

_VOXEL_FLAGS = ColumnGrid.OCC | ColumnGrid.FLOOR


def column_runs(keys: np.ndarray, columns: np.ndarray) -> np.ndarray:
    """Indices of the sorted packed ``keys`` whose column key is in the sorted distinct
    ``columns`` (in key order)."""
    lo = np.searchsorted(keys, columns << COLUMN_SHIFT)
    hi = np.searchsorted(keys, (columns + 1) << COLUMN_SHIFT)
    n = hi - lo
    total = int(n.sum())
    if total == 0:
        return np.zeros(0, dtype=np.int64)
    start = np.repeat(lo - (np.cumsum(n) - n), n)
    return start + np.arange(total)


def reclassify_columns(grid: ColumnGrid, keys: np.ndarray, columns: np.ndarray,
                       level: int) -> bool:
    """Set the occupied and floor flags of ``columns`` (sorted distinct column keys) to
    the classification of their voxels among the sorted ``keys``, in place. False (and
    nothing changed) when a flagged column would lie outside the grid: rebuild then."""
    if grid.extent is None:
        return False
    if len(columns) == 0:
        return True
    ix0, iy0, ix1, iy1 = grid.extent
    classes = classify_keys(keys[column_runs(keys, columns)], level, grid.resolution,
                            grid.config, presorted=True)
    sets = ((classes.occupied, ColumnGrid.OCC), (classes.floor, ColumnGrid.FLOOR))
    for cols, _ in sets:
        if len(cols) and not ((cols[:, 0] >= ix0).all() and (cols[:, 0] <= ix1).all()
                              and (cols[:, 1] >= iy0).all() and (cols[:, 1] <= iy1).all()):
            return False
    ix = ((columns >> AXIS_BITS) & AXIS_MASK) - OFFSET
    iy = (columns & AXIS_MASK) - OFFSET
    inside = (ix >= ix0) & (ix <= ix1) & (iy >= iy0) & (iy <= iy1)
    grid.flags[iy[inside] - iy0, ix[inside] - ix0] &= ~_VOXEL_FLAGS
    for cols, flag in sets:
        grid.flags[cols[:, 1] - iy0, cols[:, 0] - ix0] |= flag
    return True


def fresh_extent(grid: ColumnGrid, trajectory: Sequence[tuple[float, float]],
                 carved: ColumnGrid | None) -> tuple[int, int, int, int] | None:
    """The extent a grid built from scratch from the voxels behind ``grid``'s occupied and
    floor flags, then merged with ``carved``, would have (None for an empty grid)."""
    if grid.extent is None:
        return None
    rows = np.flatnonzero((grid.flags & _VOXEL_FLAGS).any(axis=1))
    cols = np.flatnonzero((grid.flags & _VOXEL_FLAGS).any(axis=0))
    corners = np.zeros((0, 2), dtype=np.int64)
    if len(rows):
        corners = np.array([[cols[0], rows[0]], [cols[-1], rows[-1]]], dtype=np.int64) + \
            np.array(grid.extent[:2], dtype=np.int64)
    want = grid.fitted_extent([corners], trajectory)
    if carved is not None and carved.extent is not None:
        o = carved.extent
        want = (min(want[0], o[0]), min(want[1], o[1]), max(want[2], o[2]),
                max(want[3], o[3]))
    return want
