"""Synthetic RGB-D + instance frames that look like simulator renders (flat shading,
piecewise-planar depth), for log tests and benchmarks."""

from __future__ import annotations

import numpy as np

from sgtool.log import CameraIntrinsics


def synthetic_frame(i: int, width: int = 64, height: int = 48):
    """Frame ``i``: a floor, a wall and a box whose position moves with ``i``."""
    k = CameraIntrinsics.from_fov(width, height, 60.0)
    v, u = np.mgrid[0:height, 0:width]
    depth = np.full((height, width), 3.0, np.float32)
    ids = np.full((height, width), 2, np.int32)  # wall
    floor = v > height * 0.6
    depth[floor] = (1.2 * k.fy / np.maximum(v[floor] - k.cy, 1)).astype(np.float32)
    ids[floor] = 1
    x0 = (i * 3) % max(width - 10, 1)
    box = (u >= x0) & (u < x0 + 10) & (v > height * 0.4) & (v < height * 0.8)
    depth[box] = 1.5
    ids[box] = 3
    palette = np.array([[0, 0, 0], [120, 110, 90], [200, 200, 190], [30, 90, 160]], np.uint8)
    rgb = palette[ids]
    base = np.eye(4)
    base[0, 3] = 0.05 * i
    cam = np.array([[0, 0, 1, 0], [-1, 0, 0, 0], [0, -1, 0, 1.2], [0, 0, 0, 1]], float)
    pose = base @ cam
    return k, rgb, depth, ids, pose, base
