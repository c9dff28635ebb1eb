"""Benchmark your own planner (``my_planner.py``'s ``MyPlanner``) against scout.

Run::

    python examples/benchmark_my_planner.py                 # 2 houses x 4 episodes
    python examples/benchmark_my_planner.py --houses 10 --episodes 20 --seeds 3 -o results/

Every planner runs the same symbolic-benchmark episodes (generated houses, SymSearch rules,
at most ``--max-steps`` actions each); the table gives SR, SPL, steps and AUC-E per planner,
mean +- std over seeds. ``-o DIR`` also writes what ``sgtool bench -o DIR`` writes
(episodes.jsonl, summary.md, efficiency curves, ...).

Your planner enters the benchmark by name: ``module:Name`` loads the class ``Name`` from
the module ``module`` on ``sys.path`` and calls it with its options as keyword arguments
(``--max-failures`` here), exactly as ``sgtool bench --planners my_planner:MyPlanner,scout
-O my_planner:MyPlanner.max_failures=3`` does with ``PYTHONPATH=examples``. This script puts
its own folder on ``sys.path``, so it runs from anywhere.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import sgtool

HERE = Path(__file__).resolve().parent
MINE = "my_planner:MyPlanner"


def main() -> None:
    sys.path.insert(0, str(HERE))  # my_planner.py is importable (workers inherit sys.path)
    from my_planner import room_range

    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--houses", type=int, default=2, help="generated houses")
    parser.add_argument("--episodes", type=int, default=4, help="search episodes per house")
    parser.add_argument("--seeds", type=int, default=1, help="benchmark seeds")
    parser.add_argument("--rooms", type=room_range, default="4-6",
                        help="room count range of the houses, MIN-MAX")
    parser.add_argument("--max-steps", type=int, default=50, help="actions per episode")
    parser.add_argument("--max-failures", type=int, default=2,
                        help="MyPlanner: failed attempts before a node is dropped")
    parser.add_argument("--against", default="scout",
                        help="the built-in planner(s) to compare with, comma-separated")
    parser.add_argument("-o", "--out", default=None, help="also write the bench outputs here")
    args = parser.parse_args()

    others = tuple(p.strip() for p in args.against.split(",") if p.strip())
    config = sgtool.BenchConfig(
        planners=(MINE, *others), houses=args.houses, episodes=args.episodes,
        seeds=args.seeds, rooms=args.rooms, preset="default",
        max_steps=args.max_steps,
        planner_options={MINE: {"max_failures": args.max_failures}})
    result = sgtool.run_benchmark(config, progress=False)
    print(result.results_table)
    print(result.interval_tables())  # SR/SPL intervals over houses, paired comparisons
    if args.out:
        sgtool.write_bench_outputs(result, args.out)
        print(f"wrote {args.out}/summary.md and the other outputs")


if __name__ == "__main__":
    try:
        main()
    except sgtool.SgtoolError as e:
        raise SystemExit(f"benchmark_my_planner: {e}") from None
