"""A seeded random walk of a small scene graph, with the changes an incremental graph makes
(states changed, nodes added and removed, ids of equal natural order, rooms explored, an
object moved), and N_a by its definition: for the tests of the planners' reuse and
column paths."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
from support.semantics_fixtures import TableScorer

from sgtool.planning.candidates import (
    Candidate,
    distance_to,
    door_is_entrance,
    natural_key,
    node_xy,
    object_skill,
)
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
