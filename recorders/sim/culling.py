"""Which bodies the renderer draws: only those that can reach the camera's image.

PyBullet's TinyRenderer transforms and clips every triangle of every body for every image,
seen or not; at the closed loop's small images that is most of a render. It skips a body
whose colour has alpha 0 before touching its triangles, so :class:`ViewCulling` sets alpha
0 on the bodies that lie entirely outside the camera's view pyramid before each image, and
gives the others back their colour. A body outside the pyramid covers no pixel and, with
shadows off, changes no other pixel either, so the images (colour, depth and instance ids)
are exactly those of the whole house; only the time to draw them changes. The pyramid ends
at the renderer's far plane plus :data:`FAR_MARGIN_M`: TinyRenderer draws nothing beyond
the far plane (its depth test starts there), so a box wholly beyond it is dropped too.

:func:`outside_view` is the test (pure): a body's axis-aligned box is outside when all 8 of
its corners lie beyond the same side plane of the pyramid, or all behind the camera. The
planes are widened by :data:`MARGIN_PX` pixels on every side (the projection's half-pixel
shift is one of them), so a box the test drops is well clear of the image.
"""

from __future__ import annotations

import itertools
from types import ModuleType

import numpy as np

from sgtool.log.frame import CameraIntrinsics

MARGIN_PX = 4.0  # pixels the view pyramid is widened by on every side
FAR_MARGIN_M = 0.25  # metres past the far plane a dropped box must lie at least
_CORNERS = np.array(list(itertools.product((0, 1), repeat=3)), dtype=bool)  # (8, 3)


def outside_view(lo: np.ndarray, hi: np.ndarray, world_T_camera: np.ndarray,  # noqa: N803
                 k: CameraIntrinsics, far: float | None = None,
                 margin_px: float = MARGIN_PX) -> np.ndarray:
    """bool (N,): whether the box ``[lo[i], hi[i]]`` (world metres, (N, 3) each) lies
    entirely outside the view pyramid of a camera at ``world_T_camera`` (optical frame: x
    right, y down, z forward) with intrinsics ``k``, the pyramid widened by ``margin_px``
    pixels on each side and cut at ``far`` metres along the optical axis (None: not
    cut)."""
    lo = np.asarray(lo, dtype=np.float64).reshape(-1, 3)
    hi = np.asarray(hi, dtype=np.float64).reshape(-1, 3)
    corners = np.where(_CORNERS[None], hi[:, None, :], lo[:, None, :])  # (N, 8, 3)
    rot, t = world_T_camera[:3, :3], world_T_camera[:3, 3]
    cam = (corners - t) @ rot  # camera-frame corners: R^T (p - t)
    x, y, z = cam[..., 0], cam[..., 1], cam[..., 2]
    tx = (k.width / 2.0 + margin_px) / k.fx  # tangent of the widened half-angles
    ty = (k.height / 2.0 + margin_px) / k.fy
    out = ((z <= 0.0).all(axis=1) | (x > tx * z).all(axis=1) | (x < -tx * z).all(axis=1)
           | (y > ty * z).all(axis=1) | (y < -ty * z).all(axis=1))
    if far is not None:
        out |= (z > far).all(axis=1)
    return out


class ViewCulling:
    """Hides (alpha 0) the bodies of a PyBullet client that the next image cannot show
    (module doc). ``movable`` bodies (door and container panels) have their boxes asked
    again before every image; the others never move. Bodies with shapes of different
    colours are never hidden (their colours could not be given back with one call)."""

    def __init__(self, pb: ModuleType, client: int, uids: list[int], movable: list[int]
                 ) -> None:
        self._pb, self._client = pb, client
        kept = []
        colours = []
        for uid in sorted(uids):
            shapes = pb.getVisualShapeData(uid, physicsClientId=client)
            rgba = {tuple(s[7]) for s in shapes}
            if len(rgba) == 1 and next(iter(rgba))[3] > 0.0:
                kept.append(uid)
                colours.append(next(iter(rgba)))
        self.uids = np.asarray(kept, dtype=np.int64)
        self._colours = colours
        self._movable = [i for i, u in enumerate(kept) if u in set(movable)]
        boxes = [pb.getAABB(u, physicsClientId=client) for u in kept]
        self._lo = np.array([b[0] for b in boxes], dtype=np.float64).reshape(-1, 3)
        self._hi = np.array([b[1] for b in boxes], dtype=np.float64).reshape(-1, 3)
        self.hidden = np.zeros(len(kept), dtype=bool)

    def show_only_visible(self, world_T_camera: np.ndarray,  # noqa: N803
                          k: CameraIntrinsics, far: float | None = None) -> None:
        """Hide the bodies outside the view of a camera at ``world_T_camera`` (cut at
        ``far`` metres, None: not cut) and show the others again (only bodies whose state
        changes are touched)."""
        pb, cid = self._pb, self._client
        for i in self._movable:
            lo, hi = pb.getAABB(int(self.uids[i]), physicsClientId=cid)
            self._lo[i], self._hi[i] = lo, hi
        hide = outside_view(self._lo, self._hi, world_T_camera, k, far)
        for i in np.flatnonzero(hide != self.hidden).tolist():
            r, g, b, a = self._colours[i]
            pb.changeVisualShape(int(self.uids[i]), -1,
                                 rgbaColor=[r, g, b, 0.0 if hide[i] else a],
                                 physicsClientId=cid)
        self.hidden = hide
