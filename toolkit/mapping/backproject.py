"""Depth pixels to packed voxel keys, in cache-sized blocks with reused buffers.

The arithmetic is exactly that of the plain formulation, operation for operation in
float64 (so the keys are bit for bit those of ``floor((T @ [ru*z, rv*z, z, 1]) / size)``
evaluated elementwise as ``T[r,0]*xc + T[r,1]*yc + T[r,2]*z + T[r,3]``, left to right):

    xc = ru * z;  yc = rv * z
    w_r = ((T[r,0] * xc + T[r,1] * yc) + T[r,2] * z) + T[r,3]      (r = 0, 1, 2)
    v_r = floor(w_r * (1 / size))

What changes is only where the numbers live: the points are processed in blocks of
``BLOCK`` so every temporary stays in the CPU cache, and every buffer is allocated once
per image size (no page faults from fresh 2-3 MB arrays per frame). The packing adds the
fields instead of or-ing them (they do not overlap once the caller has checked the range)
and folds the axis offsets into one constant.

The packing is done in float64, not int64: numpy's float -> int64 conversion costs ten
times a multiplication, and it took three per point. The fields ``v_r + offset`` (each
below ``2**17``) are scaled by powers of two into one float sum, in units of
``2**min(shifts)``: every term and partial sum is an integer below ``2**51``, so every
addition is exact and the sum is the packed integer itself. Adding ``2**52`` puts that
integer into the low mantissa bits, where reading the float's bits as an int64 and
subtracting those of ``2**52`` recovers it; one shift gives the key. No conversion is
left, and the keys are the same integers as ``(v_x + o) << sx | (v_y + o) << sy | ...``.
Points outside the packing give meaningless keys (the caller refuses such a frame:
:func:`beyond_packing`).
"""

from __future__ import annotations

import numpy as np

from sgtool.errors import SgtoolError

BLOCK = 32768  # points per block: the 5 float64 temporaries (256 KiB each) stay in L2
_MAGIC = 2.0 ** 52  # integers in [0, 2**52) are the low mantissa bits of MAGIC + them
_MAGIC_BITS = int(np.array(_MAGIC).view(np.int64))
_EXACT_BITS = 51  # the packed sum stays below 2**51: every float addition is exact


class Scratch:
    """Buffers reused from frame to frame (grown on demand; not thread-safe)."""

    def __init__(self) -> None:
        self.n = 0
        self._alloc(BLOCK)

    def _alloc(self, n: int) -> None:
        self.n = n
        self.wx = np.empty(n, np.float64)  # world x of every point
        self.wy = np.empty(n, np.float64)  # world y
        self.wz = np.empty(n, np.float64)  # world z
        self.keys = np.empty(n, np.int64)  # voxel part of the key
        b = BLOCK
        self.z = np.empty(b, np.float64)
        self.xc = np.empty(b, np.float64)
        self.yc = np.empty(b, np.float64)
        self.t = np.empty(b, np.float64)
        self.kf = np.empty(b, np.float64)  # the packed key as an exact float

    def ensure(self, n: int) -> None:
        if n > self.n:
            self._alloc(max(n, 2 * self.n))


def world_voxels(depth: np.ndarray, idx: np.ndarray | None, ru: np.ndarray, rv: np.ndarray,
                 pose: np.ndarray, inv: float, shifts: tuple[int, int, int], offset: int,
                 s: Scratch, need_range: bool = True
                 ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, list[float]]:
    """World x, y, z (float64) and packed voxel keys without the label (int64) of the
    pixels ``idx`` of the flat ``depth`` (None: every pixel, read in place, no gathers;
    for a caller that discards the invalid ones itself), plus the voxel index range as
    floats (min x, max x, min y, max y, min z, max z). Views into ``s``: valid until the
    next call. The keys are meaningful only when the range is finite and fits the packing
    (the caller checks and falls back to ``wx, wy, wz`` otherwise). Without
    ``need_range`` (the caller has bounded the points, :func:`within_packing`) the range is
    not computed (empty)."""
    n = depth.size if idx is None else idx.size
    s.ensure(n)
    T = np.asarray(pose, dtype=np.float64)  # noqa: N806
    t = [[float(T[r, c]) for c in range(4)] for r in range(3)]
    low = min(shifts)
    if max(shifts) - low + (2 * offset - 1).bit_length() > _EXACT_BITS:
        raise ValueError(f"packing {shifts} with offset {offset} does not fit a float64")
    scale = [float(1 << (sh - low)) for sh in shifts]
    const = float(sum(offset << (sh - low) for sh in shifts)) + _MAGIC  # exact
    wx, wy, wz, keys = s.wx[:n], s.wy[:n], s.wz[:n], s.keys[:n]
    lo = [np.inf] * 3
    hi = [-np.inf] * 3
    for a in range(0, n, BLOCK):
        b = min(a + BLOCK, n)
        m = b - a
        z, xc, yc, tmp, kf = s.z[:m], s.xc[:m], s.yc[:m], s.t[:m], s.kf[:m]
        if idx is None:  # the same products, of the pixels in place
            z[:] = depth[a:b]  # float32 -> float64, exact
            np.multiply(ru[a:b], z, out=xc)
            np.multiply(rv[a:b], z, out=yc)
        else:
            sub = idx[a:b]
            z[:] = depth[sub]
            np.take(ru, sub, out=xc)
            np.multiply(xc, z, out=xc)
            np.take(rv, sub, out=yc)
            np.multiply(yc, z, out=yc)
        for r in range(3):
            out = (wx, wy, wz)[r][a:b]
            np.multiply(xc, t[r][0], out=out)
            np.multiply(yc, t[r][1], out=tmp)
            np.add(out, tmp, out=out)
            np.multiply(z, t[r][2], out=tmp)
            np.add(out, tmp, out=out)
            np.add(out, t[r][3], out=out)
            np.multiply(out, inv, out=tmp)
            np.floor(tmp, out=tmp)
            if need_range:
                lo[r] = float(np.minimum(lo[r], tmp.min()))  # NaN propagates
                hi[r] = float(np.maximum(hi[r], tmp.max()))
            if r == 0:
                np.multiply(tmp, scale[r], out=kf)
            else:
                if scale[r] != 1.0:
                    np.multiply(tmp, scale[r], out=tmp)
                np.add(kf, tmp, out=kf)
        np.add(kf, const, out=kf)  # the fields' offsets and the magic number
        kb = keys[a:b]
        np.subtract(kf.view(np.int64), _MAGIC_BITS, out=kb)
        np.left_shift(kb, low, out=kb)
    rng = [v for pair in zip(lo, hi, strict=True) for v in pair] if need_range else []
    return wx, wy, wz, keys, rng


def within_packing(pose: np.ndarray, ru: np.ndarray, rv: np.ndarray, max_depth: float,
                   inv: float, limit: int) -> bool:
    """True when every point of depth below ``max_depth`` on the rays ``ru``, ``rv``
    (monotonic tables: their ends bound them) lands at a voxel index of magnitude below
    ``limit - 2`` on every axis: ``|T[r,3]| + (|T[r,0]| + |T[r,1]| + |T[r,2]|) * e`` with
    ``e = max_depth * max(|ru|, |rv|, 1)`` bounds ``|w_r|``; the 2 voxels of margin cover
    rounding many times over. False (check every point) when it cannot say: NaN, inf."""
    T = np.asarray(pose, dtype=np.float64).tolist()  # noqa: N806 - Python floats: 4x4 is tiny
    ext = max_depth * max(abs(float(ru[0])), abs(float(ru[-1])), abs(float(rv[0])),
                          abs(float(rv[-1])), 1.0)
    return all((abs(row[3]) + (abs(row[0]) + abs(row[1]) + abs(row[2])) * ext) * inv
               < limit - 2 for row in T[:3])  # False for NaN


class MapRangeError(SgtoolError):
    """A frame's points fall outside the range of the voxel keys (they would be lost)."""


def beyond_packing(what: str, camera: np.ndarray | None, resolution: float, limit: int
                   ) -> MapRangeError:
    """The one-line error for a frame (``what``: "frame 3 at 0.100 s") whose points reach
    voxel indices of magnitude ``limit`` or more (or are not finite): names the camera
    position (``camera``, world_T_camera; None for bare points), the range in metres and
    the fix."""
    if camera is None:
        who = "world points (or NaN) reach"
    else:
        t = np.asarray(camera, dtype=np.float64)
        if np.all(np.isnan(t)):  # what a log reader gives a frame /tf does not pose
            return MapRangeError(f"{what}: no camera pose: /tf has no chain from the frame "
                                 "'world' to the depth image's frame (sgtool's logs name "
                                 "them 'world' and 'camera') at this time; the frame cannot "
                                 "be mapped")
        if not np.all(np.isfinite(t)):
            return MapRangeError(f"{what}: the camera pose is not finite; the frame cannot "
                                 "be mapped")
        who = "the camera at ({}) m sees points".format(
            ", ".join(f"{v:.1f}" for v in t[:3, 3].tolist()))
    reach = (limit - 1) * resolution
    return MapRangeError(
        f"{what}: {who} beyond +-{reach:.1f} m of the world origin, the voxel map's range "
        f"at {resolution:g} m voxels; recentre the trajectory near the origin (subtract "
        "e.g. the first pose's position from every pose) and import it again")
