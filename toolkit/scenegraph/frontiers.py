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

from sgtool.mapping.bev import near
from sgtool.mapping.grid import FREE, OCCUPIED, UNKNOWN, OccupancyGrid

_EIGHT = np.ones((3, 3), dtype=bool)
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
    def type(self) -> str:
        return "leading out" if self.leading_out else "unexplored area"


def reachable_free(occ: OccupancyGrid, start: tuple[float, float] | None,
                   snap: float = 0.5) -> np.ndarray:
    """Free cells 4-connected to ``start`` (or to the free cell nearest to it within
    ``snap``); all free cells when ``start`` is None or not near free space."""
    free = occ.grid == FREE
    if start is None or not free.any():
        return free
    r, c = occ.cell_of(start[0], start[1])
    r, c = int(r), int(c)
    k = int(np.ceil(snap / occ.resolution))
    h, w = occ.shape
    r0, r1, c0, c1 = max(r - k, 0), min(r + k + 1, h), max(c - k, 0), min(c + k + 1, w)
    if r0 >= r1 or c0 >= c1:
        return free
    rr, cc = np.nonzero(free[r0:r1, c0:c1])
    if rr.size == 0:
        return free
    d2 = (rr + r0 - r) ** 2 + (cc + c0 - c) ** 2
    i = int(np.lexsort((cc, rr, d2))[0])
    lab, _ = ndimage.label(free, structure=_FOUR)
    return lab == lab[rr[i] + r0, cc[i] + c0]


def frontier_cells(occ: OccupancyGrid, start: tuple[float, float] | None = None,
                   snap: float = 0.5, min_pocket: float = 0.0,
                   unknown_parts: tuple[np.ndarray, int] | None = None) -> np.ndarray:
    """Free cells (reachable from ``start``) 4-adjacent to unknown and not 8-adjacent to
    occupied; unknown pockets (4-connected) under ``min_pocket`` m^2 that do not touch the
    grid border do not count as unknown (the camera's blind ring around the robot, the
    shadow of a chair: not places to explore). ``unknown_parts``: :func:`unknown_parts`
    of ``occ``, when the caller has it."""
    reach = reachable_free(occ, start, snap)
    unknown = occ.grid == UNKNOWN
    max_cells = int(min_pocket / occ.resolution**2)
    if max_cells > 0 and unknown.any():
        lab, n = unknown_parts if unknown_parts is not None else _unknown_parts(occ)
        small = np.bincount(lab.ravel()) < max_cells
        small[0] = False
        small[_border_labels(lab)] = False
        unknown = unknown & ~small[lab]
    unknown = np.pad(unknown, 1, constant_values=True)
    next_unknown = (unknown[:-2, 1:-1] | unknown[2:, 1:-1] | unknown[1:-1, :-2]
                    | unknown[1:-1, 2:])
    return reach & next_unknown & ~near(occ.grid == OCCUPIED)


def _unknown_parts(occ: OccupancyGrid) -> tuple[np.ndarray, int]:
    """The 4-connected components of the unknown cells (labels, count)."""
    lab, n = ndimage.label(occ.grid == UNKNOWN, structure=_FOUR)
    return lab, int(n)


def _border_labels(lab: np.ndarray) -> np.ndarray:
    return np.unique(np.concatenate([lab[0], lab[-1], lab[:, 0], lab[:, -1]]))


def outside_footprint(occ: OccupancyGrid,
                      unknown_parts: tuple[np.ndarray, int] | None = None) -> np.ndarray:
    """Cells outside the hole-filled footprint of everything seen (free or occupied): the
    unknown cells 4-connected to the grid border (everything beyond the grid is unseen)."""
    lab, n = unknown_parts if unknown_parts is not None else _unknown_parts(occ)
    if n == 0:
        return occ.grid == UNKNOWN
    out = np.zeros(n + 1, dtype=bool)
    out[_border_labels(lab)] = True
    out[0] = False
    return out[lab]


def find_frontiers(occ: OccupancyGrid, start: tuple[float, float] | None = None,
                   config: FrontierConfig | None = None,
                   unknown_parts: tuple[np.ndarray, int] | None = None) -> list[Frontier]:
    """Frontier clusters in raster order of their medoid cells. ``unknown_parts``: the
    4-connected components of the unknown cells of ``occ`` (labels, an upper bound of the
    label values; any numbering), when the caller has them (the BEV's hole filling)."""
    cfg = config or FrontierConfig()
    parts = unknown_parts if unknown_parts is not None else _unknown_parts(occ)
    mask = frontier_cells(occ, start, cfg.snap, cfg.min_pocket, parts)
    if not mask.any():
        return []
    res = occ.resolution
    lab, n = ndimage.label(mask, structure=_EIGHT)
    outside = near(outside_footprint(occ, parts))
    min_cells = max(1, int(round(cfg.min_size / res)))
    max_cells = max(min_cells, int(round(cfg.max_size / res)))
    objs = ndimage.find_objects(lab)
    out: list[Frontier] = []
    for i, sl in enumerate(objs, start=1):
        if sl is None:
            continue
        rr, cc = np.nonzero(lab[sl] == i)
        rr = rr + sl[0].start
        cc = cc + sl[1].start
        if len(rr) < min_cells:
            continue
        for pr, pc in _split(rr, cc, max_cells):
            if len(pr) < min_cells:
                continue
            mr, mc = _medoid(pr, pc)
            x, y = occ.center_of(mr, mc)
            out.append(Frontier(
                cells=np.stack([pr, pc], axis=1), medoid=(float(x), float(y)),
                medoid_cell=(mr, mc), size=float(len(pr) * res),
                leading_out=bool(outside[pr, pc].any()),
            ))
    out.sort(key=lambda f: f.medoid_cell)
    return out


def _split(rr: np.ndarray, cc: np.ndarray, max_cells: int
           ) -> list[tuple[np.ndarray, np.ndarray]]:
    """Cut a cluster into ceil(k / max_cells) runs along its principal axis."""
    k = len(rr)
    parts = int(np.ceil(k / max_cells))
    if parts <= 1:
        return [(rr, cc)]
    pts = np.stack([rr, cc], axis=1).astype(np.float64)
    centred = pts - pts.mean(axis=0)
    cov = centred.T @ centred
    evals, evecs = np.linalg.eigh(cov)
    axis = evecs[:, int(np.argmax(evals))]
    if axis[0] < 0 or (axis[0] == 0 and axis[1] < 0):
        axis = -axis  # a sign convention, for determinism
    proj = centred @ axis
    order = np.lexsort((cc, rr, proj))
    chunks = np.array_split(order, parts)
    return [(rr[c], cc[c]) for c in chunks]


def _medoid(rr: np.ndarray, cc: np.ndarray, cap: int = 256) -> tuple[int, int]:
    k = len(rr)
    idx = np.arange(k) if k <= cap else np.linspace(0, k - 1, cap).round().astype(np.int64)
    r, c = rr[idx].astype(np.float64), cc[idx].astype(np.float64)
    d = np.hypot(r[:, None] - r[None, :], c[:, None] - c[None, :]).sum(axis=1)
    j = int(idx[int(np.argmin(d))])
    return int(rr[j]), int(cc[j])
