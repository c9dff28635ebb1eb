"""Importer figures on the real RGB-D data beside the repository (``../shared/data``):

1. folder import: frames/s and log size of ICL-NUIM livingroom1 (211 frames) and 7-Scenes
   redkitchen (100 frames), lz4 vs zstd chunks;
2. bag path: the ICL log written as a ROS 2 MCAP bag, imported back (frames/s);
3. odometry drift of ``rgbd``, ``icp`` and ``rgbd+icp`` against the 7-Scenes ground truth
   and against the ICL trajectory shipped with the frames (Open3D's own reconstruction,
   not ground truth), with the time per frame pair and the failed steps (Open3D failures,
   too little matched, motions implausible for the frame interval).

Run by hand: ``.venv/bin/python benchmarks/import_.py [--quick] [--data DIR]``.
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time
from pathlib import Path

from sgtool.log.frame import CameraIntrinsics
from sgtool.recorders.importers.bag import BagOptions, import_bag
from sgtool.recorders.importers.images import depth_to_metres, read_color_file, read_depth_file
from sgtool.recorders.importers.layouts import read_sequence
from sgtool.recorders.importers.odometry import METHODS, drift_against, estimate_trajectory
from sgtool.recorders.importers.rgbd import RgbdOptions, camera_for, import_rgbd

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))  # the test support modules
from support.bag_export import write_log_as_bag  # noqa: E402

REPO = Path(__file__).resolve().parents[1]


def folder_import(data: Path, tmp: Path) -> None:
    print("## folder import (median of 3 runs)")
    print(f"{'dataset':<28} {'comp':<5} {'frames':>6} {'s':>6} {'fps':>6} {'MB':>7} "
          f"{'MB/frame':>8}")
    for name in ("icl-livingroom1-micro", "7scenes-redkitchen-every10"):
        for comp in ("lz4", "zstd"):
            times = []
            for _ in range(3):
                out = tmp / f"{name}-{comp}.mcap"
                t0 = time.perf_counter()
                rep = import_rgbd(data / "rgbd" / name, out,
                                  RgbdOptions(progress=False, compression=comp))
                times.append(time.perf_counter() - t0)
            t = sorted(times)[1]
            mb = out.stat().st_size / 1e6
            print(f"{name:<28} {comp:<5} {rep.frames:>6} {t:>6.2f} {rep.frames / t:>6.1f} "
                  f"{mb:>7.1f} {mb / rep.frames:>8.2f}")


def bag_path(data: Path, tmp: Path) -> None:
    print("\n## bag path: ICL log -> ROS 2 MCAP bag -> sgtool log")
    log = tmp / "icl-livingroom1-micro-lz4.mcap"
    bag = tmp / "icl_bag"
    t0 = time.perf_counter()
    n = write_log_as_bag(log, bag, "ros2-mcap")
    t_w = time.perf_counter() - t0
    t0 = time.perf_counter()
    rep = import_bag(bag, tmp / "back.mcap", BagOptions(
        depth="/camera/depth/image_raw", rgb="/camera/rgb/image_raw",
        info="/camera/depth/camera_info", progress=False))
    t_i = time.perf_counter() - t0
    size = sum(p.stat().st_size for p in bag.iterdir()) / 1e6
    print(f"write bag: {n} frames in {t_w:.2f} s ({n / t_w:.1f} fps, {size:.0f} MB); "
          f"import: {rep.frames} frames in {t_i:.2f} s ({rep.frames / t_i:.1f} fps)")


def odometry(data: Path, quick: bool) -> None:
    print("\n## odometry drift (frame to frame, start at the reference pose)")
    print(f"{'dataset':<28} {'method':<9} {'frames':>6} {'path m':>7} {'ATE m':>7} "
          f"{'final m':>8} {'final %':>7} {'fin deg':>7} {'RPE cm':>7} {'RPE deg':>7} "
          f"{'fail':>4} {'ms/pair':>7}")
    for name, ref in (("7scenes-redkitchen-every10", "ground truth"),
                      ("icl-livingroom1-micro",
                       "the reference trajectory (reconstructed, not ground truth)")):
        seq = read_sequence(data / "rgbd" / name)
        frames = list(seq.frames[: 20 if quick else None])
        first = read_depth_file(frames[0].depth_path)
        k: CameraIntrinsics = camera_for(seq, RgbdOptions(), first.shape[1], first.shape[0])
        loaded = [(read_color_file(f.color_path), depth_to_metres(
            read_depth_file(f.depth_path), seq.depth_scale)) for f in frames]
        truth = [f.pose for f in frames]
        for method in METHODS:
            t0 = time.perf_counter()
            res = estimate_trajectory(loaded, k, method=method, start=truth[0],
                                      times_ns=[f.time_ns for f in frames])
            dt = time.perf_counter() - t0
            d = drift_against(list(res.poses), truth)
            pct = d.drift_percent if d.drift_percent is not None else float("nan")
            print(f"{name:<28} {method:<9} {d.frames:>6} {d.path_length_m:>7.2f} "
                  f"{d.ate_rmse_m:>7.3f} {d.final_translation_m:>8.3f} {pct:>7.1f} "
                  f"{d.final_rotation_deg:>7.2f} {d.rpe_translation_m * 100:>7.2f} "
                  f"{d.rpe_rotation_deg:>7.3f} {res.failures:>4} "
                  f"{1000 * dt / (len(frames) - 1):>7.0f}")
            if res.failed:
                print(f"  {method}: {res.summary()}")
        print(f"  (drift against {ref})")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--data", type=Path,
                    default=Path(os.environ.get("SGTOOL_SHARED_DATA",
                                                REPO.parent / "shared" / "data")))
    ap.add_argument("--quick", action="store_true", help="20 frames for the odometry")
    ap.add_argument("--skip-import", action="store_true")
    args = ap.parse_args()
    if not (args.data / "rgbd").is_dir():
        raise SystemExit(f"{args.data}/rgbd is absent")
    with tempfile.TemporaryDirectory(prefix="sgtool-import-bench-") as tmp:
        if not args.skip_import:
            folder_import(args.data, Path(tmp))
            bag_path(args.data, Path(tmp))
        odometry(args.data, args.quick)


if __name__ == "__main__":
    main()
