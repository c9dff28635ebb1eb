"""Depth images ray-cast exactly from a scene of axis-aligned rectangles (floor, walls,
desk tops) for given camera poses, and TUM folders of them: inputs whose floor, scale and
motion are known, so the import's geometric checks can be tested."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import cv2
import numpy as np

from sgtool.log.frame import CameraIntrinsics
from sgtool.log.poses import tq_from_pose

K = CameraIntrinsics(80, 60, 60.0, 60.0, 39.5, 29.5)


@dataclass(frozen=True)
class Rect:
    """The rectangle ``axis`` = ``value`` (world z up), within ``lo``..``hi`` on the other two
    axes (in x, y, z order)."""

    axis: int
    value: float
    lo: tuple[float, float]
    hi: tuple[float, float]


def room(half_x: float = 2.5, half_y: float = 2.0, height: float = 2.6) -> list[Rect]:
    """Floor at z = 0 and four walls (with a ledge on one, for structure along every axis)."""
    inf = 100.0
    walls = [Rect(axis, side * half, (-inf, 0.0), (inf, height))
             for axis, half in ((0, half_x), (1, half_y)) for side in (1, -1)]
    ledge = [Rect(2, 0.9, (1.0, 1.2), (2.5, 2.0)), Rect(0, 1.0, (1.2, 0.0), (2.0, 0.9))]
    return [Rect(2, 0.0, (-inf, -inf), (inf, inf)), *walls, *ledge]


def look_at(eye: Sequence[float], target: Sequence[float]) -> np.ndarray:
    """camera-to-world of an optical frame (x right, y down, z forward) at ``eye`` looking
    at ``target``, its x axis level."""
    e, f = np.asarray(eye, float), np.asarray(target, float) - np.asarray(eye, float)
    f /= np.linalg.norm(f)
    right = np.cross(f, [0.0, 0.0, 1.0])
    right /= np.linalg.norm(right)
    down = np.cross(f, right)
    T = np.eye(4)  # noqa: N806
    T[:3, :3] = np.stack([right, down, f], axis=1)
    T[:3, 3] = e
    return T


def render(scene: Sequence[Rect], pose: np.ndarray, k: CameraIntrinsics = K) -> np.ndarray:
    """Depth (metres along the optical axis, 0 = no hit) of ``scene`` seen from ``pose``."""
    v, u = np.mgrid[0:k.height, 0:k.width]
    ray_c = np.stack([(u - k.cx) / k.fx, (v - k.cy) / k.fy, np.ones(u.shape)], -1)
    d = ray_c @ pose[:3, :3].T
    c = pose[:3, 3]
    best = np.full(u.shape, np.inf)
    for r in scene:
        with np.errstate(divide="ignore", invalid="ignore"):
            t = (r.value - c[r.axis]) / d[..., r.axis]
        p = c + t[..., None] * d
        others = [a for a in range(3) if a != r.axis]
        ok = (t > 1e-6) & np.isfinite(t)
        for j, a in enumerate(others):
            ok &= (p[..., a] >= r.lo[j]) & (p[..., a] <= r.hi[j])
        best = np.where(ok & (t < best), t, best)
    best[~np.isfinite(best)] = 0.0
    return best.astype(np.float32)  # t along ray_c (z = 1) is the depth


def make_scene_folder(root: Path, scene: Sequence[Rect], poses: Sequence[np.ndarray], *,
                      units_per_m: float = 5000.0, fps: float = 30.0,
                      k: CameraIntrinsics = K, gt_shift_s: float = 0.0) -> Path:
    """A TUM folder of the depth ``scene`` shows from each of ``poses`` (grey colour),
    stored at ``units_per_m``, frames 1 / ``fps`` apart, with the poses as ground truth
    (stamped ``gt_shift_s`` later than the images)."""
    (root / "rgb").mkdir(parents=True)
    (root / "depth").mkdir()
    rgb_lines, depth_lines, gt = ["# rgb"], ["# depth"], ["# timestamp tx ty tz qx qy qz qw"]
    for i, pose in enumerate(poses):
        t = 100.0 + i / fps
        name = f"{i:04d}.png"
        raw = np.round(render(scene, pose, k) * units_per_m).clip(0, 65535).astype(np.uint16)
        cv2.imwrite(str(root / "depth" / name), raw)
        cv2.imwrite(str(root / "rgb" / name), np.full((k.height, k.width, 3), 90, np.uint8))
        rgb_lines.append(f"{t:.6f} rgb/{name}")
        depth_lines.append(f"{t:.6f} depth/{name}")
        tr, q = tq_from_pose(pose)
        gt.append(f"{t + gt_shift_s:.6f} " + " ".join(f"{v:.9f}" for v in (*tr, *q)))
    (root / "rgb.txt").write_text("\n".join(rgb_lines) + "\n")
    (root / "depth.txt").write_text("\n".join(depth_lines) + "\n")
    (root / "groundtruth.txt").write_text("\n".join(gt) + "\n")
    return root
