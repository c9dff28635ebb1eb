"""The incremental observed graph equals the graph rebuilt from scratch (issue 20), on
randomised small houses: generated ones of both presets and the hand-built nested house
(closed containers inside closed furniture), under seeded random walks of actions that
include opening and closing doors, furniture and objects, invalid actions and repeats."""

from __future__ import annotations

import numpy as np
import pytest
from support.nested_house import nested_house
from support.symbolic_observation import scratch_graph

from sgtool.datasets.generator import generate_house
from sgtool.house.io import load_house
from sgtool.planning.base import Action
from sgtool.recorders.symbolic_environment import SymbolicEnv, SymbolicHouse
from sgtool.scenegraph.graph import SceneGraph

SKILLS = ("navigate", "open", "close", "explore")


def houses() -> list[tuple[str, SymbolicHouse]]:
    out = [("nested", SymbolicHouse(load_house(nested_house())))]
    for seed, preset in ((3, "default"), (5, "symsearch"), (8, "symsearch")):
        out.append((f"{preset}-{seed}",
                    SymbolicHouse(generate_house(seed, rooms=(4, 6), preset=preset))))
    return out


@pytest.fixture(scope="module")
def house_list() -> list[tuple[str, SymbolicHouse]]:
    return houses()


def same(a: SceneGraph, b: SceneGraph) -> None:
    assert a == b
    assert list(a.distances) == list(b.distances)  # same order, not only the same entries
    assert a.to_json() == b.to_json()


def random_action(rng: np.random.Generator, g: SceneGraph) -> Action:
    """Any node of the graph with any skill (most do nothing or are invalid), now and then
    a node that is not in it."""
    ids = [n.id for grp in (g.rooms, g.regions, g.objects, g.doors) for n in grp]
    if rng.random() < 0.05:
        return Action(SKILLS[int(rng.integers(4))], f"obj:{int(rng.integers(1, 10_000))}")
    # favour the things that change the graph: closed doors and objects, frontiers, rooms
    pick = [n.id for n in g.doors + g.objects if n.state == "closed"] + \
        [r.id for r in g.regions if r.kind == "frontier"] + \
        [r.id for r in g.rooms if not r.explored]
    pool = pick if pick and rng.random() < 0.6 else ids
    return Action(SKILLS[int(rng.integers(4))], pool[int(rng.integers(len(pool)))])


def test_incremental_observation_equals_scratch_on_random_walks(house_list):
    checked = 0
    for name, house in house_list:
        cats = sorted(set(house.obj_cat) | set(house.furn_cat))
        for episode in range(6):
            rng = np.random.default_rng([episode, len(name)])
            # a query that is absent from the house half of the time, so walks run long
            query = cats[int(rng.integers(len(cats)))] if episode % 2 else "no such thing"
            env = SymbolicEnv(house, query, seed=episode, episode_index=episode,
                              max_steps=80)
            same(env.observe(), scratch_graph(env))
            while not env.ended:
                env.step(random_action(rng, env.observe()))
                same(env.observe(), scratch_graph(env))
                checked += 1
    assert checked > 300  # the walks went somewhere


def test_walks_change_what_is_observed(house_list):
    """The random walks above exercise the changes the incremental graph must follow:
    rooms entered, doors opened and closed, contents revealed."""
    name, house = house_list[1]
    rng = np.random.default_rng(1)
    env = SymbolicEnv(house, "no such thing", max_steps=80)
    first = env.observe()
    opened = closed = 0
    while not env.ended:
        out = env.step(random_action(rng, env.observe()))
        a = out.feedback.action
        if out.feedback.outcome == "success":
            opened += a.skill == "open"
            closed += a.skill == "close"
    last = env.observe()
    assert len(last.rooms) > len(first.rooms)
    assert len(last.objects) > len(first.objects)
    assert opened > 0 and closed > 0
    same(last, scratch_graph(env))
