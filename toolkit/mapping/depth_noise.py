"""How far a log's depth can be mapped before its noise reads the floor as obstacles.

Depth noise grows with depth (structured light and stereo cameras: sigma ~ z^2). The
bird's-eye map (:mod:`sgtool.mapping.bev`) calls a column an obstacle when it holds a
voxel more than ``floor_tolerance`` above the floor, so floor seen far away through noisy
depth becomes a field of phantom obstacles, and past some noise the map has no free floor
left for its Voronoi graph.

The noise can be read off the log itself. Nothing stands below the floor, so the points of
a frame below the floor are floor points moved down by noise: with the floor at height
``f``, the heights ``h < f`` of the floor points whose pixel rays meet the floor at depth
``z`` scatter as a half-normal whose median is ``HALF_NORMAL_MEDIAN`` (the median of
``|N(0, 1)|``) times the vertical noise at that depth,

    sigma_v(z) = median(f - h over the points with h < f at depth z) / HALF_NORMAL_MEDIAN
                                                                                  (N1)

(obstacles only add points above the floor, so they do not bias it; the median, not the
RMS, so that points below the floor that are no noise, a sunken area, a step down, a floor
seen through a glass table, move it little while they are a minority of the points below
the floor at that depth, which under noise hold half the floor's; the pixels are grouped
by the depth at which their rays meet the floor, which does not move with their depth
errors, not by their measured depth, which does). The usable depth is
where ``k`` sigma_v stays within the floor tolerance:

    z_max = the lower edge of the first depth bin with k sigma_v(z) > tolerance   (N2)

Noise moves about half the floor's points below it; a depth bin whose points below the
floor are far fewer than that holds no noise to measure, only a sunken area or a step
down seen there, and is left out:

    points below the floor >= BELOW_SHARE x points within PEAK of it, per bin     (N3)

The floor ``f`` is found as the bird's-eye map finds it (the lowest height level holding
at least half as many points as the fullest one) and measured only when it is where
sgtool's logs put it, at height 0 (recorded in simulation, or imported: the importers
level the world and move the floor there); then it is the median height of the points
within ``PEAK`` of 0. A log whose floor is elsewhere (written by other software with its
own conventions) or hardly seen is not measured, nor one with too few points below the
floor. The depth kept is at least ``MIN_DEPTH`` (what surrounds the robot is always
mapped). A floor that is not level in the world frame scatters too and is cut the same
way: far from the camera it would read as obstacles as well.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np
from scipy import ndimage

from sgtool.mapping.bev import estimate_floor_level

LEVEL = 0.05  # m; height levels of the floor search (a voxel)
PEAK = 0.1  # m; points this close to height 0 find the floor
WINDOW = 10.0  # m; heights the floor search looks at, either side of 0
MAX_BINS = 400  # depth bins (100 m): farther floor depths share the last
BIN = 0.25  # m; depth bins of (N1)
MIN_BELOW = 50  # points below the floor for a depth bin to count
MIN_FLOOR = 500  # points near height 0 for a floor
SIGMAS = 4.0  # k of (N2)
HALF_NORMAL_MEDIAN = 0.6745  # the median of |N(0, 1)|
BELOW_SHARE = 0.3  # (N3): least points below the floor per point at it (noise: about 0.5)
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
        return (f"depth noise: floor points scatter {far} (noise, or depth and poses "
                f"that disagree: a depth scale, calibration or clock error); depth mapped "
                f"to {self.max_depth:g} m, where {SIGMAS:g} sigma reaches the floor "
                "tolerance (--max-depth to choose)")


@dataclass(frozen=True)
class FramePoints:
    """What (N1) needs of one frame: the world heights ``h`` of its sampled pixels, the
    height each pixel's ray gains per metre of depth (``slope``), and the camera's height
    ``camera_z``."""

    h: np.ndarray
    slope: np.ndarray
    camera_z: float

    def floor_depths(self, floor: float) -> np.ndarray:
        """The depth at which each pixel's ray meets the height ``floor`` (inf for rays
        that do not descend to it): unlike the measured depth it does not move with the
        pixel's depth error, so binning by it does not sort the errors (a bin of measured
        depth keeps the floor points that erred into it)."""
        drop = floor - self.camera_z
        if drop >= 0:
            return np.full(self.h.shape, np.inf)
        with np.errstate(divide="ignore"):
            return np.where(self.slope < 0, drop / np.minimum(self.slope, -1e-12), np.inf)


def frame_points(depth: np.ndarray, pose: np.ndarray, fx: float, fy: float, cx: float,
                 cy: float, stride: int = 2) -> FramePoints:
    """The :class:`FramePoints` of every ``stride``-th pixel in each direction with a
    finite positive depth, ``pose`` world_T_camera (OpenCV camera axes)."""
    d = np.asarray(depth)[::stride, ::stride].astype(np.float64)
    v, u = np.mgrid[0:depth.shape[0]:stride, 0:depth.shape[1]:stride]
    ok = np.isfinite(d) & (d > 0)
    T = np.asarray(pose, dtype=np.float64)  # noqa: N806
    slope = T[2, 0] * (u[ok] - cx) / fx + T[2, 1] * (v[ok] - cy) / fy + T[2, 2]
    return FramePoints(T[2, 3] + slope * d[ok], slope, float(T[2, 3]))


def floor_height(h: np.ndarray) -> float | None:
    """The floor, when it is at height 0 (module doc): the lowest ``LEVEL`` level of the
    heights within ``WINDOW`` of 0 holding at least half as many points as the fullest
    one, as the bird's-eye map finds it; if that level lies within ``PEAK`` of 0, the
    median of the heights within ``PEAK`` of 0, else None (a floor elsewhere); None with
    fewer than ``MIN_FLOOR`` points there."""
    h = h[np.isfinite(h) & (np.abs(h) <= WINDOW)]  # (a stray pose: no huge histogram)
    if h.size < MIN_FLOOR:
        return None
    lv = np.floor(h / LEVEL).astype(np.int64)
    lo = int(lv.min())
    found = estimate_floor_level(lo, np.bincount(lv - lo))
    near = h[np.abs(h) <= PEAK]
    if found is None or abs((found + 0.5) * LEVEL) > PEAK or near.size < MIN_FLOOR:
        return None
    return float(np.median(near))


def estimate(samples: Iterable[FramePoints], tolerance: float,
             *, sigmas: float = SIGMAS, ceiling: float | None = None) -> DepthNoise | None:
    """(N1)-(N2) over frames (:func:`frame_points`); ``ceiling``: a ``max_depth`` at or
    beyond it is reported as None (nothing to lower). None when the floor is not at
    height 0 or too few points lie below it (module doc)."""
    frames = list(samples)
    if not frames:
        return None
    f = floor_height(np.concatenate([fp.h for fp in frames]))
    if f is None:
        return None
    below = _below_floor(frames, f)
    if below is None:
        return None
    keep, sigma = below
    edges = keep * BIN
    return DepthNoise(floor=round(f, 4), depths=tuple(float(e) for e in edges),
                      sigma=tuple(round(float(s), 4) for s in sigma),
                      max_depth=cut_depth(edges, sigma, tolerance, sigmas, ceiling))


def _below_floor(frames: list[FramePoints], f: float
                 ) -> tuple[np.ndarray, np.ndarray] | None:
    """(N1) below the floor ``f`` (within ``BELOW_LIMIT``): the depth bins with at least
    ``MIN_BELOW`` points and their median depth below the floor over the half-normal's
    median; None without."""
    zb_parts, db_parts, za_parts = [], [], []
    for fp in frames:
        below = (fp.h < f) & (fp.h > f - BELOW_LIMIT)
        zf = fp.floor_depths(f)
        good = np.isfinite(zf[below])
        zb_parts.append(zf[below][good])
        db_parts.append(f - fp.h[below][good])
        at = (np.abs(fp.h - f) <= PEAK) & np.isfinite(zf)  # the floor at that depth
        za_parts.append(zf[at])
    zb, db = np.concatenate(zb_parts), np.concatenate(db_parts)
    if zb.size == 0:
        return None
    bins = np.floor(np.minimum(zb, MAX_BINS * BIN) / BIN).astype(np.int64)
    n = np.bincount(bins)
    za = np.concatenate(za_parts)
    at_floor = np.bincount(np.floor(np.minimum(za, MAX_BINS * BIN) / BIN).astype(np.int64),
                           minlength=n.size)[:n.size]
    # (N3) under noise about half the floor's points lie below it; far fewer: no noise
    keep = np.flatnonzero((n >= MIN_BELOW) & (n >= BELOW_SHARE * at_floor))
    if keep.size == 0:
        return None
    medians = ndimage.median(db, labels=bins, index=keep)
    return keep, np.asarray(medians, dtype=np.float64) / HALF_NORMAL_MEDIAN


def cut_depth(edges: np.ndarray, sigma: np.ndarray, tolerance: float,
              sigmas: float = SIGMAS, ceiling: float | None = None) -> float | None:
    """(N2): the lower edge ``edges`` of the first depth bin whose vertical noise ``sigma``
    times ``sigmas`` passes ``tolerance``, at least ``MIN_DEPTH``; None when no bin does
    or the cut lies at or beyond ``ceiling``."""
    over = np.flatnonzero(sigmas * np.asarray(sigma) > tolerance)
    if over.size == 0:
        return None
    max_depth = max(MIN_DEPTH, float(np.asarray(edges)[over[0]]))
    return None if ceiling is not None and max_depth >= ceiling else max_depth


def sensor_max_depth(depth_sigma: float, camera_height: float, tolerance: float,
                     *, sigmas: float = SIGMAS, ceiling: float | None = None) -> float | None:
    """(N2) for a camera whose depth error has the std ``depth_sigma * z^2`` (a datasheet
    figure, or :class:`sgtool.recorders.sim.noise.NoiseProfile`), mounted
    ``camera_height`` above a level floor: a depth error ``e`` moves a floor point seen at
    depth ``z`` by ``e * camera_height / z`` vertically, whatever the camera's tilt, so
    the vertical noise is ``sigma_v(z) = depth_sigma * camera_height * z``, taken at the
    far edge of each bin of (N1) (so the cut is the bin edge at or before the exact one).
    None as :func:`cut_depth` (no noise: None)."""
    if depth_sigma <= 0:
        return None
    edges = np.arange(MAX_BINS) * BIN
    return cut_depth(edges, depth_sigma * camera_height * (edges + BIN), tolerance,
                     sigmas, ceiling)
