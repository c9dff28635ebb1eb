"""The plain whole-grid frontier search and hole filling (as before the shared
:class:`~sgtool.mapping.holes.UnknownParts`): each labels and scans the whole grid, the
reference the shortcuts of :mod:`sgtool.scenegraph.frontiers` are checked against."""

from __future__ import annotations

import numpy as np
from scipy import ndimage

from sgtool.mapping.grid import FREE, OCCUPIED, UNKNOWN, OccupancyGrid
from sgtool.mapping.holes import near
from sgtool.scenegraph.frontiers import (
    Frontier,
    FrontierConfig,
    cluster_medoid,
    split_cluster,
)

_EIGHT = np.ones((3, 3), dtype=bool)
_FOUR = ndimage.generate_binary_structure(2, 1)


def plain_fill_holes(grid: np.ndarray, max_cells: int) -> int:
    """Enclosed unknown holes of at most ``max_cells`` cells become free, in place."""
    if max_cells <= 0:
        return 0
    unknown = grid == UNKNOWN
    lab, n = ndimage.label(unknown)
    if n == 0:
        return 0
    sizes = np.bincount(lab.ravel())
    bad = np.zeros(n + 1, dtype=bool)
    bad[0] = True
    bad[sizes > max_cells] = True
    bad[np.unique(lab[near(grid == OCCUPIED) & unknown])] = True
    bad[np.unique(np.concatenate([lab[0], lab[-1], lab[:, 0], lab[:, -1]]))] = True
    fill = ~bad[lab]
    grid[fill] = FREE
    return int(fill.sum())


def reachable_free(occ: OccupancyGrid, start: tuple[float, float] | None,
                   snap: float = 0.5) -> np.ndarray:
    """Free cells 4-connected to the free cell nearest to ``start`` (ties: the first in
    raster order) among those at most ``ceil(snap / resolution)`` rows and columns from
    its cell; all free cells when ``start`` is None or no free cell is that near."""
    free = occ.grid == FREE
    if start is None or not free.any():
        return free
    row, col = (int(v) for v in occ.cell_of(start[0], start[1]))
    k = int(np.ceil(snap / occ.resolution))
    cells = np.argwhere(free)  # raster order
    offset = cells - np.array([row, col])
    inside = (np.abs(offset) <= k).all(axis=1)
    cells, offset = cells[inside], offset[inside]
    if not len(cells):
        return free
    r, c = cells[int(np.argmin((offset ** 2).sum(axis=1)))]  # argmin: the first of ties
    lab, _ = ndimage.label(free, structure=_FOUR)
    return lab == lab[r, c]


def _border_labels(lab: np.ndarray) -> np.ndarray:
    return np.unique(np.concatenate([lab[0], lab[-1], lab[:, 0], lab[:, -1]]))


def plain_frontier_cells(occ: OccupancyGrid, start: tuple[float, float] | None,
                         snap: float, min_pocket: float) -> np.ndarray:
    reach = reachable_free(occ, start, snap)
    unknown = occ.grid == UNKNOWN
    max_cells = int(min_pocket / occ.resolution**2)
    if max_cells > 0 and unknown.any():
        lab, _ = ndimage.label(unknown, structure=_FOUR)
        small = np.bincount(lab.ravel()) < max_cells
        small[0] = False
        small[_border_labels(lab)] = False
        unknown = unknown & ~small[lab]
    unknown = np.pad(unknown, 1, constant_values=True)
    next_unknown = (unknown[:-2, 1:-1] | unknown[2:, 1:-1] | unknown[1:-1, :-2]
                    | unknown[1:-1, 2:])
    return reach & next_unknown & ~near(occ.grid == OCCUPIED)


def plain_outside(occ: OccupancyGrid) -> np.ndarray:
    lab, n = ndimage.label(occ.grid == UNKNOWN, structure=_FOUR)
    if n == 0:
        return occ.grid == UNKNOWN
    out = np.zeros(n + 1, dtype=bool)
    out[_border_labels(lab)] = True
    out[0] = False
    return out[lab]


def plain_frontiers(occ: OccupancyGrid, start: tuple[float, float] | None,
                    cfg: FrontierConfig) -> list[Frontier]:
    """Frontier clusters: the mask labelled on the whole grid, clusters by their slices."""
    mask = plain_frontier_cells(occ, start, cfg.snap, cfg.min_pocket)
    if not mask.any():
        return []
    res = occ.resolution
    lab, _ = ndimage.label(mask, structure=_EIGHT)
    outside = near(plain_outside(occ))
    min_cells = max(1, int(round(cfg.min_size / res)))
    max_cells = max(min_cells, int(round(cfg.max_size / res)))
    out: list[Frontier] = []
    for i, sl in enumerate(ndimage.find_objects(lab), start=1):
        if sl is None:
            continue
        rr, cc = np.nonzero(lab[sl] == i)
        rr = rr + sl[0].start
        cc = cc + sl[1].start
        if len(rr) < min_cells:
            continue
        for piece in split_cluster(rr, cc, max_cells):
            pr, pc = rr[piece], cc[piece]
            if len(pr) < min_cells:
                continue
            mr, mc = cluster_medoid(pr, pc)
            x, y = occ.center_of(mr, mc)
            out.append(Frontier(cells=np.stack([pr, pc], axis=1), medoid=(float(x), float(y)),
                                medoid_cell=(mr, mc), size=float(len(pr) * res),
                                leading_out=bool(outside[pr, pc].any())))
    out.sort(key=lambda f: f.medoid_cell)
    return out
