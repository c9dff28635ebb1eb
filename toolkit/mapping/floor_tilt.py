"""How the floor a camera sees leans in the world, frame by frame (pure functions).

A camera whose pose is pitched a few degrees off the truth (a base-to-camera transform
measured wrong) sees the floor rise or fall ahead of it: a floor point ``r`` metres ahead
lands ``r tan(error)`` above or below the floor, past the bird's-eye map's floor tolerance
a few metres out, so the far floor maps as obstacle or as nothing. Nothing else in a log
shows it. :func:`floor_slopes` fits the plane ``h = a u + b w + c`` to the floor points of
one frame, ``u`` metres ahead along the camera's heading and ``w`` to its left (both
horizontal), and returns ``(a, b)``: a pitch error gives the same ``a`` in every frame
whatever the heading; a floor that is not level in the world gives an ``a`` that turns
with the heading. :func:`tilt_degrees` is the median over frames, in degrees.

Floor points are the sampled pixels (every ``stride``-th in each direction) on a surface
facing up (within 15 degrees, :data:`UPRIGHT`: the normal of the pixel and its right and
lower sampled neighbours; walls and the sides of furniture leave) whose world height lies
within :data:`BAND` of the floor's, :data:`NEAR` to :data:`FAR` metres ahead
and within :data:`FAR` to the side; the plane is fitted by least squares, then again to
the points within :data:`KEEP` (or 2.5 robust deviations, whichever is wider) of the first
fit (furniture feet and low boxes leave). A frame with fewer than :data:`MIN_POINTS` floor
points, or their distances ahead spanning less than :data:`MIN_SPAN`, or a camera looking
within :data:`STEEP` of straight down or up, gives None.
"""

from __future__ import annotations

import math
from collections.abc import Iterable

import numpy as np

BAND = 0.3  # m around the floor's height where floor points are sought
NEAR = 0.5  # m ahead: nearer floor points are left out (the fit's lever is distance)
FAR = 4.0  # m ahead (and to either side): farther points are left out (noise)
KEEP = 0.03  # m: points this near the first fit are kept for the second at least
MIN_POINTS = 200  # floor points a frame needs
MIN_SPAN = 1.0  # m: the floor points' distances ahead must span this much
STEEP = 0.1  # the optical axis' horizontal length below this: no heading (looking down)
MIN_FRAMES = 5  # frames with a fit that :func:`tilt_degrees` needs
UPRIGHT = math.cos(math.radians(15.0))  # a floor point's surface faces within 15 deg of up


def floor_slopes(depth: np.ndarray, pose: np.ndarray, fx: float, fy: float, cx: float,
                 cy: float, floor: float, stride: int = 2) -> tuple[float, float] | None:
    """``(a, b)``: the floor's rise per metre ahead of the camera and per metre to its
    left in one frame (module doc), ``pose`` world_T_camera (OpenCV camera axes), the
    floor at height ``floor``; None when the frame does not show enough floor."""
    T = np.asarray(pose, dtype=np.float64)  # noqa: N806
    ahead = T[:2, 2]
    n = float(np.hypot(ahead[0], ahead[1]))
    if n < STEEP:
        return None
    fwd = ahead / n
    left = np.array([-fwd[1], fwd[0]])
    d = np.asarray(depth)[::stride, ::stride].astype(np.float64)
    v, u = np.mgrid[0:depth.shape[0]:stride, 0:depth.shape[1]:stride]
    d = np.where(np.isfinite(d) & (d > 0), d, np.nan)
    cam = np.stack([(u - cx) / fx * d, (v - cy) / fy * d, d], axis=-1)
    world = cam @ T[:3, :3].T + T[:3, 3]
    # a surface facing up: the normal of each pixel's right and lower neighbours
    normal = np.cross(world[:-1, 1:] - world[:-1, :-1], world[1:, :-1] - world[:-1, :-1])
    world = world[:-1, :-1]
    with np.errstate(invalid="ignore"):
        up = np.abs(normal[..., 2]) >= UPRIGHT * np.linalg.norm(normal, axis=-1)
    rel = world[..., :2] - T[:2, 3]
    a_u, a_w, h = rel @ fwd, rel @ left, world[..., 2]
    with np.errstate(invalid="ignore"):
        keep = up & (np.abs(h - floor) <= BAND) & (a_u >= NEAR) & (a_u <= FAR) & \
            (np.abs(a_w) <= FAR)
    a_u, a_w, y = a_u[keep], a_w[keep], h[keep]
    if y.size < MIN_POINTS or float(np.ptp(a_u)) < MIN_SPAN:
        return None
    A = np.stack([a_u, a_w, np.ones(y.size)], axis=1)  # noqa: N806
    coef = np.linalg.lstsq(A, y, rcond=None)[0]
    r = y - A @ coef
    spread = 1.4826 * float(np.median(np.abs(r - np.median(r))))
    near = np.abs(r) <= max(KEEP, 2.5 * spread)
    if int(near.sum()) < MIN_POINTS or float(np.ptp(A[near, 0])) < MIN_SPAN:
        return None
    coef = np.linalg.lstsq(A[near], y[near], rcond=None)[0]
    return float(coef[0]), float(coef[1])


def tilt_degrees(slopes: Iterable[tuple[float, float] | None]
                 ) -> tuple[float, float] | None:
    """(ahead, left): the median over frames of :func:`floor_slopes`' rises, as angles in
    degrees (positive: the floor rises ahead of / to the left of the camera); None with
    fewer than :data:`MIN_FRAMES` frames fitted."""
    got = np.array([s for s in slopes if s is not None], dtype=np.float64).reshape(-1, 2)
    if len(got) < MIN_FRAMES:
        return None
    a, b = np.median(got, axis=0)
    return math.degrees(math.atan(float(a))), math.degrees(math.atan(float(b)))
