"""bayes-search: the target's location as a distribution, Bayes updates, the p/c ratio rule
with a look-ahead."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from support.semantics_fixtures import TableScorer

from sgtool.planning.belief import BeliefParams, place_masses
from sgtool.planning.candidates import Candidate, actionable
from sgtool.planning.registry import make_planner
from sgtool.planning.search_theory import (
    SearchParams,
    SearchTheoryPlanner,
    best_first,
    step_price,
)
from sgtool.scenegraph.graph import (
    DoorNode,
    ObjectNode,
    RegionNode,
    RobotState,
    RoomNode,
    SceneGraph,
)

SCORER = TableScorer(rooms={"kitchen": 0.9}, objects={"fridge": 0.8, "wardrobe": 0.2})


def kitchen(fridge_explored: bool = False) -> SceneGraph:
    """Robot in a kitchen; a fridge 1 m away, a wardrobe 10 m away (both closed), a closed
    door 12 m away to an unknown room."""
    fridge = ObjectNode("obj:1", "fridge", "region:1.1", "room:1", (1.0, 0.0, 0.0),
                        state="open" if fridge_explored else "closed", affordances=("open",),
                        explored=fridge_explored)
    wardrobe = ObjectNode("obj:2", "wardrobe", "region:1.1", "room:1", (-10.0, 0.0, 0.0),
                          state="closed", affordances=("open",))
    return SceneGraph(
        RobotState((0.0, 0.0), room="room:1"),
        rooms=(RoomNode("room:1", "kitchen", (0.0, 0.0)),),
        regions=(RegionNode("region:1.1", "room:1", (0.0, 0.0)),),
        objects=(fridge, wardrobe),
        doors=(DoorNode("door:1", (0.0, 12.0), "closed", ("room:1", "room:2")),),
        distances={"obj:1": 1.0, "obj:2": 10.0, "door:1": 12.0},
    )


def test_opens_the_cheap_likely_container_first() -> None:
    p = SearchTheoryPlanner(SCORER)
    p.reset("frying pan")
    a = p.decide(kitchen())
    assert (a.skill, a.target) == ("open", "obj:1")
    assert a.scores["obj:1"] > a.scores["obj:2"]


def test_bayes_update_after_an_empty_container() -> None:
    params = BeliefParams()
    before_g, after_g = kitchen(), kitchen(fridge_explored=True)
    before = dict(zip([c.node_id for c in actionable(before_g)],
                      place_masses(before_g, actionable(before_g), "q", SCORER, params),
                      strict=True))
    cands = actionable(after_g)
    after = dict(zip([c.node_id for c in cands],
                     place_masses(after_g, cands, "q", SCORER, params), strict=True))
    assert "obj:1" not in after
    # (B5): P(n | fridge empty) = P(n) / (1 - P(fridge))
    for n in ("obj:2", "door:1"):
        assert after[n] == pytest.approx(before[n] / (1.0 - before["obj:1"]))
    # the prior by hand: R(kitchen) = 0.05 + 0.95 * 0.9, C = 0.05 + 0.95 * s^2 (object
    # sharpness 2), Z = C(fridge) + C(wardrobe); the door holds R̄ (no room types: 0.3)
    r, cf, cw = 0.05 + 0.95 * 0.9, 0.05 + 0.95 * 0.8 ** 2, 0.05 + 0.95 * 0.2 ** 2
    w = np.array([r * cf / (cf + cw), r * cw / (cf + cw), 0.3])
    assert [before[n] for n in ("obj:1", "obj:2", "door:1")] == pytest.approx(w / w.sum())
    # the kitchen's remaining mass (its wardrobe, ~0.21 unnormalised) is now below the
    # unknown room's (0.3): the planner leaves for the door instead of the wardrobe
    assert after["door:1"] > after["obj:2"]
    p = SearchTheoryPlanner(SCORER)
    p.reset("frying pan")
    assert p.decide(after_g).target == "door:1"


def test_failed_attempts_lower_the_mass() -> None:
    g = kitchen()
    cands = actionable(g)
    plain = place_masses(g, cands, "q", SCORER, BeliefParams())
    failed = place_masses(g, cands, "q", SCORER, BeliefParams(miss=0.5), failures=[1, 0, 0])
    assert failed[0] < plain[0] and failed.sum() == pytest.approx(1.0)


def cand(node_id: str, x: float) -> Candidate:
    return Candidate(node_id, "navigate", "object", abs(x), (x, 0.0))


def test_look_ahead_takes_the_pair_on_the_same_side() -> None:
    # Y alone has the best p/c, but X and Z together hold more mass for about the same walk
    cands = [cand("obj:x", 10.0), cand("obj:y", -10.0), cand("obj:z", 10.5)]
    p = np.array([0.4, 0.45, 0.15])
    i, _ = best_first(cands, p, (0.0, 0.0), SearchParams(step_cost=1.0, horizon=1))
    assert cands[i].node_id == "obj:y"
    i, value = best_first(cands, p, (0.0, 0.0), SearchParams(step_cost=1.0, horizon=3))
    assert cands[i].node_id == "obj:x"
    # (S2) for (x, z, y): 11 + 0.6 * (0.5 + 1) + 0.45 * (20.5 + 1)
    assert value == pytest.approx(1.0 / 21.575)


def test_steps_get_dearer_when_the_budget_is_short() -> None:
    p = np.full(20, 0.05)  # N_eff = 20 places
    assert step_price(p, 40, 2.0) == 2.0  # plenty of steps
    assert step_price(p, 10, 2.0) == pytest.approx(4.0)  # twice as many places as steps
    assert step_price(p, None, 2.0) == 2.0  # no budget


def test_registry_options() -> None:
    p = make_planner("bayes-search", horizon="2", step_cost=0.5, timed=False)
    assert (p.params.horizon, p.params.step_cost) == (2, 0.5)
    assert dataclasses.is_dataclass(p.params)


def test_region_weight_scales_the_mass_of_an_unseen_region() -> None:
    """A kitchen with one revealed region (fridge, wardrobe) and one unexplored-area
    frontier: K = ω · n̄ · C̄ with n̄ = 2 carriers per revealed region and C̄ their mean C,
    and the frontier's share of the kitchen is K / (C(fridge) + C(wardrobe) + K)."""
    g = kitchen()
    frontier = RegionNode("frontier:1", "room:1", (0.0, 5.0), "frontier", "unexplored area")
    g = SceneGraph(g.robot, g.rooms, (*g.regions, frontier), g.objects, (),
                   {**g.distances, "frontier:1": 5.0})
    cands = actionable(g)
    assert [c.node_id for c in cands] == ["frontier:1", "obj:1", "obj:2"]
    cf, cw = 0.05 + 0.95 * 0.8 ** 2, 0.05 + 0.95 * 0.2 ** 2
    for omega in (0.5, 1.0):
        p = place_masses(g, cands, "q", SCORER, BeliefParams(region_weight=omega))
        k = omega * 2 * (cf + cw) / 2
        # one room: the masses are the kitchen's split, (B2)-(B3)
        assert p.tolist() == pytest.approx([k / (cf + cw + k), cf / (cf + cw + k),
                                            cw / (cf + cw + k)])


class TypedScorer(TableScorer):
    """A table scorer that lists the room types it knows (what R̄ averages over)."""

    room_types = ("kitchen", "bedroom")


def test_explored_room_types_leave_the_mean_of_unexplored_rooms() -> None:
    from sgtool.planning.belief import known_room_mean, unexplored_room_mean

    scorer = TypedScorer(rooms={"kitchen": 0.9, "bedroom": 0.1}, objects={"fridge": 0.8})
    g = kitchen()  # one explored kitchen, a door to an unknown room
    rk, rb = 0.05 + 0.95 * 0.9, 0.05 + 0.95 * 0.1
    off = BeliefParams()
    assert unexplored_room_mean(g, scorer, "q", off) == pytest.approx((rk + rb) / 2)
    assert unexplored_room_mean(g, scorer, "q", off) == known_room_mean(scorer, "q", off)
    # (B7): the one kitchen seen counts eta = 0.3 in the mean over the types
    on = BeliefParams(seen_type_weight=0.3)
    assert unexplored_room_mean(g, scorer, "q", on) == pytest.approx((0.3 * rk + rb) / 1.3)
    # so the door to the unknown room holds less against the kitchen's own carriers
    cands = actionable(g)
    ids = [c.node_id for c in cands]
    p_off = dict(zip(ids, place_masses(g, cands, "q", scorer, off), strict=True))
    p_on = dict(zip(ids, place_masses(g, cands, "q", scorer, on), strict=True))
    assert p_on["door:1"] < p_off["door:1"]
    assert p_on["obj:1"] > p_off["obj:1"]


def test_bayes_rooms_is_bayes_search_with_eta_and_gamma() -> None:
    p = make_planner("bayes-rooms")
    assert p.name == "bayes-rooms"
    assert p.inner.params.belief.seen_type_weight == 0.3
    assert p.inner.params.belief.instance_exponent == 0.5
    base = make_planner("bayes-search")
    assert base.name == "bayes-search"
    assert base.inner.params.belief.seen_type_weight == 1.0
    assert base.inner.params.belief.instance_exponent == 1.0


def cabinet_kitchen() -> SceneGraph:
    """An explored kitchen with four closed cabinets and one countertop, all 1 m away."""
    cabinets = tuple(ObjectNode(f"obj:{i}", "cabinet", "region:1.1", "room:1",
                                (float(i), 1.0, 0.0), state="closed", affordances=("open",))
                     for i in range(1, 5))
    counter = ObjectNode("obj:9", "countertop", "region:1.1", "room:1", (0.0, -1.0, 0.0),
                         affordances=("examine",))
    return SceneGraph(
        RobotState((0.0, 0.0), room="room:1"),
        rooms=(RoomNode("room:1", "kitchen", (0.0, 0.0)),),
        regions=(RegionNode("region:1.1", "room:1", (0.0, 0.0)),),
        objects=(*cabinets, counter),
        distances={o.id: 1.0 for o in (*cabinets, counter)},
    )


def test_like_carriers_share_their_category_mass() -> None:
    # a spatula: a cabinet and a countertop score alike, so with (B2) the four cabinets
    # hold four times the countertop's mass; with (B8) gamma = 0 they hold one share
    scorer = TableScorer(rooms={"kitchen": 0.9}, objects={"cabinet": 0.6, "countertop": 0.6})
    g = cabinet_kitchen()
    cands = actionable(g)
    ids = [c.node_id for c in cands]
    for gamma, cabinets_to_counter in ((1.0, 4.0), (0.5, 2.0), (0.0, 1.0)):
        params = BeliefParams(instance_exponent=gamma)
        p = dict(zip(ids, place_masses(g, cands, "spatula", scorer, params), strict=True))
        cab = sum(p[f"obj:{i}"] for i in range(1, 5))
        assert cab / p["obj:9"] == pytest.approx(cabinets_to_counter)
    # the countertop is looked at first once the cabinets share their mass
    planner = SearchTheoryPlanner(scorer, SearchParams(
        belief=BeliefParams(instance_exponent=0.5)))
    planner.reset("spatula")
    assert planner.decide(g).target == "obj:9"
    planner = SearchTheoryPlanner(scorer)
    planner.reset("spatula")
    assert planner.decide(g).target != "obj:9"


def _best_by_loop(cands: list[Candidate], p: np.ndarray, params: SearchParams,
                  robot: tuple[float, float]) -> tuple[int, float]:
    """best_first's look-ahead written as one sequence_value call per ordering."""
    import itertools

    from support.search_reference import sequence_value

    from sgtool.planning.search_theory import detour_factor, extra_cost

    extra = np.array([extra_cost(c, params) for c in cands])
    first = np.array([c.distance for c in cands]) + extra
    ratio = p / first
    top = sorted(range(len(cands)), key=lambda i: (-ratio[i], cands[i].node_id))[:params.top_k]
    rho = detour_factor(cands, robot)
    legs = np.zeros((len(cands), len(cands)))
    for a in top:
        for b in top:
            d = cands[a].position[0] - cands[b].position[0], \
                cands[a].position[1] - cands[b].position[1]
            legs[a, b] = rho * float(np.hypot(*d)) + extra[b]
    best = None
    for order in itertools.permutations(top, params.horizon):
        key = (-sequence_value(order, p, first, legs), tuple(cands[i].node_id for i in order))
        if best is None or key < best[0]:
            best = (key, order[0])
    assert best is not None
    return best[1], -best[0][0]


@pytest.mark.parametrize("seed", range(6))
def test_look_ahead_equals_one_sequence_value_per_ordering(seed: int) -> None:
    rng = np.random.default_rng(seed)
    n = 9
    xs = rng.integers(0, 4, n).astype(float)  # few distinct positions: ties happen
    cands = [Candidate(f"obj:{i}", "open" if i % 2 else "navigate", "object",
                       float(abs(xs[i]) + 1.0), (float(xs[i]), 0.0)) for i in range(n)]
    p = rng.choice([0.05, 0.1, 0.2], n)
    p = p / p.sum()
    params = SearchParams(step_budget=0)
    assert best_first(cands, p, (0.0, 0.0), params) == \
        _best_by_loop(cands, p, params, (0.0, 0.0))


def test_leading_out_frontiers_of_one_room_share_the_space_beyond() -> None:
    """(B10): three leading-out frontiers of the kitchen and one closed door. With δ = 1
    each frontier weighs as the door (a whole unknown room, (B4)); with δ = 0 the three
    together weigh one door, δ = 0.5 sqrt(3) doors; the carriers' masses relative to each
    other do not move, and the furniture-level model (B6) splits the same way."""
    g = kitchen()
    fronts = tuple(RegionNode(f"frontier:{k}", "room:1", (5.0, float(k)), "frontier",
                              "leading out") for k in range(1, 4))
    g = SceneGraph(g.robot, g.rooms, (*g.regions, *fronts), g.objects, g.doors,
                   {**g.distances, **{f.id: 5.0 for f in fronts}})
    cands = actionable(g)
    ids = [c.node_id for c in cands]
    door, fs = ids.index("door:1"), [ids.index(f.id) for f in fronts]
    fridge, wardrobe = ids.index("obj:1"), ids.index("obj:2")
    for furniture in (0.0, 0.9):
        masses = {d: place_masses(g, cands, "q", SCORER, BeliefParams(leading_out_exponent=d),
                                  furniture=furniture) for d in (1.0, 0.5, 0.0)}
        for d, p in masses.items():
            total = sum(p[i] for i in fs)
            assert total == pytest.approx(p[door] * 3 ** d)
            assert p[fs[0]] == pytest.approx(p[fs[1]]) == pytest.approx(p[fs[2]])
            assert p[fridge] / p[wardrobe] == pytest.approx(
                masses[1.0][fridge] / masses[1.0][wardrobe])
        # sharing moves mass from the frontiers to what the kitchen holds
        assert masses[0.0][fridge] > masses[0.5][fridge] > masses[1.0][fridge]
    assert BeliefParams().leading_out_exponent == 1.0  # (B4) unchanged by default
