"""Frontiers of the occupancy grid: clustered, centred on medoids, typed.

Frontiers are "boundaries between explored traversable space and unexplored regions"
(SCOUT sec. IV-A, after Topiwala et al.). MoMa-LLM's released code, as summarised in the
project's reference notes: free cells next to unknown, not next to occupied, connected to
the robot's free component; clustered; centre = medoid. A cluster is **leading out** when
it touches unknown cells outside the hole-filled footprint of what has been seen (occupied
or free) -- unknown space open to the outside of the explored area, e.g. beyond a doorway
-- and an **unexplored area** inside its room otherwise (an unseen pocket enclosed by seen
space, e.g. behind furniture). Pockets smaller than ``min_pocket`` (0.5 m^2) raise no
frontier at all.

Clusters are 8-connected components of frontier cells of at least ``min_size`` metres;
longer ones are cut into pieces of at most ``max_size`` along their principal axis so one
long boundary becomes several places to go. The medoid (the cluster cell with the least
summed distance to the others; computed on at most 256 evenly spaced cells) is a real
frontier cell, unlike the mean.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import ndimage
from scipy.sparse import csr_matrix
from scipy.sparse.csgraph import connected_components

from sgtool.mapping import holes
from sgtool.mapping.grid import FREE, OccupancyGrid
from sgtool.mapping.holes import UnknownParts
from sgtool.scenegraph.graph import FrontierType

_FOUR = ndimage.generate_binary_structure(2, 1)


@dataclass(frozen=True)
class FrontierConfig:
    min_size: float = 0.3  # m (cells x resolution)
    max_size: float = 2.5  # m; longer clusters are split
    snap: float = 0.5  # m: the robot's start cell may be this far from free space
    min_pocket: float = 0.5  # m^2: unknown pockets smaller than this are not worth a visit


@dataclass(frozen=True, eq=False)
class Frontier:
    cells: np.ndarray  # (k, 2) row, col
    medoid: tuple[float, float]  # world x, y
    medoid_cell: tuple[int, int]
    size: float  # m
    leading_out: bool

    @property
    def type(self) -> FrontierType:
        return "leading out" if self.leading_out else "unexplored area"


def _start_cell(occ: OccupancyGrid, free: np.ndarray, start: tuple[float, float] | None,
                snap: float) -> tuple[int, int] | None:
    """The free cell nearest to ``start`` within ``snap`` (ties: the first in raster
    order); None when ``start`` is None or not near free space."""
    if start is None or not free.any():
        return None
    row, col = occ.cell_of(start[0], start[1])
    r, c = int(row), int(col)
    k = int(np.ceil(snap / occ.resolution))
    h, w = occ.shape
    r0, r1, c0, c1 = max(r - k, 0), min(r + k + 1, h), max(c - k, 0), min(c + k + 1, w)
    if r0 >= r1 or c0 >= c1:
        return None
    rr, cc = np.nonzero(free[r0:r1, c0:c1])
    if rr.size == 0:
        return None
    d2 = (rr + r0 - r) ** 2 + (cc + c0 - c) ** 2
    i = int(np.lexsort((cc, rr, d2))[0])
    return int(rr[i] + r0), int(cc[i] + c0)


_COUNTS, _OUTSIDE = np.uint8(1), np.uint8(2)  # bits of _unknown_kinds


def _unknown_kinds(parts: UnknownParts, min_pocket: float, resolution: float) -> np.ndarray:
    """Per cell: ``_COUNTS`` for the unknown cells that count as unknown (not filled, not in
    a pocket under ``min_pocket`` m^2 off the border), ``_OUTSIDE`` too for those outside
    the footprint of what was seen (a component touching the grid border)."""
    table = np.zeros(parts.count + 1, dtype=np.uint8)
    counts = ~parts.filled
    max_cells = int(min_pocket / resolution**2)
    if max_cells > 0:
        counts &= (parts.sizes >= max_cells) | parts.border
    table[counts] = _COUNTS
    table[parts.border & counts] |= _OUTSIDE
    table[0] = 0
    return parts.per_cell(table)


def _frontier_cells(occ: OccupancyGrid, start: tuple[float, float] | None, snap: float,
                    kinds: np.ndarray, near_occupied: np.ndarray
                    ) -> tuple[np.ndarray, np.ndarray]:
    """Rows and columns, in raster order, of the frontier cells: free cells (4-connected to
    the free cell :func:`_start_cell` finds, when it finds one) 4-adjacent to a cell of
    ``kinds`` (:func:`_unknown_kinds`: unknown pockets under ``min_pocket`` off the border
    do not count) and not 8-adjacent to occupied (``near_occupied``). The free cells are
    labelled only when some candidate needs the test of reaching the start."""
    free = occ.grid == FREE
    unknown = np.pad(kinds != 0, 1, constant_values=True)
    next_unknown = (unknown[:-2, 1:-1] | unknown[2:, 1:-1] | unknown[1:-1, :-2]
                    | unknown[1:-1, 2:])
    rows, cols = np.nonzero(free & next_unknown & ~near_occupied)
    cell = _start_cell(occ, free, start, snap)
    if cell is not None and len(rows):
        lab, _ = ndimage.label(free, structure=_FOUR)
        keep = lab[rows, cols] == lab[cell]
        rows, cols = rows[keep], cols[keep]
    return rows, cols


def find_frontiers(occ: OccupancyGrid, start: tuple[float, float] | None = None,
                   config: FrontierConfig | None = None,
                   unknown_parts: UnknownParts | None = None) -> list[Frontier]:
    """Frontier clusters in raster order of their medoid cells. ``unknown_parts``: the
    :class:`~sgtool.mapping.holes.UnknownParts` of ``occ`` (the BEV's hole filling), when
    the caller has them."""
    cfg = config or FrontierConfig()
    parts = unknown_parts if unknown_parts is not None else holes.unknown_parts(occ.grid)
    kinds = _unknown_kinds(parts, cfg.min_pocket, occ.resolution)
    rows, cols = _frontier_cells(occ, start, cfg.snap, kinds, parts.near_occupied)
    if len(rows) == 0:
        return []
    res = occ.resolution
    n, of = eight_components(rows, cols, occ.shape[1])
    order = np.argsort(of, kind="stable")  # by cluster, raster order within one
    ends = np.cumsum(np.bincount(of, minlength=n))
    outside = holes.near_at((kinds & _OUTSIDE) != 0, rows, cols)
    min_cells = max(1, int(round(cfg.min_size / res)))
    max_cells = max(min_cells, int(round(cfg.max_size / res)))
    out: list[Frontier] = []
    for members in np.split(order, ends[:-1]):
        if len(members) < min_cells:
            continue
        rr, cc = rows[members], cols[members]
        for piece in split_cluster(rr, cc, max_cells):
            if len(piece) < min_cells:
                continue
            pr, pc = rr[piece], cc[piece]
            mr, mc = cluster_medoid(pr, pc)
            x, y = occ.center_of(mr, mc)
            out.append(Frontier(
                cells=np.stack([pr, pc], axis=1), medoid=(float(x), float(y)),
                medoid_cell=(mr, mc), size=float(len(pr) * res),
                leading_out=bool(outside[members[piece]].any()),
            ))
    out.sort(key=lambda f: f.medoid_cell)
    return out


def eight_components(rows: np.ndarray, cols: np.ndarray, width: int) -> tuple[int, np.ndarray]:
    """The 8-connected components of the cells (``rows``, ``cols``) in raster order (a
    grid ``width`` cells wide), found among those cells only: (count, component of each
    cell, numbered 0..count-1). The same grouping as ``ndimage.label`` of the grid."""
    k = len(rows)
    stride = width + 2  # column -1 and width stay apart from the next row
    key = rows.astype(np.int64) * stride + cols + 1  # increasing: raster order
    src, dst = [], []
    for step in (1, stride - 1, stride, stride + 1):  # E, SW, S, SE: every pair once
        j = np.searchsorted(key, key + step)
        hit = np.flatnonzero(j < k)
        hit = hit[key[j[hit]] == key[hit] + step]
        src.append(hit)
        dst.append(j[hit])
    a, b = np.concatenate(src), np.concatenate(dst)
    indptr = np.zeros(k + 1, dtype=np.int64)
    np.cumsum(np.bincount(a, minlength=k), out=indptr[1:])
    graph = csr_matrix((np.ones(len(a), dtype=np.int8), b[np.argsort(a, kind="stable")],
                        indptr), shape=(k, k))
    n, labels = connected_components(graph, directed=False)
    return int(n), labels


def split_cluster(rr: np.ndarray, cc: np.ndarray, max_cells: int) -> list[np.ndarray]:
    """Cut a cluster into ceil(k / max_cells) runs along its principal axis: the indices
    of each run's cells."""
    k = len(rr)
    parts = int(np.ceil(k / max_cells))
    if parts <= 1:
        return [np.arange(k)]
    pts = np.stack([rr, cc], axis=1).astype(np.float64)
    centred = pts - pts.mean(axis=0)
    cov = centred.T @ centred
    evals, evecs = np.linalg.eigh(cov)
    axis = evecs[:, int(np.argmax(evals))]
    if axis[0] < 0 or (axis[0] == 0 and axis[1] < 0):
        axis = -axis  # a sign convention, for determinism
    proj = centred @ axis
    order = np.lexsort((cc, rr, proj))
    return np.array_split(order, parts)


def cluster_medoid(rr: np.ndarray, cc: np.ndarray, cap: int = 256) -> tuple[int, int]:
    """The cell (row, col) of the cluster (``rr``, ``cc``) with the least summed Euclidean
    distance to the others, among at most ``cap`` evenly spaced cells of it (ties: the
    first in the given order)."""
    k = len(rr)
    idx = np.arange(k) if k <= cap else np.linspace(0, k - 1, cap).round().astype(np.int64)
    r, c = rr[idx].astype(np.float64), cc[idx].astype(np.float64)
    d = np.hypot(r[:, None] - r[None, :], c[:, None] - c[None, :]).sum(axis=1)
    j = int(idx[int(np.argmin(d))])
    return int(rr[j]), int(cc[j])
