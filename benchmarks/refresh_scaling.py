"""How the scene-graph refresh scales with the house: 4, 8, 16 and 30 rooms.

Houses come from the generator (``generate_house(seed, rooms=(n, n))``), recorded once
with the scripted exploration in PyBullet at 320x240 and 4 frames/s (cached under
``--cache``, as ``benchmarks/replay.py`` does), then replayed without output the way
``sgtool replay LOG`` does (a refresh every 10 frames and at every action). Printed per
house: frames, refreshes, the first refresh, the median and the max of the others
(max / median), the total refresh CPU per replay, integration ms per frame, and the
median ms of every builder stage (the stages that grow are the ones to look at). Times
are thread CPU time by default (``--clock cpu``: the machine this runs on is shared), wall
time with ``--clock wall``.

Targets (issue 20): median <= 25 ms at 16 rooms and <= 40 ms at 30 rooms, max <= 3x the
median after the first refresh, first refresh <= 50 ms.

Usage: ``python benchmarks/refresh_scaling.py [--rooms 4,8,16,30] [--seed 3]``

Side by side with an older tree (``--against DIR``, e.g. ``git -C . archive HEAD | tar -x
-C DIR``): each round runs the benchmark once per tree, each in a fresh process (the older
tree imported through a shadow package on ``PYTHONPATH``, as ``benchmarks/side_by_side.py``
does), the order alternating between rounds (``--rounds``, default 2); printed per tree the
median over rounds of every figure, then base / this tree for the median refresh.
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
import tempfile
import time
import types
from pathlib import Path

from harness import alternate_trees

from sgtool.datasets.generator import generate_house
from sgtool.recorders.sim.recording import RecordOptions, record_house
from sgtool.replayers.derived_log import ReplayOptions, replay
from sgtool.scenegraph import builder as builder_module
from sgtool.scenegraph.builder import SceneGraphBuilder

STAGES = ("bev", "voronoi", "rooms", "assign", "regions", "doors", "frontiers",
          "categories", "distances", "assemble")


def recorded(seed: int, rooms: int, fps: float, cache: Path, frames: int | None = None
             ) -> Path:
    """The recording of house ``seed`` with ``rooms`` rooms at 320x240 (the whole tour, or
    its first ``frames``), made once into ``cache``."""
    cache.mkdir(parents=True, exist_ok=True)
    cut = f"_{frames}frames" if frames else ""
    log = cache / f"house{seed}_{rooms}rooms_320x240_fps{fps:g}{cut}.mcap"
    if not log.exists():
        t0 = time.perf_counter()
        rep = record_house(generate_house(seed, rooms=(rooms, rooms)), log,
                           RecordOptions(fps=fps, frames=frames), house_id=f"house-{seed}")
        print(f"  recorded {log.name}: {rep.frames} frames in {time.perf_counter() - t0:.0f} s",
              file=sys.stderr)
    return log


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--rooms", default="4,8,16,30", help="room counts, comma-separated")
    ap.add_argument("--seed", type=int, default=3)
    ap.add_argument("--fps", type=float, default=4.0)
    ap.add_argument("--clock", choices=("cpu", "wall"), default="cpu",
                    help="stage timings in thread CPU time (robust on a loaded machine) or "
                    "wall time")
    ap.add_argument("--cache", type=Path,
                    default=Path(tempfile.gettempdir()) / "sgtool-bench-replay")
    ap.add_argument("--against", type=Path, help="an older source tree, run side by side")
    ap.add_argument("--rounds", type=int, default=2, help="rounds with --against")
    ap.add_argument("--worst", type=int, default=0,
                    help="also print the stage times of the N slowest refreshes per house")
    ap.add_argument("--frames", type=int, default=None,
                    help="record only the first N frames of each house (default: its tour)")
    ap.add_argument("--json", action="store_true", help=argparse.SUPPRESS)
    a = ap.parse_args(argv)
    if a.against is not None:
        return side_by_side(a)
    if a.clock == "cpu":
        SceneGraphBuilder.clock = staticmethod(time.thread_time)
        # an older tree (run side by side through PYTHONPATH) reads time.perf_counter
        builder_module.time = types.SimpleNamespace(perf_counter=time.thread_time)
    rows = []
    for n in (int(r) for r in a.rooms.split(",")):
        log = recorded(a.seed, n, a.fps, a.cache, a.frames)
        seen: dict[str, object] = {}

        def keep(ref, stream, seen=seen) -> None:  # type: ignore[no-untyped-def]  # noqa: ANN001
            seen["builder"] = stream.builder

        cpu0 = time.process_time()
        rep = replay(log, None, ReplayOptions(), on_refresh=keep)
        cpu = time.process_time() - cpu0
        b = seen["builder"]
        t = b.timings  # type: ignore[attr-defined]
        ref = t["refresh"]
        rest = ref[1:] or ref
        med, mx = statistics.median(rest), max(rest)
        stages = {s: statistics.median(t[s]) for s in STAGES if t.get(s)}
        rows.append((n, rep.frames, len(ref), ref[0], med, mx, sum(ref) / 1e3,
                     statistics.median(t["integrate"]), stages, cpu))
        if a.worst:
            print_worst(n, t, a.worst)
    if a.json:
        print(json.dumps(rows))
    else:
        table(rows)
    return 0


def print_worst(rooms: int, t: dict[str, list[float]], k: int) -> None:
    """The ``k`` slowest refreshes after the first: their index and every stage's ms."""
    ref = t["refresh"]
    worst = sorted(range(1, len(ref)), key=lambda i: -ref[i])[:k]
    stages = [s for s in STAGES if len(t.get(s, ())) == len(ref)]
    print(f"{rooms} rooms, slowest refreshes (index: total ms | stages ms)", file=sys.stderr)
    for i in worst:
        print(f"  #{i:<4} {ref[i]:7.1f} | " + " ".join(f"{s} {t[s][i]:.1f}" for s in stages),
              file=sys.stderr)


def table(rows: list) -> None:  # type: ignore[type-arg]
    print(f"{'rooms':>5}{'frames':>7}{'refr':>6}{'first ms':>9}{'median':>8}{'max':>8}"
          f"{'max/med':>8}{'sum s':>7}{'integ ms':>9}{'cpu s':>7}  stage medians (ms)")
    for n, fr, cnt, first, med, mx, total, integ, stages, cpu in rows:
        st = " ".join(f"{k} {v:.1f}" for k, v in stages.items())
        print(f"{n:>5}{fr:>7}{cnt:>6}{first:>9.1f}{med:>8.1f}{mx:>8.1f}{mx / med:>8.2f}"
              f"{total:>7.2f}{integ:>9.2f}{cpu:>7.1f}  {st}")


def side_by_side(a: argparse.Namespace) -> int:
    """Alternating rounds of this benchmark with this tree and with ``a.against``."""
    args = ["--json", "--rooms", a.rooms, "--seed", str(a.seed), "--fps", str(a.fps),
            "--clock", a.clock, "--cache", str(a.cache.resolve()),
            *(["--frames", str(a.frames)] if a.frames else [])]
    got = alternate_trees(Path(__file__), args, a.against, a.rounds,
                          labels=("base", "this tree"))
    med: dict[str, list] = {}  # type: ignore[type-arg]
    for name, runs in got.items():
        rows = []
        for i, first in enumerate(runs[0]):
            per = [run[i] for run in runs]
            fig = [statistics.median(row[j] for row in per) for j in range(1, 8)]
            stages = {k: statistics.median(row[8][k] for row in per) for k in first[8]}
            rows.append([first[0], *fig, stages, statistics.median(row[9] for row in per)])
        med[name] = rows
        print(f"{name} (median of {a.rounds} rounds):")
        table(rows)
    print("median refresh, base / this tree: " + ", ".join(
        f"{b[0]} rooms {b[4]:.1f} / {t[4]:.1f} = {b[4] / t[4]:.2f}x"
        for b, t in zip(med["base"], med["this tree"], strict=True)))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
