"""The per-episode reuse in the planners' decisions gives what a fresh computation gives:
:func:`actionable`'s order kept per node tuple and updated when the tuple changes (nodes
replaced, added, removed; equal natural keys; key ranges of the groups that meet), and the
utilities of :class:`EpisodeCache` (room utilities per rooms tuple, the object table reused
over state changes) against the utilities without it, on seeded random walks
of a graph."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from support.candidate_utilities import candidate_utilities
from support.planning_walk import SCORER, as_tuples, plain_actionable, step
from support.semantics_fixtures import house

from sgtool.planning.candidates import actionable, natural_key
from sgtool.planning.utility import EpisodeCache, UtilityParams
from sgtool.scenegraph.graph import ObjectNode


@pytest.mark.parametrize("seed", range(6))
def test_actionable_order_kept_over_a_random_walk_is_a_fresh_sort(seed: int) -> None:
    rng = np.random.default_rng(seed)
    graph = house()
    graph = dataclasses.replace(graph, distances={
        i: 1.0 + k for k, i in enumerate(sorted(graph.node_ids()))})
    seen_equal_keys = False
    for k in range(120):
        got = as_tuples(actionable(graph))
        want = plain_actionable(graph)
        assert got == want, k
        keys = [natural_key(c[0]) for c in want]
        seen_equal_keys |= len(set(keys)) < len(keys)
        graph = step(graph, rng, k)
    assert seen_equal_keys  # the walk met ids of equal natural order ("obj:012", "obj:12")


def test_actionable_of_the_same_tuples_in_two_graphs_alternating() -> None:
    """Two episodes' graphs interleaved (two planners on one process): each gets its own
    order, whatever the other left in the cache."""
    a = house(distances=None)
    a = dataclasses.replace(a, distances={i: 2.0 for i in a.node_ids()})
    extra = ObjectNode("obj:5", "box", "region:1.1", "room:1", (0.2, 0.2, 0.0),
                       state="closed", affordances=("open",))
    b = house(extra_objects=(extra,))
    b = dataclasses.replace(b, distances={i: 1.0 for i in b.node_ids()})
    for _ in range(3):
        for g in (a, b):
            assert as_tuples(actionable(g)) == plain_actionable(g)
    assert "obj:5" in [c.node_id for c in actionable(b)]
    assert "obj:5" not in [c.node_id for c in actionable(a)]


@pytest.mark.parametrize("seed", range(4))
def test_episode_cache_gives_the_utilities_without_it(seed: int) -> None:
    rng = np.random.default_rng(100 + seed)
    graph = house()
    graph = dataclasses.replace(graph, distances={i: 3.0 for i in graph.node_ids()})
    params = UtilityParams.scout()
    cache = EpisodeCache()
    reused = 0
    for k in range(80):
        cands = actionable(graph)
        if cands:
            table_before = cache._table
            got = candidate_utilities(graph, cands, "bowl", SCORER, params, cache)
            assert got == candidate_utilities(graph, cands, "bowl", SCORER, params)
            reused += table_before is not None and cache._table is not None and \
                cache._table.x is table_before.x
        graph = step(graph, rng, k)
    assert reused > 0  # state changes kept the table's arrays
