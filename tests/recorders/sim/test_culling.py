"""View culling: bodies outside the camera's view (or wholly beyond its far plane) are not
drawn, and the images are exactly those of the whole house (colour, depth, ids), with doors
and containers moving."""

from __future__ import annotations

import math
import random

import numpy as np

from sgtool.datasets.generator import generate_house
from sgtool.log.frame import CameraIntrinsics
from sgtool.recorders.sim import CameraConfig, Simulation
from sgtool.recorders.sim.culling import outside_view


def _camera_at(x: float, y: float, yaw: float) -> np.ndarray:
    """world_T_camera of a level camera at (x, y, 1) looking along ``yaw`` (optical frame:
    x right, y down, z forward)."""
    fwd = np.array([math.cos(yaw), math.sin(yaw), 0.0])
    right = np.array([math.sin(yaw), -math.cos(yaw), 0.0])
    down = np.array([0.0, 0.0, -1.0])
    m = np.eye(4)
    m[:3, 0], m[:3, 1], m[:3, 2], m[:3, 3] = right, down, fwd, (x, y, 1.0)
    return m


def test_outside_view_of_boxes_around_a_camera() -> None:
    """A level camera at the origin looking along +x with a 90 degree horizontal view:
    a box ahead is in view, boxes behind, far to the side, above the view or straddling
    nothing are out, and one that straddles the view's edge is kept."""
    k = CameraIntrinsics(100, 100, 50.0, 50.0, 49.5, 49.5)  # 90 degrees both ways
    cam = _camera_at(0.0, 0.0, 0.0)
    boxes = {
        "ahead": ((2.0, -0.2, 0.8), (2.4, 0.2, 1.2)),
        "behind": ((-3.0, -0.5, 0.5), (-2.0, 0.5, 1.5)),
        "left, outside 45 degrees": ((1.0, 2.0, 0.8), (1.5, 3.0, 1.2)),
        "above the view": ((1.0, -0.2, 3.0), (1.2, 0.2, 3.5)),
        "straddling the left edge": ((1.0, 0.5, 0.8), (1.5, 1.6, 1.2)),
        "around the camera": ((-0.5, -0.5, 0.5), (0.5, 0.5, 1.5)),
    }
    lo = np.array([b[0] for b in boxes.values()])
    hi = np.array([b[1] for b in boxes.values()])
    got = dict(zip(boxes, outside_view(lo, hi, cam, k).tolist(), strict=True))
    assert got == {"ahead": False, "behind": True, "left, outside 45 degrees": True,
                   "above the view": True, "straddling the left edge": False,
                   "around the camera": False}
    # cut at a far plane: a box wholly beyond it is out, one reaching into it stays
    far = np.array([[6.5, -0.2, 0.8], [5.5, -0.2, 0.8]]), np.array([[7.0, 0.2, 1.2]] * 2)
    assert outside_view(*far, cam, k, far=6.25).tolist() == [True, False]
    assert outside_view(*far, cam, k).tolist() == [False, False]


def test_culled_images_equal_the_whole_house() -> None:
    """At random poses of a generated house, with doors and containers opened, half open
    and closed on the way, the culled renderer gives the same colour, depth and ids as the
    one that draws every body, while it hides most bodies."""
    spec = generate_house(3, rooms=(5, 5))
    rng = random.Random(1)
    x0, y0, x1, y1 = spec.bounds()
    cam = CameraConfig(width=64, height=48)
    hidden = []
    with Simulation(spec, camera=cam) as a, Simulation(spec, camera=cam, cull=False) as b:
        assert a.culling is not None and b.culling is None
        openable = sorted(a.world.panels)
        for i in range(40):
            if i % 8 == 7:
                sid, fraction = rng.choice(openable), rng.choice([0.0, 0.5, 1.0])
                for s in (a, b):
                    s._set_open(sid, fraction, s._layout_for_opening(sid))
            pose = (rng.uniform(x0, x1), rng.uniform(y0, y1), rng.uniform(-math.pi, math.pi))
            a.teleport(pose)
            b.teleport(pose)
            fa, fb = a.render(), b.render()
            assert np.array_equal(fa.rgb, fb.rgb)
            assert np.array_equal(fa.depth, fb.depth)
            assert fa.ids is not None and fb.ids is not None
            assert np.array_equal(fa.ids, fb.ids)
            hidden.append(float(a.culling.hidden.mean()))
    assert np.mean(hidden) > 0.3
