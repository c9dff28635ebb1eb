"""The floor of an imported scene: the lowest *large* horizontal plane seen across a few
depth frames, with a confidence.

The lowest upward-facing surface is not the floor when the floor is out of view (a camera
over a desk takes the desk), and a handful of stray points below the floor must not pull
it down either. So the upward-facing points (normal within 20 degrees of up) of every
sampled frame are weighted by the area each one covers (its pixel's footprint at its
depth and slant, m^2) and grouped into horizontal planes (heights within
:data:`PLANE_HALF_WIDTH_M`). A plane is *large* when it covers at least
:data:`LARGE_SHARE` of the largest one's area; the floor is the lowest large plane.

Its confidence (0..1) is the product of
- what vouches for a floor: its mean visible area per sampled frame against
  :data:`FLOOR_AREA_M2` (a floor in view covers square metres, a desk top a fraction of
  one) or the camera's median height above it against :data:`FLOOR_CAMERA_HEIGHT_M` (a
  camera held well above it), whichever says more;
- nothing below it: the share of the scene's area (all points, any normal) more than
  :data:`BELOW_M` under the plane, against :data:`MAX_BELOW_SHARE` (the floor has nothing
  under it; a desk has the floor and the chairs);
- consistency: the share of the sampled frames (with depth) that see the plane, counted at
  half weight (a camera looks at the floor in some frames only).

An import refuses a floor estimate under :data:`MIN_CONFIDENCE`, or no horizontal plane at
all, in one line naming ``--floor``. All pure functions of the samples.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from sgtool.errors import SgtoolError
from sgtool.log.frame import CameraIntrinsics
from sgtool.recorders.importers.upright import DepthSample, surface_points

UPWARD_COS = float(np.cos(np.radians(20.0)))  # an upward-facing normal is this close to up
PLANE_HALF_WIDTH_M = 0.04  # heights within this of a plane's centre belong to it
PLANE_SEPARATION_M = 0.10  # two planes closer than this are one
LARGE_SHARE = 0.25  # of the largest plane's area: a large plane
SEEN_AREA_M2 = 0.05  # a frame sees a plane when it covers at least this
FLOOR_AREA_M2 = 2.0  # visible floor per frame that fully vouches for a floor
FLOOR_CAMERA_HEIGHT_M = (0.45, 0.9)  # camera height above the plane: no .. full evidence
BELOW_M = 0.10  # points further below the plane than this count against it
MAX_BELOW_SHARE = 0.05  # of the scene's area below the plane: no confidence left
MIN_CONFIDENCE = 0.5


@dataclass(frozen=True)
class FloorEstimate:
    """The floor found in the samples: ``height`` along the up direction (source world),
    ``confidence`` 0..1 and what it is made of (``area_m2``: mean visible area per sampled
    frame; ``frames_seen`` of ``frames``; ``below_share`` of the scene's area under it;
    ``camera_height_m``: the cameras' median height above it). ``method`` is
    ``horizontal-plane``, or ``all-points`` when no upward-facing surface was found (then
    the height is the 1st percentile of all points and the confidence 0)."""

    height: float
    confidence: float
    method: str
    area_m2: float = 0.0
    frames_seen: int = 0
    frames: int = 0
    below_share: float = 0.0
    camera_height_m: float = 0.0

    def describe(self) -> str:
        if self.method == "all-points":
            return "no horizontal surface in the sampled frames (lowest depth points taken)"
        return (f"confidence {self.confidence:.2f}: {self.area_m2:.2f} m^2 visible per frame, "
                f"seen in {self.frames_seen} of {self.frames} sampled frames, "
                f"{100 * self.below_share:.0f} % of the scene below it, camera "
                f"{self.camera_height_m:.2f} m above it")


def _points(s: DepthSample, stride: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """World points, normals and the area (m^2) each point's pixel block covers."""
    p, n = surface_points(s, stride=stride)
    R, t = s.pose[:3, :3], s.pose[:3, 3]  # noqa: N806
    pc = (p - t) @ R  # camera frame
    dist = np.linalg.norm(pc, axis=1)
    z = pc[:, 2]
    cos = np.abs(np.einsum("ij,ij->i", n @ R, pc)) / np.maximum(dist, 1e-9)
    k = s.intrinsics
    area = (stride * z) ** 2 / (k.fx * k.fy) / np.maximum(cos, 0.15)
    return p, n, area


def _planes(h: np.ndarray, w: np.ndarray) -> list[tuple[float, float]]:
    """(centre height, area) of the horizontal planes among heights ``h`` with areas ``w``:
    the heaviest 2 cm bin first, each bin further than :data:`PLANE_SEPARATION_M` from the
    chosen ones starts a plane; a plane's centre is the area-weighted median of its
    heights."""
    if len(h) == 0:
        return []
    lo = float(h.min())
    bins = np.floor((h - lo) / 0.02).astype(np.int64)
    mass = np.bincount(bins, weights=w)
    planes: list[tuple[float, float]] = []
    for b in np.argsort(-mass, kind="stable"):
        if mass[b] <= 0:
            break
        c = lo + (b + 0.5) * 0.02
        if any(abs(c - pc) < PLANE_SEPARATION_M for pc, _ in planes):
            continue
        sel = np.abs(h - c) <= PLANE_HALF_WIDTH_M
        hs, ws = h[sel], w[sel]
        order = np.argsort(hs, kind="stable")
        cum = np.cumsum(ws[order])
        centre = float(hs[order][np.searchsorted(cum, cum[-1] / 2)])
        planes.append((centre, float(ws.sum())))
        if len(planes) >= 12:
            break
    return planes


def estimate_floor(samples: Sequence[DepthSample], up: np.ndarray) -> FloorEstimate | None:
    """The floor of ``samples`` (module doc) along unit vector ``up``; None when no sample
    has a valid depth point."""
    u = np.asarray(up, dtype=np.float64) / np.linalg.norm(up)
    per: list[tuple[np.ndarray, np.ndarray, np.ndarray]] = []
    for s in samples:
        p, n, a = _points(s, max(1, s.depth.shape[1] // 160))
        if len(p):
            per.append((p @ u, n @ u, a))
    if not per:
        return None
    h_all = np.concatenate([h for h, _, _ in per])
    up_all = np.concatenate([d for _, d, _ in per]) > UPWARD_COS
    a_all = np.concatenate([a for _, _, a in per])
    cams = np.array([float(np.asarray(s.pose)[:3, 3] @ u) for s in samples])
    if up_all.sum() < max(100, 0.01 * len(h_all)):
        fl = float(np.percentile(h_all, 1.0))
        return FloorEstimate(fl, 0.0, "all-points", frames=len(per),
                             camera_height_m=float(np.median(cams - fl)))
    planes = _planes(h_all[up_all], a_all[up_all])
    largest = max(a for _, a in planes)
    height = min(c for c, a in planes if a >= LARGE_SHARE * largest)
    seen = 0
    area = 0.0
    for h, d, a in per:
        on = (d > UPWARD_COS) & (np.abs(h - height) <= PLANE_HALF_WIDTH_M)
        frame_area = float(a[on].sum())
        area += frame_area
        seen += frame_area >= SEEN_AREA_M2
    area /= len(per)
    below = float(a_all[h_all < height - BELOW_M].sum() / max(a_all.sum(), 1e-12))
    cam_h = float(np.median(cams - height))
    lo, hi = FLOOR_CAMERA_HEIGHT_M
    vouch = max(min(1.0, area / FLOOR_AREA_M2), float(np.clip((cam_h - lo) / (hi - lo), 0, 1)))
    nothing_below = float(np.clip(1.0 - below / MAX_BELOW_SHARE, 0.0, 1.0))
    consistent = 0.5 + 0.5 * seen / len(per)
    return FloorEstimate(height, vouch * nothing_below * consistent, "horizontal-plane",
                         area, seen, len(per), below, cam_h)


def floor_confidence_problem(height: float, confidence: float, method: str, detail: str,
                             camera_height_m: float, band: tuple[float, float]) -> str | None:
    """The problem of an estimated floor at source ``height`` too uncertain to build a map
    on (``confidence`` under :data:`MIN_CONFIDENCE`, or ``method`` ``all-points``: no
    horizontal surface at all), naming ``--floor`` with the height that puts the camera
    (``camera_height_m`` above the estimate) at 1.3 m; None when the estimate is
    confident or was not made."""
    if method not in ("horizontal-plane", "all-points"):
        return None
    if method != "all-points" and confidence >= MIN_CONFIDENCE:
        return None
    example = height + camera_height_m - 1.3
    return (f"the floor is not clear in the sampled depth frames (estimate at {height:.3f} m "
            f"in the source; {detail}): a desk, counter or wall may have been taken for it; "
            f"give the floor's height with --floor (e.g. --floor {example:.2f} puts the camera "
            f"at 1.3 m; {band[0]:g}-{band[1]:g} m above the floor is expected), or --floor "
            "none to keep the source's heights")


def frame_floor_problem(depths: Sequence[np.ndarray], k: CameraIntrinsics,
                        band: tuple[float, float]) -> str | None:
    """The floor check of a few depth images (metres) before any pose is known (before
    odometry): each frame on its own, its up from the camera's image-up refined by its
    horizontal normals, its floor the lowest large horizontal plane. None when the median
    camera height over the frames with a confident floor is within ``band``; the problem
    (naming ``--floor``) when no frame has a confident floor or the height is outside."""
    from sgtool.recorders.importers.upright import estimate_alignment

    heights: list[float] = []
    best: tuple[float, str] | None = None
    eye = np.eye(4)
    for d in depths:
        if not np.any(d > 0):
            continue
        try:
            a = estimate_alignment([eye], [DepthSample(d, k, eye)])
        except SgtoolError:
            continue
        if a.floor_method == "horizontal-plane" and a.floor_confidence >= MIN_CONFIDENCE:
            heights.append(-a.floor)  # the camera is at the origin
        elif best is None or a.floor_confidence > best[0]:
            best = (a.floor_confidence, a.floor_detail)
    if not heights:
        detail = best[1] if best else "no valid depth"
        return (f"the floor is not clear in any of the {len(depths)} sampled depth frames "
                f"(the best: {detail}); poses are to be estimated, so the floor must be "
                "seen: give the floor's height with --floor (metres along up in the first "
                "camera's world), or --floor none to keep the estimated heights")
    h = float(np.median(heights))
    if band[0] <= h <= band[1]:
        return None
    return (f"the camera is {h:.2f} m above the floor seen in {len(heights)} of the "
            f"{len(depths)} sampled depth frames, outside --camera-height {band[0]:g}:"
            f"{band[1]:g} (checked before odometry): the floor is probably not in view and a "
            "table or counter was taken for it; give the floor's height with --floor, or a "
            "wider --camera-height")
