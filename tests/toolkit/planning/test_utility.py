"""SCOUT's utility math (Eqs. 2-4, 12-13) and the utility planner on a hand-made house."""

from __future__ import annotations

import dataclasses

import pytest
from support.candidate_utilities import candidate_utilities
from support.semantics_fixtures import TableScorer, house

from sgtool.planning.base import Feedback
from sgtool.planning.candidates import actionable
from sgtool.planning.planners import UtilityPlanner
from sgtool.planning.utility import (
    UtilityParams,
    frontier_utility,
    room_influence,
    room_utilities,
    select_with_margin,
)
from sgtool.scenegraph.graph import ObjectNode


@pytest.mark.parametrize(
    "room,obj,updated",
    [  # SCOUT Table VIII, query "plate": (room score, object score) -> updated score
        (0.78, 0.94, 0.75),  # kitchen cabinet
        (0.78, 0.45, 0.48),  # kitchen fridge
        (0.78, 0.12, 0.30),  # kitchen chair
        (0.30, 0.94, 0.29),  # living-room cabinet
        (0.30, 0.04, 0.10),  # living-room tv
        (0.21, 0.94, 0.20),  # bathroom cabinet
    ],
)
def test_room_influence_reproduces_table_viii(room: float, obj: float, updated: float) -> None:
    assert room_influence(room, obj, 0.3) == pytest.approx(updated, abs=0.006)


def test_room_influence_bounds() -> None:
    # w = 1: the room alone decides; w = 0: the product of room and object scores
    assert room_influence(0.6, 0.1, 1.0) == pytest.approx(0.6)
    assert room_influence(0.6, 0.5, 0.0) == pytest.approx(0.3)


def test_margin_selection_prefers_nearest_within_delta() -> None:
    u = [0.80, 0.75, 0.50]
    d = [10.0, 2.0, 1.0]
    ids = ["a", "b", "c"]
    assert select_with_margin(u, d, ids, delta=0.1) == 1  # b is within 0.1 and nearer
    assert select_with_margin(u, d, ids, delta=0.0) == 0  # Eq. 13: argmax
    assert select_with_margin(u, d, ids, delta=0.5) == 2  # everything qualifies: nearest
    # equal utility and distance: the smaller id, independent of order
    assert select_with_margin([0.5, 0.5], [1.0, 1.0], ["z", "y"], 0.0) == 1
    with pytest.raises(ValueError):
        select_with_margin([], [], [], 0.1)


def test_frontier_utility_never_below_fallback() -> None:
    assert frontier_utility([], 0.6) == 0.6
    assert frontier_utility([0.2, 0.1], 0.6) == 0.6
    assert frontier_utility([0.2, 0.9], 0.6) == 0.9


QUERY = "plate"
SCORER = TableScorer(
    rooms={"kitchen": 0.8, "bathroom": 0.1, "living_room": 0.3},
    objects={"bottom_cabinet": 0.9, "fridge": 0.4, "countertop": 0.95, "chair": 0.1,
             "sink": 0.9, "sofa": 0.05, "coffee_table": 0.6},
)


def test_candidate_utilities_by_node_type() -> None:
    g = house()
    cands = actionable(g)
    ids = [c.node_id for c in cands]
    # chairs offer nothing to explore; regions are not actionable; the door to room:4 is
    assert ids == ["door:1", "frontier:1", "frontier:2", "obj:10", "obj:11", "obj:12",
                   "obj:20", "obj:21", "obj:30", "obj:31", "room:4"]
    u = dict(zip(ids, candidate_utilities(g, cands, QUERY, SCORER, UtilityParams()),
                 strict=True))
    assert u["room:4"] == 0.7 and u["door:1"] == 0.7  # default room score
    assert u["obj:11"] == pytest.approx(0.8 * (0.3 + 0.7 * 0.9))  # kitchen cabinet
    assert u["obj:21"] == pytest.approx(0.1 * (0.3 + 0.7 * 0.9))  # bathroom cabinet
    # in-room frontier, no object within 2 m: the kitchen's score
    assert u["frontier:1"] == pytest.approx(0.8)
    # leading-out frontier with nothing informative nearby: the default frontier score
    assert u["frontier:2"] == 0.6
    noroom = UtilityParams(room_influence=False)
    u2 = dict(zip(ids, candidate_utilities(g, cands, QUERY, SCORER, noroom), strict=True))
    assert u2["obj:11"] == u2["obj:21"] == 0.9  # without room context they tie


class NoBathrooms(TableScorer):
    """A table scorer with no score for bathrooms (like the distilled prior for a room
    type its training data hardly covers)."""

    def can_score_room(self, name: str) -> bool:
        return name != "bathroom"


def test_a_room_the_scorer_cannot_score_is_treated_as_uncategorised() -> None:
    g = house()
    scorer = NoBathrooms(SCORER.room_table, SCORER.object_table)
    params = UtilityParams()
    # Eq. 2 for the kitchen and the living room; the bathroom and the unexplored room:4
    # take the default room score
    assert room_utilities(g, QUERY, scorer, params) == {
        "room:1": 0.8, "room:2": 0.7, "room:3": 0.3, "room:4": 0.7}
    cands = actionable(g)
    u = dict(zip([c.node_id for c in cands], candidate_utilities(g, cands, QUERY, scorer,
                                                                 params), strict=True))
    assert u["obj:21"] == pytest.approx(0.7 * (0.3 + 0.7 * 0.9))  # bathroom cabinet
    assert u["obj:11"] == pytest.approx(0.8 * (0.3 + 0.7 * 0.9))  # kitchen cabinet: as before
    # a scorer without can_score_room scores every room (TableScorer): the bathroom's 0.1
    assert room_utilities(g, QUERY, SCORER, params)["room:2"] == pytest.approx(0.1)


def test_scout_prefers_the_kitchen_cabinet_and_breaks_ties_by_distance() -> None:
    p = UtilityPlanner("scout", SCORER, UtilityParams())
    p.reset(QUERY)
    a = p.decide(house())
    # within 0.1 of the best (frontier:1 0.8 at 4 m): countertop 0.772 at 1 m, kitchen
    # cabinet 0.744 at 2 m, the door and room:4 at 0.7 far away -> the countertop
    assert (a.skill, a.target) == ("navigate", "obj:12")
    assert a.scores["obj:21"] < a.scores["obj:11"]
    p0 = UtilityPlanner("scout-delta0", SCORER, UtilityParams(delta=0.0))
    p0.reset(QUERY)
    # delta 0 (Eq. 13): the maximum only, the kitchen's unexplored area
    assert p0.decide(house()).target == "frontier:1"


def test_without_room_influence_bathroom_cabinet_competes() -> None:
    p = UtilityPlanner("scout-noroom", SCORER, UtilityParams(room_influence=False, delta=0.0))
    p.reset(QUERY)
    a = p.decide(house())
    assert a.target == "obj:12"  # 0.95, the top raw co-occurrence
    p.feedback(Feedback(a, "success"))
    a2 = p.decide(house())
    # bathroom and kitchen cabinets and the sink tie at 0.9: distance decides (kitchen 2 m)
    assert a2.target == "obj:11"


def test_done_when_target_observed_and_only_then() -> None:
    p = UtilityPlanner("scout", SCORER, UtilityParams())
    p.reset("Plate")
    assert p.decide(house()).skill != "done"
    plate = ObjectNode("obj:99", "plate.n.01", "obj:11", "room:1", (-1.0, -1.0, 0.5),
                       relation="inside")
    a = p.decide(house(extra_objects=[plate]))
    assert (a.skill, a.target) == ("done", "obj:99")


def test_failed_targets_are_dropped_after_two_failures() -> None:
    p = UtilityPlanner("scout", SCORER, UtilityParams())
    p.reset(QUERY)
    g = house()
    a = p.decide(g)
    p.feedback(Feedback(a, "failure", "handle out of reach"))
    assert p.decide(g).target == a.target  # one failure: still the best choice
    p.feedback(Feedback(a, "failure"))
    assert p.decide(g).target != a.target


def test_unreachable_nodes_are_not_candidates() -> None:
    g = house()
    d = dict(g.distances)
    del d["obj:12"], d["frontier:1"]
    g2 = dataclasses.replace(g, distances=d)
    ids = {c.node_id for c in actionable(g2)}
    assert "obj:12" not in ids and "frontier:1" not in ids and "obj:11" in ids


def test_sbert_defaults_are_table_vi() -> None:
    s = UtilityParams.sbert()
    assert (s.default_room, s.default_frontier, s.delta, s.room_weight) == (0.3, 0.25, 0.05, 0.3)
    t = UtilityParams()
    assert (t.default_room, t.default_frontier, t.delta, t.room_weight) == (0.7, 0.6, 0.1, 0.3)
