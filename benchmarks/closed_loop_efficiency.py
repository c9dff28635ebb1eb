"""Closed-loop cost per episode, this tree against another checkout, on the same episodes.

Runs the episodes of ``sgtool run-bench`` (planners x generated houses x episodes, the
same tasks and logs ``run-bench`` would run) one after the other in a worker process per
tree, the trees in alternating rounds (each checkout's ``sgtool`` through a shadow
package, :func:`harness.shadow_tree`). Per episode it keeps the frames, the CPU
seconds of the episode (``time.process_time`` around the run, house generation excluded:
houses are built before the clock starts), success and SPL. Printed per tree: frames and
CPU-s per episode, SR, SPL; then the paired figures over the episodes, with cluster
bootstrap intervals over episodes (:mod:`sgtool.analysis.intervals`): frames and CPU
this / base (ratio of sums), episodes per CPU-hour base / this, and the SR and SPL
differences.

    git worktree add /tmp/cl-base da14047
    nice -n 5 .venv/bin/python benchmarks/closed_loop_efficiency.py --base /tmp/cl-base \\
        --planners random,greedy,scout,bayes-search --houses 2 --episodes 1 \\
        --resolution 96x72

``--jobs J`` runs J workers per tree (the houses split between them) and both trees'
workers at the same time, so both see the same load:

    nice -n 5 .venv/bin/python benchmarks/closed_loop_efficiency.py --base /tmp/cl-base \\
        --houses 4 --episodes 1 --jobs 2 --json eff.json

``--option KEY=VALUE`` sets a field of ``ClosedLoopOptions`` (a number or a word) in each
tree that has the field, e.g. ``--option render_step_m=0`` for every driving tick a
frame; the printout says which fields each tree applied.
"""

from __future__ import annotations

import argparse
import json
import math
import statistics
import sys
import tempfile
import time
from concurrent.futures import ThreadPoolExecutor
from dataclasses import fields, replace
from pathlib import Path
from typing import Any

from harness import add_output_options, emit, round_order, run_script, shadow_tree


def _value(text: str) -> Any:
    try:
        return json.loads(text)
    except json.JSONDecodeError:
        return text


def worker(args: argparse.Namespace) -> dict[str, Any]:
    """Run the episodes with the ``sgtool`` on the path; one JSON document."""
    from sgtool.analysis import closed_loop_bench
    from sgtool.analysis.closed_loop_bench import ClosedLoopBenchConfig, run_task, tasks_of
    from sgtool.analysis.search_metrics import episode_spl
    from sgtool.recorders.sim.camera import CameraConfig
    from sgtool.recorders.sim.closed_loop import ClosedLoopOptions

    w, _, h = args.resolution.lower().partition("x")
    opts = ClosedLoopOptions(camera=CameraConfig(width=int(w), height=int(h)),
                             every=args.every)
    names = {f.name for f in fields(ClosedLoopOptions)}
    overrides = dict(o.split("=", 1) for o in args.option)
    opts = replace(opts, **{k: _value(v) for k, v in overrides.items() if k in names})
    lo, _, hi = args.rooms.partition("-")
    cfg = ClosedLoopBenchConfig(
        planners=tuple(args.planners.split(",")), houses=args.houses,
        house_seed=args.house_seed, episodes=args.episodes, rooms=(int(lo), int(hi or lo)),
        options=opts)
    out = []
    with tempfile.TemporaryDirectory() as tmp:
        tasks = tasks_of(cfg, Path(tmp))
        # houses built before the clock starts (older trees, e.g. the base, call
        # the function _house)
        house_episodes = getattr(closed_loop_bench, "house_episodes", None)
        if house_episodes is None:
            house_episodes = closed_loop_bench._house
        for t in tasks:
            house_episodes(t)
        for t in tasks:
            c0 = time.process_time()
            row = run_task(t)
            cpu = time.process_time() - c0
            r = row.result
            out.append({"planner": r.planner, "house": r.house, "episode": r.episode,
                        "frames": row.frames, "cpu_s": cpu, "success": bool(r.success),
                        "spl": episode_spl(r.success, r.shortest_m, r.travelled_m),
                        "steps": r.steps, "end": r.end})
    return {"episodes": out, "applied": sorted(k for k in overrides if k in names)}


def _paired(base: list[dict[str, Any]], this: list[dict[str, Any]]) -> dict[str, Any]:
    from sgtool.analysis.intervals import ratio_interval

    def key(e: dict[str, Any]) -> tuple[str, str, int]:
        return (e["planner"], e["house"], e["episode"])

    b = {key(e): e for e in base}
    pairs = [(b[key(e)], e) for e in this if key(e) in b]
    ones = [1.0] * len(pairs)
    return {
        "episodes": len(pairs),
        "frames_this_over_base": ratio_interval([t["frames"] for _, t in pairs],
                                                [s["frames"] for s, _ in pairs]),
        "cpu_this_over_base": ratio_interval([t["cpu_s"] for _, t in pairs],
                                             [s["cpu_s"] for s, _ in pairs]),
        "episodes_per_cpu_hour_this_over_base": ratio_interval(
            [s["cpu_s"] for s, _ in pairs], [t["cpu_s"] for _, t in pairs]),
        "sr_difference": ratio_interval([float(t["success"]) - float(s["success"])
                                         for s, t in pairs], ones),
        # an episode without a shortest path has no SPL (NaN): its pair is left out
        "spl_difference": ratio_interval(
            [t["spl"] - s["spl"] for s, t in pairs if math.isfinite(t["spl"] - s["spl"])],
            [1.0 for s, t in pairs if math.isfinite(t["spl"] - s["spl"])]),
    }


def _mean_finite(values: Any) -> float:
    """The mean of the finite values (SPL leaves out episodes without a shortest path)."""
    kept = [v for v in values if math.isfinite(v)]
    return statistics.mean(kept) if kept else math.nan


def _median_runs(runs: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """Per episode, the CPU seconds' median over the rounds (the rest is deterministic)."""
    first = runs[0]["episodes"]
    out = []
    for i, e in enumerate(first):
        cpus = [r["episodes"][i]["cpu_s"] for r in runs]
        out.append({**e, "cpu_s": statistics.median(cpus)})
    return out


def _alternate(args: list[str], base: Path | None, tree: Path | None, rounds: int,
               groups: list[list[str]] | None = None) -> dict[str, list[Any]]:
    """The worker's documents per tree (``base``: none when None; ``this``: ``tree``, or
    this checkout when None), the order alternating over the rounds. With ``groups``
    (house arguments per worker, :func:`_house_groups`) each round runs one worker per
    tree and group, all at once (both trees under the same load), and a round's document
    per tree holds the groups' episodes in order."""
    trees: dict[str, str | None] = {}
    if base is not None:
        trees["base"] = shadow_tree(base)
    trees["this"] = None if tree is None else shadow_tree(tree)
    out: dict[str, list[Any]] = {name: [] for name in trees}
    for r in range(rounds):
        if groups is None:
            for name in round_order(list(trees), r):
                text = run_script(Path(__file__), args, trees[name])
                out[name].append(json.loads(text.strip().splitlines()[-1]))
            continue
        jobs = [(name, g) for g in groups for name in round_order(list(trees), r)]
        with ThreadPoolExecutor(len(jobs)) as pool:
            texts = list(pool.map(lambda j: run_script(Path(__file__), args + j[1],
                                                       trees[j[0]]), jobs))
        for name in trees:
            docs = [json.loads(t.strip().splitlines()[-1])
                    for (n, _), t in zip(jobs, texts, strict=True) if n == name]
            out[name].append({"episodes": [e for d in docs for e in d["episodes"]],
                              "applied": docs[0]["applied"]})
    return out


def _house_groups(first: int, count: int, jobs: int) -> list[list[str]]:
    """``--house-seed``/``--houses`` arguments splitting houses ``first .. first+count-1``
    into ``jobs`` contiguous groups (as even as they go)."""
    jobs = max(1, min(jobs, count))
    out, seed = [], first
    for j in range(jobs):
        n = count // jobs + (1 if j < count % jobs else 0)
        out.append(["--house-seed", str(seed), "--houses", str(n)])
        seed += n
    return out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--base", type=Path, default=None, help="the other checkout (none: "
                    "this tree only)")
    ap.add_argument("--tree", type=Path, default=None, help="the tree to measure (default: "
                    "this checkout), e.g. a worktree of HEAD with one engineer's files laid "
                    "over it")
    ap.add_argument("--planners", default="random,greedy,scout,bayes-search")
    ap.add_argument("--houses", type=int, default=2)
    ap.add_argument("--house-seed", type=int, default=0)
    ap.add_argument("--episodes", type=int, default=1, help="per house")
    ap.add_argument("--rooms", default="12-16")
    ap.add_argument("--resolution", default="96x72")
    ap.add_argument("--every", type=int, default=10)
    ap.add_argument("--rounds", type=int, default=1)
    ap.add_argument("--jobs", type=int, default=1, help="worker processes per tree, the "
                    "houses split between them, all trees' workers at once (1: one worker "
                    "per tree, one tree after the other)")
    ap.add_argument("--option", action="append", default=[], metavar="KEY=VALUE",
                    help="a ClosedLoopOptions field for this tree (repeatable)")
    ap.add_argument("--worker", action="store_true", help=argparse.SUPPRESS)
    add_output_options(ap)
    a = ap.parse_args(argv)
    if a.worker:
        print(json.dumps(worker(a)))
        return 0
    common = ["--worker", "--planners", a.planners, "--episodes", str(a.episodes),
              "--rooms", a.rooms, "--resolution", a.resolution, "--every", str(a.every)]
    common += [x for o in a.option for x in ("--option", o)]
    if a.jobs > 1:
        got = _alternate(common, a.base, a.tree, a.rounds,
                         _house_groups(a.house_seed, a.houses, a.jobs))
    else:
        got = _alternate(common + ["--houses", str(a.houses), "--house-seed",
                                   str(a.house_seed)], a.base, a.tree, a.rounds)
    for name, runs in got.items():
        print(f"{name}: options applied: {', '.join(runs[0]['applied']) or 'none'}")
    per = {name: _median_runs(runs) for name, runs in got.items()}
    print(f"{'tree':<6} {'episodes':>8} {'frames/ep':>10} {'CPU-s/ep':>9} {'SR':>5} "
          f"{'SPL':>6}")
    for name, eps in per.items():
        n = len(eps)
        print(f"{name:<6} {n:>8} {statistics.mean(e['frames'] for e in eps):>10.0f} "
              f"{statistics.mean(e['cpu_s'] for e in eps):>9.1f} "
              f"{statistics.mean(e['success'] for e in eps):>5.2f} "
              f"{_mean_finite(e['spl'] for e in eps):>6.3f}")
    doc: dict[str, Any] = {"episodes": per}
    if "base" in per:
        paired = _paired(per["base"], per["this"])
        print(f"paired over {paired['episodes']} episodes (95 % cluster bootstrap over "
              "episodes):")
        for k, v in paired.items():
            if k != "episodes":
                print(f"  {k:<38} {v.value:8.3f}  [{v.low:.3f}, {v.high:.3f}]")
        doc["paired"] = {k: (v if k == "episodes" else v.to_dict())
                         for k, v in paired.items()}
        for e in per["this"]:
            if not math.isfinite(e["cpu_s"]):
                raise SystemExit("a CPU time is not finite")
    emit(doc, a.json_out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
