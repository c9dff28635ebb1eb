"""The planners' column path gives what the list path gives: :func:`actionable_columns`
against the :class:`Candidate` list, the memory's column filter, a whole
:class:`UtilityPlanner` decision against one built from the plain parts (candidate list,
list filter, utilities without a cache, the margin rule as a loop), the margin rule against
that loop on ties and NaN."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from support.candidate_utilities import candidate_utilities
from support.planning_walk import SCORER, plain_actionable, step
from support.semantics_fixtures import house

from sgtool.planning.base import Action, Feedback
from sgtool.planning.candidates import (
    Candidate,
    CandidateColumns,
    actionable,
    actionable_columns,
)
from sgtool.planning.memory import EpisodeMemory
from sgtool.planning.planners import GreedyPlanner, RandomPlanner, UtilityPlanner
from sgtool.planning.utility import UtilityParams, select_with_margin
from sgtool.scenegraph.graph import SceneGraph


def loop_select(utilities: list[float], distances: list[float], ids: list[str],
                delta: float) -> int:
    """The margin rule as the loop it was (Eq. 12; the first of the smallest key)."""
    u_max = max(utilities)
    best = None
    for i, (u, d, nid) in enumerate(zip(utilities, distances, ids, strict=True)):
        if u >= u_max - delta - 1e-9:
            key = (d, nid)
            if best is None or key < best[0]:
                best = (key, i)
    assert best is not None
    return best[1]


def plain_decision(graph: SceneGraph, memory: EpisodeMemory, query: str,
                   params: UtilityParams) -> Action:
    """A UtilityPlanner decision from the plain parts (no target in view)."""
    cands = memory.filter([Candidate(*t) for t in plain_actionable(graph)])
    if not cands:
        return Action("done", target=None, reason="nothing left to explore")
    u = candidate_utilities(graph, cands, query, SCORER, params)
    i = loop_select(u, [c.distance for c in cands], [c.node_id for c in cands], params.delta)
    scores = {c.node_id: round(v, 4) for c, v in zip(cands, u, strict=True)}
    reason = f"u={u[i]:.3f} (max {max(u):.3f}), d={cands[i].distance:.2f} m"
    return Action(cands[i].skill, target=cands[i].node_id, reason=reason, scores=scores)


def walk(seed: int, steps: int) -> list[SceneGraph]:
    rng = np.random.default_rng(seed)
    graph = house()
    graph = dataclasses.replace(graph, distances={
        i: 1.0 + (k % 7) for k, i in enumerate(sorted(graph.node_ids()))})
    out = []
    for k in range(steps):
        out.append(graph)
        graph = step(graph, rng, k)
    return out


@pytest.mark.parametrize("seed", range(4))
def test_columns_are_the_candidate_list(seed: int) -> None:
    for graph in walk(seed, 60):
        cols = actionable_columns(graph)
        assert cols.candidates() == actionable(graph)
        assert [(c.node_id, c.skill, c.kind, c.distance, c.position)
                for c in cols.candidates()] == plain_actionable(graph)
        assert len(cols) == len(cols.ids) == len(cols.distances) == len(cols.positions)
        assert all(type(d) is float and math.isfinite(d) for d in cols.distances)


def test_columns_of_a_graph_without_distances_are_straight_lines() -> None:
    graph = dataclasses.replace(house(), distances={})
    cols = actionable_columns(graph)
    assert cols.candidates() == actionable(graph)
    rx, ry = graph.robot.position
    for c in cols.candidates():
        assert c.distance == pytest.approx(math.hypot(c.position[0] - rx, c.position[1] - ry))


def test_take_and_of_round_trip() -> None:
    cols = actionable_columns(walk(0, 1)[0])
    assert len(cols) >= 3
    cands = cols.candidates()
    assert CandidateColumns.of(cands) == cols
    assert cols.take([0, 2]).candidates() == [cands[0], cands[2]]


@pytest.mark.parametrize("seed", range(3))
def test_column_filter_is_the_list_filter(seed: int) -> None:
    rng = np.random.default_rng(seed)
    memory = EpisodeMemory(max_failures=2)
    left_out = 0
    for graph in walk(seed, 50):
        cols = actionable_columns(graph)
        got = memory.filter_columns(cols).candidates()
        want = memory.filter(cols.candidates())
        assert got == want
        left_out += len(cols) - len(want)
        if cols.ids:  # a random outcome on a random candidate
            c = cols.candidates()[int(rng.integers(len(cols)))]
            memory.offered_columns(cols)
            outcome = "success" if rng.random() < 0.5 else "failure"
            memory.record(Feedback(Action(c.skill, target=c.node_id), outcome))  # type: ignore[arg-type]
    assert left_out > 0  # the memory did leave candidates out


@pytest.mark.parametrize("seed", range(4))
def test_utility_planner_decides_as_the_plain_parts(seed: int) -> None:
    rng = np.random.default_rng(50 + seed)
    params = UtilityParams.scout()
    planner = UtilityPlanner("scout", SCORER, params)
    planner.reset("bowl", seed=seed)
    reference = EpisodeMemory(max_failures=2)
    chosen = set()
    for graph in walk(seed, 60):
        want = plain_decision(graph, reference, "bowl", params)
        got = planner.decide(graph)
        assert got == want
        chosen.add(got.target)
        if got.target is not None:
            reference.offered(reference.filter([Candidate(*t)
                                                for t in plain_actionable(graph)]))
            fb = Feedback(got, "success" if rng.random() < 0.7 else "failure")
            planner.feedback(fb)
            reference.record(fb)
    assert len(chosen) > 3


def test_list_planners_see_the_same_candidates() -> None:
    """Planners that take the Candidate list (greedy, random) choose as before."""
    for graph in walk(7, 30):
        cands = actionable(graph)
        if not cands:
            continue
        greedy = GreedyPlanner()
        greedy.reset("bowl")
        i = min(range(len(cands)), key=lambda k: (cands[k].distance, cands[k].node_id))
        assert greedy.decide(graph).target == cands[i].node_id
        a, b = RandomPlanner(), RandomPlanner()
        a.reset("bowl", seed=3)
        b.reset("bowl", seed=3)
        assert a.decide(graph).target == cands[b.choose(graph, cands)[0]].node_id


@pytest.mark.parametrize("seed", range(20))
def test_margin_rule_is_the_loop(seed: int) -> None:
    rng = np.random.default_rng(seed)
    n = int(rng.integers(1, 30))
    u = [float(v) for v in rng.choice([0.1, 0.5, 0.55, 0.6, 0.7], n)]  # ties
    if seed % 4 == 0:
        u[int(rng.integers(n))] = math.nan
    d = [float(v) for v in rng.choice([1.0, 2.0, 2.5], n)]  # ties
    ids = [str(v) for v in rng.choice(["a", "b", "c", "room:1", "room:10"], n)]  # ties
    for delta in (0.0, 0.05, 0.1, 1.0):
        try:
            want = loop_select(u, d, ids, delta)
        except AssertionError:  # (a NaN first: nothing qualifies)
            with pytest.raises(ValueError):
                select_with_margin(u, d, ids, delta)
            continue
        assert select_with_margin(u, d, ids, delta) == want
