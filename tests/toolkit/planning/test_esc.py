"""ESC-Interactive: frontiers and carriers scored by soft commonsense rules."""

from __future__ import annotations

import pytest
from support.semantics_fixtures import TableScorer

from sgtool.planning.candidates import actionable
from sgtool.planning.esc import EscParams, EscPlanner, esc_scores
from sgtool.scenegraph.graph import ObjectNode, RegionNode, RobotState, RoomNode, SceneGraph

SCORER = TableScorer(rooms={"kitchen": 0.8}, objects={"stove": 0.9, "bed": 0.05})


def kitchen(stove_near: str) -> SceneGraph:
    """A kitchen with two frontiers 5 m east and west of the robot, a stove (no affordance:
    nothing to open) by one of them and a bed by the other."""
    west, east = (-5.0, 0.0), (5.0, 0.0)
    stove_xy, bed_xy = (west, east) if stove_near == "west" else (east, west)
    objects = (
        ObjectNode("obj:1", "stove", "region:1.1", "room:1", (*stove_xy, 0.0)),
        ObjectNode("obj:2", "bed", "region:1.1", "room:1", (*bed_xy, 0.0)),
    )
    regions = (RegionNode("region:1.1", "room:1", (0.0, 0.0)),
               RegionNode("frontier:1", "room:1", west, "frontier", "unexplored area"),
               RegionNode("frontier:2", "room:1", east, "frontier", "unexplored area"))
    return SceneGraph(RobotState((0.0, 0.0), room="room:1"),
                      rooms=(RoomNode("room:1", "kitchen", (0.0, 0.0)),),
                      regions=regions, objects=objects,
                      distances={"frontier:1": 5.0, "frontier:2": 5.0})


@pytest.mark.parametrize("side,frontier", [("west", "frontier:1"), ("east", "frontier:2")])
def test_prefers_the_frontier_near_co_occurring_objects(side: str, frontier: str) -> None:
    p = EscPlanner(SCORER)
    p.reset("frying pan")
    a = p.decide(kitchen(side))
    assert (a.skill, a.target) == ("explore", frontier)
    # both frontiers share room and distance: the scores differ by w_obj (0.9 - 0.05)
    other = "frontier:2" if frontier == "frontier:1" else "frontier:1"
    assert a.scores[frontier] - a.scores[other] == pytest.approx(0.85)


def test_rule_weights_add_up() -> None:
    g = kitchen("west")
    cands = actionable(g)
    s = esc_scores(g, cands, "frying pan", SCORER, EscParams(w_obj=1.0, w_room=2.0, w_dist=0.5))
    # frontier:1: T_obj 0.9 (stove), T_room 0.8 (kitchen), T_dist 1 - 5/5 = 0
    assert s[0] == pytest.approx(0.9 + 2.0 * 0.8 + 0.0)


def test_distance_is_one_soft_rule_among_others() -> None:
    g = kitchen("west")
    g = SceneGraph(g.robot, g.rooms, g.regions, g.objects, (),
                   {"frontier:1": 5.0, "frontier:2": 2.0})
    # frontier:1: 0.9 + 0.8 + 0.5 * 0 = 1.7; frontier:2: 0.05 + 0.8 + 0.5 * (1 - 2/5) = 1.15
    p = EscPlanner(SCORER, EscParams(w_dist=0.5))
    p.reset("frying pan")
    a = p.decide(g)
    assert a.target == "frontier:1"
    assert (a.scores["frontier:1"], a.scores["frontier:2"]) == pytest.approx((1.7, 1.15))
    # without the co-occurrence rule the nearer frontier wins
    p = EscPlanner(SCORER, EscParams(w_obj=0.0))
    p.reset("frying pan")
    assert p.decide(g).target == "frontier:2"


def test_a_carrier_is_scored_by_itself_not_by_its_neighbours() -> None:
    """Two closed carriers 1 m apart (within the 2 m radius): a cabinet (co-occurrence 0.9)
    and a wardrobe (0.1). A frontier between them takes the best neighbour (R1), but each
    carrier is checked for itself: the wardrobe keeps its own 0.1."""
    scorer = TableScorer(rooms={"kitchen": 0.8}, objects={"cabinet": 0.9, "wardrobe": 0.1})
    objects = (
        ObjectNode("obj:1", "cabinet", "region:1.1", "room:1", (3.0, 0.0, 0.0), state="closed"),
        ObjectNode("obj:2", "wardrobe", "region:1.1", "room:1", (4.0, 0.0, 0.0),
                   state="closed"),
    )
    regions = (RegionNode("region:1.1", "room:1", (0.0, 0.0)),
               RegionNode("frontier:1", "room:1", (3.5, 0.0), "frontier", "unexplored area"))
    g = SceneGraph(RobotState((0.0, 0.0), room="room:1"),
                   rooms=(RoomNode("room:1", "kitchen", (0.0, 0.0)),), regions=regions,
                   objects=objects, distances={"obj:1": 3.0, "obj:2": 4.0, "frontier:1": 3.5})
    cands = actionable(g)
    assert [c.node_id for c in cands] == ["frontier:1", "obj:1", "obj:2"]
    s = esc_scores(g, cands, "frying pan", scorer, EscParams(w_obj=1.0, w_room=0.0, w_dist=0.0))
    assert s.tolist() == pytest.approx([0.9, 0.9, 0.1])
