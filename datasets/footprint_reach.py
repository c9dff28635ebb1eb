"""The cells of a grid whose centre is within a distance of a piece's footprint.

Episode goals (:mod:`sgtool.datasets.episodes`), furniture targets
(:mod:`sgtool.datasets.episode_mix`) and reachability (:mod:`sgtool.datasets.start_poses`)
all ask which cell centres lie within ``reach`` of a piece of furniture's oriented box seen
from above. :func:`near_footprint` answers on the window of the grid around the box (its
bounding box grown by ``reach`` and two cells), not on the whole grid: a house grid holds
~10^5 cells, a window a few hundred. Cells outside the window are farther than ``reach``
from the box by more than a cell, so they are never within it; inside the window every
cell gets exactly the value of the whole-grid formula (the same float64 operations on the
same cell centres), so the mask is the same bit for bit.
"""

from __future__ import annotations

import numpy as np

from sgtool.house.spec import Furniture
from sgtool.mapping.raster import Grid, cell_window

Window = tuple[slice, slice]


def near_footprint(grid: Grid, X: np.ndarray, Y: np.ndarray, piece: Furniture,
                   reach: float) -> tuple[Window, np.ndarray] | None:
    """(window, mask over the window) of the cells of ``grid`` (centres ``X``, ``Y`` from
    :func:`~sgtool.mapping.raster.cell_centers`) within ``reach`` of ``piece``'s footprint;
    None when the window misses the grid."""
    margin = abs(reach) + 2.0 * grid.resolution
    corners = piece.footprint()
    xs = [c[0] for c in corners]
    ys = [c[1] for c in corners]
    window = cell_window(grid, [min(xs) - margin, max(xs) + margin],
                         [min(ys) - margin, max(ys) + margin])
    if window is None:
        return None
    lx, ly = piece.to_local(X[window], Y[window])  # type: ignore[arg-type]
    dx = np.maximum(np.abs(lx) - piece.size[0] / 2, 0.0)
    dy = np.maximum(np.abs(ly) - piece.size[1] / 2, 0.0)
    return window, dx ** 2 + dy ** 2 <= reach ** 2


def full_mask(shape: tuple[int, ...], near: tuple[Window, np.ndarray] | None) -> np.ndarray:
    """The window mask of :func:`near_footprint` as a mask of the whole grid."""
    out = np.zeros(shape, dtype=bool)
    if near is not None:
        out[near[0]] = near[1]
    return out
