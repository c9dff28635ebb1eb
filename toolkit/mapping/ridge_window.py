"""The Voronoi ridge cells (step 1 of :mod:`sgtool.mapping.voronoi`) recomputed only where
the free space changed, with the same result as computing them from scratch.

Between two refreshes the free cells change in a small window around where the camera looked
(a small share of a house's grid), but the distance field with its nearest obstacles (the
feature transform) and the ridge cells were computed over the whole grid.
:func:`update_fields` recomputes them in a window around the changed cells and keeps the
rest, exactly:

- **Distance field.** Let D be the bounding box of the cells whose freedom changed. A
  cell whose old distance to its nearest obstacle is *less than* its distance to D keeps
  its distance and nearest obstacle: its old nearest obstacles are unchanged, and every
  cell that became (or stopped being) an obstacle is strictly farther. The window W is D
  grown by a margin; outside W the margin exceeds every old distance (checked). Inside W
  the field is recomputed by scipy on W alone, the ring around W counting as obstacles
  (as the grid's own border does); a cell whose distance there is *less than* its
  distance to that ring (on the sides where W does not reach the grid's border) has
  exactly the nearest obstacles it has in the whole grid, and scipy's choice among tied
  nearest obstacles depends only on those (their relative positions; checked against
  the whole grid in the tests). Every cell of W must satisfy one of the two rules, else
  the margin doubles (up to the whole grid: then everything is recomputed).
- **Ridge cells.** A cell's flag depends only on its own and its four neighbours'
  values (:func:`ridge_from_fields`), so the flags are recomputed on the bounding box of
  the cells whose values changed, grown by two cells, and its interior is kept.

From scratch (:func:`ridge_fields`) the field is computed on the free cells' bounding
box grown by one cell: cells outside it are obstacles (distance 0, their own nearest
obstacle), and the ring of obstacles (or the grid's border) around the box is strictly
nearer to any free cell than whatever lies beyond it, so the distances and nearest
obstacles in the box are those of the whole grid (checked cell for cell in the tests).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from sgtool.mapping.esdf import distance_field

if TYPE_CHECKING:
    from sgtool.mapping.voronoi import VoronoiConfig


@dataclass(frozen=True, eq=False)
class RidgeFields:
    """The distance field and ridge cells of one free-cell grid (module doc)."""

    free: np.ndarray  # bool (H, W)
    feat: np.ndarray  # (2, H, W) int32 row, col of the nearest obstacle (-1, H, W: border)
    d2: np.ndarray  # (H, W) int64 squared distance in cells
    dist_m: np.ndarray  # (H, W) distance in metres
    ridge0: np.ndarray  # (H, W) bool ridge cells before thinning
    resolution: float
    config: VoronoiConfig


def _own_cells(h: int, w: int) -> np.ndarray:
    feat = np.empty((2, h, w), dtype=np.int32)
    feat[0] = np.arange(h, dtype=np.int32)[:, None]
    feat[1] = np.arange(w, dtype=np.int32)[None, :]
    return feat


def _squared(feat: np.ndarray) -> np.ndarray:
    """Squared distance (cells) from every cell to its ``feat`` cell."""
    h, w = feat.shape[1:]
    dr = feat[0].astype(np.int64) - np.arange(h, dtype=np.int64)[:, None]
    dc = feat[1].astype(np.int64) - np.arange(w, dtype=np.int64)[None, :]
    return dr * dr + dc * dc


def ridge_fields(free: np.ndarray, resolution: float, config: VoronoiConfig) -> RidgeFields:
    """The fields from scratch (module doc)."""
    h, w = free.shape
    feat = _own_cells(h, w)
    dist_m = np.zeros((h, w))
    ridge0 = np.zeros((h, w), dtype=bool)
    rows = np.flatnonzero(free.any(axis=1))
    if rows.size:
        cols = np.flatnonzero(free.any(axis=0))
        r0, r1 = max(int(rows[0]) - 1, 0), min(int(rows[-1]) + 2, h)
        c0, c1 = max(int(cols[0]) - 1, 0), min(int(cols[-1]) + 2, w)
        box = free[r0:r1, c0:c1]
        dm, f = distance_field(~box, resolution, with_features=True)
        assert f is not None
        ridge0[r0:r1, c0:c1] = ridge_from_fields(box, dm, f, resolution, config)
        dist_m[r0:r1, c0:c1] = dm
        feat[0, r0:r1, c0:c1] = f[0] + r0
        feat[1, r0:r1, c0:c1] = f[1] + c0
    return RidgeFields(free.copy(), feat, _squared(feat), dist_m, ridge0, resolution, config)


def _max_outside(a: np.ndarray, r0: int, r1: int, c0: int, c1: int) -> int:
    """The largest value of ``a`` outside rows r0:r1 x cols c0:c1 (-1 when none)."""
    parts = [a[:r0], a[r1:], a[r0:r1, :c0], a[r0:r1, c1:]]
    return max((int(p.max()) for p in parts if p.size), default=-1)


def update_fields(prev: RidgeFields, free: np.ndarray, resolution: float,
                  config: VoronoiConfig) -> RidgeFields | None:
    """The fields of ``free`` from those of an earlier grid of the same shape (module
    doc); None when they must be computed from scratch (another shape, resolution or
    config, or a change whose window would be the whole grid)."""
    if (prev.free.shape != free.shape or prev.resolution != resolution
            or prev.config != config):
        return None
    changed = prev.free != free
    rows = np.flatnonzero(changed.any(axis=1))
    if rows.size == 0:
        return prev
    cols = np.flatnonzero(changed.any(axis=0))
    h, w = free.shape
    dr0, dr1, dc0, dc1 = int(rows[0]), int(rows[-1]) + 1, int(cols[0]), int(cols[-1]) + 1
    margin = math.isqrt(int(prev.d2.max())) + 2  # beyond every old distance
    while True:
        r0, r1 = max(dr0 - margin, 0), min(dr1 + margin, h)
        c0, c1 = max(dc0 - margin, 0), min(dc1 + margin, w)
        if (r0, r1, c0, c1) == (0, h, 0, w):
            return None
        if _max_outside(prev.d2, r0, r1, c0, c1) < margin * margin:
            got = _window(prev, free, resolution, (r0, r1, c0, c1), (dr0, dr1, dc0, dc1))
            if got is not None:
                return got
        margin *= 2


def _window(prev: RidgeFields, free: np.ndarray, resolution: float,
            win: tuple[int, int, int, int], box: tuple[int, int, int, int]
            ) -> RidgeFields | None:
    """The fields recomputed in the window ``win`` around the changed box ``box``; None
    when a cell of the window satisfies neither rule of the module doc."""
    h, w = free.shape
    r0, r1, c0, c1 = win
    dr0, dr1, dc0, dc1 = box
    sub = free[r0:r1, c0:c1]
    dm, f = distance_field(~sub, resolution, with_features=True)
    assert f is not None
    hh, ww = sub.shape
    d2w = _squared(f)
    rr = np.arange(hh, dtype=np.int64)[:, None]
    cc = np.arange(ww, dtype=np.int64)[None, :]
    far = np.int64(h + w + 2)  # a side on the grid's border has no stand-in obstacles
    ring = np.minimum(np.minimum(rr + 1 if r0 > 0 else far, hh - rr if r1 < h else far),
                      np.minimum(cc + 1 if c0 > 0 else far, ww - cc if c1 < w else far))
    exact = d2w < ring * ring
    gr, gc = rr + r0, cc + c0
    br = np.maximum(np.maximum(dr0 - gr, gr - (dr1 - 1)), 0)
    bc = np.maximum(np.maximum(dc0 - gc, gc - (dc1 - 1)), 0)
    old_d2 = prev.d2[r0:r1, c0:c1]
    unchanged = br * br + bc * bc > old_d2
    if not (exact | unchanged).all():
        return None
    feat, d2, dist_m = prev.feat.copy(), prev.d2.copy(), prev.dist_m.copy()
    fw = feat[:, r0:r1, c0:c1]
    moved = exact & ((fw[0] != f[0] + r0) | (fw[1] != f[1] + c0) | (old_d2 != d2w)
                     | (dist_m[r0:r1, c0:c1] != dm))
    moved |= prev.free[r0:r1, c0:c1] != sub
    fw[0][exact] = f[0][exact] + r0
    fw[1][exact] = f[1][exact] + c0
    d2[r0:r1, c0:c1][exact] = d2w[exact]
    dist_m[r0:r1, c0:c1][exact] = dm[exact]
    ridge0 = prev.ridge0.copy()
    mr = np.flatnonzero(moved.any(axis=1))
    if mr.size:
        mc = np.flatnonzero(moved.any(axis=0))
        # the flags of the moved cells and their neighbours, from a box two cells wider
        a0, a1 = max(r0 + int(mr[0]) - 2, 0), min(r0 + int(mr[-1]) + 3, h)
        b0, b1 = max(c0 + int(mc[0]) - 2, 0), min(c0 + int(mc[-1]) + 3, w)
        local = feat[:, a0:a1, b0:b1] - np.asarray([a0, b0], dtype=np.int32)[:, None, None]
        flags = ridge_from_fields(free[a0:a1, b0:b1], dist_m[a0:a1, b0:b1], local,
                                  resolution, prev.config)
        i0, i1 = (1 if a0 > 0 else 0), flags.shape[0] - (1 if a1 < h else 0)
        j0, j1 = (1 if b0 > 0 else 0), flags.shape[1] - (1 if b1 < w else 0)
        ridge0[a0 + i0:a0 + i1, b0 + j0:b0 + j1] = flags[i0:i1, j0:j1]
    return RidgeFields(free.copy(), feat, d2, dist_m, ridge0, resolution, prev.config)


def ridge_from_fields(free: np.ndarray, dist_m: np.ndarray, feat: np.ndarray,
                      resolution: float, config: VoronoiConfig) -> np.ndarray:
    """The ridge cells of ``free`` from its distance field and nearest-obstacle cells
    (``feat``, in the coordinates of ``free``). A cell's flag depends only on its own and
    its four neighbours' values, so a sub-array gives its interior's flags."""
    h, w = free.shape
    ridge = np.zeros((h, w), dtype=bool)
    ok = free & (dist_m >= config.min_clearance)
    fr = feat[0].astype(np.int32).ravel()
    fc = feat[1].astype(np.int32).ravel()
    dflat = dist_m.ravel() / resolution
    okf = ok.ravel()
    min_sep = config.min_ridge / resolution
    for step in (1, w):  # right and down neighbours in flat indices
        a = np.flatnonzero(okf[:-step] & okf[step:])
        if step == 1:
            a = a[(a % w) != w - 1]  # no wrap-around between rows
        b = a + step
        sep2 = (fr[a] - fr[b]) ** 2 + (fc[a] - fc[b]) ** 2
        thr = np.maximum(min_sep, config.ridge_ratio * np.minimum(dflat[a], dflat[b]))
        keep = sep2 > thr * thr
        a, b = a[keep], b[keep]
        if a.size == 0:
            continue
        # imbalance: how much farther the other cell's obstacle is than one's own
        ra, ca = np.divmod(a, w)
        rb, cb = np.divmod(b, w)
        imb_a = np.hypot(ra - fr[b], ca - fc[b]) - dflat[a]
        imb_b = np.hypot(rb - fr[a], cb - fc[a]) - dflat[b]
        pick_a = imb_a <= imb_b
        ridge.ravel()[a[pick_a]] = True
        ridge.ravel()[b[~pick_a]] = True
    return ridge
