"""Rendering of the PyBullet house: image shapes and types, metric depth against PyBullet
ray tests, instance ids against the bodies the rays hit, determinism."""

from __future__ import annotations

import math

import numpy as np
import pytest
from support.small_house import small_house

from sgtool.recorders.sim import CameraConfig, Simulation
from sgtool.recorders.sim.build import pybullet
from sgtool.recorders.sim.camera import base_T_camera


@pytest.mark.parametrize("size", [(160, 120), (97, 61)])
def test_depth_matches_ray_tests_through_pixel_centres(size: tuple[int, int]) -> None:
    """Depth along the optical axis from the depth buffer equals the distance a PyBullet
    ray through the pixel centre travels to the first surface (projected on the axis):
    within 1 cm at the image centre, and everywhere on a grid of pixels (tighter than
    1 mm: the rasteriser samples exactly the intrinsics' pixel centres)."""
    w, h = size
    with Simulation(small_house(), camera=CameraConfig(width=w, height=h)) as sim:
        for pose in [(2.0, 1.2, 0.0), (1.0, 2.0, -1.2), (3.2, 1.5, 0.1)]:
            sim.teleport(pose)
            f = sim.render()
            cu, cv = (w - 1) // 2, (h - 1) // 2
            z = sim.ray_depth(cu, cv)
            assert z > 0
            assert abs(float(f.depth[cv, cu]) - z) < 0.01
            errs = []
            for v in range(2, h, max(h // 7, 1)):
                for u in range(3, w, max(w // 9, 1)):
                    zr = sim.ray_depth(u, v)
                    if zr > 0 and f.depth[v, u] > 0:
                        errs.append(abs(float(f.depth[v, u]) - zr))
            assert len(errs) > 40
            assert max(errs) < 1e-3


def test_images_have_the_camera_shape_and_types() -> None:
    cfg = CameraConfig(width=64, height=48)
    with Simulation(small_house(), camera=cfg) as sim:
        f = sim.render()
    assert f.rgb.shape == (48, 64, 3) and f.rgb.dtype == np.uint8
    assert f.depth.shape == (48, 64) and f.depth.dtype == np.float32
    assert f.ids.shape == (48, 64) and f.ids.dtype == np.int32
    assert f.intrinsics == cfg.intrinsics()
    assert np.allclose(np.linalg.inv(f.base_pose) @ f.pose,
                       base_T_camera(cfg.mount_height, cfg.tilt_deg))
    assert math.isclose(f.pose[2, 3], cfg.mount_height)
    valid = f.depth[f.depth > 0]
    assert valid.min() >= cfg.depth_min and valid.max() <= cfg.depth_max


def test_ids_are_the_instances_of_the_bodies_hit() -> None:
    """Every id in the mask is in the instances table, and at sampled pixels the id is the
    instance of the body a ray through the pixel hits (PyBullet uid -> table row)."""
    pb = pybullet()
    cfg = CameraConfig(width=80, height=60)
    with Simulation(small_house(), camera=cfg) as sim:
        table = {i.id for i in sim.instances}
        k = sim.intrinsics
        checked = 0
        for pose in [(2.0, 1.2, -1.3), (2.0, 1.5, 0.8), (3.0, 1.5, 3.0)]:
            sim.teleport(pose)
            f = sim.render()
            assert set(np.unique(f.ids).tolist()) - {0} <= table
            cam = sim.camera_matrix()
            for v in range(5, 60, 11):
                for u in range(4, 80, 9):
                    d = np.array([(u - k.cx) / k.fx, (v - k.cy) / k.fy, 1.0])
                    end = cam[:3, 3] + cam[:3, :3] @ (d * cfg.depth_max)
                    hit = pb.rayTest(cam[:3, 3].tolist(), end.tolist(),
                                     physicsClientId=sim.client)[0]
                    if hit[0] < 0 or f.depth[v, u] == 0:
                        continue
                    assert f.ids[v, u] == sim.world.body_instance[hit[0]]
                    checked += 1
        assert checked > 100


def test_two_sessions_render_the_same_bytes() -> None:
    cfg = CameraConfig(width=64, height=48)
    frames = []
    for _ in range(2):
        with Simulation(small_house(), camera=cfg) as sim:
            sim.teleport((2.5, 1.0, 2.0))
            frames.append(sim.render())
    a, b = frames
    assert a.rgb.tobytes() == b.rgb.tobytes()
    assert a.depth.tobytes() == b.depth.tobytes()
    assert a.ids.tobytes() == b.ids.tobytes()
