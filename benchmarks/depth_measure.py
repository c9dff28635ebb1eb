"""What measuring a log's depth noise costs a replay.

``sgtool replay`` reads the first frames of a log that records no depth of its own and
measures its depth noise (:mod:`sgtool.replayers.depth_range`) before it maps anything.
This script times that measurement and the whole replay (without output, the depth fixed
so the replay itself does not measure) of each log given, in alternating rounds, and
prints the medians and their ratio, with the depth the measurement chose.

Usage: ``python benchmarks/depth_measure.py LOG [LOG ...] [--rounds 5] [--json PATH]``
"""

from __future__ import annotations

import argparse
from pathlib import Path

from harness import add_output_options, alternate, emit

from sgtool.log import LogReader
from sgtool.replayers.depth_range import first_frames
from sgtool.replayers.derived_log import ReplayOptions, replay


def measure(log: Path) -> float | None:
    with LogReader(log) as r:
        noise = first_frames(r, 5.0).noise
    return None if noise is None else noise.max_depth


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("logs", nargs="+", type=Path)
    ap.add_argument("--rounds", type=int, default=5)
    add_output_options(ap)
    args = ap.parse_args()
    rows = []
    print(f"{'log':<40}{'measure s':>11}{'replay s':>10}{'ratio':>8}  depth chosen")
    for log in args.logs:
        t = alternate({"measure": lambda log=log: measure(log),
                       "replay": lambda log=log: replay(log, None, ReplayOptions(max_depth=5.0))},
                      args.rounds)
        m, rp = t["measure"].wall_s, t["replay"].wall_s
        depth = measure(log)
        rows.append({"log": str(log), "measure_s": m, "replay_s": rp, "ratio": m / rp,
                     "max_depth": depth})
        print(f"{log.name:<40}{m:>11.3f}{rp:>10.3f}{m / rp:>8.3f}  "
              f"{'5 m (unchanged)' if depth is None else f'{depth:g} m'}")
    emit({"logs": rows, "rounds": args.rounds}, args.json_out)


if __name__ == "__main__":
    main()
