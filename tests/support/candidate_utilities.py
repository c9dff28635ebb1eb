"""SCOUT utilities of candidates given as a list of
:class:`~sgtool.planning.candidates.Candidate` objects (what
:func:`sgtool.planning.candidates.actionable` returns), for tests that build candidates one
by one; the package scores candidate columns
(:func:`sgtool.planning.utility.column_utilities`)."""

from __future__ import annotations

from collections.abc import Sequence

from sgtool.planning.candidates import Candidate
from sgtool.planning.utility import EpisodeCache, UtilityParams, column_utilities
from sgtool.scenegraph.graph import SceneGraph
from sgtool.semantics.priors import RelationScorer


def candidate_utilities(graph: SceneGraph, candidates: Sequence[Candidate], query: str,
                        scorer: RelationScorer, params: UtilityParams,
                        cache: EpisodeCache | None = None) -> list[float]:
    """u_q(n) for each candidate, in order (:func:`column_utilities` of their columns)."""
    return column_utilities(graph, [c.node_id for c in candidates],
                            [c.kind for c in candidates], [c.position for c in candidates],
                            query, scorer, params, cache)
