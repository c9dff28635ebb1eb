"""SCOUT and the SBERT baselines with the real encoder and shipped weights, via the registry."""

from __future__ import annotations

import pytest
from semantics_fixtures import encoder, house
from test_planning_invariants import World

from sgtool.planning.registry import PLANNER_NAMES, make_planner
from sgtool.semantics.text import same_category

UTILITY_PLANNERS = [n for n in PLANNER_NAMES if n.startswith(("scout", "sbert"))]


def room_of(graph, node_id: str) -> str | None:
    n = graph.node(node_id)
    return getattr(n, "room", None)


@pytest.mark.parametrize("query,room", [("frying pan", "room:1"), ("razor", "room:2"),
                                        ("remote control", "room:3")])
def test_scout_goes_where_a_person_would(query: str, room: str) -> None:
    g = house()
    p = make_planner("scout", encoder=encoder())
    p.reset(query)
    a = p.decide(g)
    assert room_of(g, a.target) == room, (a, a.scores)
    assert a.decision_time_s > 0 and a.scores


def test_variants_differ_only_in_their_parameters() -> None:
    scout = make_planner("scout", encoder=encoder(), timed=False)
    noroom = make_planner("scout-noroom", encoder=encoder(), timed=False)
    delta0 = make_planner("scout-delta0", encoder=encoder(), timed=False)
    sbert = make_planner("sbert", encoder=encoder(), timed=False)
    assert (scout.params.delta, delta0.params.delta) == (0.1, 0.0)
    assert scout.params.room_influence and not noroom.params.room_influence
    assert (sbert.params.default_room, sbert.params.delta) == (0.3, 0.05)
    assert make_planner("scout", encoder=encoder(), delta=0.3, timed=False).params.delta == 0.3


@pytest.mark.parametrize("name", UTILITY_PLANNERS)
@pytest.mark.parametrize("seed", range(6))
def test_invariants_with_real_scores(name: str, seed: int) -> None:
    p = make_planner(name, encoder=encoder())
    world = World(seed)
    p.reset(world.query, seed=seed)
    for _ in range(60):
        g = world.graph()
        a = p.decide(g)
        observed = {o.id for o in g.objects if same_category(o.category, world.query)}
        if a.skill == "done":
            assert (a.target in observed) if a.target is not None else not observed
            break
        assert not observed and a.target in g.node_ids()
        p.feedback(world.execute(a))
    else:
        pytest.fail("no end after 60 steps")
