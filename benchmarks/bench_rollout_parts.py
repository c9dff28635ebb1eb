"""Where a bench house task's time goes, measured so that a loaded machine matters little.

Run by hand (not part of the test suite)::

    .venv/bin/python benchmarks/bench_rollout_parts.py [--planner scout] [--houses 2]
        [--repeats 4] [--rounds 1] [--against CHECKOUT]

For each house (``house-<i>``, the bench's preset, rooms and episode mix) it times the
house preparation once (generation, the symbolic house, the episode list: CPU seconds),
then rolls out the bench's 20 episodes x 3 seeds ``--repeats`` times, each from an empty
priors memo as a bench task does. Every call of ``observe``, ``decide`` (and within it
``actionable`` and ``column_utilities``) and ``execute`` is timed; a call's time is its
minimum over the repeats (the same call, deterministic, so the minimum is the time it
takes when nothing else runs), and the table sums them. The first repeat of the first
house warms the process and is left out. ``--against CHECKOUT`` first runs the same in
another checkout (:func:`harness.alternate_trees`), then in this one, and prints the
ratios; ``--rounds N`` runs N worker processes per tree, alternately (base, this, base,
...), and takes each call's minimum over all of them, so that load that changes during the
run reaches both trees.
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

from harness import add_output_options, alternate_trees, emit

PARTS = ("observe", "decide", "actionable", "utilities", "execute")


def measure(args: argparse.Namespace) -> dict[str, float]:
    import sgtool.planning.planners as planners
    import sgtool.recorders.symbolic_environment.environment as environment
    from sgtool.analysis.bench import BenchConfig, planner_options_for
    from sgtool.analysis.bench_houses import bench_episodes, generated_houses
    from sgtool.blas import single_blas_thread
    from sgtool.planning.registry import make_planner
    from sgtool.recorders.symbolic_environment.house import SymbolicHouse
    from sgtool.recorders.symbolic_environment.rollout import run_episode
    from sgtool.semantics.priors import forget_default_scores

    calls: dict[str, list[float]] = {}

    def timed(owner: object, name: str, label: str) -> None:
        f = getattr(owner, name)

        def g(*a: object, **k: object) -> object:
            t = time.perf_counter()
            r = f(*a, **k)
            calls.setdefault(label, []).append(time.perf_counter() - t)
            return r

        setattr(owner, name, g)

    timed(planners.NodeSelectionPlanner, "decide", "decide")
    # the names the planners module calls (columns since round 4; lists before)
    timed(planners, next(n for n in ("actionable_columns", "actionable")
                         if hasattr(planners, n)), "actionable")
    timed(planners, next(n for n in ("column_utilities", "candidate_utilities")
                         if hasattr(planners, n)), "utilities")
    timed(environment.SymbolicEnv, "observe", "observe")
    timed(environment.SymbolicEnv, "execute", "execute")
    cfg = BenchConfig(planners=(args.planner,), houses=args.houses, episodes=20, seeds=3)
    total: dict = {"prepare": 0.0, "episodes": 0.0, "calls": {p: [] for p in PARTS}}
    # one planner for every house, as a bench worker keeps the planners it built
    planner = make_planner(args.planner, **planner_options_for(cfg, args.planner))
    for ref in generated_houses(args.houses, 0):
        c0 = time.process_time()
        spec = ref.load(cfg.rooms, cfg.preset)
        house = SymbolicHouse(spec)
        episodes = bench_episodes(spec, cfg.episodes, cfg.preset)
        total["prepare"] += time.process_time() - c0
        runs = []
        with single_blas_thread():
            for k in range(args.repeats + (1 if ref.seed == 0 else 0)):
                calls.clear()
                forget_default_scores()
                for seed in range(cfg.seeds):
                    for i, ep in enumerate(episodes):
                        run_episode(house, planner, ep.query, ep.targets, seed=seed,
                                    episode_index=i, avoid_rooms=ep.target_rooms,
                                    max_steps=cfg.max_steps)
                if ref.seed == 0 and k == 0:
                    continue  # warms the process
                runs.append({p: list(v) for p, v in calls.items()})
        for p in PARTS:  # each call's minimum over the repeats
            total["calls"][p] += [min(c) for c in zip(*(r.get(p, []) for r in runs),
                                                      strict=True)]
        total["episodes"] += cfg.seeds * len(episodes)
    return total


def summed(runs: list[dict]) -> dict[str, float]:
    """The parts of worker runs of one tree: each call's minimum over all the runs, summed;
    house preparation: the smallest."""
    out = {p: sum(map(min, zip(*(r["calls"][p] for r in runs), strict=True)))
           for p in PARTS}
    return out | {"prepare": min(r["prepare"] for r in runs),
                  "episodes": runs[0]["episodes"]}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--planner", default="scout")
    ap.add_argument("--houses", type=int, default=2)
    ap.add_argument("--repeats", type=int, default=4)
    ap.add_argument("--rounds", type=int, default=1,
                    help="worker processes per tree, run alternately")
    ap.add_argument("--against", type=Path, default=None)
    ap.add_argument("--worker", action="store_true", help=argparse.SUPPRESS)
    args = add_output_options(ap).parse_args()
    if args.worker:
        print(json.dumps(measure(args)))
        return
    worker = ["--worker", "--planner", args.planner, "--houses", str(args.houses),
              "--repeats", str(args.repeats)]
    runs = alternate_trees(Path(__file__), worker, args.against, args.rounds,
                           labels=("base", "this"))  # alternating: both see the same load
    rows = {t: summed(r) for t, r in runs.items()}
    print(f"{args.planner}, {args.houses} houses x 20 episodes x 3 seeds; roll-out parts: "
          f"sums of per-call minima over {args.repeats} repeats x {args.rounds} rounds (s); "
          "prepare: CPU s")
    print(f"{'':10s} " + " ".join(f"{p:>10s}" for p in (*PARTS, "rollout", "prepare")))
    for t, r in rows.items():
        rollout = r["observe"] + r["decide"] + r["execute"]
        print(f"{t:10s} " + " ".join(f"{r[p]:10.3f}" for p in PARTS)
              + f" {rollout:10.3f} {r['prepare']:10.3f}   episodes/s of roll-outs: "
              f"{r['episodes'] / rollout:.1f}")
    if len(rows) == 2:
        b, n = rows["base"], rows["this"]
        ratio = {p: b[p] / n[p] for p in (*PARTS, "prepare") if n[p]}
        ratio["rollout"] = sum(b[p] for p in ("observe", "decide", "execute")) / \
            sum(n[p] for p in ("observe", "decide", "execute"))
        print(f"{'base/this':10s} " + " ".join(
            f"{ratio.get(p, float('nan')):10.2f}" for p in (*PARTS, "rollout", "prepare")))
    emit({"planner": args.planner, "houses": args.houses, "sums_s": rows}, args.json_out)


if __name__ == "__main__":
    main()
