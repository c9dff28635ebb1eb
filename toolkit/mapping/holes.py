"""The unknown components of an occupancy grid, and the filling of small holes in free space.

One labelling of the unknown cells (4-connected) serves the BEV's hole filling
(:func:`fill_holes_parts`) and the frontiers (:mod:`sgtool.scenegraph.frontiers`: unknown
pockets too small to visit, unknown space open to the outside): :class:`UnknownParts`
keeps it with what both ask of a component (its size, whether it touches the grid border,
whether it was filled) and the cells next to obstacles, so neither labels nor scans the
grid again.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
from scipy import ndimage

from sgtool.mapping.grid import FREE, OCCUPIED, UNKNOWN


@dataclass(frozen=True, eq=False)
class UnknownParts:
    """The 4-connected components of the unknown cells of a grid (before its hole filling:
    the filled components keep their label and are flagged in ``filled``)."""

    labels: np.ndarray  # intp grid: the component of every unknown cell, 0 elsewhere
    count: int  # components, labelled 1..count
    sizes: np.ndarray  # cells per label (index 0: the cells that are not unknown)
    border: np.ndarray  # bool per label: touches the grid border (index 0: False)
    filled: np.ndarray  # bool per label: turned free by the hole filling
    near_occupied: np.ndarray  # bool grid: cells 8-adjacent to (or on) an occupied cell

    def per_cell(self, table: np.ndarray) -> np.ndarray:
        """``table[label]`` of every cell (a small per-label table spread on the grid)."""
        return np.take(table, self.labels)


def near(mask: np.ndarray) -> np.ndarray:
    """Cells 8-adjacent to (or in) ``mask`` (a 3x3 dilation by shifted ORs)."""
    p = np.pad(mask, 1)
    out = p[1:-1, 1:-1].copy()
    h, w = mask.shape
    for dr in (0, 1, 2):
        for dc in (0, 1, 2):
            if dr != 1 or dc != 1:
                out |= p[dr:dr + h, dc:dc + w]
    return out


def near_at(mask: np.ndarray, rows: np.ndarray, cols: np.ndarray) -> np.ndarray:
    """``near(mask)[rows, cols]``, looking at the 3x3 neighbourhoods of those cells only."""
    p = np.pad(mask, 1)
    out = np.zeros(len(rows), dtype=bool)
    for dr in (0, 1, 2):
        for dc in (0, 1, 2):
            out |= p[rows + dr, cols + dc]
    return out


def unknown_parts(grid: np.ndarray, near_occupied: np.ndarray | None = None) -> UnknownParts:
    """The 4-connected components of the unknown cells of ``grid`` (none filled);
    ``near_occupied``: ``near(grid == OCCUPIED)``, when the caller has it."""
    labels, n = ndimage.label(grid == UNKNOWN, output=np.intp)
    sizes = np.bincount(labels.ravel(), minlength=n + 1)
    border = np.zeros(n + 1, dtype=bool)
    if n:  # (an empty grid has no components, and no border rows to read)
        border[np.concatenate([labels[0], labels[-1], labels[:, 0], labels[:, -1]])] = True
        border[0] = False
    if near_occupied is None:
        near_occupied = near(grid == OCCUPIED)
    return UnknownParts(labels, int(n), sizes, border, np.zeros(n + 1, dtype=bool),
                        near_occupied)


def fill_holes_parts(grid: np.ndarray, max_cells: int) -> tuple[int, UnknownParts | None]:
    """Turn enclosed unknown holes of at most ``max_cells`` cells (4-connected, bordered
    only by free cells, not touching the grid border) into free space, in place: (the
    number of cells filled, the :class:`UnknownParts` of the grid before the filling; None
    when ``max_cells`` <= 0 skips the labelling). Filling turns whole components free, so
    the unknown components left are those of that labelling, less the filled."""
    if max_cells <= 0:
        return 0, None
    parts = unknown_parts(grid)
    if parts.count == 0:
        return 0, parts
    bad = parts.border | (parts.sizes > max_cells)
    bad[0] = True
    # holes next to an obstacle are not holes in free space
    bad[parts.labels[parts.near_occupied & (grid == UNKNOWN)]] = True
    if bad.all():
        return 0, parts
    filled = ~bad
    grid[parts.per_cell(filled)] = FREE
    return int(parts.sizes[filled].sum()), replace(parts, filled=filled)
