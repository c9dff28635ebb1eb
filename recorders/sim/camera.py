"""The simulated RGB-D + instance camera: mounting, OpenGL matrices, depth and id conversion.

Pure functions over numpy arrays, testable without a simulator. PyBullet renders with
OpenGL conventions (camera looks along -z, y up, a depth buffer in [0, 1]); sgtool logs use
the optical frame (x right, y down, z forward, see :mod:`sgtool.log.frame`). This module is
where the two meet:

- :func:`base_T_camera`: the camera on a mast of ``mount_height`` metres, looking along the
  base's +x and tilted down by ``tilt_deg`` (so low container shelves are in view);
- :func:`view_matrix` / :func:`projection_matrix`: PyBullet's column-major 4x4 lists for a
  world_T_camera pose and the pinhole of :meth:`CameraConfig.intrinsics` (square pixels,
  principal point at the image centre ``(W-1)/2, (H-1)/2``, the OpenGL convention of pixel
  centres at half-integers in normalised device coordinates);
- :func:`depth_from_buffer`: metric depth along the optical axis from the non-linear depth
  buffer, ``z = far * near / (far - (far - near) * buf)``; the far plane (nothing hit) and
  anything outside ``[depth_min, depth_max]`` becomes 0 = no return;
- :func:`ids_from_segmentation`: PyBullet's ``ER_SEGMENTATION_MASK_OBJECT_AND_LINKINDEX``
  mask (``uid + ((link + 1) << 24)``, -1 for background) mapped through a body -> instance
  look-up table to the log's small int32 instance ids (0 = background).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from sgtool.arg_checks import number, whole
from sgtool.errors import SgtoolError
from sgtool.log.frame import CameraIntrinsics

# optical (x right, y down, z forward) -> OpenGL camera (x right, y up, z backward)
_OPTICAL_T_GL = np.diag([1.0, -1.0, -1.0, 1.0])
UID_MASK = 0xFFFFFF  # low 24 bits of a segmentation value: the body's unique id
SIDE_RANGE = (8, 4096)  # pixels a camera image side may have (each of width, height)


TILT_MIN, TILT_MAX = -60.0, 80.0  # degrees down from the horizontal, mast or head


@dataclass(frozen=True)
class CameraConfig:
    """The robot's RGB-D camera.

    ``vfov_deg`` is the vertical field of view (the horizontal one follows from the aspect
    ratio with square pixels: 75 deg at 4:3 gives ~91 deg). ``depth_min``/``depth_max`` is
    the sensor's range (metres); ``near`` is the renderer's near clipping plane.
    """

    width: int = 320
    height: int = 240
    vfov_deg: float = 75.0
    mount_height: float = 1.2
    tilt_deg: float = 15.0
    depth_min: float = 0.1
    depth_max: float = 6.0
    near: float = 0.05

    def __post_init__(self) -> None:
        whole("width", self.width)
        whole("height", self.height)
        for name in ("vfov_deg", "mount_height", "tilt_deg", "depth_min", "depth_max", "near"):
            # kept as a float: vfov_deg=75 logs as the CLI's 75.0 does
            object.__setattr__(self, name, number(name, getattr(self, name)))
        if not (SIDE_RANGE[0] <= self.width <= SIDE_RANGE[1]
                and SIDE_RANGE[0] <= self.height <= SIDE_RANGE[1]):
            raise SgtoolError(f"camera resolution {self.width}x{self.height}: each side must "
                              f"be {SIDE_RANGE[0]}..{SIDE_RANGE[1]} pixels")
        if not 10.0 <= self.vfov_deg <= 150.0:
            raise SgtoolError(f"camera field of view {self.vfov_deg} deg: must be 10..150")
        if not 0.0 < self.near <= self.depth_min < self.depth_max:
            raise SgtoolError(f"camera depth range {self.depth_min}..{self.depth_max} m: need "
                              f"{self.near} <= min < max")
        if self.depth_max > 65.0:
            raise SgtoolError(f"camera depth_max {self.depth_max} m: the log stores depth "
                              "as 16-bit millimetres, at most 65 m")
        if not 0.1 <= self.mount_height <= 3.0:
            raise SgtoolError(f"camera height {self.mount_height} m: must be 0.1..3")
        if not TILT_MIN <= self.tilt_deg <= TILT_MAX:
            raise SgtoolError(f"camera tilt {self.tilt_deg} deg: must be "
                              f"{TILT_MIN:g}..{TILT_MAX:g}")

    @property
    def far(self) -> float:
        """The renderer's far plane: the sensor's maximum range."""
        return self.depth_max

    def nearest_floor_depth(self) -> float | None:
        """The depth (along the optical axis) of the nearest floor the camera sees at its
        mounting: where the bottom row's middle ray meets the floor; None when it looks
        above the floor."""
        down = math.radians(self.tilt_deg + self.vfov_deg / 2.0)
        if down <= 0.0:
            return None
        return self.mount_height / math.sin(down) * math.cos(math.radians(self.vfov_deg / 2.0))

    def intrinsics(self) -> CameraIntrinsics:
        return CameraIntrinsics.from_fov(self.width, self.height, self.vfov_deg)


# ----------------------------------------------------------------------------------------
# poses
# ----------------------------------------------------------------------------------------
def se2_matrix(x: float, y: float, yaw: float, z: float = 0.0) -> np.ndarray:
    """4x4 pose of a frame at (x, y, z) rotated by ``yaw`` about world z."""
    c, s = math.cos(yaw), math.sin(yaw)
    return np.array([[c, -s, 0.0, x], [s, c, 0.0, y], [0.0, 0.0, 1.0, z],
                     [0.0, 0.0, 0.0, 1.0]])


LINK_TOL = 1e-9  # m / rotation entries: a base -> camera link this close is the mounting


def base_T_camera(mount_height: float, tilt_deg: float) -> np.ndarray:  # noqa: N802
    """The camera's optical frame in the base frame (x forward, y left, z up): at
    ``mount_height`` above the base origin, optical axis along +x pitched down by
    ``tilt_deg``. Columns of the rotation are the optical axes: x right = -y_base,
    z forward = (cos t, 0, -sin t), y down = z x x."""
    t = math.radians(tilt_deg)
    c, s = math.cos(t), math.sin(t)
    m = np.eye(4)
    m[:3, 0] = (0.0, -1.0, 0.0)
    m[:3, 1] = (-s, 0.0, -c)
    m[:3, 2] = (c, 0.0, -s)
    m[2, 3] = mount_height
    return m


def view_matrix(world_T_camera: np.ndarray) -> list[float]:  # noqa: N803
    """PyBullet's view matrix (column-major 16 floats) for an optical-frame pose."""
    world_T_gl = world_T_camera @ _OPTICAL_T_GL  # noqa: N806
    return np.linalg.inv(world_T_gl).flatten(order="F").tolist()


def projection_matrix(cfg: CameraConfig) -> list[float]:
    """OpenGL perspective projection (column-major) matching :meth:`CameraConfig.intrinsics`:
    ``f = 1 / tan(vfov / 2)`` on y, ``f / aspect`` on x, clip planes near / far, as
    ``pybullet.computeProjectionMatrixFOV`` builds it, plus a half-pixel shift on both axes.

    The shift is measured, not assumed: PyBullet's TinyRenderer samples column ``u`` at
    NDC ``x = 2u / W - 1`` and row ``v`` at ``y = 1 - 2(v + 1) / H`` (pixel corners, not
    centres), so with the plain matrix the image's principal point sits at ``(W/2, H/2 - 1)``
    instead of ``((W-1)/2, (H-1)/2)``. Shifting NDC by ``+1/W`` and ``+1/H`` puts the pixel
    centres where the intrinsics say; rendered depth then matches ray tests through the
    pixel centres to < 0.1 mm at any resolution (tests/recorders/sim/test_camera.py)."""
    f = 1.0 / math.tan(math.radians(cfg.vfov_deg) / 2.0)
    aspect = cfg.width / cfg.height
    n, fa = cfg.near, cfg.far
    m = np.zeros((4, 4))
    m[0, 0] = f / aspect
    m[1, 1] = f
    m[2, 2] = (fa + n) / (n - fa)
    m[2, 3] = 2.0 * fa * n / (n - fa)
    m[3, 2] = -1.0
    m[0, 2] = 1.0 / cfg.width
    m[1, 2] = 1.0 / cfg.height
    return m.flatten(order="F").tolist()


# ----------------------------------------------------------------------------------------
# images
# ----------------------------------------------------------------------------------------
def depth_from_buffer(buf: np.ndarray, cfg: CameraConfig) -> np.ndarray:
    """Metric depth (float32 metres along the optical axis, 0 = no return) from PyBullet's
    depth buffer: ``z = far * near / (far - (far - near) * buf)``. The far plane (nothing
    within range) and depths outside ``[depth_min, depth_max]`` read 0."""
    b = np.asarray(buf, dtype=np.float32)
    near, far = np.float32(cfg.near), np.float32(cfg.far)
    z = (far * near) / (far - (far - near) * b)
    z[(b >= np.float32(1.0)) | (z < np.float32(cfg.depth_min))
      | (z > np.float32(cfg.depth_max))] = 0.0
    return z


def ids_from_segmentation(seg: np.ndarray, lut: np.ndarray) -> np.ndarray:
    """int32 instance ids from a segmentation mask: ``lut[seg & 0xFFFFFF]`` where the mask
    is >= 0, 0 on background (-1) and on bodies outside the table."""
    s = np.asarray(seg)
    uid = s & UID_MASK
    # background (-1) reads 0xFFFFFF: clip into the table's spare last slot, which is 0
    np.minimum(uid, lut.shape[0] - 1, out=uid)
    return lut[uid]


def uid_lut(body_to_instance: dict[int, int]) -> np.ndarray:
    """Look-up table body uid -> instance id (int32), with one spare 0 slot at the end for
    background and unknown bodies (see :func:`ids_from_segmentation`)."""
    n = (max(body_to_instance) + 2) if body_to_instance else 1
    lut = np.zeros(n, dtype=np.int32)
    for uid, iid in body_to_instance.items():
        if uid < 0:
            raise ValueError(f"body uid {uid} < 0")
        lut[uid] = iid
    return lut


def pixel_ray(k: CameraIntrinsics, u: float, v: float) -> np.ndarray:
    """Direction in the optical frame through pixel (column u, row v), with z = 1."""
    return np.array([(u - k.cx) / k.fx, (v - k.cy) / k.fy, 1.0])
