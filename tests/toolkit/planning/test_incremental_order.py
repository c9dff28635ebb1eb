"""The per-episode reuse in the planners' decisions gives what a fresh computation gives:
:func:`actionable`'s order kept per node tuple and updated when the tuple changes (nodes
replaced, added, removed; equal natural keys; key ranges of the groups that meet), and the
utilities of :class:`EpisodeCache` (room utilities per rooms tuple, the object table reused
over state changes) against :func:`candidate_utilities` without it, on seeded random walks
of a graph."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from support.semantics_fixtures import TableScorer, house

from sgtool.planning.candidates import (
    Candidate,
    actionable,
    distance_to,
    door_is_entrance,
    natural_key,
    node_xy,
    object_skill,
)
from sgtool.planning.utility import EpisodeCache, UtilityParams, candidate_utilities
from sgtool.scenegraph.graph import ObjectNode, RoomNode, SceneGraph

SCORER = TableScorer(
    rooms={"kitchen": 0.8, "bathroom": 0.1, "living_room": 0.3, "bedroom": 0.5},
    objects={"bottom_cabinet": 0.9, "fridge": 0.4, "countertop": 0.95, "chair": 0.1,
             "sink": 0.9, "sofa": 0.05, "coffee_table": 0.6, "box": 0.7},
)


def plain_actionable(graph: SceneGraph) -> list[tuple]:
    """N_a by the definition: every actionable reachable node, one stable sort by natural
    key in graph order (rooms, regions, objects, doors)."""
    out = []
    for group, kind in ((graph.rooms, "room"), (graph.regions, "frontier"),
                        (graph.objects, "object")):
        for n in group:
            if kind == "room":
                skill = None if n.explored else "explore"
            elif kind == "frontier":
                skill = "explore" if n.kind == "frontier" else None
            else:
                skill = object_skill(n)
            d = distance_to(graph, n)
            if skill is not None and d is not None:
                out.append((n.id, skill, kind, d, node_xy(n)))
    for door in graph.doors:
        d = distance_to(graph, door)
        if door_is_entrance(graph, door) and d is not None:
            out.append((door.id, "open", "door", d, node_xy(door)))
    return sorted(out, key=lambda c: natural_key(c[0]))


def as_tuples(cands: list[Candidate]) -> list[tuple]:
    return [(c.node_id, c.skill, c.kind, c.distance, c.position) for c in cands]


def step(graph: SceneGraph, rng: np.random.Generator, k: int) -> SceneGraph:
    """One random change of the kinds an incremental graph makes, new tuples only for the
    groups that change, and new distances (some unreachable)."""
    objects, rooms = list(graph.objects), list(graph.rooms)
    move = int(rng.integers(6))
    if move == 0 and objects:  # a container opened or looked into: same row, new node
        i = int(rng.integers(len(objects)))
        objects[i] = dataclasses.replace(objects[i], explored=True, state=None)
    elif move == 1:  # objects revealed, ids that may collide in natural order
        for _ in range(int(rng.integers(1, 25))):
            nid = str(rng.choice([f"obj:{100 + k}", f"obj:0{int(rng.integers(10, 40))}",
                                  f"obj:{int(rng.integers(10, 40))}", f"obj:7.{k}",
                                  "frontier:1", "room:4", f"door:{k}"]))  # other groups
            objects.insert(int(rng.integers(len(objects) + 1)), ObjectNode(
                nid, "box", "region:1.1", "room:1",
                (float(rng.uniform(-2, 14)), float(rng.uniform(-2, 4)), 0.0),
                state="closed", affordances=("open",)))
    elif move == 2 and objects:  # objects gone (a rebuilt map)
        for _ in range(int(rng.integers(1, 4))):
            if objects:
                objects.pop(int(rng.integers(len(objects))))
    elif move == 3:  # a room explored or forgotten
        i = int(rng.integers(len(rooms)))
        r = rooms[i]
        rooms[i] = RoomNode(r.id, "bedroom" if not r.explored else "unknown", r.position,
                            not r.explored)
    elif move == 4 and objects:  # an object moved (to or from frontier:2): a new row
        i = int(rng.integers(len(objects)))
        o = objects[i]
        to = (12.0, 4.0) if o.position[:2] != (12.0, 4.0) else (0.0, -1.0)
        objects[i] = dataclasses.replace(o, position=(*to, o.position[2]))
    ids = [n.id for g in (rooms, graph.regions, objects, graph.doors) for n in g]
    dist = {i: float(rng.uniform(0.5, 20.0)) for i in ids if rng.random() < 0.9}
    for i in list(dist)[:2]:
        dist[i] = math.inf
    return dataclasses.replace(
        graph, rooms=tuple(rooms) if move == 3 else graph.rooms,
        objects=tuple(objects) if move in (0, 1, 2, 4) else graph.objects, distances=dist)


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
