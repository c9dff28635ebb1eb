"""The fast paths of the planners' per-decision work give what the plain code gives: the
vectorised frontier radius test (points exactly on the radius included), the vectorised
utilities against the per-node formulas on seeded random graphs, the per-node memo of
:func:`actionable` when a node changes state, and the memo of the object table."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from support.candidate_utilities import candidate_utilities
from support.semantics_fixtures import TableScorer, house

from sgtool.planning.base import Action, Feedback
from sgtool.planning.candidates import Candidate, actionable, object_skill
from sgtool.planning.memory import EpisodeMemory
from sgtool.planning.planners import UtilityPlanner
from sgtool.planning.utility import (
    ObjectTable,
    UtilityParams,
    object_table,
    objects_within,
    room_utilities,
)
from sgtool.scenegraph.graph import SceneGraph

SCORER = TableScorer(
    rooms={"kitchen": 0.8, "bathroom": 0.1, "living_room": 0.3},
    objects={"bottom_cabinet": 0.9, "fridge": 0.4, "countertop": 0.95, "chair": 0.1,
             "sink": 0.9, "sofa": 0.05, "coffee_table": 0.6},
)


def plain_utilities(graph: SceneGraph, cands: list[Candidate], query: str,
                    params: UtilityParams) -> list[float]:
    """The per-node code the vectorised utilities (:func:`column_utilities`) replaced."""
    rooms = room_utilities(graph, query, SCORER, params)
    raw = SCORER.objects([o.category for o in graph.objects], query)
    objects = {}
    for o, s in zip(graph.objects, raw, strict=True):
        r = rooms.get(o.room, params.default_room)
        objects[o.id] = r * (params.room_weight + (1.0 - params.room_weight) * float(s)) \
            if params.room_influence else float(s)
    xy = [(o.id, float(o.position[0]), float(o.position[1])) for o in graph.objects]
    out = []
    for c in cands:
        if c.kind == "room":
            out.append(rooms.get(c.node_id, params.default_room))
        elif c.kind == "door":
            out.append(params.default_room)
        elif c.kind == "object":
            out.append(objects[c.node_id])
        else:
            region = graph.node(c.node_id)
            near = [objects[i] for i in objects_within(xy, c.position, params.frontier_radius)]
            fallback = params.default_frontier if region.frontier_type == "leading out" \
                else rooms.get(region.room, params.default_room)
            out.append(max([fallback, *near]))
    return out


def shuffled(graph: SceneGraph, rng: np.random.Generator) -> SceneGraph:
    """The house with objects moved to random places (some exactly 2 m from a frontier,
    the radius) and into random rooms."""
    rooms = [r.id for r in graph.rooms]
    frontiers = [r for r in graph.regions if r.kind == "frontier"]
    objs = []
    for o in graph.objects:
        if rng.random() < 0.3:
            f = frontiers[int(rng.integers(len(frontiers)))]
            a = float(rng.choice([0.0, math.pi / 2, math.pi, math.pi / 3]))
            pos = (f.position[0] + 2.0 * math.cos(a), f.position[1] + 2.0 * math.sin(a), 0.5)
        else:
            pos = (float(rng.uniform(0, 12)), float(rng.uniform(0, 8)), 0.5)
        objs.append(dataclasses.replace(o, position=pos,
                                        room=rooms[int(rng.integers(len(rooms)))]))
    return dataclasses.replace(graph, objects=tuple(objs))


def test_within_matches_objects_within_on_and_near_the_radius() -> None:
    rng = np.random.default_rng(7)
    pts = rng.uniform(-3, 3, (300, 2))
    centre = (0.1, -0.2)
    # exactly on the radius along the axes and the diagonal, and a hair inside/outside
    ring = [(centre[0] + 2.0, centre[1]), (centre[0], centre[1] - 2.0),
            (centre[0] + 2.0 / math.sqrt(2), centre[1] + 2.0 / math.sqrt(2)),
            (centre[0] + math.nextafter(2.0, 0), centre[1]),
            (centre[0] + math.nextafter(2.0, 3), centre[1])]
    xy = [(f"obj:{k}", float(x), float(y)) for k, (x, y) in enumerate([*pts.tolist(), *ring])]
    g = SceneGraph(robot=house().robot, objects=tuple(
        dataclasses.replace(house().objects[0], id=i, position=(x, y, 0.0)) for i, x, y in xy))
    table = ObjectTable(g.objects)
    for position in (centre, (1.0, 1.0), (-2.5, 0.3)):
        got = [table.ids[k] for k in np.flatnonzero(table.within([position], 2.0)[0])]
        assert got == objects_within(xy, position, 2.0)
    on_ring = objects_within(xy, centre, 2.0)
    assert f"obj:{len(pts) + 3}" in on_ring and f"obj:{len(pts) + 4}" not in on_ring


@pytest.mark.parametrize("params", [UtilityParams(), UtilityParams(room_influence=False),
                                    UtilityParams.sbert()])
def test_vectorised_utilities_equal_the_per_node_formulas(params: UtilityParams) -> None:
    rng = np.random.default_rng(3)
    for _ in range(25):
        g = shuffled(house(), rng)
        cands = actionable(g)
        fast = candidate_utilities(g, cands, "plate", SCORER, params)
        assert fast == plain_utilities(g, cands, "plate", params)  # exactly, not approx


def test_object_table_is_reused_for_the_same_objects_only() -> None:
    g = house()
    t = object_table(g)
    assert object_table(dataclasses.replace(g, distances={})) is t  # same objects tuple
    moved = shuffled(g, np.random.default_rng(0))
    assert object_table(moved) is not t
    assert t.raw_scores(SCORER, "plate") is t.raw_scores(SCORER, "plate")
    assert t.raw_scores(SCORER, "cup") is not t.raw_scores(SCORER, "plate")


def test_actionable_follows_a_node_that_changes_state() -> None:
    g = house()
    cabinet = next(o for o in g.objects if o.id == "obj:11")
    assert object_skill(cabinet) is not None
    before = {c.node_id: c for c in actionable(g)}
    assert "obj:11" in before
    done = dataclasses.replace(cabinet, explored=True)
    g2 = dataclasses.replace(g, objects=tuple(done if o is cabinet else o for o in g.objects))
    after = {c.node_id: c for c in actionable(g2)}
    assert "obj:11" not in after and set(before) - set(after) == {"obj:11"}
    assert actionable(g) == list(before.values())  # the old node still answers as before
    with pytest.raises(dataclasses.FrozenInstanceError):
        before["obj:12"].distance = 0.0  # type: ignore[misc]


def test_memory_filter_fast_path_agrees_with_excluded() -> None:
    g = house()
    cands = actionable(g)
    m = EpisodeMemory(max_failures=2)
    assert m.filter(cands) == cands
    m.offered(cands)
    first, second = cands[0], cands[1]
    m.record(Feedback(Action("navigate", first.node_id), "success"))
    m.record(Feedback(Action("open", second.node_id), "failure"))
    assert m.filter(cands) == [c for c in cands if not m.excluded(c)] == cands[1:]
    m.record(Feedback(Action("open", second.node_id), "failure"))
    assert m.filter(cands) == cands[2:]


def test_planner_scores_are_the_rounded_utilities() -> None:
    p = UtilityPlanner("scout", SCORER, UtilityParams())
    p.reset("plate")
    g = house()
    a = p.decide(g)
    cands = actionable(g)
    u = candidate_utilities(g, cands, "plate", SCORER, UtilityParams())
    assert a.scores == {c.node_id: round(v, 4) for c, v in zip(cands, u, strict=True)}
