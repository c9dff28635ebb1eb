"""Camera math of the simulator (pure functions, no PyBullet): mounting, depth from the
depth buffer, ids from the segmentation mask, the projection matrix."""

from __future__ import annotations

import math

import numpy as np
import pytest

from sgtool.errors import SgtoolError
from sgtool.recorders.sim.camera import (
    CameraConfig,
    base_T_camera,
    depth_from_buffer,
    ids_from_segmentation,
    projection_matrix,
    uid_lut,
    view_matrix,
)


def test_mount_looks_along_base_x_and_tilts_down() -> None:
    m = base_T_camera(1.2, 0.0)
    r = m[:3, :3]
    assert np.allclose(r.T @ r, np.eye(3)) and math.isclose(np.linalg.det(r), 1.0)
    assert np.allclose(r[:, 2], [1, 0, 0])  # optical z forward = base x
    assert np.allclose(r[:, 0], [0, -1, 0])  # optical x right = base -y
    assert np.allclose(r[:, 1], [0, 0, -1])  # optical y down = base -z
    assert math.isclose(m[2, 3], 1.2)
    t = base_T_camera(1.2, 30.0)[:3, 2]
    assert np.allclose(t, [math.cos(math.radians(30)), 0, -math.sin(math.radians(30))])


def _buffer_of(z: np.ndarray, near: float, far: float) -> np.ndarray:
    """The inverse of z = far*near / (far - (far-near)*buf)."""
    return (far - far * near / z) / (far - near)


def test_depth_from_buffer_inverts_the_depth_buffer_and_clips_the_range() -> None:
    cfg = CameraConfig(depth_min=0.3, depth_max=5.0, near=0.05)
    z = np.array([[0.2, 0.31, 1.0], [2.5, 4.99, 5.0]], np.float64)
    buf = _buffer_of(z, cfg.near, cfg.far).astype(np.float32)
    buf[1, 2] = 1.0  # the far plane: nothing hit
    d = depth_from_buffer(buf, cfg)
    assert d.dtype == np.float32
    assert d[0, 0] == 0.0  # nearer than depth_min
    assert d[1, 2] == 0.0  # far plane
    assert np.allclose(d[0, 1:], [0.31, 1.0], atol=1e-5)
    assert np.allclose(d[1, :2], [2.5, 4.99], atol=2e-4)


def test_ids_from_segmentation_masks_the_link_bits_and_background() -> None:
    lut = uid_lut({0: 1, 1: 7, 3: 9})
    assert lut.tolist() == [1, 7, 0, 9, 0]  # the last slot is the spare 0
    link2_of_body3 = 3 + ((2 + 1) << 24)
    seg = np.array([[-1, 0, 1], [3, link2_of_body3, 2]], np.int32)
    ids = ids_from_segmentation(seg, lut)
    assert ids.dtype == np.int32
    assert ids.tolist() == [[0, 1, 7], [9, 9, 0]]


def test_projection_matches_the_intrinsics() -> None:
    """A camera-frame point projects with the OpenGL matrices to the pixel the pinhole
    intrinsics give (pixel centres at integers, rows downwards)."""
    cfg = CameraConfig(width=160, height=120, vfov_deg=60.0)
    k = cfg.intrinsics()
    p = np.array(projection_matrix(cfg)).reshape(4, 4, order="F")
    pose = np.eye(4)
    pose[:3, 3] = (1.0, 2.0, 1.2)
    v = np.array(view_matrix(pose)).reshape(4, 4, order="F")
    for pc in ([0.3, -0.2, 2.0], [-1.0, 0.5, 3.0], [0.0, 0.0, 1.0]):
        world = pose @ np.array([*pc, 1.0])
        clip = p @ v @ world
        ndc = clip[:3] / clip[3]
        # TinyRenderer: column u at ndc x = 2u/W - 1, row v at ndc y = 1 - 2(v+1)/H
        u = (ndc[0] + 1) * cfg.width / 2
        row = (1 - ndc[1]) * cfg.height / 2 - 1
        assert math.isclose(u, k.fx * pc[0] / pc[2] + k.cx, abs_tol=1e-6)
        assert math.isclose(row, k.fy * pc[1] / pc[2] + k.cy, abs_tol=1e-6)


def test_camera_config_rejects_bad_values() -> None:
    with pytest.raises(SgtoolError, match="resolution"):
        CameraConfig(width=4)
    with pytest.raises(SgtoolError, match="depth range"):
        CameraConfig(depth_min=2.0, depth_max=1.0)
    with pytest.raises(SgtoolError, match="65 m"):
        CameraConfig(depth_max=80.0)
    with pytest.raises(SgtoolError, match="field of view"):
        CameraConfig(vfov_deg=170.0)
