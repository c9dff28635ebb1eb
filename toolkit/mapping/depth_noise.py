"""How far a log's depth can be mapped before its noise reads the floor as obstacles.

Depth noise grows with depth (structured light and stereo cameras: sigma ~ z^2). The
bird's-eye map (:mod:`sgtool.mapping.bev`) calls a column an obstacle when it holds a
voxel more than ``floor_tolerance`` above the floor, so floor seen far away through noisy
depth becomes a field of phantom obstacles, and past some noise the map has no free floor
left for its Voronoi graph.

The noise can be read off the log itself. Nothing stands below the floor, so the points of
a frame below the floor are floor points moved down by noise: with the floor at height
``f``, the heights ``h < f`` of the floor points whose pixel rays meet the floor at depth
``z`` scatter as a half-normal whose second moment is the vertical noise at that depth,

    sigma_v(z) = sqrt(mean((f - h)^2 over the points with h < f at depth z))      (N1)

(the pixels are grouped by the depth at which their rays meet the floor, which does not
move with their depth errors, not by their measured depth, which does).

(obstacles only add points above the floor, so they do not bias it). The usable depth is
where ``k`` sigma_v stays within the floor tolerance:

    z_max = the lower edge of the first depth bin with k sigma_v(z) > tolerance   (N2)

The floor ``f`` is where sgtool's logs put it, at height 0 (recorded in simulation, or
imported: the importers level the world and move the floor there), refined to the median
height of the points within ``PEAK`` of 0; a log with too few points there (a floor
elsewhere, or hardly seen) is not measured. It is also not measured when too few points fall below
the floor. The depth kept is at least ``MIN_DEPTH`` (what surrounds the robot is always
mapped). A floor that is not level in the world frame scatters too and is cut the same
way: far from the camera it would read as obstacles as well.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np

PEAK = 0.1  # m; points this close to height 0 find the floor
BIN = 0.25  # m; depth bins of (N1)
MIN_BELOW = 50  # points below the floor for a depth bin to count
MIN_FLOOR = 500  # points near height 0 for a floor
SIGMAS = 4.0  # k of (N2)
BELOW_LIMIT = 1.0  # m; points further below the floor are not floor (stairs, reflections)
MIN_DEPTH = 1.0  # m; the least depth kept: what is around the robot is always mapped


@dataclass(frozen=True)
class DepthNoise:
    """What (N1)-(N2) found: the floor height ``floor`` (m), the vertical noise
    ``sigma`` (m) of each depth bin with enough points, keyed by the bin's lower edge
    ``depths`` (m), and ``max_depth``: the depth to map to (None when every measured bin
    is within the tolerance)."""

    floor: float
    depths: tuple[float, ...]
    sigma: tuple[float, ...]
    max_depth: float | None

    def describe(self) -> str:
        """One line: the noise at the farthest measured bin and the depth chosen."""
        far = f"{self.sigma[-1]:.2f} m (1 sigma) at {self.depths[-1] + BIN / 2:g} m"
        if self.max_depth is None:
            return f"depth noise: floor points scatter {far}; within the floor tolerance"
        return (f"depth noise: floor points scatter {far}; depth mapped to "
                f"{self.max_depth:g} m, where {SIGMAS:g} sigma reaches the floor tolerance "
                "(--max-depth to choose)")


def frame_heights(depth: np.ndarray, pose: np.ndarray, fx: float, fy: float, cx: float,
                  cy: float, stride: int = 2) -> tuple[np.ndarray, np.ndarray]:
    """(floor depth, world height) of every ``stride``-th pixel in each direction with a
    finite positive depth, ``pose`` world_T_camera (OpenCV camera axes). The floor depth
    of a pixel is the depth at which its ray meets height 0 (inf for rays that do not
    descend): unlike the measured depth it does not move with the pixel's depth error,
    so binning by it does not sort the errors (a bin of measured depth keeps the floor
    points that erred into it)."""
    d = np.asarray(depth)[::stride, ::stride].astype(np.float64)
    v, u = np.mgrid[0:depth.shape[0]:stride, 0:depth.shape[1]:stride]
    ok = np.isfinite(d) & (d > 0)
    z = d[ok]
    T = np.asarray(pose, dtype=np.float64)  # noqa: N806
    slope = T[2, 0] * (u[ok] - cx) / fx + T[2, 1] * (v[ok] - cy) / fy + T[2, 2]
    h = T[2, 3] + slope * z
    with np.errstate(divide="ignore"):
        zf = np.where(slope < 0, -T[2, 3] / np.minimum(slope, -1e-12), np.inf)
    return zf, h


def floor_height(h: np.ndarray) -> float | None:
    """The floor: the median of the heights within ``PEAK`` m of 0 (module doc); None
    with fewer than ``MIN_FLOOR`` such points."""
    near = h[np.abs(h) <= PEAK]
    return float(np.median(near)) if near.size >= MIN_FLOOR else None


def estimate(samples: Iterable[tuple[np.ndarray, np.ndarray]], tolerance: float,
             *, sigmas: float = SIGMAS, ceiling: float | None = None) -> DepthNoise | None:
    """(N1)-(N2) over (floor depth, height) samples (:func:`frame_heights`); ``ceiling``: a
    ``max_depth`` at or beyond it is reported as None (nothing to lower). None when the
    floor cannot be found or is not sharp near the camera (module doc)."""
    pairs = [(np.asarray(z, dtype=np.float64), np.asarray(h, dtype=np.float64))
             for z, h in samples]
    if not pairs:
        return None
    z = np.concatenate([p[0] for p in pairs])
    h = np.concatenate([p[1] for p in pairs])
    f = floor_height(h)
    if f is None:
        return None
    below = (h < f) & (h > f - BELOW_LIMIT)
    zb, db = z[below], f - h[below]
    bins = np.floor(zb / BIN).astype(np.int64)
    if bins.size == 0:
        return None
    n = np.bincount(bins)
    ss = np.bincount(bins, weights=db * db)
    keep = np.flatnonzero(n >= MIN_BELOW)
    if keep.size == 0:
        return None
    sigma = np.sqrt(ss[keep] / n[keep])
    edges = keep * BIN
    over = sigmas * sigma > tolerance
    max_depth = max(MIN_DEPTH, float(edges[np.flatnonzero(over)[0]])) if over.any() else None
    if max_depth is not None and ceiling is not None and max_depth >= ceiling:
        max_depth = None
    return DepthNoise(floor=round(f, 4), depths=tuple(float(e) for e in edges),
                      sigma=tuple(round(float(s), 4) for s in sigma), max_depth=max_depth)
