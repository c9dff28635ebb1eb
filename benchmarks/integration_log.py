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
import time
from pathlib import Path

from harness import add_output_options, alternate_trees, emit


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


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("log")
    ap.add_argument("--against", type=Path, default=None, help="baseline source tree")
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--repeats", type=int, default=2, help="integrations per process")
    ap.add_argument("--worker", action="store_true", help=argparse.SUPPRESS)
    a = add_output_options(ap).parse_args(argv)
    if a.worker:
        print(json.dumps(measure(a.log, a.repeats)))
        return 0
    docs = alternate_trees(Path(__file__), [str(Path(a.log).resolve()), "--worker",
                                            "--repeats", str(a.repeats)],
                           a.against, a.rounds, env={"OPENBLAS_NUM_THREADS": "1"})
    frames = int(next(iter(docs.values()))[0]["frames"])
    med = {k: statistics.median(statistics.median(d["cpu"]) for d in v)
           for k, v in docs.items()}
    digests = {k: {x for d in v for x in d["digest"]} for k, v in docs.items()}
    for name, c in med.items():
        print(f"{name:<10} {c:7.3f} CPU-s  {1e3 * c / frames:6.3f} ms/frame  "
              f"{frames / c:7.1f} frames/CPU-s  map digest {','.join(sorted(digests[name]))}")
    if "baseline" in med:
        same = digests["baseline"] == digests["this tree"]
        print(f"speed-up (baseline / this tree): {med['baseline'] / med['this tree']:.2f}x "
              f"({a.rounds} alternating rounds, load average {os.getloadavg()[0]:.1f}); "
              f"same map: {same}")
    emit({"frames": frames, "cpu_s_median": med, "runs": docs,
          "digests": {k: sorted(v) for k, v in digests.items()}}, a.json_out)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
