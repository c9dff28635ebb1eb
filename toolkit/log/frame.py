"""One time step of a log: camera images, pose and calibration, grouped.

Conventions (used everywhere in sgtool):
- metres, seconds, radians; world frame z up; yaw counter-clockwise from +x;
- camera optical frame: x right, y down, z forward (as in ROS and Foxglove);
- ``pose`` is world_T_camera, a 4x4 float64 matrix mapping camera-frame points to world;
- depth is metric along the optical axis (float32 metres, 0 or NaN = no return);
- instance ids are int32; 0 means "no instance" (background); other ids are keys of the
  log's ``sgtool.Instances`` table.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class CameraIntrinsics:
    """Pinhole camera intrinsics: the image is ``width`` x ``height`` pixels, ``fx``, ``fy``
    the focal lengths and ``cx``, ``cy`` the principal point, all in pixels (:attr:`K` is
    the 3x3 matrix)."""

    width: int
    height: int
    fx: float
    fy: float
    cx: float
    cy: float

    @property
    def K(self) -> np.ndarray:  # noqa: N802 (the usual name)
        return np.array(
            [[self.fx, 0.0, self.cx], [0.0, self.fy, self.cy], [0.0, 0.0, 1.0]], dtype=np.float64
        )

    @classmethod
    def from_fov(cls, width: int, height: int, vfov_deg: float) -> CameraIntrinsics:
        """Pinhole intrinsics with square pixels from a vertical field of view."""
        fy = (height / 2.0) / np.tan(np.deg2rad(vfov_deg) / 2.0)
        return cls(width, height, float(fy), float(fy), (width - 1) / 2.0, (height - 1) / 2.0)


@dataclass(frozen=True, eq=False)
class Frame:
    """A camera frame. ``rgb`` (H,W,3) uint8, ``depth`` (H,W) float32 metres, ``ids`` (H,W)
    int32 or None when the source has no instance segmentation, ``pose`` world_T_camera,
    ``base_pose`` world_T_base (None when the source has no robot base)."""

    index: int
    time_ns: int
    rgb: np.ndarray | None
    depth: np.ndarray
    ids: np.ndarray | None
    pose: np.ndarray
    intrinsics: CameraIntrinsics
    base_pose: np.ndarray | None = None
