"""Speed, memory, determinism and quality of ``sgtool replay`` on recorded full-house logs.

A 10-room evaluation house (``generate_house(seed, rooms=(10, 10))``) is recorded once with
the scripted exploration in PyBullet at 320x240 (cached under ``--cache``; the frame rate
is chosen so the whole tour is about 1,000 frames), then replayed into a derived log the
way ``sgtool replay LOG -o OUT`` does. Printed:

- per stage of the scene-graph builder: median and max ms (integration per frame, the
  refresh stages every ``--every`` frames and at every action);
- frames/s of voxel integration alone, of integration plus refreshes, and of the whole
  replay (decoding, integration, refreshes, writing the derived log);
- the incremental refresh against a from-scratch rebuild of the same state, timed side by
  side at every ``--compare``-th refresh (medians and the median ratio); the two graphs
  must be byte-identical;
- peak traced memory (tracemalloc) of a second replay without output, and whether two
  replays wrote byte-identical files (sha256);
- quality of the final graph against the house (``--score`` figures), strict and merged.

Usage: ``python benchmarks/replay.py [--seeds 3] [--fps 4] [--every 10]``
"""

from __future__ import annotations

import argparse
import hashlib
import json
import statistics
import sys
import tempfile
import time
import tracemalloc
from pathlib import Path

from harness import add_output_options, emit, timed

from sgtool.datasets.generator import generate_house
from sgtool.house.io import load_house
from sgtool.log import LogReader
from sgtool.recorders.sim.recording import RecordOptions, record_house
from sgtool.replayers.derived_log import ReplayOptions, replay, stage_lines
from sgtool.replayers.score import score, score_lines


def recorded(seed: int, fps: float, cache: Path, frames: int | None = None) -> Path:
    """The recording of the 10-room house ``seed`` at 320x240 (the whole tour, or its first
    ``frames``), made once into ``cache``."""
    cache.mkdir(parents=True, exist_ok=True)
    cut = f"_{frames}frames" if frames else ""
    log = cache / f"house{seed}_10rooms_320x240_fps{fps:g}{cut}.mcap"
    if not log.exists():
        t0 = time.perf_counter()
        rep = record_house(generate_house(seed, rooms=(10, 10)), log,
                           RecordOptions(fps=fps, frames=frames), house_id=f"house-{seed}")
        print(f"  recorded {log.name}: {rep.frames} frames in {time.perf_counter() - t0:.0f} s",
              file=sys.stderr)
    return log


def sha(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--seeds", default="3", help="house seeds, comma-separated")
    ap.add_argument("--fps", type=float, default=4.0, help="recording frame rate")
    ap.add_argument("--every", type=int, default=10, help="refresh every K frames")
    ap.add_argument("--compare", type=int, default=5,
                    help="time a from-scratch rebuild at every N-th refresh")
    ap.add_argument("--cache", type=Path,
                    default=Path(tempfile.gettempdir()) / "sgtool-bench-replay")
    ap.add_argument("--frames", type=int, default=None,
                    help="record only the first N frames (default: the whole tour)")
    a = add_output_options(ap).parse_args(argv)
    opts = ReplayOptions(every=a.every)
    doc: dict[str, dict] = {}
    for seed in (int(s) for s in a.seeds.split(",")):
        log = recorded(seed, a.fps, a.cache, a.frames)
        pairs: list[tuple[float, float]] = []
        last: dict[str, object] = {}

        def on_refresh(ref, stream, last=last, pairs=pairs) -> None:  # type: ignore[no-untyped-def]  # noqa: ANN001, E501
            last["ref"], last["stream"] = ref, stream
            if ref.index % a.compare == 0:
                b = stream.builder
                inc = b.timings["refresh"][-1]
                t0 = time.perf_counter()
                full = b.refresh(ref.time_ns, from_scratch=True)
                pairs.append((inc, (time.perf_counter() - t0) * 1e3))
                assert full.to_json() == ref.graph.to_json(), "incremental != from scratch"

        out1 = a.cache / f"derived{seed}_a.mcap"
        out2 = a.cache / f"derived{seed}_b.mcap"
        rep = replay(log, out1, opts, on_refresh=on_refresh)
        rep2, second = timed(lambda log=log, out2=out2: replay(log, out2, opts))
        wall2 = second.wall_s
        same = sha(out1) == sha(out2)
        tracemalloc.start()
        replay(log, None, opts)
        _, peak = tracemalloc.get_traced_memory()
        tracemalloc.stop()
        with LogReader(log) as r:
            spec = load_house(json.loads(r.house_json() or "{}"))
        print(f"\nhouse seed {seed}: {len(spec.rooms)} rooms, {rep.frames} frames 320x240, "
              f"{rep.refreshes} refreshes (every {a.every} frames and at every action), log "
              f"{log.stat().st_size / 1e6:.1f} MB")
        print("\n".join(stage_lines(rep2.stages)))
        b = last["stream"].builder  # type: ignore[attr-defined]
        integ = sum(b.timings["integrate"]) / 1e3
        refresh = sum(b.timings["refresh"]) / 1e3
        print(f"voxel integration: {rep.frames / integ:.1f} frames/s; integration + refreshes: "
              f"{rep.frames / (integ + refresh):.1f} frames/s; whole replay with the derived "
              f"log (second run): {rep2.frames / wall2:.1f} frames/s ({wall2:.1f} s)")
        if pairs:
            inc = [p[0] for p in pairs]
            full = [p[1] for p in pairs]
            print(f"refresh incremental vs from scratch ({len(pairs)} points side by side): "
                  f"median {statistics.median(inc):.1f} ms vs {statistics.median(full):.1f} ms, "
                  f"ratio median {statistics.median(i / f for i, f in pairs):.2f}")
        print(f"peak traced memory (replay without output): {peak / 2**20:.1f} MiB; two "
              f"replays byte-identical: {'yes' if same else 'NO'} ({sha(out1)[:16]})")
        ref = last["ref"]
        q = score(spec, b.instances, ref.layers, ref.graph)  # type: ignore[attr-defined]
        g = ref.graph  # type: ignore[attr-defined]
        print(f"graph: {len(g.rooms)} rooms ({sum(not r.explored for r in g.rooms)} "
              f"unexplored), {len(g.objects)} objects, {len(g.frontiers())} frontiers, "
              f"{len(g.doors)} doors")
        for line in score_lines(q):
            print(line)
        doc[str(seed)] = {"frames": rep.frames, "refreshes": rep.refreshes,
                          "integration_s": integ, "refresh_s": refresh,
                          "second_replay": second, "peak_traced_mib": peak / 2**20,
                          "byte_identical": same, "refresh_pairs_ms": pairs}
    emit(doc, a.json_out)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
