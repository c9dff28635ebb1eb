"""Voxel integration of a recorded log's frames, this tree against an older one, side by side.

Every frame of LOG is read once into memory; a round integrates them all into a fresh
``VoxelMap`` (viewpoint: the base pose, as the scene-graph builder passes it) and flushes.
Each tree runs in its own process (the older one through a shadow package,
``side_by_side.shadow_package``), rounds alternate, and the figures are CPU seconds
(``time.process_time``) of the integration alone, medians over the rounds. Each run
prints a digest of the whole map (keys, vote counts and every per-label statistic), so
the two trees must print the same digest: the map is the same bit for bit.

    .venv/bin/python benchmarks/integration_log.py --against /tmp/old-tree --rounds 3 \\
        /tmp/sgtool-bench-replay/house3_10rooms_320x240_fps4.mcap
"""

from __future__ import annotations

import argparse
import hashlib
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path


def measure(log: str, repeats: int) -> dict[str, object]:
    """CPU seconds of ``repeats`` integrations of every frame of ``log``, and the digest."""
    import numpy as np

    from sgtool.log.reader import LogReader
    from sgtool.mapping.voxels import VoxelMap

    with LogReader(log) as r:
        frames = list(r.frames())
    times, digests = [], set()
    for _ in range(repeats):
        vm = VoxelMap()
        t0 = time.process_time()
        for fr in frames:
            src = fr.base_pose if fr.base_pose is not None else fr.pose
            vm.integrate(fr, (float(src[0, 3]), float(src[1, 3])))
        vm.flush()
        times.append(time.process_time() - t0)
        keys, counts = vm.entries()
        h = hashlib.sha256(keys.tobytes() + counts.tobytes())
        st = vm._stats
        for a in (st.points_max, st.points_total, st.frames, st.last_index, st.view_dist,
                  st.view_xy, st.vox_n, st.vox_sum):
            h.update(np.ascontiguousarray(a).tobytes())
        digests.add(h.hexdigest()[:16])
    return {"frames": len(frames), "cpu": times, "digest": sorted(digests)}


def run_tree(log: str, repeats: int, pythonpath: str | None) -> dict[str, object]:
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1")
    if pythonpath:
        env["PYTHONPATH"] = pythonpath + os.pathsep + env.get("PYTHONPATH", "")
    code = (f"import json, sys; sys.path.insert(0, {str(Path(__file__).parent)!r}); "
            f"import integration_log as m; print(json.dumps(m.measure({log!r}, {repeats})))")
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True,
                         text=True, check=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("log")
    ap.add_argument("--against", type=Path, default=None, help="baseline source tree")
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--repeats", type=int, default=2, help="integrations per process")
    a = ap.parse_args(argv)
    sys.path.insert(0, str(Path(__file__).parent))
    from side_by_side import shadow_package

    trees: dict[str, str | None] = {"this tree": None}
    if a.against is not None:
        trees["baseline"] = str(shadow_package(a.against.resolve(),
                                               Path(tempfile.mkdtemp(prefix="sgtool-int-"))))
    got: dict[str, list[float]] = {k: [] for k in trees}
    digests: dict[str, set[str]] = {k: set() for k in trees}
    frames = 0
    for r in range(a.rounds):
        for name in (list(trees) if r % 2 == 0 else list(trees)[::-1]):
            res = run_tree(a.log, a.repeats, trees[name])
            frames = int(res["frames"])  # type: ignore[call-overload]
            got[name].append(statistics.median(res["cpu"]))  # type: ignore[arg-type]
            digests[name].update(res["digest"])  # type: ignore[arg-type]
            print(f"round {r + 1} {name:<10} cpu {got[name][-1]:.3f} s", file=sys.stderr)
    med = {k: statistics.median(v) for k, v in got.items()}
    for name, c in med.items():
        print(f"{name:<10} {c:7.3f} CPU-s  {1e3 * c / frames:6.3f} ms/frame  "
              f"{frames / c:7.1f} frames/CPU-s  map digest {','.join(sorted(digests[name]))}")
    if "baseline" in med:
        same = digests["baseline"] == digests["this tree"]
        print(f"speed-up (baseline / this tree): {med['baseline'] / med['this tree']:.2f}x "
              f"({a.rounds} alternating rounds, load average {os.getloadavg()[0]:.1f}); "
              f"same map: {same}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
