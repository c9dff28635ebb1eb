"""Which scene-graph nodes a planner may act on, how far they are, and whether the search is over.

SCOUT (sec. IV-D) selects among the actionable nodes N_a: "nodes with exploration
affordances such as openable containers, closed doors, or unexplored frontiers", plus the
unexplored room nodes that closed doors reveal (sec. IV-A). The mapping from a node to the
skill of :class:`~sgtool.planning.base.Action` is:

===========================================  =============  ==========================
node                                         skill          condition
===========================================  =============  ==========================
room, ``explored=False``                     ``explore``    always
region, ``kind="frontier"``                  ``explore``    always
object, not ``explored``                     ``open``       ``state == "closed"`` or
                                                            affordance ``open``
object, not ``explored``                     ``navigate``   affordance ``explore``,
                                                            ``examine`` or ``search``
                                                            (look on/into it)
door, ``state == "closed"``                  ``open``       joins an unexplored or
                                                            unknown room
===========================================  =============  ==========================

A node is reachable when it has an entry in ``graph.distances``; if the graph carries no
distances at all (a hand-made graph), the straight-line distance from the robot is used.

The query counts as found when an object whose category equals the query after
:func:`~sgtool.semantics.text.category_text` is in the graph (no embeddings involved:
"frying_pan.n.01" matches "Frying pan", "pan" does not).
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

from sgtool.planning.base import Skill
from sgtool.scenegraph.graph import DoorNode, ObjectNode, RegionNode, RoomNode, SceneGraph
from sgtool.semantics.text import category_text

OPEN_AFFORDANCES = frozenset({"open", "openable"})
EXAMINE_AFFORDANCES = frozenset({"explore", "examine", "search"})
CARRIER_AFFORDANCES = OPEN_AFFORDANCES | EXAMINE_AFFORDANCES | {"container", "supporter"}

NodeKind = str  # "room" | "frontier" | "object" | "door"


@dataclass(frozen=True)
class Candidate:
    node_id: str
    skill: Skill
    kind: NodeKind
    distance: float
    position: tuple[float, float]

    def __init__(self, node_id: str, skill: Skill, kind: NodeKind, distance: float,
                 position: tuple[float, float]) -> None:
        # the dataclass's frozen __init__ sets each field through object.__setattr__;
        # a decision builds ~100 candidates, so fill the instance dict at once (still
        # frozen: assigning a field afterwards raises FrozenInstanceError)
        d = self.__dict__
        d["node_id"] = node_id
        d["skill"] = skill
        d["kind"] = kind
        d["distance"] = distance
        d["position"] = position


@functools.lru_cache(maxsize=65536)
def natural_key(node_id: str) -> tuple[str, tuple[tuple[int, int | str], ...]]:
    """Sort ids naturally: ``room:2`` before ``room:10``, ``region:3.1`` before ``region:3.12``."""
    prefix, _, rest = node_id.partition(":")
    return prefix, tuple((0, int(p)) if p.isdigit() else (1, p) for p in rest.split("."))


def node_xy(node: RoomNode | RegionNode | ObjectNode | DoorNode) -> tuple[float, float]:
    p = node.position
    return float(p[0]), float(p[1])


def distance_to(graph: SceneGraph, node: RoomNode | RegionNode | ObjectNode | DoorNode
                ) -> float | None:
    """Travel distance from the robot, None when unreachable (see module doc)."""
    if graph.distances:
        d = graph.distances.get(node.id)
        return None if d is None or not math.isfinite(d) else float(d)
    x, y = node_xy(node)
    rx, ry = graph.robot.position
    return math.hypot(x - rx, y - ry)


def object_skill(obj: ObjectNode) -> Skill | None:
    """The exploring skill of an object, None when it offers nothing to explore."""
    if obj.explored:
        return None
    affs = {a.lower() for a in obj.affordances}
    if obj.state == "closed" or (obj.state is None and affs & OPEN_AFFORDANCES):
        return "open"
    if affs & EXAMINE_AFFORDANCES:
        return "navigate"
    return None


def is_carrier(obj: ObjectNode) -> bool:
    """Whether an object can hold others (a container or supporter), explored or not: it
    has a state, or an open/examine/container/supporter affordance."""
    if obj.state is not None:
        return True
    return any(a.lower() in CARRIER_AFFORDANCES for a in obj.affordances)


def door_is_entrance(graph: SceneGraph, door: DoorNode) -> bool:
    """A closed door is worth opening when it joins a room that is unexplored or unknown."""
    if door.state != "closed":
        return False
    if not door.rooms:
        return True
    for rid in door.rooms:
        room = graph.room(rid)
        if room is None or not room.explored:
            return True
    return False


_Entry = tuple[object, "Skill | None", str, tuple, str, tuple[float, float]]


class _NodeMemo:
    """What is fixed about a node, by node identity: its skill and kind (None when it is
    not actionable), its natural sort key, id and (x, y).

    Scene-graph nodes are frozen, and an incremental graph (the symbolic environment's)
    hands the same node objects from step to step, so this is computed once per node. The
    memo keeps each node alive while it holds it, so an id is never reused under it; it is
    emptied when full."""

    def __init__(self, limit: int = 1 << 13) -> None:
        self.memo: dict[int, _Entry] = {}
        self._limit = limit

    def add(self, node: RoomNode | RegionNode | ObjectNode) -> _Entry:
        skill: Skill | None
        if isinstance(node, RoomNode):
            skill, kind = (None if node.explored else "explore"), "room"
        elif isinstance(node, RegionNode):
            skill, kind = ("explore" if node.kind == "frontier" else None), "frontier"
        else:
            skill, kind = object_skill(node), "object"
        if len(self.memo) >= self._limit:
            self.memo.clear()
        entry = (node, skill, kind, natural_key(node.id), node.id, node_xy(node))
        self.memo[id(node)] = entry
        return entry


_STATIC = _NodeMemo()


def actionable(graph: SceneGraph) -> list[Candidate]:
    """N_a in natural id order; unreachable nodes are left out."""
    keyed: list[tuple[tuple, int, Candidate]] = []
    dists = graph.distances
    memo, add = _STATIC.memo, _STATIC.add
    isfinite = math.isfinite
    for group in (graph.rooms, graph.regions, graph.objects):
        for node in group:
            entry = memo.get(id(node))
            if entry is None or entry[0] is not node:
                entry = add(node)
            if entry[1] is None:
                continue
            if dists:
                d = dists.get(node.id)
                if d is None or not isfinite(d):
                    continue
                d = float(d)
            else:
                d = distance_to(graph, node)  # type: ignore[assignment]
            keyed.append((entry[3], len(keyed),
                          Candidate(entry[4], entry[1], entry[2], d, entry[5])))
    for door in graph.doors:
        if door_is_entrance(graph, door):
            d = distance_to(graph, door)
            if d is not None:
                keyed.append((natural_key(door.id), len(keyed),
                              Candidate(door.id, "open", "door", d, node_xy(door))))
    keyed.sort()  # by natural key, then (equal ids) in graph order, as a stable sort
    return [c for _, _, c in keyed]


def find_target(graph: SceneGraph, query: str) -> ObjectNode | None:
    """The nearest observed object of the query category (exact name match), or None."""
    best: tuple[float, str, ObjectNode] | None = None
    want = category_text(query)
    for o in graph.objects:
        if category_text(o.category) != want:
            continue
        d = distance_to(graph, o)
        key = (d if d is not None else math.inf, o.id, o)
        if best is None or key[:2] < best[:2]:
            best = key
    return None if best is None else best[2]
