"""Camera resolution against map quality and closed-loop cost: which size ``run-bench``
should use.

Two parts, per resolution (``--resolutions``, default 96x72, 160x120, 320x240):

- **map quality on the golden houses**: each case of :data:`sgtool.replayers.golden.CASES`
  (its house, frame rate and frame budget, the scripted tour) is recorded at the
  resolution and replayed with ``sgtool replay --score --json`` (the golden replay
  options); printed per case: rooms found against rooms seen, the room count error,
  Voronoi purity and ARI, objects found and the share in the right room, strict and
  merged (rooms joined by open-plan passages as one), and the CPU seconds of the replay;
- **closed-loop cost**: the episodes of ``run-bench`` (``--planners`` x ``--houses`` x
  ``--episodes``, :mod:`closed_loop_efficiency`'s worker, this tree) at the resolution:
  frames and CPU seconds per episode, SR and SPL. ``--planners ''`` skips this part.

    nice -n 5 .venv/bin/python benchmarks/resolution_study.py --json /tmp/res.json
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
import tempfile
from pathlib import Path
from typing import Any

from closed_loop_efficiency import worker
from harness import REPO, add_output_options, emit, sgtool_output, timed


def quality(case: Any, width: int, height: int, folder: Path) -> dict[str, Any]:
    """Record golden case ``case`` at ``width x height`` and score its replay."""
    from sgtool.datasets.generator import generate_house
    from sgtool.recorders.sim.camera import CameraConfig
    from sgtool.recorders.sim.recording import RecordOptions, record_house
    from sgtool.replayers.golden import REPLAY

    house = generate_house(case.seed, rooms=(case.rooms, case.rooms))
    log = folder / f"{case.name}-{width}x{height}.mcap"
    opts = RecordOptions(fps=case.fps, frames=case.frames,
                         camera=CameraConfig(width=width, height=height))
    record_house(house, log, opts, house_id=f"house-{case.seed}")
    args = ["replay", str(log), "--score", "--json", "--every", str(REPLAY.every),
            "--classifier", REPLAY.classifier]
    text, sample = timed(lambda: sgtool_output(args))
    doc = json.loads(text)
    return {"case": case.name, "size": f"{width}x{height}", "frames": doc["frames"],
            "replay_wall_s": sample.wall_s, "score": doc["score"]}


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--resolutions", default="96x72,160x120,320x240")
    ap.add_argument("--cases", default="", help="golden case names (default: all)")
    ap.add_argument("--planners", default="random,scout")
    ap.add_argument("--houses", type=int, default=1)
    ap.add_argument("--house-seed", type=int, default=0)
    ap.add_argument("--episodes", type=int, default=1)
    ap.add_argument("--rooms", default="12-16")
    ap.add_argument("--every", type=int, default=10)
    ap.add_argument("--option", action="append", default=[], metavar="KEY=VALUE",
                    help="a ClosedLoopOptions field of the closed-loop part (repeatable)")
    add_output_options(ap)
    a = ap.parse_args(argv)
    from sgtool.replayers.golden import CASES

    sizes = [tuple(int(v) for v in s.lower().split("x")) for s in a.resolutions.split(",")]
    cases = [c for c in CASES if not a.cases or c.name in a.cases.split(",")]
    rows: list[dict[str, Any]] = []
    with tempfile.TemporaryDirectory() as tmp:
        for case in cases:
            for w, h in sizes:
                rows.append(quality(case, w, h, Path(tmp)))
    print("map quality of the golden houses (scripted tour, replay --score):")
    print(f"{'case':<14} {'size':>8} {'view':<7} {'rooms':>9} {'err':>4} {'purity':>7} "
          f"{'ARI':>6} {'objects':>8} {'right':>6}")
    for r in rows:
        for view in ("strict", "merged"):
            q = r["score"][view]
            print(f"{r['case']:<14} {r['size']:>8} {view:<7} "
                  f"{q['rooms']:>3} of {q['gt_rooms_seen']:>2} {q['room_count_error']:>+4d} "
                  f"{q['purity']:>7.3f} {q['ari']:>6.3f} {q['objects']:>8d} "
                  f"{q['object_accuracy']:>6.1%}")
    cost: dict[str, Any] = {}
    if a.planners:
        print("\nclosed-loop cost per episode (this tree):")
        print(f"{'size':>8} {'episodes':>8} {'frames/ep':>10} {'CPU-s/ep':>9} {'SR':>5} "
              f"{'SPL':>6}")
        for w, h in sizes:
            ns = argparse.Namespace(resolution=f"{w}x{h}", every=a.every, option=a.option,
                                    rooms=a.rooms, planners=a.planners, houses=a.houses,
                                    house_seed=a.house_seed, episodes=a.episodes)
            eps = worker(ns)["episodes"]
            cost[f"{w}x{h}"] = eps
            print(f"{w}x{h:<5} {len(eps):>8} {statistics.mean(e['frames'] for e in eps):>10.0f} "
                  f"{statistics.mean(e['cpu_s'] for e in eps):>9.1f} "
                  f"{statistics.mean(e['success'] for e in eps):>5.2f} "
                  f"{statistics.mean(e['spl'] for e in eps):>6.3f}", flush=True)
    emit({"quality": rows, "closed_loop": cost, "repo": str(REPO)}, a.json_out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
