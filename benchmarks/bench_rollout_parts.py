"""Where a bench house task's time goes, measured so that a loaded machine matters little.

Run by hand (not part of the test suite)::

    .venv/bin/python benchmarks/bench_rollout_parts.py [--planner scout] [--houses 2]
        [--repeats 4] [--rounds 1] [--against CHECKOUT]

For each house (``house-<i>``, the bench's preset, rooms and episode mix) it times the
house preparation once (generation, the symbolic house, the episode list: CPU seconds),
then rolls out the bench's 20 episodes x 3 seeds ``--repeats`` times, each from an empty
priors memo as a bench task does. Every call of ``observe``, ``decide`` (and within it
``actionable`` and ``candidate_utilities``) and ``execute`` is timed; a call's time is its
minimum over the repeats (the same call, deterministic, so the minimum is the time it
takes when nothing else runs), and the table sums them. The first repeat of the first
house warms the process and is left out. ``--against CHECKOUT`` first runs the same in
another checkout (loaded as :mod:`bench_throughput` does), then in this one, and prints the
ratios; ``--rounds N`` runs N worker processes per tree, alternately (base, this, base,
...), and takes each call's minimum over all of them, so that load that changes during the
run reaches both trees.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

PARTS = ("observe", "decide", "actionable", "utilities", "execute")


def measure(args: argparse.Namespace) -> dict[str, float]:
    import sgtool.planning.planners as planners
    import sgtool.recorders.symbolic_environment.environment as environment
    from sgtool.analysis.bench import BenchConfig, _planner, planner_options_for
    from sgtool.analysis.bench_houses import bench_episodes, generated_houses
    from sgtool.blas import single_blas_thread
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
    for ref in generated_houses(args.houses, 0):
        c0 = time.process_time()
        spec = ref.load(cfg.rooms, cfg.preset)
        house = SymbolicHouse(spec)
        episodes = bench_episodes(spec, cfg.episodes, cfg.preset)
        total["prepare"] += time.process_time() - c0
        planner = _planner(args.planner, planner_options_for(cfg, args.planner))
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


def run_tree(args: argparse.Namespace, site: Path | None) -> dict:
    env = dict(os.environ)
    if site is not None:
        env["PYTHONPATH"] = str(site) + os.pathsep + env.get("PYTHONPATH", "")
    cmd = [sys.executable, str(Path(__file__).resolve()), "--worker", "--planner",
           args.planner, "--houses", str(args.houses), "--repeats", str(args.repeats)]
    done = subprocess.run(cmd, env=env, capture_output=True, text=True, check=False,
                          cwd=tempfile.gettempdir())
    if done.returncode != 0:
        sys.exit(f"worker failed:\n{done.stderr.strip()}")
    return json.loads(done.stdout.strip().splitlines()[-1])


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--planner", default="scout")
    ap.add_argument("--houses", type=int, default=2)
    ap.add_argument("--repeats", type=int, default=4)
    ap.add_argument("--rounds", type=int, default=1,
                    help="worker processes per tree, run alternately")
    ap.add_argument("--against", type=Path, default=None)
    ap.add_argument("--worker", action="store_true", help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.worker:
        print(json.dumps(measure(args)))
        return
    sys.path.insert(0, str(Path(__file__).parent))
    from bench_throughput import site_of

    with tempfile.TemporaryDirectory() as tmp:
        trees = {"base": site_of(args.against.resolve(), Path(tmp) / "base")} \
            if args.against else {}
        trees["this"] = None
        runs: dict[str, list[dict]] = {t: [] for t in trees}
        for _ in range(args.rounds):  # alternating, so that both see the same load
            for t, site in trees.items():
                runs[t].append(run_tree(args, site))
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


if __name__ == "__main__":
    main()
