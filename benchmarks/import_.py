"""Importer figures on the real RGB-D data beside the repository (``../shared/data``):

1. folder import: frames/s and log size of ICL-NUIM livingroom1 (211 frames) and 7-Scenes
   redkitchen (100 frames), lz4 vs zstd chunks;
2. bag path: the ICL log written as a ROS 2 MCAP bag, imported back (frames/s);
3. odometry drift of ``rgbd``, ``icp`` and ``rgbd+icp`` against the 7-Scenes ground truth
   and against the ICL trajectory shipped with the frames (Open3D's own reconstruction,
   not ground truth), with the time per frame pair and the failed steps (Open3D failures,
   too little matched, motions implausible for the frame interval).

4. ``--checks`` (issue 18) instead: the report lines saying where the intrinsics, depth scale,
   up direction and floor of each real recording came from; the silent-wrong inputs of the
   issue, built synthetically, each with the error or warning it now gives; the export round
   trip of a replayed golden log (messages written = read back by rosbags, per topic).

Run by hand: ``.venv/bin/python benchmarks/import_.py [--quick] [--checks] [--data DIR]``.
"""

from __future__ import annotations

import argparse
import os
import tempfile
import time
from pathlib import Path

from harness import REPO, support

from sgtool.log.frame import CameraIntrinsics
from sgtool.recorders.importers.bag import BagOptions, import_bag
from sgtool.recorders.importers.images import depth_to_metres, read_color_file_kind, read_depth_file
from sgtool.recorders.importers.layouts import read_sequence
from sgtool.recorders.importers.odometry import METHODS, drift_against, estimate_trajectory
from sgtool.recorders.importers.rgbd import RgbdOptions, camera_for, import_rgbd

write_log_as_bag = support("bag_export").write_log_as_bag


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
        loaded = [(read_color_file_kind(f.color_path)[0], depth_to_metres(
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


def provenance(data: Path, tmp: Path) -> None:
    print("## where each parameter came from (import report lines)")
    cases = [("rgbd", data / "rgbd" / name, []) for name in
             ("icl-livingroom1-micro", "7scenes-redkitchen-every10", "open3d-testdata")]
    cases.append(("bag", data / "logs" / "rosbag2-mcap" / "evo_nav2_turtlebot.mcap",
                  ["--tf-frames", "map:base_footprint"]))
    cases.append(("bag", data / "logs" / "evo" / "tf_example.bag",
                  ["--tf-frames", "odom:base_link"]))
    # a camera bag: the imported ICL frames written as a ROS 2 bag, imported without --info
    cases.append(("bag", tmp / "icl_bag", ["--depth", "/camera/depth/image_raw", "--rgb",
                                           "/camera/rgb/image_raw"]))
    for kind, src, extra in cases:
        if src.name == "icl_bag":
            write_log_as_bag(tmp / "prov-icl-livingroom1-micro.mcap", src, "ros2-mcap")
        out = tmp / f"prov-{src.stem}.mcap"
        r = _cli(["import", kind, str(src), "-o", str(out), "--quiet", *extra])
        shown = src.relative_to(data) if src.is_relative_to(data) else f"(ICL as a bag) {src.name}"
        print(f"$ sgtool import {kind} {shown} {' '.join(extra)}".rstrip())
        keep = ("wrote", "poses:", "intrinsics:", "depth scale:", "up:", "floor:", "warning")
        for line in r.output.splitlines():
            if line.startswith(keep) or line.startswith("sgtool: "):
                print("  " + line)


def _cli(args: list[str]):  # type: ignore[no-untyped-def]
    from click.testing import CliRunner

    from sgtool.cli import cli

    return CliRunner().invoke(cli, args)


def silent_cases(tmp: Path) -> None:
    """The inputs of issue 18 that gave silently wrong results, and what they give now."""
    import numpy as np
    BagWriter = support("bag_export").BagWriter  # noqa: N806
    synthetic_frame = support("logfixtures").synthetic_frame
    make_tum_folder = support("rgbd_folders").make_tum_folder

    print("\n## issue 18's silent-wrong inputs (synthetic), and what they give now")
    good = [100.0 + i / 30 for i in range(12)]
    k = ["--intrinsics", "60,60,39.5,29.5", "--quiet"]
    rng = np.random.default_rng(1)
    folders = {
        "interval time stamps": (make_tum_folder(tmp / "c1", list(rng.uniform(0.03, 0.034, 12)),
                                                 ground_truth=False), k),
        "duplicated time stamps": (make_tum_folder(tmp / "c2", good[:6] + good[5:]), k),
        "time stamps in ms, not s (1000 fps)": (make_tum_folder(
            tmp / "c2b", [100.0 + i / 1000 for i in range(12)]), k),
        "mm depth at TUM scale 5000": (make_tum_folder(tmp / "c3", good, units_per_m=1000), k),
        "desk top taken for the floor": (make_tum_folder(tmp / "c4", good, cam_height=0.42), k),
        "intrinsics from the folder name": (make_tum_folder(
            tmp / "rgbd_dataset_freiburg1_c5", good[:3],
            k=CameraIntrinsics(640, 480, 517.3, 516.5, 318.6, 255.3)), ["--quiet"]),
        "files listed but missing": (make_tum_folder(tmp / "c6", good, missing=(3,)), k),
    }
    bag = tmp / "c7"
    with BagWriter(bag, "ros2-mcap") as w:
        for i in range(3):
            kk, rgb, depth, _, pose, _ = synthetic_frame(i)
            t = 1_000_000 + i * 33_000_000
            w.write("/cam/info", "sensor_msgs/msg/CameraInfo", t, w.camera_info(t, "c", kk))
            w.write("/cam/depth", "sensor_msgs/msg/Image", t,  # one header stamp for all
                    w.image(1_000_000, "c", np.round(depth * 1000).astype(np.uint16), "16UC1"))
            w.write("/cam/rgb", "sensor_msgs/msg/Image", t, w.image(t, "c", rgb, "rgb8"))
    ros2_mcap = bag / "c7.mcap"  # the bag's storage file: a ROS 2 MCAP recording
    rows = [(name, ["import", "rgbd", str(root), "-o", str(tmp / f"o{i}.mcap"), *flags])
            for i, (name, (root, flags)) in enumerate(folders.items())]
    rows.append(("bag images all with one header stamp",
                 ["import", "bag", str(bag), "-o", str(tmp / "oa.mcap"), "--depth",
                  "/cam/depth", "--intrinsics", "60,60,31.5,23.5"]))
    rows.append(("--rgb pointing at a 16UC1 topic",
                 ["import", "bag", str(bag), "-o", str(tmp / "ob.mcap"), "--depth",
                  "/cam/depth", "--rgb", "/cam/depth"]))
    rows.append(("replay of a ROS 2 MCAP", ["replay", str(ros2_mcap)]))
    handled = 0
    for name, args in rows:
        r = _cli(args)
        msg = next((x for x in r.output.splitlines() if x.startswith("sgtool: ")), "")
        outcome = "error" if r.exit_code == 2 else ("warning" if "warning" in msg else "ok?")
        handled += outcome in ("error", "warning")
        print(f"- {name}: {msg[len('sgtool: '):][:160]}")
    print(f"{handled} of {len(rows)} now warn or fail (before: all silent or unhelpful)")


def export_round_trip(tmp: Path) -> None:
    from rosbags.highlevel import AnyReader
    from rosbags.typesys import Stores, get_typestore

    print("\n## export round trip: the golden house6-tour replayed, exported, read back")
    derived = tmp / "derived.mcap"
    _cli(["replay", str(REPO / "tests" / "golden" / "house6-tour.mcap"), "-o", str(derived),
          "--no-progress"])
    for fmt, out in (("ros2", tmp / "bag2"), ("ros1", tmp / "bag1.bag")):
        t0 = time.perf_counter()
        r = _cli(["export", "bag", str(derived), "-o", str(out), "--format", fmt])
        dt = time.perf_counter() - t0
        written = {ln.split()[0]: int(ln.split()[-1]) for ln in r.output.splitlines()[1:]
                   if ln.startswith("  /")}
        back: dict[str, int] = {}
        with AnyReader([out], default_typestore=get_typestore(Stores.LATEST)) as rd:
            for c, _, _ in rd.messages():
                back[c.topic] = back.get(c.topic, 0) + 1
        print(f"{fmt}: {sum(written.values())} messages in {dt:.2f} s; per topic "
              "written/read back:")
        for topic in sorted(written):
            print(f"  {topic:<28} {written[topic]:>5} / {back.get(topic, 0):>5}")
        print(f"  all equal: {written == back}")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--data", type=Path,
                    default=Path(os.environ.get("SGTOOL_SHARED_DATA",
                                                REPO.parent / "shared" / "data")))
    ap.add_argument("--quick", action="store_true", help="20 frames for the odometry")
    ap.add_argument("--skip-import", action="store_true")
    ap.add_argument("--checks", action="store_true",
                    help="only the figures of issue 18 (provenance, checks, export)")
    args = ap.parse_args()
    if not (args.data / "rgbd").is_dir():
        raise SystemExit(f"{args.data}/rgbd is absent")
    if args.checks:
        with tempfile.TemporaryDirectory(prefix="sgtool-import-checks-") as tmp:
            provenance(args.data, Path(tmp))
            silent_cases(Path(tmp))
            export_round_trip(Path(tmp))
        return
    with tempfile.TemporaryDirectory(prefix="sgtool-import-bench-") as tmp:
        if not args.skip_import:
            folder_import(args.data, Path(tmp))
            bag_path(args.data, Path(tmp))
        odometry(args.data, args.quick)


if __name__ == "__main__":
    main()
