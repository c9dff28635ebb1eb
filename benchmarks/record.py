"""Recorder speed: recorded frames/s against PyBullet's bare ``getCameraImage`` rate on the
same scene, side by side in one run.

For each resolution (320x240 and 640x480 by default) the demo house's scripted
exploration is run once without rendering to collect the first N base poses. Then, in
alternating rounds (so both share whatever else the machine is doing):

- **bare**: a Simulation of the house; per pose, ``getCameraImage`` with the recorder's
  exact arguments (TinyRenderer, segmentation mask with link indices), nothing else;
- **record**: ``record_house`` with ``frames=N``: the whole recorder, i.e. the scripted
  exploration (A*, door animations), rendering, depth and id conversion and writing
  the MCAP log (zstd), file closed and renamed.

Reported: median frames/s of each over the rounds and their ratio (goal: the recorder
keeps >= 80 % of the bare rate), plus a per-stage split of one recorder pass over the
same poses (render / convert / write), and log MB per frame.

Run by hand: ``.venv/bin/python benchmarks/record.py [--frames 300] [--rounds 3]``.
"""

from __future__ import annotations

import argparse
import statistics
import tempfile
import time
from pathlib import Path

import numpy as np
from harness import add_output_options, emit, round_order

from sgtool.datasets import demo_house
from sgtool.log.writer import LogWriter
from sgtool.recorders.sim import (
    CameraConfig,
    RecordOptions,
    SimObserver,
    Simulation,
    StopSimulation,
    explore_house,
    record_house,
)
from sgtool.recorders.sim.camera import depth_from_buffer, ids_from_segmentation, view_matrix
from sgtool.recorders.sim.simulation import LIGHT_DIRECTION


class _Poses(SimObserver):
    def __init__(self, n: int) -> None:
        self.n, self.poses = n, []

    def on_tick(self, sim: Simulation) -> None:
        if len(self.poses) >= self.n:
            raise StopSimulation
        self.poses.append(sim.base)


def _poses(house, cam: CameraConfig, n: int) -> list:  # type: ignore[no-untyped-def]
    with Simulation(house, camera=cam) as sim:
        obs = _Poses(n)
        sim.observers.append(obs)
        try:
            sim.tick()
            explore_house(sim)
        except StopSimulation:
            pass
    return obs.poses


def _bare(house, cam: CameraConfig, poses: list) -> float:  # type: ignore[no-untyped-def]
    with Simulation(house, camera=cam) as sim:
        pb, proj = sim._pb, sim._proj
        views = []
        for p in poses:
            sim.teleport(p)
            views.append(view_matrix(sim.camera_matrix()))
        t0 = time.perf_counter()
        for v in views:
            pb.getCameraImage(cam.width, cam.height, v, proj, renderer=pb.ER_TINY_RENDERER,
                              flags=pb.ER_SEGMENTATION_MASK_OBJECT_AND_LINKINDEX, shadow=0,
                              lightDirection=list(LIGHT_DIRECTION), physicsClientId=sim.client)
        return len(views) / (time.perf_counter() - t0)


def _record(house, cam: CameraConfig, n: int, out: Path) -> tuple[float, int, float]:  # type: ignore[no-untyped-def]
    t0 = time.perf_counter()
    rep = record_house(house, out, RecordOptions(camera=cam, frames=n))
    dt = time.perf_counter() - t0
    return rep.frames / dt, rep.frames, out.stat().st_size / 1e6 / rep.frames


def _stages(house, cam: CameraConfig, poses: list, out: Path) -> dict[str, float]:  # type: ignore[no-untyped-def]
    """Seconds per frame of render / convert / write over the same poses."""
    t = {"render": 0.0, "convert": 0.0, "write": 0.0}
    with Simulation(house, camera=cam) as sim, LogWriter(out) as w:
        pb = sim._pb
        for i, p in enumerate(poses):
            sim.teleport(p)
            pose = sim.camera_matrix()
            a = time.perf_counter()
            _, _, rgba, buf, seg = pb.getCameraImage(
                cam.width, cam.height, view_matrix(pose), sim._proj,
                renderer=pb.ER_TINY_RENDERER,
                flags=pb.ER_SEGMENTATION_MASK_OBJECT_AND_LINKINDEX, shadow=0,
                lightDirection=list(LIGHT_DIRECTION), physicsClientId=sim.client)
            b = time.perf_counter()
            rgb = np.asarray(rgba, np.uint8).reshape(cam.height, cam.width, 4)[..., :3]
            depth = depth_from_buffer(np.asarray(buf, np.float32).reshape(cam.height, cam.width),
                                      cam)
            ids = ids_from_segmentation(np.asarray(seg, np.int32).reshape(cam.height, cam.width),
                                        sim.world.lut)
            c = time.perf_counter()
            w.write_frame(i * 100_000_000, depth=depth, pose=pose, intrinsics=sim.intrinsics,
                          rgb=rgb, ids=ids, base_pose=sim.base_matrix())
            d = time.perf_counter()
            t["render"] += b - a
            t["convert"] += c - b
            t["write"] += d - c
    return {k: v / len(poses) for k, v in t.items()}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--frames", type=int, default=300, help="frames at 320x240 (640x480: "
                    "a third)")
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--resolutions", default="320x240,640x480")
    args = add_output_options(ap).parse_args()
    rows: list[dict] = []
    house = demo_house()
    print(f"demo house: {len(house.rooms)} rooms, {len(house.furniture)} pieces, "
          f"{len(house.objects)} objects; {args.rounds} alternating rounds, medians")
    print(f"{'resolution':<10} {'frames':>6} {'bare fps':>9} {'record fps':>10} {'ratio':>6} "
          f"{'render ms':>9} {'convert ms':>10} {'write ms':>8} {'MB/frame':>8}")
    with tempfile.TemporaryDirectory() as tmp:
        for res in args.resolutions.split(","):
            w, h = (int(v) for v in res.split("x"))
            cam = CameraConfig(width=w, height=h)
            n = args.frames if w * h <= 320 * 240 else max(args.frames // 3, 20)
            poses = _poses(house, cam, n)
            bare, rec, mb = [], [], 0.0
            for k in range(args.rounds):
                for case in round_order(["bare", "record"], k):
                    if case == "bare":
                        bare.append(_bare(house, cam, poses))
                        continue
                    fps, frames, mb = _record(house, cam, n, Path(tmp) / "rec.mcap")
                    assert frames == n
                    rec.append(fps)
            st = _stages(house, cam, poses, Path(tmp) / "stages.mcap")
            b, r = statistics.median(bare), statistics.median(rec)
            print(f"{res:<10} {n:>6} {b:>9.1f} {r:>10.1f} {r / b:>6.2f} "
                  f"{st['render'] * 1e3:>9.1f} {st['convert'] * 1e3:>10.2f} "
                  f"{st['write'] * 1e3:>8.2f} {mb:>8.3f}")
            print(f"{'':<10} rounds: bare {', '.join(f'{x:.1f}' for x in bare)}; "
                  f"record {', '.join(f'{x:.1f}' for x in rec)}")
            rows.append({"resolution": res, "frames": n, "bare_fps": bare, "record_fps": rec,
                         "stages_s_per_frame": st, "mb_per_frame": mb})
    emit({"rounds": args.rounds, "resolutions": rows}, args.json_out)


if __name__ == "__main__":
    main()
