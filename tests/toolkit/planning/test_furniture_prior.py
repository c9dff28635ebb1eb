"""φ(q) of (B6): furniture-level queries move belief from carriers to unrevealed space."""

from __future__ import annotations

import json

import numpy as np
import pytest
from support.semantics_fixtures import TableScorer

from sgtool.errors import SgtoolError
from sgtool.planning.belief import BeliefParams, place_masses
from sgtool.planning.candidates import actionable
from sgtool.planning.furniture_prior import (
    furniture_level,
    load_levels,
    parse_levels,
    query_key,
)
from sgtool.planning.registry import make_planner
from sgtool.planning.search_theory import SearchTheoryPlanner
from sgtool.scenegraph.graph import ObjectNode, RegionNode, RobotState, RoomNode, SceneGraph

SCORER = TableScorer(rooms={"kitchen": 0.9}, objects={"fridge": 0.8, "wardrobe": 0.2})


def kitchen_with_frontier() -> SceneGraph:
    """A kitchen: a closed fridge 1 m away, a closed wardrobe 10 m away, and one
    unexplored-area frontier 6 m away."""
    fridge = ObjectNode("obj:1", "fridge", "region:1.1", "room:1", (1.0, 0.0, 0.0),
                        state="closed", affordances=("open",))
    wardrobe = ObjectNode("obj:2", "wardrobe", "region:1.1", "room:1", (-10.0, 0.0, 0.0),
                          state="closed", affordances=("open",))
    frontier = RegionNode("frontier:1", "room:1", (0.0, 6.0), "frontier", "unexplored area")
    return SceneGraph(
        RobotState((0.0, 0.0), room="room:1"),
        rooms=(RoomNode("room:1", "kitchen", (0.0, 0.0)),),
        regions=(RegionNode("region:1.1", "room:1", (0.0, 0.0)), frontier),
        objects=(fridge, wardrobe),
        doors=(),
        distances={"obj:1": 1.0, "obj:2": 10.0, "frontier:1": 6.0},
    )


def test_mixture_moves_mass_from_carriers_to_the_frontier() -> None:
    g = kitchen_with_frontier()
    cands = actionable(g)
    assert [c.node_id for c in cands] == ["frontier:1", "obj:1", "obj:2"]
    params = BeliefParams()
    p_o = place_masses(g, cands, "q", SCORER, params)
    assert place_masses(g, cands, "q", SCORER, params, furniture=0.0).tolist() == \
        pytest.approx(p_o.tolist())
    # φ = 1: no carrier holds a first-level piece, the one frontier holds all the mass
    assert place_masses(g, cands, "q", SCORER, params, furniture=1.0).tolist() == \
        pytest.approx([1.0, 0.0, 0.0])
    # (B6): P = (1 - φ) P_O + φ P_F, P_F = (1, 0, 0) here
    half = place_masses(g, cands, "q", SCORER, params, furniture=0.5)
    assert half.tolist() == pytest.approx((0.5 * p_o + 0.5 * np.array([1.0, 0, 0])).tolist())


def test_nothing_left_to_reveal_keeps_the_object_model() -> None:
    g = kitchen_with_frontier()
    g = SceneGraph(g.robot, g.rooms, g.regions[:1], g.objects, (),
                   {"obj:1": 1.0, "obj:2": 10.0})
    cands = actionable(g)
    params = BeliefParams()
    assert place_masses(g, cands, "q", SCORER, params, furniture=0.9).tolist() == \
        pytest.approx(place_masses(g, cands, "q", SCORER, params).tolist())


def test_planner_reveals_for_a_furniture_query_and_opens_for_an_object() -> None:
    p = SearchTheoryPlanner(SCORER, furniture_levels={"dishwasher": 0.95})
    p.reset("Dishwasher")
    assert p.furniture == 0.95
    assert p.decide(kitchen_with_frontier()).target == "frontier:1"
    p.reset("frying pan")  # not in the table: φ = 0, the near likely fridge first
    assert p.furniture == 0.0
    assert p.decide(kitchen_with_frontier()).target == "obj:1"


def test_table_parsing_and_lookup(tmp_path) -> None:
    levels = parse_levels({"version": 1, "levels": {"Coffee_Table": 0.9}}, "t")
    assert furniture_level(levels, "coffee  table") == 0.9
    assert furniture_level(levels, "apple") == 0.0
    assert furniture_level(None, "coffee table") == 0.0
    assert query_key(" Floor_Lamp ") == "floor lamp"
    for bad in ({"levels": {}}, {"version": 1, "levels": {"x": 1.5}}, [1]):
        with pytest.raises(SgtoolError, match="^t: "):
            parse_levels(bad, "t")
    broken = tmp_path / "broken.json"
    broken.write_text("{", encoding="utf-8")
    with pytest.raises(SgtoolError, match="cannot read"):
        load_levels(str(broken))


def test_registry_option(tmp_path) -> None:
    shipped = make_planner("bayes-search", timed=False)
    assert furniture_level(shipped.furniture_levels, "sofa") > 0.9
    assert make_planner("bayes-search", furniture_levels="none",
                        timed=False).furniture_levels is None
    table = tmp_path / "levels.json"
    table.write_text(json.dumps({"version": 1, "levels": {"kiln": 1.0}}), encoding="utf-8")
    p = make_planner("bayes-search", furniture_levels=str(table), timed=False)
    assert dict(p.furniture_levels) == {"kiln": 1.0}
