"""Voxel integration against Open3D's tensor ``VoxelBlockGrid`` on the same real frames.

The 100 real Kinect frames of 7-Scenes "redkitchen" (every 10th, 640x480, ground-truth
poses; ``../shared/data/rgbd/7scenes-redkitchen-every10``) are integrated at the same
voxel size (5 cm) and range (5 m) by

- sgtool's :class:`~sgtool.mapping.voxels.VoxelMap` (semantic votes: the frames carry a
  label image of 48 tiles, 80 x 80 pixels each, so every point votes for a label), the
  depth conversion from millimetres included in the time;
- Open3D's ``VoxelBlockGrid`` (TSDF + weight, 16^3 blocks), block allocation
  (``compute_unique_block_coordinates``) and ``integrate`` in the time.

Rounds alternate the order; figures are frames per CPU-second (``time.process_time``,
which counts every thread of Open3D's parallel loops), medians over the rounds, and the
ratio. Target (issue 20): VoxelMap >= 1.0x Open3D.

Usage: ``python benchmarks/integration.py [--rounds 3] [--data DIR]``
"""

from __future__ import annotations

import argparse
import os
from pathlib import Path

import cv2
import numpy as np
from harness import add_output_options, alternate, emit

from sgtool.log.frame import CameraIntrinsics, Frame
from sgtool.mapping.voxels import VoxelConfig, VoxelMap

DATA = Path(os.environ.get("SGTOOL_SHARED_DATA", Path(__file__).resolve().parents[2]
                           / "shared" / "data")) / "rgbd" / "7scenes-redkitchen-every10"
K = CameraIntrinsics(640, 480, 585.0, 585.0, 320.0, 240.0)
VOXEL = 0.05
MAX_RANGE = 5.0


def load(folder: Path, limit: int | None = None) -> list[tuple[np.ndarray, np.ndarray]]:
    """(depth uint16 mm with 0 = none, camera-to-world 4x4) per frame, in order (the first
    ``limit`` when given)."""
    out = []
    for p in sorted(folder.glob("frame-*.depth.png"))[:limit]:
        d = cv2.imread(str(p), cv2.IMREAD_UNCHANGED).astype(np.uint16)
        d[d == 65535] = 0  # 7-Scenes: no return
        pose = np.loadtxt(str(p).replace(".depth.png", ".pose.txt"))
        out.append((d, pose))
    return out


def tiles(h: int, w: int) -> np.ndarray:
    v, u = np.mgrid[0:h, 0:w]
    return (1 + u // 80 + 8 * (v // 80)).astype(np.int32)


def ours(frames: list[tuple[np.ndarray, np.ndarray]], ids: np.ndarray) -> VoxelMap:
    vm = VoxelMap(VoxelConfig(resolution=VOXEL, max_range=MAX_RANGE))
    for i, (d, pose) in enumerate(frames):
        depth = d.astype(np.float32) / np.float32(1000.0)
        vm.integrate(Frame(i, i, None, depth, ids, pose, K, None))
    vm.flush()
    return vm


def open3d(frames: list[tuple[np.ndarray, np.ndarray]]):  # type: ignore[no-untyped-def]
    import open3d as o3d
    import open3d.core as o3c

    dev = o3c.Device("CPU:0")
    vbg = o3d.t.geometry.VoxelBlockGrid(
        attr_names=("tsdf", "weight"), attr_dtypes=(o3c.float32, o3c.float32),
        attr_channels=((1), (1)), voxel_size=VOXEL, block_resolution=16,
        block_count=20000, device=dev)
    intr = o3c.Tensor([[K.fx, 0, K.cx], [0, K.fy, K.cy], [0, 0, 1]], o3c.Dtype.Float64)
    for d, pose in frames:
        depth = o3d.t.geometry.Image(o3c.Tensor(d)).to(dev)
        extr = o3c.Tensor(np.linalg.inv(pose), o3c.Dtype.Float64)
        blocks = vbg.compute_unique_block_coordinates(depth, intr, extr, 1000.0, MAX_RANGE)
        vbg.integrate(blocks, depth, intr, extr, 1000.0, MAX_RANGE)
    return vbg


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--data", type=Path, default=DATA)
    ap.add_argument("--frames", type=int, default=None, help="only the first N frames")
    a = add_output_options(ap).parse_args(argv)
    if not a.data.is_dir():
        raise SystemExit(f"{a.data}: no 7-Scenes frames (set SGTOOL_SHARED_DATA)")
    frames = load(a.data, a.frames)
    ids = tiles(*frames[0][0].shape)
    size: dict[str, int] = {}

    def run_ours() -> None:
        size["sgtool VoxelMap"] = len(ours(frames, ids))

    def run_open3d() -> None:
        size["Open3D VoxelBlockGrid"] = int(open3d(frames).hashmap().size())

    timings = alternate({"sgtool VoxelMap": run_ours, "Open3D VoxelBlockGrid": run_open3d},
                        a.rounds)
    rates = {name: t.per_cpu_s(len(frames)) for name, t in timings.items()}
    print(f"{len(frames)} frames 640x480 of {a.data.name}, {VOXEL} m voxels, range "
          f"{MAX_RANGE} m; frames per CPU-second, median of {a.rounds} alternating rounds")
    base = rates["Open3D VoxelBlockGrid"]
    for name, rate in rates.items():
        unit = "(voxel, label) entries" if name.startswith("sgtool") else "blocks of 16^3"
        print(f"  {name:<24}{rate:>8.1f}  {rate / base:.2f}x  ({size[name]} {unit})")
    emit({"frames": len(frames), "frames_per_cpu_s": rates, "sizes": size,
          "timings": timings}, a.json_out)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
