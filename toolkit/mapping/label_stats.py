"""Per-label statistics of the voxel map and their update by one frame.

Per label index the map keeps the points per frame (most, total), the frames it appeared
in, its last frame, and the closest viewpoint it was seen from: the xy distance from the
viewpoint to the mean x, y of its points in a frame with at least ``min_points`` of them
(MoMa-LLM keeps the closest viewpoint per object). The means are float sums over the
frame's points in pixel order (what ``np.bincount(labels, weights=wx)`` gives), so the
stored distances are bit for bit those sums' results.

Those two weighted sums over every point were a fifth of the integration, yet most
labels of a frame cannot come closer than they already were. The frame's distinct voxel
keys bound each label's mean within ``resolution`` (every point lies within half a voxel
of its voxel's centre on each axis, and the mean with it, so the xy distance moves by at
most ``sqrt(2)/2`` of a voxel, plus rounding far below that). A label whose bounded
distance cannot beat its stored one is left alone; the others get their exact sums, a
few alone (the points of the label in pixel order, summed sequentially by ``cumsum`` from
0.0, which is ``bincount``'s order) or all through the two bincounts.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

FEW = 2  # at most this many labels are summed alone; more go through the bincounts


@dataclass
class LabelStats:
    """Per label index arrays (grown on demand)."""

    size: int = 0
    points_max: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))
    points_total: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))
    frames: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))
    last_index: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))
    view_dist: np.ndarray = field(default_factory=lambda: np.zeros(0, np.float64))
    view_xy: np.ndarray = field(default_factory=lambda: np.zeros((0, 2), np.float64))
    vox_n: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))
    vox_sum: np.ndarray = field(default_factory=lambda: np.zeros((0, 3), np.int64))

    def grow(self, n: int) -> None:
        if n <= self.size:
            return
        m = max(n, 2 * self.size, 64)
        pad = m - self.size

        def ext(a: np.ndarray, fill: float) -> np.ndarray:
            shape = (pad,) + a.shape[1:]
            return np.concatenate([a, np.full(shape, fill, dtype=a.dtype)])

        self.points_max = ext(self.points_max, 0)
        self.points_total = ext(self.points_total, 0)
        self.frames = ext(self.frames, 0)
        self.last_index = ext(self.last_index, -1)
        self.view_dist = ext(self.view_dist, np.inf)
        self.view_xy = ext(self.view_xy, np.nan)
        self.vox_n = ext(self.vox_n, 0)
        self.vox_sum = ext(self.vox_sum, 0)
        self.size = m


def point_sums(labels: np.ndarray, ws: tuple[np.ndarray, ...], which: np.ndarray,
               counts: np.ndarray, n_lab: int) -> list[np.ndarray]:
    """Per array ``w`` of ``ws``: the sum of ``w`` over the points of each label in
    ``which`` (``counts`` points each), in point order from 0.0: exactly
    ``np.bincount(labels, weights=w, minlength=n_lab)[which]``. A few labels are summed
    alone; more, holding under half the points, by bincounts of their points only (the
    same order per label); else by bincounts of all points."""
    if len(which) <= FEW:
        out = [np.zeros(len(which), dtype=np.float64) for _ in ws]
        for j, lab in enumerate(which.tolist()):
            mask = labels == lab
            for o, w in zip(out, ws, strict=True):
                sel = w[mask]
                if sel.size:  # 0.0 + the sequential sum: bincount's, sign of zero included
                    o[j] = 0.0 + float(np.cumsum(sel)[-1])
        return out
    if 2 * int(counts.sum()) < labels.size:
        pick = np.zeros(n_lab, dtype=bool)
        pick[which] = True
        mask = pick[labels]
        labels = labels[mask]
        ws = tuple(w[mask] for w in ws)
    return [np.bincount(labels, weights=w, minlength=n_lab)[which] for w in ws]


def update_frame(st: LabelStats, pts: np.ndarray,
                 approx_xy: Callable[[], tuple[np.ndarray, np.ndarray]],
                 labels: np.ndarray, wx: np.ndarray, wy: np.ndarray, n_lab: int,
                 viewpoint: tuple[float, float], frame_index: int, min_points: int,
                 resolution: float) -> None:
    """Add one frame: ``pts`` its points per label index, ``approx_xy()`` the mean voxel
    centre (x, y) per label index (from the frame's distinct keys; asked for only when a
    label has ``min_points``), ``labels``, ``wx``, ``wy`` its points (module doc)."""
    st.grow(n_lab)
    present = np.flatnonzero(pts)
    present = present[present > 0]
    if present.size == 0:
        return
    p = pts[present]
    st.points_max[present] = np.maximum(st.points_max[present], p)
    st.points_total[present] += p
    st.frames[present] += 1
    st.last_index[present] = frame_index
    want = p >= min_points
    cand, pc = present[want], p[want]
    if cand.size == 0:
        return
    ax, ay = approx_xy()
    bound = np.hypot(ax[cand] - viewpoint[0], ay[cand] - viewpoint[1])
    maybe = bound - resolution < st.view_dist[cand]  # the exact distance could be smaller
    cand, pc = cand[maybe], pc[maybe]
    if cand.size == 0:
        return
    sx, sy = point_sums(labels, (wx, wy), cand, pc, n_lab)
    dist = np.hypot(sx / pc - viewpoint[0], sy / pc - viewpoint[1])
    better = dist < st.view_dist[cand]
    sel = cand[better]
    st.view_dist[sel] = dist[better]
    st.view_xy[sel] = viewpoint


@dataclass(frozen=True)
class InstanceObservation:
    """What the map knows of one instance id."""

    id: int
    max_points: int  # most points of it in one frame
    total_points: int
    frames: int  # frames it appeared in (kept when the map forgets it: it exists)
    last_index: int  # frame index of its last appearance
    viewpoint: tuple[float, float] | None  # closest viewpoint (x, y) among seen frames
    view_distance: float  # xy distance from that viewpoint to its points' centroid
    voxels: int  # distinct voxels it voted for
    centroid: tuple[float, float, float] | None  # mean of those voxels' centres
