"""``godhs``: explore everything first, then search the rooms by relevance (SCOUT sec. VI, [12]).

GODHS (Zhang et al. 2025, "Language-enhanced mobile manipulation for efficient object search
in indoor environments") as SCOUT's baseline describes it: the agent first explores all
rooms and frontiers; it then ranks the visited rooms by their relevance to the target and
visits them in that order; within each room it first identifies the potential carriers of
the target, then ranks them by the likelihood of holding it. Our reading:

1. **explore**: while any room, frontier or entrance door (closed door to unknown space) is
   actionable, take the nearest one (node id breaks ties);
2. **rank rooms**: every explored room gets a relevance (:meth:`Ranker.rooms`); unscorable
   or uncategorised rooms get the mean relevance of the known room types;
3. **within the best room that still has unchecked carriers**: the carriers the ranker
   identifies (:meth:`Ranker.carriers` at or above ``carrier_threshold``), best first,
   nearer first among equals;
4. when no identified carrier is left anywhere, the remaining carriers in the same room
   order, so the search still ends with everything checked.

The ranker is a hook: :class:`PriorRanker` answers from the distilled priors (containment,
co-occurrence); an LLM ranker (GODHS's original, :mod:`sgtool.planning.llm_ranker`)
implements the same :class:`Ranker` protocol and is passed to :class:`GodhsPlanner`; no LLM
is called here. A ranker is asked about each (query, names) once: the scores are memoised by
the scorer. The planner's ``exchanges`` are its ranker's (none for the priors), so the
episode loop logs an LLM ranker's exchanges like moma-llm's.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any, Protocol

import numpy as np

from sgtool.planning.belief import BeliefParams, known_room_mean, room_probabilities
from sgtool.planning.candidates import Candidate
from sgtool.planning.planners import NodeSelectionPlanner
from sgtool.scenegraph.graph import SceneGraph
from sgtool.semantics.priors import RelationScorer

EXPLORE_KINDS = frozenset({"room", "frontier", "door"})
# the uncalibrated priors: relevance is a ranking, no floor or exponent
_RAW = BeliefParams(room_floor=0.0, object_floor=0.0)


class Ranker(Protocol):
    """What GODHS asks its ranker (an LLM in the original)."""

    name: str

    def rooms(self, graph: SceneGraph, query: str) -> dict[str, float]:
        """Relevance of every room node of ``graph`` to the query (higher first)."""

    def carriers(self, categories: Sequence[str], query: str) -> np.ndarray:
        """Likelihood that a carrier of each category holds the query."""


class PriorRanker:
    """The ranker from the distilled priors (containment for rooms, co-occurrence for
    carriers)."""

    def __init__(self, scorer: RelationScorer) -> None:
        self.scorer = scorer
        self.name = f"priors({scorer.name})"

    def rooms(self, graph: SceneGraph, query: str) -> dict[str, float]:
        unknown = known_room_mean(self.scorer, query, _RAW)
        return room_probabilities(graph, query, self.scorer, _RAW, unknown)

    def carriers(self, categories: Sequence[str], query: str) -> np.ndarray:
        return np.asarray(self.scorer.objects(categories, query), dtype=np.float64)


class GodhsPlanner(NodeSelectionPlanner):
    """Explore all, then rooms by relevance, then carriers by likelihood (module doc)."""

    def __init__(self, ranker: Ranker, carrier_threshold: float = 0.1,
                 name: str = "godhs", max_failures: int = 2) -> None:
        super().__init__(max_failures=max_failures)
        self.name = name
        self.ranker = ranker
        self.carrier_threshold = float(carrier_threshold)

    @property
    def exchanges(self) -> list[dict[str, Any]] | None:
        """The ranker's LLM exchanges, when it keeps them (``godhs-llm``), else None: the
        episode loop takes each decision's new ones into the log (``/sgtool/llm``)."""
        kept = getattr(self.ranker, "exchanges", None)
        return kept if isinstance(kept, list) else None

    def drain_exchanges(self) -> list[dict[str, Any]]:
        """Exchanges since the last call (for a log writer, the closed loop), oldest first."""
        kept = self.exchanges
        if kept is None:
            return []
        out = list(kept)
        kept.clear()
        return out

    def choose(self, graph: SceneGraph, cands: list[Candidate]
               ) -> tuple[int, str, dict[str, float]]:
        explore = [i for i, c in enumerate(cands) if c.kind in EXPLORE_KINDS]
        if explore:
            i = min(explore, key=lambda k: (cands[k].distance, cands[k].node_id))
            return i, f"exploring first: {len(explore)} place(s) left", {}
        objs = [i for i, c in enumerate(cands) if c.kind == "object"]
        if not objs:  # nothing but what the classes above cover; keep the contract
            return 0, "no carrier left", {}
        rooms = self.ranker.rooms(graph, self.query)
        index = {o.id: o for o in graph.objects}
        nodes = [index.get(cands[i].node_id) for i in objs]
        room_of = [getattr(n, "room", "") or "" for n in nodes]
        likely = self.ranker.carriers([getattr(n, "category", "") for n in nodes], self.query)
        identified = likely >= self.carrier_threshold
        if not identified.any():
            identified[:] = True  # step 4: every remaining carrier
        best = min(
            (k for k in range(len(objs)) if identified[k]),
            key=lambda k: (-rooms.get(room_of[k], 0.0), room_of[k], -likely[k],
                           cands[objs[k]].distance, cands[objs[k]].node_id),
        )
        scores = {cands[i].node_id: round(float(v), 4) for i, v in zip(objs, likely,
                                                                       strict=True)}
        return (objs[best], f"room {room_of[best]} (relevance "
                f"{rooms.get(room_of[best], 0.0):.2f}), carrier {likely[best]:.2f}", scores)
