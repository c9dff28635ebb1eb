"""Closed-loop search in PyBullet: SR, SPL, steps, decision time and frames/s per planner.

Runs ``sgtool run``'s episode loop (:func:`sgtool.recorders.sim.closed_loop.run_episode`)
for each planner on the same episodes and writes every episode log to ``--out``:

- houses: generated evaluation-split houses (``--house-seeds``, ``--rooms``), or the demo
  house shipped with sgtool (``--demo``);
- episodes: ``--episodes`` in all, spread evenly over the houses; in each house, evenly
  spaced entries of ``sgtool scenes episodes HOUSE`` (one per small-object category), so
  every log is also exactly ``sgtool run --planner P --seed S --rooms A-B --episode K``
  (the command is printed per episode);
- per planner: SR, SPL, mean high-level steps, median decision time (wall seconds per
  decide call), frames/s (frames over the wall time of the whole episode: rendering,
  logging, mapping, planning), then the table ``sgtool eval`` computes from the logs.

Run by hand, e.g. (the figures of the closed-loop note)::

    HF_HUB_OFFLINE=1 .venv/bin/python benchmarks/closed_loop.py --out /tmp/closed-loop

``--json PATH`` also writes the per-episode rows and the per-planner figures as JSON.

The closed-loop benchmark proper is ``sgtool run-bench`` (resumable, noise profiles, the
bench's tables); this script stays for quick comparisons. Episodes run one after the
other in this process (wall-clock figures are not shared with
other workers). Same command, same logs, except the measured decision times.
"""

from __future__ import annotations

import argparse
import math
import shlex
import statistics
import sys
from pathlib import Path
from typing import Any

from harness import add_output_options, emit, timed

from sgtool.datasets.episodes import list_episodes


def _rooms(text: str) -> tuple[int, int]:
    lo, _, hi = text.replace(",", "-").partition("-")
    return int(lo), int(hi or lo)


def _finite(x: float | None) -> float | None:
    """``x``, or None for NaN (JSON has no NaN)."""
    return None if x is None or math.isnan(x) else x


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--planners", default="scout,greedy,random",
                    help="comma-separated planners (default: %(default)s)")
    ap.add_argument("--episodes", type=int, default=10, help="episodes in all (default 10)")
    ap.add_argument("--house-seeds", default="0,1",
                    help="generated evaluation houses (default: %(default)s)")
    ap.add_argument("--rooms", default="6-8", help="room count range MIN-MAX (default 6-8)")
    ap.add_argument("--demo", action="store_true", help="use the demo house instead")
    ap.add_argument("--resolution", default="320x240", help="camera WxH (default 320x240)")
    ap.add_argument("--max-steps", type=int, default=50)
    ap.add_argument("--navigation", choices=("live", "house"), default="live",
                    help="live: on the robot's own map; house: on the ground truth (before "
                    "issue 17)")
    ap.add_argument("--out", default="closed-loop-logs", help="folder for the episode logs")
    ap.add_argument("--force", action="store_true", help="overwrite existing logs")
    add_output_options(ap)
    args = ap.parse_args(argv)

    from click.testing import CliRunner

    from sgtool.cli import cli
    from sgtool.datasets import demo_house
    from sgtool.datasets.generator import generate_house
    from sgtool.planning.registry import make_planner
    from sgtool.recorders.sim import CameraConfig
    from sgtool.recorders.sim.closed_loop import ClosedLoopOptions, run_episode

    w, _, h = args.resolution.lower().partition("x")
    opts = ClosedLoopOptions(camera=CameraConfig(width=int(w), height=int(h)),
                             max_steps=args.max_steps, navigation=args.navigation)
    planners = [p.strip() for p in args.planners.split(",") if p.strip()]
    lo, hi = _rooms(args.rooms)
    if args.demo:
        houses = [("demo", demo_house(), [])]
    else:
        houses = [(f"house-{s}", generate_house(s, rooms=(lo, hi)),
                   ["--seed", str(s), "--rooms", f"{lo}-{hi}"])
                  for s in (int(x) for x in args.house_seeds.split(","))]
    per = [args.episodes // len(houses) + (i < args.episodes % len(houses))
           for i in range(len(houses))]
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    print(f"closed loop: planners {', '.join(planners)}; {args.episodes} episodes over "
          f"{', '.join(hid for hid, _, _ in houses)}; {args.resolution}, max "
          f"{args.max_steps} steps; logs in {out}/")
    print(f"{'planner':<8} {'house':<9} {'ep':>3} {'query':<22} {'found':<5} {'steps':>5} "
          f"{'m':>6} {'short':>6} {'SPL':>5} {'frames':>6} {'fr/s':>6} {'dec ms':>7}  end")
    rows: dict[str, list] = {p: [] for p in planners}
    logs: list[str] = []
    commands: list[str] = []
    episodes: list[dict[str, Any]] = []
    for (hid, house, flags), n in zip(houses, per, strict=True):
        eps = list_episodes(house)
        picks = sorted({round(i * len(eps) / n) for i in range(n)}) if n else []
        for k in picks:
            ep = eps[k]
            for p in planners:
                path = out / f"{p}_{hid}_ep{k}.mcap"
                if path.exists() and args.force:
                    path.unlink()
                rep = run_episode(house, ep, make_planner(p), path, opts, house_id=hid,
                                  episode_index=k)
                rows[p].append(rep)
                logs.append(str(path))
                med = 1e3 * statistics.median(rep.decision_times) if rep.decision_times \
                    else float("nan")
                spl = "-" if rep.spl is None else f"{rep.spl:.3f}"
                short = "-" if rep.shortest_m is None else f"{rep.shortest_m:.2f}"
                print(f"{p:<8} {hid:<9} {k:>3} {ep.query[:22]:<22} "
                      f"{'yes' if rep.success else 'no':<5} {rep.steps:>5} "
                      f"{rep.travelled_m:>6.1f} {short:>6} {spl:>5} {rep.frames:>6} "
                      f"{rep.frames_per_s:>6.1f} {med:>7.2f}  {rep.end}", flush=True)
                episodes.append({
                    "planner": p, "house": hid, "episode": k, "query": ep.query,
                    "success": rep.success, "steps": rep.steps, "travelled_m": rep.travelled_m,
                    "shortest_m": rep.shortest_m, "spl": rep.spl, "frames": rep.frames,
                    "frames_per_s": rep.frames_per_s, "decision_ms_median": _finite(med),
                    "end": str(rep.end), "log": str(path)})
                commands.append(shlex.join(
                    ["sgtool", "run", "--planner", p, *flags, "--episode", str(k),
                     "--resolution", args.resolution, "--max-steps", str(args.max_steps),
                     "-o", str(path)]))
    print()
    print("| Planner | Episodes | SR | SPL | Mean steps | Median decision (ms) | Frames/s |")
    print("|---|---|---|---|---|---|---|")
    summary: dict[str, dict[str, Any]] = {}
    for p, reps in rows.items():
        sr = sum(r.success for r in reps) / len(reps)
        spls = [r.spl for r in reps if r.spl is not None]
        spl = sum(spls) / len(spls) if spls else float("nan")
        steps = statistics.mean(r.steps for r in reps)
        dts = [d for r in reps for d in r.decision_times]
        med = 1e3 * statistics.median(dts) if dts else float("nan")
        fps = sum(r.frames for r in reps) / sum(r.seconds for r in reps)
        print(f"| {p} | {len(reps)} | {sr:.3f} | {spl:.3f} | {steps:.1f} | {med:.2f} | "
              f"{fps:.1f} |")
        summary[p] = {"episodes": len(reps), "sr": sr, "spl": _finite(spl),
                      "mean_steps": steps, "decision_ms_median": _finite(med),
                      "frames_per_s": fps}
    print()
    r, eval_time = timed(lambda: CliRunner().invoke(cli, ["eval", *logs]))
    print(f"$ sgtool eval {out}/*.mcap   ({eval_time.wall_s:.1f} s)")
    print(r.output, end="")
    if commands:
        print("\nEach log again, one by one (same logs except the decision times):")
        print(f"  {commands[0]}\n  ... ({len(commands)} commands, one per log)")
    emit({"planners": summary, "episodes": episodes, "eval": eval_time,
          "eval_exit_code": r.exit_code}, args.json_out)
    return 0 if r.exit_code == 0 else 1


if __name__ == "__main__":
    sys.exit(main())
