"""Symbolic benchmark throughput: episodes per CPU-second per planner on the dense houses.

Run by hand (not part of the test suite)::

    .venv/bin/python benchmarks/bench_throughput.py [--houses 3] [--episodes 10] [--seeds 2]
        [--repeats 3] [--planners env-only,random,sbert,scout] [--against CHECKOUT]

The houses are the bench's (``--preset symsearch``, 12-16 rooms, the bench's episode mix).
Each repeat runs in a fresh process (one core's worth of work, CPU time of the whole
process, BLAS threads included): per planner, every episode of every house and seed once
with a freshly built planner ("cold": its priors have scored nothing yet, as in a bench
worker, so the relational models run on every new (query, name)), then the same episodes
again ("warm": every score is memoised; the roll-out machinery and the decision loop
alone). Rates are medians over the repeats. "env-only" is a planner that takes the first
actionable node: the environment (observation, distances, actions) with a negligible
decision.

``--blas-threads N`` sets the BLAS threads of the measured processes. The relational
models' first scoring of a (query, name) batch is a few small matrix products; OpenBLAS
splits them over its threads, which on a loaded machine costs far more than the product
(and the split changes the last float32 bit of some scores).

``--against CHECKOUT`` measures another checkout of the repository (e.g. ``git worktree add
/tmp/base HEAD`` before a change) side by side: the repeats alternate between the two
trees, so load from other processes hits both alike, and the ratio is printed.
"""

from __future__ import annotations

import argparse
import json
import statistics
import time
from pathlib import Path

from harness import add_output_options, alternate_trees, emit

DEFAULT = "env-only,random,sbert,scout"


class FirstCandidate:
    name = "env-only"

    def reset(self, query: str, seed: int = 0) -> None:
        self.query = query
        self.done: set[str] = set()

    def decide(self, graph):  # noqa: ANN001, ANN201 - any sgtool version's types
        from sgtool.planning.base import Action
        from sgtool.planning.candidates import actionable, find_target

        if find_target(graph, self.query) is not None:
            return Action("done", None)
        for c in actionable(graph):
            if c.node_id not in self.done:
                return Action(c.skill, c.node_id)
        return Action("done", None)

    def feedback(self, fb) -> None:  # noqa: ANN001
        if fb.action.target:
            self.done.add(fb.action.target)


def fresh_planner(name: str):  # noqa: ANN201
    """A planner whose priors have scored nothing yet (the shipped priors' process-wide
    instance is memoised, so the learned ones are loaded anew)."""
    from sgtool.planning.registry import make_planner

    if name == "env-only":
        return FirstCandidate()
    if name.startswith(("scout", "godhs", "esc", "bayes")):
        from sgtool.semantics.priors import WEIGHTS_DIR

        return make_planner(name, weights_dir=str(WEIGHTS_DIR))
    return make_planner(name)


def worker(args: argparse.Namespace) -> dict:
    """One repeat in this process: per planner, cold then warm CPU seconds."""
    from sgtool.analysis.bench_houses import bench_episodes
    from sgtool.datasets.generator import generate_house
    from sgtool.recorders.symbolic_environment import SymbolicHouse, run_episode

    lo, hi = (int(x) for x in args.rooms.split("-"))
    houses = []
    for h in range(args.houses):
        spec = generate_house(h, rooms=(lo, hi), preset=args.preset)
        houses.append((SymbolicHouse(spec), bench_episodes(spec, args.episodes, args.preset)))
    out = {}
    for name in args.planners.split(","):
        planner = fresh_planner(name)
        row: dict[str, float] = {}
        for phase in ("cold", "warm"):
            n = steps = 0
            c0, w0 = time.process_time(), time.perf_counter()
            for house, eps in houses:
                for seed in range(args.seeds):
                    for i, e in enumerate(eps):
                        r = run_episode(house, planner, e.query, e.targets, seed=seed,
                                        episode_index=i, avoid_rooms=e.target_rooms)
                        n += 1
                        steps += r.steps
            row[f"{phase}_cpu_s"] = time.process_time() - c0
            row[f"{phase}_wall_s"] = time.perf_counter() - w0
        row["episodes"], row["steps"] = n, steps
        out[name] = row
    return out


def run_repeats(args: argparse.Namespace) -> dict[str, list[dict]]:
    """Per tree ("base" with --against, "this"), one worker document per repeat, the trees
    alternating."""
    env = {"OPENBLAS_NUM_THREADS": str(args.blas_threads),
           "OMP_NUM_THREADS": str(args.blas_threads)} if args.blas_threads else None
    worker_args = ["--worker", "--houses", str(args.houses), "--episodes", str(args.episodes),
                   "--seeds", str(args.seeds), "--planners", args.planners, "--rooms",
                   args.rooms, "--preset", args.preset]
    return alternate_trees(Path(__file__), worker_args, args.against, args.repeats,
                           labels=("base", "this"), env=env)


def report(runs: dict[str, list[dict]], planners: list[str]) -> None:
    trees = list(runs)
    head = f"{'planner':10s}"
    for t in trees:
        head += f" | {t + ' cold':>14s} {t + ' warm':>14s} {'steps/ep':>8s}"
    if len(trees) == 2:
        head += f" | {'cold x':>7s} {'warm x':>7s}"
    print(head)
    for p in planners:
        line, rates = f"{p:10s}", []
        for t in trees:
            rs = runs[t]
            cold = statistics.median(r[p]["episodes"] / r[p]["cold_cpu_s"] for r in rs)
            warm = statistics.median(r[p]["episodes"] / r[p]["warm_cpu_s"] for r in rs)
            spe = rs[0][p]["steps"] / rs[0][p]["episodes"]
            rates.append((cold, warm))
            line += f" | {cold:14.1f} {warm:14.1f} {spe:8.1f}"
        if len(trees) == 2:
            (c0, w0), (c1, w1) = rates
            line += f" | {c1 / c0:7.2f} {w1 / w0:7.2f}"
        print(line)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--houses", type=int, default=3)
    ap.add_argument("--episodes", type=int, default=10)
    ap.add_argument("--seeds", type=int, default=2)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--planners", default=DEFAULT)
    ap.add_argument("--rooms", default="12-16")
    ap.add_argument("--preset", default="symsearch")
    ap.add_argument("--against", type=Path, default=None,
                    help="another checkout of the repository, measured side by side")
    ap.add_argument("--blas-threads", type=int, default=0,
                    help="BLAS threads of the measured processes (default: the library's)")
    ap.add_argument("--worker", action="store_true", help=argparse.SUPPRESS)
    args = add_output_options(ap).parse_args()
    if args.worker:
        print(json.dumps(worker(args)))
        return
    planners = args.planners.split(",")
    runs = run_repeats(args)
    trees = list(runs)
    n = args.houses * args.episodes * args.seeds
    print(f"{args.houses} houses (preset {args.preset}, {args.rooms} rooms) x {args.episodes} "
          f"episodes x {args.seeds} seeds = {n} episodes per planner and phase; episodes "
          f"per CPU-second of the process, median of {args.repeats} repeats"
          + (" alternating between the trees" if len(trees) == 2 else "")
          + (f"; {args.blas_threads} BLAS thread(s)" if args.blas_threads else ""))
    report(runs, planners)
    emit({"planners": planners, "episodes_per_planner": n, "runs": runs}, args.json_out)


if __name__ == "__main__":
    main()
