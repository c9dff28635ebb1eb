"""Frames per second of ``sgtool run`` in this checkout against another checkout of sgtool
(e.g. the previous commit: ``git worktree add /tmp/cl-base HEAD``), side by side.

Each round runs the same episode once per checkout, the order alternating, each as its own
``sgtool run`` process; the other checkout's code is imported through a shadow package
(:func:`harness.shadow_tree`). Prints every run and the medians and their ratio.

    .venv/bin/python benchmarks/closed_loop_fps.py --base /tmp/cl-base --rounds 3
"""

from __future__ import annotations

import argparse
import re
import statistics
import sys
import tempfile
from pathlib import Path

from harness import round_order, sgtool_output, shadow_tree


def run(pythonpath: str | None, args: list[str]) -> float:
    """frames/s of one `sgtool run` with the tree on ``pythonpath`` (None: this one)."""
    with tempfile.TemporaryDirectory() as tmp:
        out = sgtool_output(["run", *args, "-o", f"{tmp}/ep.mcap"], pythonpath)
    m = re.search(r"\(([\d.]+) frames/s\)", out)
    if m is None:
        raise SystemExit(f"no frames/s in the output of {pythonpath or 'this tree'}:\n{out}")
    return float(m.group(1))


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--base", required=True, help="the other checkout")
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--planner", default="random")
    ap.add_argument("--seed", default="6")
    ap.add_argument("--rooms", default="4-4")
    ap.add_argument("--episode", default="3")
    ap.add_argument("--frames", default="400")
    ap.add_argument("--resolution", default="320x240")
    args = ap.parse_args(argv)
    common = ["--planner", args.planner, "--seed", args.seed, "--rooms", args.rooms,
              "--episode", args.episode, "--frames", args.frames, "--resolution",
              args.resolution]  # not --quiet: the report carries frames/s
    trees = {"base": shadow_tree(Path(args.base)), "this": None}
    fps: dict[str, list[float]] = {"this": [], "base": []}
    for k in range(args.rounds):
        for name in round_order(list(trees), k):
            fps[name].append(run(trees[name], common))
            print(f"round {k}: {name} {fps[name][-1]:.1f} frames/s", flush=True)
    med = {k: statistics.median(v) for k, v in fps.items()}
    print(f"median frames/s: this {med['this']:.1f}, base {med['base']:.1f}, ratio "
          f"{med['this'] / med['base']:.2f} ({args.rounds} rounds, {args.resolution}, "
          f"{args.frames} frames, {args.planner} on seed {args.seed} episode {args.episode})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
