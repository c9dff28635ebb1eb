"""The closed-loop benchmark next to the symbolic one on the same houses and episodes.

    .venv/bin/python tools/closed_loop_vs_symbolic.py RUN_BENCH_DIR BENCH_DIR

RUN_BENCH_DIR is an ``sgtool run-bench`` output folder (complete or cut short: its
``episodes.jsonl``, e.g. after ``--report-only``), BENCH_DIR an ``sgtool bench`` one with
``--seeds 1`` over the same houses and episodes. Only the (house, episode) pairs the
closed loop ran for every planner are compared, and each must hold the same query on both
sides (else the episodes are not the same and the script says so). Per planner: SR, SPL
and steps of each benchmark (means over the pairs) and the rank by SR then SPL; then the
episodes by where they were solved (both, closed loop only, symbolic only, neither), which
says whether the closed loop's failures are the planner's (failed symbolically too) or the
robot's.
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
from collections import Counter, defaultdict
from pathlib import Path
from typing import Any


def _rows(path: Path) -> list[dict[str, Any]]:
    return [json.loads(s) for s in path.read_text().splitlines() if s.strip()]


def _spl(r: dict[str, Any]) -> float:
    if not r["success"] or not r.get("shortest_m"):
        return 0.0
    return r["shortest_m"] / max(r["shortest_m"], r["travelled_m"], 1e-9)


def _ranks(stats: dict[str, tuple[float, float, float]]) -> dict[str, int]:
    order = sorted(stats, key=lambda p: (-stats[p][0], -stats[p][1], p))
    return {p: i + 1 for i, p in enumerate(order)}


def main(argv: list[str]) -> int:
    ap = argparse.ArgumentParser(
        description="The closed-loop benchmark next to the symbolic one on the same houses "
                    "and episodes (module doc).")
    ap.add_argument("run_bench_dir", type=Path, help="an sgtool run-bench output folder")
    ap.add_argument("bench_dir", type=Path, help="an sgtool bench output folder (--seeds 1)")
    args = ap.parse_args(argv)
    for folder in (args.run_bench_dir, args.bench_dir):
        if not (folder / "episodes.jsonl").is_file():
            ap.error(f"{folder}: no episodes.jsonl (not a finished output folder)")
    closed = _rows(args.run_bench_dir / "episodes.jsonl")
    sym = _rows(args.bench_dir / "episodes.jsonl")
    planners = list(dict.fromkeys(r["planner"] for r in closed))
    by_pair: dict[tuple[str, int], dict[str, dict[str, Any]]] = defaultdict(dict)
    for r in closed:
        by_pair[(r["house"], r["episode"])][r["planner"]] = r
    pairs = sorted(k for k, v in by_pair.items() if set(v) == set(planners))
    sym_by = {(r["house"], r["episode"], r["planner"]): r for r in sym if r.get("seed", 0) == 0}
    bad = [k for k in pairs for p in planners
           if (k[0], k[1], p) not in sym_by or
           sym_by[(k[0], k[1], p)]["query"] != by_pair[k][p]["query"]]
    if bad:
        print(f"not the same episodes: {sorted(set(bad))}")
        return 1
    print(f"{len(pairs)} episodes ({len({h for h, _ in pairs})} houses) x {len(planners)} "
          "planners, the same query on both sides")
    stats: dict[str, dict[str, tuple[float, float, float]]] = {"closed": {}, "symbolic": {}}
    for p in planners:
        for side, get in (("closed", lambda k, p=p: by_pair[k][p]),
                          ("symbolic", lambda k, p=p: sym_by[(k[0], k[1], p)])):
            rs = [get(k) for k in pairs]
            stats[side][p] = (statistics.mean(float(r["success"]) for r in rs),
                              statistics.mean(_spl(r) for r in rs),
                              statistics.mean(r["steps"] for r in rs))
    rank = {side: _ranks(s) for side, s in stats.items()}
    print("| Planner | SR closed | SR symbolic | SPL closed | SPL symbolic | steps closed | "
          "steps symbolic | rank closed | rank symbolic |")
    print("|---|---|---|---|---|---|---|---|---|")
    for p in planners:
        c, s = stats["closed"][p], stats["symbolic"][p]
        print(f"| {p} | {c[0]:.3f} | {s[0]:.3f} | {c[1]:.3f} | {s[1]:.3f} | {c[2]:.1f} | "
              f"{s[2]:.1f} | {rank['closed'][p]} | {rank['symbolic'][p]} |")
    print()
    print("| Planner | solved in both | closed loop only | symbolic only | neither |")
    print("|---|---|---|---|---|")
    for p in planners:
        n = Counter((bool(by_pair[k][p]["success"]), bool(sym_by[(k[0], k[1], p)]["success"]))
                    for k in pairs)
        print(f"| {p} | {n[(True, True)]} | {n[(True, False)]} | {n[(False, True)]} | "
              f"{n[(False, False)]} |")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
