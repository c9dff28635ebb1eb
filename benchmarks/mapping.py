"""Speed and quality of the mapping / scene-graph pipeline on rendered multi-room houses.

Houses come from the generator (``sgtool.datasets.generator.generate_house``, 10 rooms),
rendered with the numpy ray-caster of :mod:`support.synthetic_world` along a tour that
visits every reachable room (A* on the house's occupancy grid, closed doors blocked) and
looks around (``--spin`` views) in each: about 1,000 frames of 320x240 depth + instance
ids. Rendering is not timed; frames are cached as .npy files (``--cache``).

Printed figures:

- per stage of :class:`~sgtool.scenegraph.builder.SceneGraphBuilder`: median and max ms
  (integration per frame, refresh stages every ``--refresh-every`` frames), frames/s of
  integration alone and of integration plus refreshes;
- the incremental refresh against a from-scratch rebuild of the same state, timed side by
  side every 100 frames (median of each and of their ratio);
- peak traced memory (tracemalloc) of a second, identical pass, whose final scene graph
  must be byte-identical to the first pass's (determinism);
- quality of the final graph against the house's room polygons (see
  :mod:`sgtool.scenegraph.quality`), strict and with doorless rooms merged.

Usage: ``python benchmarks/mapping.py [--seeds 3,1] [--width 320 --height 240]``
"""

from __future__ import annotations

import argparse
import hashlib
import math
import os
import sys
import tempfile
import time
import tracemalloc
from pathlib import Path

import numpy as np
from harness import support

from sgtool.datasets.generator import generate_house
from sgtool.datasets.room_evidence import frequency_room_classifier
from sgtool.house.spec import HouseSpec
from sgtool.log.frame import CameraIntrinsics, Frame
from sgtool.mapping.occupancy import astar, house_occupancy
from sgtool.mapping.voxels import VoxelConfig
from sgtool.replayers.score import score, score_lines
from sgtool.scenegraph.builder import BuilderConfig, SceneGraphBuilder

_world = support("synthetic_world")
HouseWorld, base_pose, camera_pose = _world.HouseWorld, _world.base_pose, _world.camera_pose
look_around, render, walk = _world.look_around, _world.render, _world.walk
world_of_house = _world.world_of_house

VFOV = 60.0
HEIGHT = 1.2
PITCH = 0.25


def tour(spec: HouseSpec, spin: int, step: float = 0.1) -> list[tuple[float, float, float]]:
    """Poses: look around at the start, then greedily walk to the nearest unvisited room
    centre (A* with closed doors blocked) and look around there."""
    occ = house_occupancy(spec, robot_radius=0.25)
    s = spec.starts[0]
    poses = look_around(s.x, s.y, s.yaw, spin)
    cur = (s.x, s.y)
    todo = list(spec.rooms)
    while todo:
        best = None
        for r in todo:
            p = astar(occ, cur, r.centroid)
            if p is None:
                continue
            length = sum(math.dist(p[i], p[i + 1]) for i in range(len(p) - 1))
            if best is None or length < best[0]:
                best = (length, r, p)
        if best is None:
            break
        _, room, path = best
        todo.remove(room)
        poses += walk(path[::3] + [path[-1]], step)
        cur = path[-1]
        poses += look_around(cur[0], cur[1], poses[-1][2], spin)
    return poses


def rendered(seed: int, width: int, height: int, spin: int, cache: Path
             ) -> tuple[HouseSpec, HouseWorld, CameraIntrinsics, dict[str, np.ndarray]]:
    spec = generate_house(seed, rooms=(10, 10))
    hw = world_of_house(spec)
    k = CameraIntrinsics.from_fov(width, height, VFOV)
    folder = cache / f"house{seed}_{width}x{height}_spin{spin}"
    names = ("depth", "ids", "poses")
    if not all((folder / f"{n}.npy").exists() for n in names):
        poses = np.asarray(tour(spec, spin), dtype=np.float64)
        folder.mkdir(parents=True, exist_ok=True)
        depth = np.lib.format.open_memmap(folder / "depth.tmp.npy", "w+", np.float32,
                                          (len(poses), height, width))
        ids = np.lib.format.open_memmap(folder / "ids.tmp.npy", "w+", np.int32,
                                        (len(poses), height, width))
        t0 = time.perf_counter()
        for i, (x, y, yaw) in enumerate(poses):
            depth[i], ids[i] = render(hw.world, camera_pose(x, y, yaw, HEIGHT, PITCH), k)
            if i % 100 == 0:
                print(f"  rendering house {seed}: {i}/{len(poses)} frames "
                      f"({time.perf_counter() - t0:.0f} s)", file=sys.stderr)
        depth.flush()
        ids.flush()
        del depth, ids
        np.save(folder / "poses.tmp.npy", poses)
        for n in names:
            os.replace(folder / f"{n}.tmp.npy", folder / f"{n}.npy")
    arrays = {n: np.load(folder / f"{n}.npy", mmap_mode="r") for n in names}
    return spec, hw, k, arrays


def frames(arrays: dict[str, np.ndarray], k: CameraIntrinsics, limit: int | None):
    n = len(arrays["poses"]) if limit is None else min(limit, len(arrays["poses"]))
    for i in range(n):
        x, y, yaw = arrays["poses"][i]
        yield Frame(i, i * 100_000_000, None, np.array(arrays["depth"][i]),
                    np.array(arrays["ids"][i]), camera_pose(x, y, yaw, HEIGHT, PITCH), k,
                    base_pose(x, y, yaw))


def run(builder: SceneGraphBuilder, frame_iter, compare_every: int = 100
        ) -> tuple[object, list[tuple[float, float]], int]:
    sg = None
    pairs: list[tuple[float, float]] = []
    n = 0
    for f in frame_iter:
        builder.integrate(f)
        n += 1
        if builder.due():
            sg = builder.refresh(f.time_ns)
            if compare_every and n % compare_every == 0:
                inc = builder.timings["refresh"][-1]
                t0 = time.perf_counter()
                full = builder.refresh(f.time_ns, from_scratch=True)
                pairs.append((inc, (time.perf_counter() - t0) * 1e3))
                assert full.to_json() == sg.to_json(), "incremental != from scratch"
    sg = builder.refresh(n * 100_000_000)
    return sg, pairs, n


def quality(spec: HouseSpec, hw: HouseWorld, builder: SceneGraphBuilder, sg) -> dict:  # noqa: ANN001
    return score(spec, hw.instances, builder.layers, sg)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--seeds", default="3,1", help="house seeds (10 rooms each)")
    ap.add_argument("--width", type=int, default=320)
    ap.add_argument("--height", type=int, default=240)
    ap.add_argument("--spin", type=int, default=36, help="views per look-around")
    ap.add_argument("--frames", type=int, default=None, help="use only the first N frames")
    ap.add_argument("--refresh-every", type=int, default=10)
    ap.add_argument("--cache", type=Path,
                    default=Path(tempfile.gettempdir()) / "sgtool-bench-mapping",
                    help="folder of rendered frames (reused across runs)")
    ap.add_argument("--no-memory", action="store_true", help="skip the traced second pass")
    a = ap.parse_args(argv)
    clf = frequency_room_classifier()
    pixels = a.width * a.height
    cfg = BuilderConfig(voxels=VoxelConfig(min_points=max(5, round(50 * pixels / 76800))),
                        refresh_every=a.refresh_every)
    for seed in (int(s) for s in a.seeds.split(",")):
        spec, hw, k, arrays = rendered(seed, a.width, a.height, a.spin, a.cache)
        b = SceneGraphBuilder(hw.instances, clf, cfg)
        t0 = time.perf_counter()
        sg, pairs, n = run(b, frames(arrays, k, a.frames))
        wall = time.perf_counter() - t0
        digest = hashlib.sha256(sg.to_json().encode()).hexdigest()[:16]
        print(f"\nhouse seed {seed}: {len(spec.rooms)} rooms, {n} frames {a.width}x{a.height}, "
              f"{len(b.voxels)} (voxel, label) entries at {b.voxels.resolution} m")
        scratch = b.stage_summary(from_scratch=True)
        print(f"{'stage':<12}{'median ms':>10}{'max ms':>10}{'calls':>7}"
              f"{'scratch median':>16}{'scratch max':>13}")
        for stage, (med, mx, cnt) in b.stage_summary().items():
            sm = scratch.get(stage)
            extra = f"{sm[0]:>16.2f}{sm[1]:>13.2f}" if sm else ""
            print(f"{stage:<12}{med:>10.2f}{mx:>10.2f}{cnt:>7}{extra}")
        integ = sum(b.timings["integrate"]) / 1e3
        print(f"integration: {n / integ:.1f} frames/s; integration + refreshes: "
              f"{n / (integ + sum(b.timings['refresh']) / 1e3):.1f} frames/s "
              f"(wall {wall:.1f} s incl. frame loading and from-scratch comparisons)")
        if pairs:
            inc = np.array([p[0] for p in pairs])
            full = np.array([p[1] for p in pairs])
            print(f"refresh incremental vs from scratch ({len(pairs)} points side by side): "
                  f"median {np.median(inc):.1f} ms vs {np.median(full):.1f} ms, "
                  f"ratio median {np.median(inc / full):.2f}")
        if not a.no_memory:
            tracemalloc.start()
            b2 = SceneGraphBuilder(hw.instances, clf, cfg)
            sg2, _, _ = run(b2, frames(arrays, k, a.frames), compare_every=0)
            _, peak = tracemalloc.get_traced_memory()
            tracemalloc.stop()
            same = sg2.to_json() == sg.to_json()
            print(f"peak traced memory (second pass): {peak / 2**20:.1f} MiB; final scene graph "
                  f"byte-identical to the first pass: {'yes' if same else 'NO'} ({digest})")
        q = quality(spec, hw, b, sg)
        unexplored = sum(not r.explored for r in sg.rooms)
        print(f"graph: {len(b.layers.voronoi)} Voronoi nodes, {len(sg.rooms)} rooms "
              f"({unexplored} unexplored behind closed doors), {len(sg.objects)} objects, "
              f"{len(sg.frontiers())} frontiers, {len(sg.doors)} doors")
        for line in score_lines(q):
            print(line)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
