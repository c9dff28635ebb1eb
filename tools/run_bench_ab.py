"""Two ``sgtool run-bench`` output folders of the same episodes, compared paired.

``run-bench`` compares planners within one run; this compares one planner across two
runs (two code versions, two option settings) on the episodes both hold: per planner
the SR and SPL of each run, the paired SR difference and SPL ratio (B against A) with
cluster-bootstrap intervals over houses (:func:`sgtool.analysis.intervals.paired_comparison`),
then the SR of each run within frame budgets per room of the house, with the paired SR
difference within each budget and, within each run, every planner against
``--reference`` at those budgets.

Episodes are matched by (house, episode, seed); frames come from each log's closing
Episode record, the rooms of the house from the log's ``house.json`` attachment.

    sgtool run-bench --planners scout,random --houses 6 --episodes 6 --rooms 8-16 \\
        --preset symsearch --resolution 96x72 -o A --explore-on 0
    sgtool run-bench ... -o B --explore-on 3
    .venv/bin/python tools/run_bench_ab.py A B --budgets 50,80 --reference random

Folders of several noise profiles are compared one profile at a time (``--noise NAME``,
the profile's name as the episode rows record it).
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import sys
from pathlib import Path

from sgtool.analysis.closed_loop_tables import within_budget
from sgtool.analysis.intervals import paired_comparison, planner_intervals
from sgtool.analysis.report import fmt_interval
from sgtool.analysis.search_metrics import CostModel
from sgtool.errors import SgtoolError
from sgtool.log.reader import LogReader
from sgtool.results import EpisodeResult, read_jsonl, source_log


def _frames_per_room(r: EpisodeResult, table: Path) -> float | None:
    """Frames per room of the house of ``r``'s log (a row of ``table``); None without a
    readable log."""
    log_path = source_log(r, table)
    if log_path is None:
        return None
    with LogReader(log_path) as log:
        ep = log.last_record("episode")
        spec = log.house_spec()
    frames = float((ep or {}).get("frames") or 0)
    rooms = max(1, len(spec.rooms)) if spec is not None else 1
    return frames / rooms


def load(folder: Path, noise: str | None = None
         ) -> tuple[list[EpisodeResult], dict[tuple[str, int, str, int], float] | None]:
    """The episodes of a run-bench folder (those of the noise profile ``noise`` when
    given; a folder of several profiles needs it) and their frames per room (by result
    key; None when some episode's log is not there)."""
    path = folder / "episodes.jsonl"
    if not path.is_file():
        raise SgtoolError(f"{folder}: no episodes.jsonl (not a finished run-bench folder)")
    results = list(read_jsonl(path))
    profiles = sorted({r.noise for r in results})
    if noise is not None:
        results = [r for r in results if r.noise == noise]
        if not results:
            raise SgtoolError(f"{folder}: no episode of noise {noise!r} (it has "
                              f"{', '.join(map(repr, profiles))})")
    elif len(profiles) > 1:
        raise SgtoolError(f"{folder}: episodes of several noise profiles "
                          f"({', '.join(map(repr, profiles))}): give --noise")
    frames = {r.key(): _frames_per_room(r, path) for r in results}
    if any(v is None for v in frames.values()):
        return results, None
    return results, {k: v for k, v in frames.items() if v is not None}


def _within(results: list[EpisodeResult], frames: dict[tuple[str, int, str, int], float],
            budget: float) -> list[EpisodeResult]:
    """``results`` scored within ``budget`` frames per room (over it: failed)."""
    model = CostModel("frames", "frames per room", budget, lambda r: frames[r.key()])
    return within_budget(results, model, budget)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("a", type=Path, help="run-bench output folder A (the baseline)")
    ap.add_argument("b", type=Path, help="run-bench output folder B")
    ap.add_argument("--budgets", default="50,80",
                    help="frame budgets per room of the house, comma-separated")
    ap.add_argument("--reference", default="random",
                    help="planner the others are compared with within each run")
    ap.add_argument("--json", type=Path, help="also write the figures here")
    ap.add_argument("--noise", default=None,
                    help="the noise profile compared, when the folders ran several")
    args = ap.parse_args(argv)
    try:
        budgets = [float(x) for x in args.budgets.split(",") if x.strip()]
        (ra, fa), (rb, fb) = load(args.a, args.noise), load(args.b, args.noise)
    except (SgtoolError, ValueError) as e:
        print(f"run_bench_ab: {e}", file=sys.stderr)
        return 2
    planners = [p for p in dict.fromkeys(r.planner for r in ra)
                if any(r.planner == p for r in rb)]
    out: dict[str, object] = {"a": str(args.a), "b": str(args.b), "planners": {}}
    print(f"A = {args.a}, B = {args.b}; intervals: 95 % cluster bootstrap over houses\n")
    print("| planner | SR A | SR B | SR B - A | SPL A | SPL B | SPL B / A | wins/losses/ties |")
    print("|---|---|---|---|---|---|---|---|")
    for p in planners:
        both = [dataclasses.replace(r, planner="A") for r in ra if r.planner == p] + \
               [dataclasses.replace(r, planner="B") for r in rb if r.planner == p]
        c = paired_comparison(both, "B", "A", check=False)
        ia, ib = planner_intervals(both, "A", check=False), \
                planner_intervals(both, "B", check=False)
        print(f"| {p} | {fmt_interval(ia.sr)} | {fmt_interval(ib.sr)} | "
              f"{fmt_interval(c.sr_diff, signed=True)} | {fmt_interval(ia.spl)} | "
              f"{fmt_interval(ib.spl)} | {fmt_interval(c.spl_ratio)} | "
              f"{c.wins}/{c.losses}/{c.ties} |")
        out["planners"][p] = {"a": ia.to_dict(), "b": ib.to_dict(),  # type: ignore[index]
                              "b_vs_a": c.to_dict()}
    if fa is None or fb is None:
        print("\nframe budgets: not scored (some episode logs are not there)")
        budgets = []
    rows = []
    for b in budgets:
        assert fa is not None and fb is not None
        sa, sb = _within(ra, fa, b), _within(rb, fb, b)
        for p in planners:
            both = [dataclasses.replace(r, planner="A") for r in sa if r.planner == p] + \
                   [dataclasses.replace(r, planner="B") for r in sb if r.planner == p]
            c = paired_comparison(both, "B", "A", check=False)
            ref = [] if p == args.reference else [
                paired_comparison(s, p, args.reference, check=False).sr_diff for s in (sa, sb)]
            ia, ib = planner_intervals(both, "A", check=False), \
                planner_intervals(both, "B", check=False)
            rows.append((b, p, ia.sr, ib.sr, c.sr_diff, ref))
    print(f"\nSR within a frame budget per room (over it: failed); vs: planner - "
          f"{args.reference} in the same run\n")
    print("| f/room | planner | SR A | SR B | SR B - A | vs ref A | vs ref B |")
    print("|---|---|---|---|---|---|---|")
    for b, p, sa_, sb_, d, ref in rows:
        refs = [fmt_interval(x, signed=True) for x in ref] or ["", ""]
        print(f"| {b:.0f} | {p} | {fmt_interval(sa_)} | {fmt_interval(sb_)} | "
              f"{fmt_interval(d, signed=True)} | {refs[0]} | {refs[1]} |")
    out["budgets"] = [{"frames_per_room": b, "planner": p, "sr_a": sa_.to_dict(),
                       "sr_b": sb_.to_dict(), "b_minus_a": d.to_dict(),
                       "vs_reference": [x.to_dict() for x in ref]}
                      for b, p, sa_, sb_, d, ref in rows]
    if args.json:
        args.json.write_text(json.dumps(out, indent=1, sort_keys=True) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
