"""The planners that choose among actionable nodes: random, greedy, SBERT similarity, SCOUT.

They share one loop (:class:`NodeSelectionPlanner`): if an object of the query category is
in the graph, ``done`` on the nearest one; otherwise choose among the actionable nodes
(:func:`~sgtool.planning.candidates.actionable`) that the episode memory has not ruled out;
with nothing left, give up with ``done`` and no target (the executor counts that as a
failure, never as a success). Subclasses implement :meth:`NodeSelectionPlanner.choose`.
"""

from __future__ import annotations

import functools
from typing import Generic, TypeVar

import numpy as np

from sgtool.planning.base import Action, Feedback
from sgtool.planning.candidates import (
    Candidate,
    CandidateColumns,
    actionable_columns,
    find_target,
)
from sgtool.planning.memory import EpisodeMemory
from sgtool.planning.utility import (
    EpisodeCache,
    UtilityParams,
    column_utilities,
    select_with_margin,
)
from sgtool.scenegraph.graph import SceneGraph
from sgtool.semantics.priors import RelationScorer

GIVE_UP = "nothing left to explore"

P = TypeVar("P")  # a scoring planner's parameters (a frozen dataclass)


@functools.lru_cache(maxsize=1 << 13)
def _round4(v: float) -> float:
    """``round(v, 4)``, memoised: the same utilities come back at every decision."""
    return round(v, 4)


class NodeSelectionPlanner:
    name = "node-selection"

    def __init__(self, max_failures: int = 2) -> None:
        self.query = ""
        self.seed = 0
        self.memory = EpisodeMemory(max_failures=max_failures)

    def reset(self, query: str, seed: int = 0) -> None:
        self.query = query
        self.seed = int(seed)
        self.memory.reset()

    def feedback(self, fb: Feedback) -> None:
        self.memory.record(fb)

    def decide(self, graph: SceneGraph) -> Action:
        if not self.query:
            raise RuntimeError(f"{self.name}: reset(query) must be called before decide()")
        found = find_target(graph, self.query)
        if found is not None:
            return Action("done", target=found.id, reason=f"{found.category} observed")
        cols = self.memory.filter_columns(actionable_columns(graph))
        self.memory.offered_columns(cols)
        if not cols:
            return Action("done", target=None, reason=GIVE_UP)
        i, reason, scores = self.choose_columns(graph, cols)
        return Action(cols.skills[i], target=cols.ids[i], reason=reason, scores=scores)

    def choose_columns(self, graph: SceneGraph, cols: CandidateColumns
                       ) -> tuple[int, str, dict[str, float]]:
        """:meth:`choose` on the candidates as columns; planners that score columns
        override it, the others get the :class:`Candidate` list."""
        return self.choose(graph, cols.candidates())

    def choose(self, graph: SceneGraph, cands: list[Candidate]
               ) -> tuple[int, str, dict[str, float]]:
        raise NotImplementedError


class RandomPlanner(NodeSelectionPlanner):
    """SCOUT's random agent: uniform over actionable nodes (seeded per episode)."""

    name = "random"

    def reset(self, query: str, seed: int = 0) -> None:
        super().reset(query, seed)
        self._rng = np.random.default_rng(self.seed)

    def choose(self, graph: SceneGraph, cands: list[Candidate]
               ) -> tuple[int, str, dict[str, float]]:
        return self._pick(len(cands))

    def choose_columns(self, graph: SceneGraph, cols: CandidateColumns
                       ) -> tuple[int, str, dict[str, float]]:
        if type(self).choose is not RandomPlanner.choose:  # a subclass's own choice
            return super().choose_columns(graph, cols)
        return self._pick(len(cols))

    def _pick(self, n: int) -> tuple[int, str, dict[str, float]]:
        i = int(self._rng.integers(n))
        return i, f"random among {n}", {}


class GreedyPlanner(NodeSelectionPlanner):
    """Nearest actionable node (MoMa-LLM's greedy baseline); id breaks ties."""

    name = "greedy"

    def choose(self, graph: SceneGraph, cands: list[Candidate]
               ) -> tuple[int, str, dict[str, float]]:
        i = min(range(len(cands)), key=lambda k: (cands[k].distance, cands[k].node_id))
        return i, f"nearest ({cands[i].distance:.2f} m)", {}


class ScoringPlanner(NodeSelectionPlanner, Generic[P]):
    """A node-selection planner that scores candidates with a relation scorer, tuned by
    ``params`` (its own parameter dataclass ``P``); ``cache`` lives for one episode."""

    def __init__(self, name: str, scorer: RelationScorer, params: P,
                 max_failures: int = 2) -> None:
        super().__init__(max_failures=max_failures)
        self.name = name
        self.scorer = scorer
        self.params = params
        self.cache = EpisodeCache()

    def reset(self, query: str, seed: int = 0) -> None:
        super().reset(query, seed)
        self.cache = EpisodeCache()  # per episode (its docstring)


class UtilityPlanner(ScoringPlanner[UtilityParams]):
    """Utility-driven selection (SCOUT Eqs. 1-4, 12-13) over any relation scorer: the
    distilled priors give SCOUT, SBERT cosine gives the similarity baselines."""

    def choose(self, graph: SceneGraph, cands: list[Candidate]
               ) -> tuple[int, str, dict[str, float]]:
        return self._choose(graph, CandidateColumns.of(cands))

    def choose_columns(self, graph: SceneGraph, cols: CandidateColumns
                       ) -> tuple[int, str, dict[str, float]]:
        if type(self).choose is not UtilityPlanner.choose:  # a subclass's own choice
            return super().choose_columns(graph, cols)
        return self._choose(graph, cols)

    def _choose(self, graph: SceneGraph, cols: CandidateColumns
                ) -> tuple[int, str, dict[str, float]]:
        ids, dist = cols.ids, cols.distances
        u = column_utilities(graph, ids, cols.kinds, cols.positions, self.query, self.scorer,
                             self.params, self.cache)
        i = select_with_margin(u, dist, ids, self.params.delta)
        scores = dict(zip(ids, map(_round4, u), strict=True))
        return i, f"u={u[i]:.3f} (max {max(u):.3f}), d={dist[i]:.2f} m", scores
