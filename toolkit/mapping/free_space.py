"""Projective free-space evidence: voxels that later depth rays see through lose their votes.

A depth pixel says two things: something is at its depth, and the space in front of it
along its ray is free. The voxel map counts the first (votes); this module counts the
second, OctoMap-style (Hornung et al. 2013: hits and misses per voxel, clamped), for the
voxels that can be noise: a depth error, a mixed pixel, a door panel seen mid-swing
leaves a voxel with a few votes in free space, and in the bird's-eye view one vote in the
height band makes its column an obstacle for good.

Instead of tracing every ray through the grid (OctoMap), the test is projective (as a
TSDF update): a voxel centre is projected into a view; when the view's depth at that
pixel is farther than the centre by more than ``margin``, the view saw through it (a
miss). The depth used is the smallest over the voxel's whole image (the *near depth*
over a square of its projected half-diagonal: the smallest depth of each pixel's
(2 r + 1)^2 neighbourhood, 0 where any of them has no valid depth, the border's pixels
repeated beyond the image), so a ray grazing a thin thing or passing
beside a surface never clears the voxel holding it, and a pixel without depth (a hole,
out of range) is no evidence either way. Only *weak* voxels
(at most ``weak_votes`` votes) are tested: a voxel with more is a surface seen many
times, kept whatever the misses (the clamping, which bounds the work too). A weak voxel
goes when its misses reach its votes.

Pure functions; the voxel map keeps the counts
(:meth:`~sgtool.mapping.voxels.VoxelMap.clear_seen_through`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from sgtool.log.frame import CameraIntrinsics


@dataclass(frozen=True)
class FreeSpaceConfig:
    margin: float = 0.15  # m: a view sees through a voxel when its depth is this much beyond
    weak_votes: int = 4  # voxels with more votes are never cleared (clamping)


RADII = (1, 2, 4, 8)  # pixel half-widths of the neighbourhoods a view keeps


@dataclass(frozen=True, eq=False)
class View:
    """One depth frame as free-space evidence: camera-to-world ``pose`` (4 x 4, optical
    axes: x right, y down, z forward), intrinsics and the near depth (module doc) of its
    depth at every radius of ``RADII`` (``levels[i]``: float32 m, 0 = no evidence)."""

    pose: np.ndarray
    intrinsics: CameraIntrinsics
    levels: np.ndarray  # (len(RADII), h, w)

    @classmethod
    def of(cls, pose: np.ndarray, intrinsics: CameraIntrinsics, depth: np.ndarray,
           min_range: float) -> View:
        """The view of a depth image: its near depth at every radius of ``RADII`` (depths
        below ``min_range`` or not finite are invalid), each grown from the one before by
        repeated 3 x 3 minima."""
        d = np.asarray(depth, dtype=np.float32)
        level = np.where(np.isfinite(d) & (d >= min_range), d, np.float32(0.0))
        levels = []
        r = 0
        for want in RADII:
            while r < want:
                level = _min3(level)
                r += 1
            levels.append(level)
        return cls(np.asarray(pose, dtype=np.float64), intrinsics, np.stack(levels))


def _min3(a: np.ndarray) -> np.ndarray:
    """The minimum over each pixel's 3 x 3 neighbourhood (border pixels repeat)."""
    b = a.copy()
    np.minimum(b[1:], a[:-1], out=b[1:])
    np.minimum(b[:-1], a[1:], out=b[:-1])
    c = b.copy()
    np.minimum(c[:, 1:], b[:, :-1], out=c[:, 1:])
    np.minimum(c[:, :-1], b[:, 1:], out=c[:, :-1])
    return c


def seen_through(centres: np.ndarray, view: View, margin: float, min_range: float,
                 max_range: float, resolution: float) -> np.ndarray:
    """Bool (n,): which voxels of edge ``resolution`` centred at the world points
    ``centres`` (n, 3) the ``view`` saw through: in front of the camera between
    ``min_range`` and ``max_range``, inside the image, and the depth everywhere over the
    voxel's image (a square of the projected half-diagonal, the smallest radius of
    ``RADII`` that covers it; a voxel nearer than that covers is no evidence) beyond the
    centre's depth by more than ``margin`` (module doc)."""
    n = len(centres)
    if n == 0:
        return np.zeros(0, dtype=bool)
    pose = np.asarray(view.pose, dtype=np.float64)
    rot, t = pose[:3, :3], pose[:3, 3]
    cam = (centres - t) @ rot  # R^T (p - t), row vectors
    z = cam[:, 2]
    k = view.intrinsics
    h, w = view.levels.shape[1:]
    ok = (z >= min_range) & (z < max_range)
    idx = np.flatnonzero(ok)
    if not len(idx):
        return np.zeros(n, dtype=bool)
    zi = z[idx]
    u = np.rint(k.fx * cam[idx, 0] / zi + k.cx)
    v = np.rint(k.fy * cam[idx, 1] / zi + k.cy)
    half = np.ceil(max(k.fx, k.fy) * resolution * (3 ** 0.5 / 2) / zi)  # pixels
    level = np.searchsorted(np.asarray(RADII), half)  # the first radius >= half
    inside = (u >= 0) & (u < w) & (v >= 0) & (v < h) & (level < len(RADII))
    idx, zi, level = idx[inside], zi[inside], level[inside]
    ui, vi = u[inside].astype(np.int64), v[inside].astype(np.int64)
    d = view.levels[level, vi, ui]
    out = np.zeros(n, dtype=bool)
    out[idx] = (d > 0) & (d > zi + margin)
    return out
