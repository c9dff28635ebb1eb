"""A planner of your own: nearest unexplored space first, then containers by name.

``MyPlanner`` implements the :class:`sgtool.Planner` protocol (``name``, ``reset``,
``decide``, ``feedback``) with the public API only. On every scene graph it

1. explores the nearest unexplored space: a frontier, a room known only through a door,
   or the closed door leading to one;
2. when none is left, opens or looks into the container whose category is most similar,
   as text, to the query (``difflib``; the nearer breaks ties);
3. gives up (``done``) when nothing is left to act on.

A node it failed on ``max_failures`` times is dropped for the rest of the episode.

Use it by name wherever sgtool names a planner, with this folder on ``PYTHONPATH``
(``module:Name`` loads a class from a module)::

    PYTHONPATH=examples sgtool bench --planners my_planner:MyPlanner,scout --houses 2

or build it yourself: ``MyPlanner(max_failures=3)``. Run this file to watch one episode::

    python examples/my_planner.py --seed 3 --rooms 4-6
"""

from __future__ import annotations

import argparse
import difflib
from collections import Counter

import sgtool

# what counts as unexplored space (sgtool.actionable's kinds), searched first
UNEXPLORED = ("frontier", "room", "door")


class MyPlanner:
    """Nearest unexplored space, then containers by name similarity to the query (module
    doc). ``max_failures``: failed attempts on a node before it is dropped."""

    name = "my-planner"

    def __init__(self, max_failures: int = 2) -> None:
        if max_failures < 1:
            raise ValueError(f"max_failures must be >= 1, got {max_failures}")
        self.max_failures = max_failures
        self.query = ""
        self.failures: Counter[str] = Counter()

    def reset(self, query: str, seed: int = 0) -> None:
        """A new episode: remember the query, forget the failures (no randomness)."""
        self.query = query.lower().replace("_", " ")
        self.failures = Counter()

    def decide(self, graph: sgtool.SceneGraph) -> sgtool.Action:
        """The next action on ``graph`` (module doc)."""
        found = sgtool.find_target(graph, self.query)
        if found is not None:  # in view: say so (episodes under the "done" rule need it)
            return sgtool.Action("done", found.id, reason=f"{found.category} in view")
        candidates = [c for c in sgtool.actionable(graph)
                      if self.failures[c.node_id] < self.max_failures]
        if not candidates:
            return sgtool.Action("done", None, reason="nothing left to search")
        unexplored = [c for c in candidates if c.kind in UNEXPLORED]
        if unexplored:
            best = min(unexplored, key=lambda c: (c.distance, c.node_id))
            return sgtool.Action(best.skill, best.node_id,
                                 reason=f"nearest unexplored {best.kind} ({best.distance:.1f} m)")
        scored = [(self.similarity(graph, c.node_id), c) for c in candidates]
        score, best = max(scored, key=lambda sc: (sc[0], -sc[1].distance, sc[1].node_id))
        return sgtool.Action(best.skill, best.node_id, reason=f"name similarity {score:.2f}",
                             scores={best.node_id: score})

    def similarity(self, graph: sgtool.SceneGraph, node_id: str) -> float:
        """How alike, as text, the node's category and the query are (0..1)."""
        node = graph.node(node_id)
        category = getattr(node, "category", "").lower().replace("_", " ")
        return difflib.SequenceMatcher(None, self.query, category).ratio()

    def feedback(self, fb: sgtool.Feedback) -> None:
        """Count a failed or invalid action against its node."""
        if fb.outcome != "success" and fb.action.target is not None:
            self.failures[fb.action.target] += 1


def room_range(text: str) -> tuple[int, int]:
    """``--rooms MIN-MAX`` (or one count) as (MIN, MAX); anything else is argparse's one
    line."""
    lo, _, hi = text.partition("-")
    try:
        return int(lo), int(hi or lo)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r}: give MIN-MAX, e.g. 4-6") from None


def main() -> None:
    parser = argparse.ArgumentParser(description="One symbolic episode with MyPlanner.")
    parser.add_argument("--seed", type=int, default=0, help="house seed")
    parser.add_argument("--rooms", type=room_range, default="4-6",
                        help="room count range MIN-MAX")
    parser.add_argument("--episode", type=int, default=0, help="which search episode")
    args = parser.parse_args()
    house = sgtool.generate_house(args.seed, rooms=args.rooms)
    episodes = sgtool.list_episodes(house)
    if not 0 <= args.episode < len(episodes):
        raise SystemExit(f"my_planner: --episode: the house has {len(episodes)} episodes")
    query = episodes[args.episode].query
    result = sgtool.run_one(house, MyPlanner(), query, episode_index=args.episode)
    print(f"house {args.seed}, find {query!r}: {'found' if result.success else 'not found'} "
          f"in {result.steps} steps, {result.travelled_m:.1f} m (shortest "
          f"{result.shortest_m if result.shortest_m is None else round(result.shortest_m, 1)} m)")
    for i, step in enumerate(result.trace):
        print(f"  {i:>2} {step.skill:<8} {step.target or '-':<14} {step.outcome}")


if __name__ == "__main__":
    try:
        main()
    except sgtool.SgtoolError as e:
        raise SystemExit(f"my_planner: {e}") from None
