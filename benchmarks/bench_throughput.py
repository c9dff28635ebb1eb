"""Symbolic benchmark throughput: episodes per second per planner, measured side by side.

Run by hand (not part of the test suite)::

    .venv/bin/python benchmarks/bench_throughput.py [--houses 3] [--episodes 10] [--repeats 3]

Every planner runs the same episodes (same houses, same starts) in one process, one core;
the planners are interleaved per repeat (random, greedy, ..., then again) so that load from
other processes hits them alike, and the median over repeats is reported. House
preparation (generation, regions, place distances) is timed separately, once per house.
"Environment only" is a planner that always takes the first actionable node: it measures
the roll-out machinery (observation, distances, actions) with a negligible decision.
"""

from __future__ import annotations

import argparse
import statistics
import time

from sgtool.analysis.bench import DEFAULT_PLANNERS, DEFAULT_ROOMS
from sgtool.datasets.episodes import list_episodes
from sgtool.datasets.generator import generate_house
from sgtool.planning.base import Action, Feedback
from sgtool.planning.candidates import actionable, find_target
from sgtool.planning.registry import make_planner
from sgtool.recorders.symbolic_environment import SymbolicHouse, run_episode
from sgtool.scenegraph.graph import SceneGraph


class FirstCandidate:
    name = "env-only"

    def reset(self, query: str, seed: int = 0) -> None:
        self.query = query
        self.done: set[str] = set()

    def decide(self, graph: SceneGraph) -> Action:
        if find_target(graph, self.query) is not None:
            return Action("done", None)
        for c in actionable(graph):
            if c.node_id not in self.done:
                return Action(c.skill, c.node_id)
        return Action("done", None)

    def feedback(self, fb: Feedback) -> None:
        if fb.action.target:
            self.done.add(fb.action.target)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--houses", type=int, default=3)
    ap.add_argument("--episodes", type=int, default=10)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--rooms", default=f"{DEFAULT_ROOMS[0]}-{DEFAULT_ROOMS[1]}")
    args = ap.parse_args()
    lo, hi = (int(x) for x in args.rooms.split("-"))

    prep = []
    houses = []
    for h in range(args.houses):
        t0 = time.perf_counter()
        spec = generate_house(h, rooms=(lo, hi))
        t1 = time.perf_counter()
        house = SymbolicHouse(spec)
        t2 = time.perf_counter()
        houses.append((house, list_episodes(spec, args.episodes, seed=h)))
        prep.append((t1 - t0, t2 - t1, len(house.places)))
    planners = {"env-only": FirstCandidate()}
    planners.update({name: make_planner(name) for name in DEFAULT_PLANNERS})
    for p in planners.values():  # warm up caches (encoder, priors) outside the timing
        house, eps = houses[0]
        run_episode(house, p, eps[0].query, eps[0].targets, seed=99)
    rates: dict[str, list[float]] = {n: [] for n in planners}
    steps: dict[str, int] = {n: 0 for n in planners}
    for rep in range(args.repeats):
        for name, p in planners.items():
            n = 0
            t0 = time.perf_counter()
            for house, eps in houses:
                for i, e in enumerate(eps):
                    r = run_episode(house, p, e.query, e.targets, seed=rep, episode_index=i,
                                    avoid_rooms=e.target_rooms)
                    n += 1
                    if rep == 0:
                        steps[name] += r.steps
            rates[name].append(n / (time.perf_counter() - t0))
    n_eps = args.houses * args.episodes
    print(f"houses {args.houses} ({lo}-{hi} rooms), {n_eps} episodes x {args.repeats} repeats,"
          f" one core")
    g = statistics.median(x[0] for x in prep)
    b = statistics.median(x[1] for x in prep)
    pl = statistics.median(x[2] for x in prep)
    print(f"house preparation (median): generate {g:.3f} s, regions + place distances "
          f"{b:.3f} s ({pl:.0f} places)")
    print(f"{'planner':14s} {'episodes/s':>11s} {'steps/s':>9s} {'min-max ep/s':>15s}")
    for name, xs in rates.items():
        med = statistics.median(xs)
        sps = med * steps[name] / n_eps
        print(f"{name:14s} {med:11.1f} {sps:9.0f} {min(xs):7.1f}-{max(xs):<7.1f}")


if __name__ == "__main__":
    main()
