"""Decision time per planner on a 10-room scene graph (SCOUT Table VII "inference time").

A deterministic 10-room house (kitchen, bathrooms, bedrooms, ...; ~8 pieces of furniture
per room, frontiers, closed doors to unexplored rooms) is revealed step by step: every
episode takes 20 decisions on successive snapshots (each snapshot opens the chosen
container and reveals its contents). Per planner we report the median and 90th percentile
of ``decide`` wall time (``Action.decision_time_s``), measured side by side in one process:

- "warm": embeddings in memory, the planner already saw the query (steady state);
- "first decision": a fresh planner and scorer per episode, embeddings in memory, no score
  memoised yet (all MLP forward passes or cosines happen inside the measured call).

``moma-llm`` runs against an in-process client that answers instantly with a valid
command, so its row is the cost of encoding the scene, parsing and grounding, *without*
any model latency (SCOUT reports ~300 s per decision for real LLM calls).

``--dense N`` measures instead on the bench's dense houses (generated, ``symsearch``
preset, house seeds 0..N-1, ~230 explorable pieces each): the bench's first ``--episodes``
episodes of each house are rolled out in the symbolic environment by each of
``--planners`` in turn (episode by episode, so a change of machine load hits every planner
alike), and every ``decide`` call is timed (wall seconds, the planner's whole decision:
candidates, belief, choice). The first decision of each episode is reported apart (a new
query: its scores are computed then).

    .venv/bin/python benchmarks/decide.py [--episodes 10]
    .venv/bin/python benchmarks/decide.py --dense 2 --episodes 5 --planners scout,bayes-rooms,voi
"""

from __future__ import annotations

import argparse
import re
import statistics
import time

import numpy as np
from harness import add_output_options, emit

from sgtool.llm.client import ChatResult
from sgtool.planning.base import Feedback
from sgtool.planning.registry import PLANNER_NAMES, make_planner
from sgtool.scenegraph.graph import (
    DoorNode,
    ObjectNode,
    RegionNode,
    RobotState,
    RoomNode,
    SceneGraph,
)

ROOMS = ["kitchen", "living_room", "dining_room", "bathroom", "bedroom", "bedroom",
         "bathroom", "private_office", "utility_room", "corridor"]
FURNITURE = {
    "kitchen": ["bottom_cabinet", "electric_refrigerator", "countertop", "dishwasher", "stove",
                "top_cabinet", "sink", "chair"],
    "living_room": ["sofa", "coffee_table", "shelf", "television", "armchair", "bookcase",
                    "cabinet", "carpet"],
    "dining_room": ["table", "chair", "chair", "cabinet", "shelf", "sideboard", "chair",
                    "carpet"],
    "bathroom": ["toilet", "sink", "bathtub", "cabinet", "towel_rack", "shelf", "mirror",
                 "hamper"],
    "bedroom": ["bed", "nightstand", "wardrobe", "chest_of_drawers", "desk", "chair", "shelf",
                "carpet"],
    "private_office": ["desk", "office_chair", "bookcase", "filing_cabinet", "shelf",
                       "printer", "cabinet", "carpet"],
    "utility_room": ["washing_machine", "clothes_dryer", "shelf", "cabinet", "sink", "bucket",
                     "hamper", "carpet"],
    "corridor": ["shelf", "cabinet", "coatrack", "carpet", "bench", "shoe_rack", "plant",
                 "carpet"],
}
SMALL = ["plate", "cup", "book", "towel", "apple", "toothbrush", "pillow", "remote control",
         "frying pan", "soap", "pen", "laptop"]
OPENABLE = {"bottom_cabinet", "electric_refrigerator", "dishwasher", "top_cabinet", "cabinet",
            "wardrobe", "chest_of_drawers", "filing_cabinet", "nightstand", "washing_machine",
            "clothes_dryer", "sideboard", "hamper"}


def house(seed: int = 0) -> tuple[list, dict[str, list[ObjectNode]]]:
    rng = np.random.default_rng(seed)
    rooms, regions, objects, doors, hidden = [], [], [], [], {}
    k = 0
    for i, cat in enumerate(ROOMS):
        rid = f"room:{i + 1}"
        x, y = 6.0 * (i % 5), 6.0 * (i // 5)
        rooms.append(RoomNode(rid, cat, (x, y), explored=True))
        regions.append(RegionNode(f"region:{i + 1}.1", rid, (x, y)))
        regions.append(RegionNode(f"frontier:{i + 1}", rid, (x + 2.0, y + 2.0), "frontier",
                                  "leading out" if i % 3 == 0 else "unexplored area", 1.5))
        for f in FURNITURE[cat]:
            k += 1
            opn = f in OPENABLE
            o = ObjectNode(f"obj:{k}", f, f"region:{i + 1}.1", rid,
                           (x + rng.uniform(-2, 2), y + rng.uniform(-2, 2), 0.0),
                           state="closed" if opn else None,
                           affordances=("open",) if opn else ("explore",))
            objects.append(o)
            contents = []
            for _ in range(int(rng.integers(0, 3))):
                k += 1
                contents.append(ObjectNode(f"obj:{k}", SMALL[int(rng.integers(len(SMALL)))],
                                           o.id, rid, o.position, relation="inside"))
            hidden[o.id] = contents
        if i % 4 == 3:
            doors.append(DoorNode(f"door:{i}", (x + 3.0, y), "closed", (rid, f"room:{20 + i}")))
            rooms.append(RoomNode(f"room:{20 + i}", "unknown", (x + 5.0, y), explored=False))
    return [rooms, regions, objects, doors], hidden


def graph(parts: list, robot=(0.0, 0.0)) -> SceneGraph:
    rooms, regions, objects, doors = parts
    dist = {n.id: float(np.hypot(n.position[0] - robot[0], n.position[1] - robot[1]))
            for g in parts for n in g}
    return SceneGraph(RobotState(robot, room="room:1"), tuple(rooms), tuple(regions),
                      tuple(objects), tuple(doors), dist)


class InstantLlm:
    """Answers every MoMa-LLM prompt with a valid navigate command, instantly."""

    model = "instant"
    source = "benchmark"

    def complete(self, messages):
        user = messages[1]["content"]
        m = re.search(r"^- ([^:\n]+): \[([^,\]]+)", user, re.M)
        if m is None:  # not MoMa-LLM's scene text (unstructured-llm's raw JSON graph)
            return ChatResult("Analysis: a.\nReasoning: b.\nCommand: done()", self.model, 0.0)
        room, obj = m.group(1), re.sub(r"^\d+ ", "", m.group(2))
        text = f"Analysis: a.\nReasoning: b.\nCommand: navigate({room}, {obj})"
        return ChatResult(text, self.model, 0.0)


def run(name: str, episodes: int, fresh: bool) -> list[float]:
    times: list[float] = []
    queries = ["frying pan", "toothbrush", "book", "pillow", "laptop"]
    planner = None
    for ep in range(episodes):
        parts, hidden = house(ep % 3)
        parts = [list(p) for p in parts]
        if planner is None or fresh:
            opts: dict = {}
            if name in ("moma-llm", "unstructured-llm"):
                opts = {"client": InstantLlm(), "stuck_repeats": 0}
            elif name == "godhs-llm":  # its JSON requests get no JSON: the priors rank
                opts = {"client": InstantLlm()}
            elif fresh and name.startswith(("scout", "sbert")):
                from sgtool.semantics.encoder import default_encoder

                opts = {"encoder": default_encoder()}  # new scorer: nothing memoised
            planner = make_planner(name, **opts)
        planner.reset(f"{queries[ep % len(queries)]} #absent", seed=ep)  # never found
        for _ in range(20):
            g = graph(parts)
            a = planner.decide(g)
            times.append(a.decision_time_s)
            if a.skill == "done" or a.target is None:
                break
            objs = parts[2]
            for i, o in enumerate(objs):
                if o.id == a.target:
                    objs[i] = ObjectNode(o.id, o.category, o.parent, o.room, o.position,
                                         state="open" if o.state else None,
                                         affordances=o.affordances, explored=True)
                    objs.extend(hidden.pop(o.id, []))
            parts[1] = [r for r in parts[1] if r.id != a.target]
            planner.feedback(Feedback(a, "success"))
            if fresh:
                break  # only the first decision of a fresh planner
    return times


class _Clocked:
    """A planner whose ``decide`` calls are timed into ``times`` (wall seconds)."""

    def __init__(self, planner, times: list[float], first: list[float]) -> None:
        self.planner, self.name = planner, planner.name
        self.times, self.first, self._fresh = times, first, True

    def reset(self, query: str, seed: int = 0) -> None:
        self.planner.reset(query, seed)
        self._fresh = True

    def decide(self, graph):
        t0 = time.perf_counter()
        a = self.planner.decide(graph)
        (self.first if self._fresh else self.times).append(time.perf_counter() - t0)
        self._fresh = False
        return a

    def feedback(self, fb) -> None:
        self.planner.feedback(fb)


def run_dense(names: list[str], houses: int, episodes: int) -> dict[str, dict[str, float]]:
    """Decision times on the bench's dense houses (module doc), per planner."""
    from sgtool.analysis.bench_houses import bench_episodes
    from sgtool.datasets.generator import generate_house
    from sgtool.recorders.symbolic_environment import SymbolicHouse, run_episode

    times: dict[str, list[float]] = {n: [] for n in names}
    first: dict[str, list[float]] = {n: [] for n in names}
    planners = {n: _Clocked(make_planner(n, timed=False), times[n], first[n]) for n in names}
    for seed in range(houses):
        spec = generate_house(seed, rooms=(12, 16), split="eval", preset="symsearch")
        house = SymbolicHouse(spec)
        eps = bench_episodes(spec, episodes, "symsearch")
        print(f"house {seed}: {len(spec.furniture)} pieces, {len(spec.objects)} objects")
        for i, ep in enumerate(eps):
            for n in names:
                run_episode(house, planners[n], ep.query, ep.targets, seed=0,
                            episode_index=i, avoid_rooms=ep.target_rooms)
    rows: dict[str, dict[str, float]] = {}
    print(f"{'planner':<14} {'median':>10} {'p90':>10} {'first':>10} {'decisions':>10}")
    for n in names:
        t = times[n] or [0.0]
        p90 = float(np.percentile(t, 90))
        f = statistics.median(first[n]) if first[n] else 0.0
        print(f"{n:<14} {statistics.median(t) * 1e3:>7.3f} ms {p90 * 1e3:>7.3f} ms "
              f"{f * 1e3:>7.3f} ms {len(times[n]):>10}")
        rows[n] = {"median_s": statistics.median(t), "p90_s": p90, "first_median_s": f,
                   "decisions": len(times[n])}
    return rows


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--episodes", type=int, default=10)
    ap.add_argument("--dense", type=int, default=0, metavar="N",
                    help="measure on N dense bench houses instead (module doc)")
    ap.add_argument("--planners", default="scout,bayes-search,bayes-rooms,voi",
                    help="planners of --dense (comma-separated)")
    args = add_output_options(ap).parse_args()
    if args.dense:
        names = [n.strip() for n in args.planners.split(",") if n.strip()]
        emit({"dense_houses": args.dense, "episodes": args.episodes,
              "planners": run_dense(names, args.dense, args.episodes)}, args.json_out)
        return
    rows: dict[str, dict[str, float]] = {}
    from sgtool.semantics.encoder import default_encoder

    parts, _ = house(0)
    g = graph(parts)
    print(f"scene graph: {len(g.rooms)} rooms, {len(g.objects)} objects, "
          f"{len(g.frontiers())} frontiers, {len(g.doors)} doors")
    t0 = time.perf_counter()
    for name in ("scout", "sbert"):  # fill the embedding cache outside the measurement
        p = make_planner(name)
        p.reset("warm-up")
        p.decide(g)
    print(f"warm-up (encoder load / cache fill): {time.perf_counter() - t0:.2f} s, "
          f"encoder loads: {default_encoder().model_loads}")
    print(f"{'planner':<14} {'warm median':>12} {'warm p90':>10} {'first decision':>15} "
          f"{'n warm':>7}")
    for name in PLANNER_NAMES:
        warm = run(name, args.episodes, fresh=False)
        first = run(name, args.episodes, fresh=True)
        p90 = float(np.percentile(warm, 90))
        print(f"{name:<14} {statistics.median(warm) * 1e3:>9.3f} ms {p90 * 1e3:>7.3f} ms "
              f"{statistics.median(first) * 1e3:>12.3f} ms {len(warm):>7}")
        rows[name] = {"warm_median_s": statistics.median(warm), "warm_p90_s": p90,
                      "first_median_s": statistics.median(first), "warm_decisions": len(warm)}
    emit({"episodes": args.episodes, "planners": rows}, args.json_out)


if __name__ == "__main__":
    main()
