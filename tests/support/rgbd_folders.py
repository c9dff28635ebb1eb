"""Synthetic RGB-D inputs whose content is known exactly: the depth a camera sees of a level
floor and a wall, and TUM RGB-D folders made of such frames (for the import checks)."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import cv2
import numpy as np

from sgtool.log.frame import CameraIntrinsics
from sgtool.log.poses import tq_from_pose

SMALL_K = CameraIntrinsics(80, 60, 60.0, 60.0, 39.5, 29.5)


def room_depth(k: CameraIntrinsics, cam_height: float, pitch_deg: float) -> np.ndarray:
    """Depth of a level floor seen by a camera ``cam_height`` above it, pitched down by
    ``pitch_deg``; the upper image rows see a wall 3 m ahead."""
    v, u = np.mgrid[0:k.height, 0:k.width]
    ray = np.stack([(u - k.cx) / k.fx, (v - k.cy) / k.fy, np.ones_like(u, float)], -1)
    p = np.radians(pitch_deg)
    # camera-frame down direction of the world, and forward on the floor plane
    down = np.array([0.0, np.cos(p), np.sin(p)])
    fwd = np.array([0.0, -np.sin(p), np.cos(p)])
    t_floor = cam_height / np.maximum(ray @ down, 1e-9)
    t_floor[ray @ down <= 1e-6] = np.inf
    t_wall = 3.0 / np.maximum(ray @ fwd, 1e-9)
    t = np.minimum(t_floor, t_wall)
    return (t * ray[..., 2]).astype(np.float32)


def level_camera(x: float, height: float, pitch_deg: float) -> np.ndarray:
    """camera-to-world of an optical frame at (x, 0, height) of a z-up world, looking
    along +x, pitched down by ``pitch_deg``."""
    p = np.radians(pitch_deg)
    fwd = np.array([np.cos(p), 0.0, -np.sin(p)])
    right = np.array([0.0, -1.0, 0.0])
    down = np.cross(fwd, right)
    T = np.eye(4)  # noqa: N806
    T[:3, :3] = np.stack([right, down, fwd], axis=1)
    T[:3, 3] = (x, 0.0, height)
    return T


def tum_line(t: float, name: str) -> str:
    return f"{t:.6f} {name}"


def make_tum_folder(
    root: Path, times: Sequence[float], *, units_per_m: float = 5000.0,
    cam_height: float = 1.4, pitch_deg: float = 25.0, missing: Sequence[int] = (),
    ground_truth: bool = True, k: CameraIntrinsics = SMALL_K,
) -> Path:
    """A TUM folder (``rgb.txt``, ``depth.txt``, ``groundtruth.txt``) of ``len(times)``
    frames (80x60 unless ``k`` says) at the listed ``times`` (written in the order given),
    depth stored at ``units_per_m``, the camera ``cam_height`` above the visible floor
    moving 2 cm per frame; the frames numbered in ``missing`` are listed but have no files."""
    (root / "rgb").mkdir(parents=True)
    (root / "depth").mkdir()
    depth = room_depth(k, cam_height, pitch_deg)
    raw = np.round(depth * units_per_m).clip(0, 65535).astype(np.uint16)
    colour = np.full((k.height, k.width, 3), 90, np.uint8)
    rgb_lines, depth_lines, gt = ["# rgb"], ["# depth"], ["# timestamp tx ty tz qx qy qz qw"]
    for i, t in enumerate(times):
        name = f"{i:04d}.png"
        if i not in missing:
            cv2.imwrite(str(root / "rgb" / name), colour)
            cv2.imwrite(str(root / "depth" / name), raw)
        rgb_lines.append(tum_line(t, f"rgb/{name}"))
        depth_lines.append(tum_line(t, f"depth/{name}"))
    for i, t in enumerate(sorted(set(times))):  # ground truth around each frame time
        tr, q = tq_from_pose(level_camera(0.02 * i, cam_height, pitch_deg))
        for dt in (-0.005, 0.0, 0.005):
            gt.append(f"{t + dt:.6f} " + " ".join(f"{v:.9f}" for v in (*tr, *q)))
    (root / "rgb.txt").write_text("\n".join(rgb_lines) + "\n")
    (root / "depth.txt").write_text("\n".join(depth_lines) + "\n")
    if ground_truth:
        (root / "groundtruth.txt").write_text("\n".join(gt) + "\n")
    return root
