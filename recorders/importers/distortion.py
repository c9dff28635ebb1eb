"""Lens distortion of a ``CameraInfo``, which sgtool does not undo: how far it moves pixels,
and the line the import report gives it.

sgtool maps depth pixels through the pinhole intrinsics alone, so a camera whose
``CameraInfo`` has non-zero distortion coefficients puts the depth points near the image
edges in the wrong place. The shift is estimated on a grid of pixels over the whole image
by applying the model's forward mapping to the pinhole ray of each pixel (``plumb_bob`` and
``rational_polynomial``: radial k1..k6 and tangential p1, p2; ``equidistant``: the fisheye
model k1..k4). A shift of ``WARN_SHIFT_PX`` or more is a warning, a smaller one a note.
"""

from __future__ import annotations

import math

import numpy as np

from sgtool.log.frame import CameraIntrinsics

WARN_SHIFT_PX = 2.0  # from here on the distortion is a warning rather than a note
_GRID = 17  # pixels per image side on which the shift is measured


def _pinhole_rays(k: CameraIntrinsics) -> tuple[np.ndarray, np.ndarray]:
    """Normalised image coordinates (x, y) of a grid of pixels over the image, borders
    included."""
    u = np.linspace(0.0, k.width - 1.0, _GRID)
    v = np.linspace(0.0, k.height - 1.0, _GRID)
    uu, vv = np.meshgrid(u, v)
    return (uu - k.cx) / k.fx, (vv - k.cy) / k.fy


def distortion_shift_px(model: str, coeffs: tuple[float, ...],
                        k: CameraIntrinsics) -> float | None:
    """The largest shift (pixels) the distortion moves a pixel of the image by, or None for
    a model sgtool does not know (or coefficients that are not finite)."""
    x, y = _pinhole_rays(k)
    c = np.zeros(8)
    c[: min(len(coeffs), 8)] = coeffs[:8]
    if not np.all(np.isfinite(c)):
        return None
    with np.errstate(all="ignore"):  # implausible coefficients overflow: an inf shift
        shift = _shift(model.strip().lower(), c, x, y, k)
    if shift is None:
        return None
    return float(np.max(shift)) if np.all(np.isfinite(shift)) else math.inf


def _shift(name: str, c: np.ndarray, x: np.ndarray, y: np.ndarray,
           k: CameraIntrinsics) -> np.ndarray | None:
    """The shift (pixels) of each ray (x, y), None for a model sgtool does not know."""
    r2 = x * x + y * y
    if name in ("plumb_bob", "rational_polynomial", ""):
        k1, k2, p1, p2, k3, k4, k5, k6 = c
        radial = (1 + r2 * (k1 + r2 * (k2 + r2 * k3))) / (1 + r2 * (k4 + r2 * (k5 + r2 * k6)))
        xd = x * radial + 2 * p1 * x * y + p2 * (r2 + 2 * x * x)
        yd = y * radial + p1 * (r2 + 2 * y * y) + 2 * p2 * x * y
    elif name in ("equidistant", "fisheye"):
        k1, k2, k3, k4 = c[:4]
        r = np.sqrt(r2)
        theta = np.arctan(r)
        t2 = theta * theta
        rd = theta * (1 + t2 * (k1 + t2 * (k2 + t2 * (k3 + t2 * k4))))
        scale = np.divide(rd, r, out=np.ones_like(r), where=r > 0)
        xd, yd = x * scale, y * scale
    else:
        return None
    return np.hypot((xd - x) * k.fx, (yd - y) * k.fy)


def distortion_finding(distortion: tuple[str, tuple[float, ...]] | None, topic: str,
                       k: CameraIntrinsics) -> tuple[str, bool] | None:
    """(the line for the report, whether it is a warning) for a ``CameraInfo``'s distortion
    (model, coefficients), or None when every coefficient is zero."""
    if distortion is None:
        return None
    model, coeffs = distortion
    if not any(v != 0.0 for v in coeffs):
        return None
    shift = distortion_shift_px(model, coeffs, k)
    listed = ",".join(f"{v:g}" for v in coeffs)
    how_far = ("its effect is not known to sgtool" if shift is None else
               "it moves pixels by more than 10,000 px (implausible coefficients)"
               if shift > 1e4 else f"it moves pixels by up to {shift:.1f} px")
    text = (f"--info {topic} has {model or 'unnamed'} lens distortion (D={listed}) and sgtool "
            f"does not undistort: {how_far}, and depth points near the image edges are "
            "misplaced accordingly; import rectified images (image_rect topics) if the bag "
            "has them")
    return text, shift is None or shift >= WARN_SHIFT_PX
