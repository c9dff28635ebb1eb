"""Log write/read throughput and size, per resolution and chunk compression.

    .venv/bin/python benchmarks/log_io.py [--frames 300] [--repeats 3]

Frames are simulator-like renders (flat-shaded floor, walls and a moving box with a
lighting gradient, piecewise-planar depth, instance ids): what `sgtool record` writes.
Prints, per resolution and compression: frames/s written (through LogWriter.write_frame,
i.e. protobuf encoding + chunking + compression + file I/O), frames/s read back as Frames
(decompression + decoding + pose composition), and bytes per frame; medians of the repeats.
Target (issue 2): at least 300 frames/s written at 320x240 on 2 cores.
"""

from __future__ import annotations

import argparse
import statistics
import tempfile
from pathlib import Path

import numpy as np
from harness import add_output_options, emit, timed

from sgtool.log import CameraIntrinsics, LogReader, LogWriter


def render(i: int, w: int, h: int) -> tuple:
    k = CameraIntrinsics.from_fov(w, h, 60.0)
    v, u = np.mgrid[0:h, 0:w].astype(np.float32)
    depth = np.full((h, w), 4.0, np.float32)
    ids = np.full((h, w), 2, np.int32)
    floor = v > k.cy + 1
    depth[floor] = 1.2 * k.fy / (v[floor] - k.cy)
    ids[floor] = 1
    x0 = int((i * 7) % max(w - w // 5, 1))
    box = (u >= x0) & (u < x0 + w // 5) & (v > h * 0.4) & (v < h * 0.85)
    depth[box] = 1.5 + 0.002 * (u[box] - x0)
    ids[box] = 3
    base = np.array([[0, 0, 0], [140, 120, 100], [210, 205, 195], [40, 90, 170]], np.float32)
    shade = np.clip(1.1 - 0.12 * depth, 0.4, 1.0)[..., None]
    rgb = (base[ids] * shade).astype(np.uint8)
    pose = np.eye(4)
    pose[0, 3] = 0.01 * i
    return k, rgb, depth, ids, pose


def bench(w: int, h: int, compression: str, n: int, frames: list) -> dict[str, float]:
    """One write and read-back of ``n`` frames: frames/s written and read (wall, as
    printed, and per CPU-second) and bytes per frame."""
    with tempfile.TemporaryDirectory() as d:
        path = Path(d) / "b.mcap"

        def write() -> None:
            with LogWriter(path, compression=compression) as log:
                for i in range(n):
                    k, rgb, depth, ids, pose = frames[i % len(frames)]
                    log.write_frame(i * 33_333_333, rgb=rgb, depth=depth, ids=ids, pose=pose,
                                    intrinsics=k, base_pose=pose)

        def read() -> int:
            with LogReader(path) as r:
                return sum(1 for _ in r.frames())

        _, wrote = timed(write)
        size = path.stat().st_size
        m, red = timed(read)
        assert m == n
    return {"write_fps": n / wrote.wall_s, "read_fps": n / red.wall_s,
            "write_per_cpu_s": n / max(wrote.cpu_s, 1e-9),
            "read_per_cpu_s": n / max(red.cpu_s, 1e-9), "bytes_per_frame": size / n}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--frames", type=int, default=300)
    ap.add_argument("--repeats", type=int, default=3)
    a = add_output_options(ap).parse_args()
    rows = []
    print(f"{'resolution':<10} {'compr':<5} {'write fps':>10} {'read fps':>9} {'KB/frame':>9}")
    for w, h in [(320, 240), (640, 480)]:
        frames = [render(i, w, h) for i in range(60)]
        for comp in ["zstd", "lz4"]:
            runs = [bench(w, h, comp, a.frames, frames) for _ in range(a.repeats)]
            med = {k: statistics.median(r[k] for r in runs) for k in runs[0]}
            print(f"{w}x{h:<6} {comp:<5} {med['write_fps']:>10.0f} {med['read_fps']:>9.0f} "
                  f"{med['bytes_per_frame'] / 1024:>9.1f}")
            rows.append({"resolution": f"{w}x{h}", "compression": comp, **med})
    emit({"frames": a.frames, "repeats": a.repeats, "medians": rows}, a.json_out)


if __name__ == "__main__":
    main()
