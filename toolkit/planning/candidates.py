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

import math
from bisect import bisect_left
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from itertools import compress, repeat
from operator import attrgetter, eq, is_, is_not
from typing import Literal

import numpy as np

from sgtool.arg_checks import of_type
from sgtool.planning.base import Skill
from sgtool.scenegraph.graph import (
    DoorNode,
    NaturalKey,
    ObjectNode,
    RegionNode,
    RoomNode,
    SceneGraph,
    natural_key,
)
from sgtool.semantics.text import category_text

OPEN_AFFORDANCES = frozenset({"open", "openable"})
EXAMINE_AFFORDANCES = frozenset({"explore", "examine", "search"})
CARRIER_AFFORDANCES = OPEN_AFFORDANCES | EXAMINE_AFFORDANCES | {"container", "supporter"}

NodeKind = Literal["room", "frontier", "object", "door"]
_CATEGORY = attrgetter("category")


@dataclass(frozen=True)
class Candidate:
    """One actionable node (:func:`actionable`): its ``node_id``, the ``skill`` that acts on
    it (module doc's table), its ``kind`` (room, frontier, object, door), the travel
    ``distance`` from the robot in metres and its (x, y) ``position``."""

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


def node_xy(node: RoomNode | RegionNode | ObjectNode | DoorNode) -> tuple[float, float]:
    p = node.position
    return float(p[0]), float(p[1])


def distance_to(graph: SceneGraph, node: RoomNode | RegionNode | ObjectNode | DoorNode
                ) -> float | None:
    """Travel distance from the robot, None when unreachable (see module doc)."""
    if graph.distances:
        d = graph.distances.get(node.id)
        return None if d is None or not math.isfinite(d) else float(d)
    return _straight_line(graph, node)


def _straight_line(graph: SceneGraph, node: RoomNode | RegionNode | ObjectNode | DoorNode
                   ) -> float:
    """The straight-line distance from the robot (a graph without travel distances)."""
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
    return _entrance(door, graph.room)


def _entrance(door: DoorNode, room_of: Callable[[str], RoomNode | None]) -> bool:
    """:func:`door_is_entrance`, ``room_of`` the graph's room of an id (None: unknown)."""
    if door.state != "closed":
        return False
    if not door.rooms:
        return True
    for rid in door.rooms:
        room = room_of(rid)
        if room is None or not room.explored:
            return True
    return False


# (node, skill (None: not actionable), kind, natural key, id, (x, y)) of a node
_Entry = tuple[object, Skill | None, NodeKind, NaturalKey, str, tuple[float, float]]


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
        kind: NodeKind
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

# (key, node id, skill, kind, (x, y)) of an actionable node, key its natural sort key
_Ordered = list[tuple[NaturalKey, str, Skill, NodeKind, tuple[float, float]]]
# (ids, skills, kinds, positions) of an _Ordered list
_Columns = tuple[list[str], list[Skill], list[NodeKind], list[tuple[float, float]]]


class _GroupOrder:
    """The actionable nodes of one node tuple of a graph (rooms, regions or objects; doors
    with the rooms tuple they are judged by), in natural id order, by tuple identity.

    Node tuples are immutable and their nodes frozen, and an incremental graph passes the
    same tuple while its nodes do not change, so the order is computed once per tuple; a
    decision then only looks up distances. When a slot's tuple changes (a container
    opened, objects revealed), the order is updated from the last one: the entries of nodes
    that left are taken out and those of new nodes sorted in by key, which gives the order
    of a fresh sort as long as no two keys are equal (else it is sorted afresh). Each slot
    keeps its last tuple alive, so a node id is never reused under it."""

    def __init__(self) -> None:
        self.last: dict[str, tuple[tuple, tuple, _Ordered]] = {}
        # per slot: id(node) of every node of the last tuple -> key of its entry (None
        # when not actionable); None when two entries had equal keys
        self.keys: dict[str, dict[int, tuple | None] | None] = {}

    def nodes(self, slot: str, group: tuple) -> _Ordered:
        hit = self.last.get(slot)
        if hit is not None and hit[0] is group:
            return hit[2]
        keys = self.keys.get(slot) if hit is not None else None
        out = None
        if hit is not None and keys is not None:
            out = self._update(hit[0], hit[2], keys, group)
        if out is None:
            out, keys = self._sorted(group)
        self.last[slot] = (group, (), out)
        self.keys[slot] = keys
        return out

    @staticmethod
    def _entry(node: RoomNode | RegionNode | ObjectNode) -> _Entry:
        entry = _STATIC.memo.get(id(node))
        if entry is None or entry[0] is not node:
            entry = _STATIC.add(node)
        return entry

    def _sorted(self, group: tuple) -> tuple[_Ordered, dict[int, tuple | None] | None]:
        out: _Ordered = []
        keys: dict[int, tuple | None] = {}
        for node in group:
            entry = self._entry(node)
            if entry[1] is not None:
                out.append((entry[3], entry[4], entry[1], entry[2], entry[5]))
                keys[id(node)] = entry[3]
            else:
                keys[id(node)] = None
        out.sort(key=_first)  # stable: equal ids stay in graph order
        unique = all(a[0] < b[0] for a, b in zip(out, out[1:], strict=False))
        return out, (keys if unique and len(keys) == len(group) else None)

    def _update(self, prev: tuple, last: _Ordered, keys: dict[int, tuple | None],
                group: tuple) -> _Ordered | None:
        """``last`` (the order of ``prev``) updated to ``group`` (class doc); None to sort
        afresh. ``keys`` is updated in place. Entries are taken out and put in by bisection
        on the (unique) keys, which is where a sort of the whole would put them."""
        if len(prev) == len(group):  # nodes replaced in place, the usual change
            at = list(compress(range(len(group)), map(is_not, prev, group)))
            new = [group[k] for k in at]
            if len({id(n) for n in new} - keys.keys()) != len(new):
                return None  # a node moved within the tuple, or is in it twice
            gone: Iterable[int] = [id(prev[k]) for k in at]
        else:
            now = dict(zip(map(id, group), group, strict=True))
            if len(now) != len(group):
                return None  # a node twice in the tuple
            gone = keys.keys() - now.keys()
            new = [now[k] for k in now.keys() - keys.keys()]
        out = last
        drop = [key for key in map(keys.pop, gone) if key is not None]
        if drop:
            out = list(last)
            for key in drop:
                k = bisect_left(out, (key,))  # (key,) sorts just before key's entry
                if k == len(out) or out[k][0] != key:
                    return None  # (never: a key of ``keys`` is in ``last``)
                del out[k]
        added = []
        for node in new:
            entry = self._entry(node)
            if entry[1] is None:
                keys[id(node)] = None
                continue
            added.append((entry[3], entry[4], entry[1], entry[2], entry[5]))
            keys[id(node)] = entry[3]
        if added:
            if out is last:
                out = list(last)
            for e in added:
                k = bisect_left(out, (e[0],))
                if k < len(out) and out[k][0] == e[0]:
                    return None  # equal keys: their order is the graph's
                out.insert(k, e)
        return out

    def doors(self, graph: SceneGraph) -> _Ordered:
        hit = self.last.get("door")
        if hit is not None and hit[0] is graph.doors and hit[1] is graph.rooms:
            return hit[2]
        rooms: dict[str, RoomNode] = {}
        for r in graph.rooms:  # the first room of an id, as graph.room
            rooms.setdefault(r.id, r)
        out: _Ordered = [(natural_key(d.id), d.id, "open", "door", node_xy(d))
                         for d in graph.doors if _entrance(d, rooms.get)]
        out.sort(key=_first)
        self.last["door"] = (graph.doors, graph.rooms, out)
        return out


def _first(entry: tuple) -> tuple:
    return entry[0]


_ORDER = _GroupOrder()


def _in_order(groups: list[_Ordered]) -> _Ordered:
    """The entries of ``groups`` (each in natural id order) sorted by natural key, then
    group, then place in the group: the order of one stable sort of all of them. Groups
    whose key ranges do not meet (rooms, regions, objects and doors have different id
    prefixes) are put one after the other."""
    runs = sorted((g for g in groups if g), key=lambda g: g[0][0])
    if all(a[-1][0] < b[0][0] for a, b in zip(runs, runs[1:], strict=False)):
        return [e for g in runs for e in g]
    keyed = [(e[0], k, i, e) for k, g in enumerate(groups) for i, e in enumerate(g)]
    keyed.sort(key=lambda t: t[:3])
    return [t[3] for t in keyed]


@dataclass(frozen=True)
class CandidateColumns:
    """N_a as columns, one list per :class:`Candidate` field, in the order of
    :func:`actionable`. Planners that score columns (:class:`~sgtool.planning.planners.
    UtilityPlanner`) use them as they are; :meth:`candidates` builds the
    :class:`Candidate` list for those that take one. The lists may be shared with the next
    decision's columns: read them, never change them."""

    ids: list[str]
    skills: list[Skill]
    kinds: list[NodeKind]
    distances: list[float]
    positions: list[tuple[float, float]]

    def __len__(self) -> int:
        return len(self.ids)

    def candidates(self) -> list[Candidate]:
        return list(map(Candidate, self.ids, self.skills, self.kinds, self.distances,
                        self.positions))

    def take(self, keep: list[int]) -> CandidateColumns:
        """The rows ``keep`` (ascending indices)."""
        return CandidateColumns([self.ids[k] for k in keep], [self.skills[k] for k in keep],
                                [self.kinds[k] for k in keep],
                                [self.distances[k] for k in keep],
                                [self.positions[k] for k in keep])

    @classmethod
    def of(cls, candidates: list[Candidate]) -> CandidateColumns:
        return cls([c.node_id for c in candidates], [c.skill for c in candidates],
                   [c.kind for c in candidates], [c.distance for c in candidates],
                   [c.position for c in candidates])


# the ordered groups last put in order (kept alive, compared by identity) and their
# (ids, skills, kinds, positions) columns; the columns of each group's last ordered list
_LAST_ORDER: list[tuple[tuple[_Ordered, ...], _Columns]] = []
_GROUP_COLUMNS: dict[int, tuple[_Ordered, _Columns]] = {}


def _columns(entries: _Ordered) -> _Columns:
    """(ids, skills, kinds, positions) of ``entries``."""
    if not entries:
        return [], [], [], []
    _, ids, skills, kinds, xy = zip(*entries, strict=True)
    return list(ids), list(skills), list(kinds), list(xy)


def _ordered_columns(groups: tuple[_Ordered, ...]) -> _Columns:
    """The columns of :func:`_in_order` of ``groups``: those of each group end to end when
    the groups' key ranges do not meet (kept per group while its ordered list is the
    same), else of the merged order."""
    last = _LAST_ORDER[0] if _LAST_ORDER else None
    if last is not None and all(map(is_, last[0], groups)):
        return last[1]
    runs = sorted((k for k, g in enumerate(groups) if g), key=lambda k: groups[k][0][0])
    if all(groups[a][-1][0] < groups[b][0][0] for a, b in zip(runs, runs[1:], strict=False)):
        out: _Columns = ([], [], [], [])
        for k in runs:
            hit = _GROUP_COLUMNS.get(k)
            if hit is None or hit[0] is not groups[k]:
                hit = _GROUP_COLUMNS[k] = (groups[k], _columns(groups[k]))
            ids, skills, kinds, xy = hit[1]
            out[0].extend(ids)
            out[1].extend(skills)
            out[2].extend(kinds)
            out[3].extend(xy)
    else:
        out = _columns(_in_order(list(groups)))
    _LAST_ORDER[:] = [(groups, out)]
    return out


def actionable_columns(graph: SceneGraph) -> CandidateColumns:
    """:func:`actionable` as columns (:class:`CandidateColumns`)."""
    dists = graph.distances
    if not dists:
        return CandidateColumns.of(_actionable_without_distances(graph))
    ids, skills, kinds, xy = _ordered_columns((
        _ORDER.nodes("room", graph.rooms), _ORDER.nodes("region", graph.regions),
        _ORDER.nodes("object", graph.objects), _ORDER.doors(graph)))
    try:  # float64, as float(d); a missing id is unreachable
        d = np.fromiter(map(dists.get, ids, repeat(math.inf)), dtype=np.float64,
                        count=len(ids))
    except (TypeError, ValueError):  # a distance that is None or no number
        d = np.array([_finite_or_inf(dists.get(i)) for i in ids], dtype=np.float64)
    if math.isfinite(np.add.reduce(d)):  # all finite (an inf or NaN makes the sum so)
        return CandidateColumns(ids, skills, kinds, d.tolist(), xy)
    fin = np.isfinite(d)
    keep = np.flatnonzero(fin).tolist()
    return CandidateColumns([ids[k] for k in keep], [skills[k] for k in keep],
                            [kinds[k] for k in keep], d[fin].tolist(), [xy[k] for k in keep])


def _finite_or_inf(d: float | None) -> float:
    return math.inf if d is None else float(d)


def actionable(graph: SceneGraph) -> list[Candidate]:
    """The nodes a planner may act on (SCOUT's N_a; the module doc's table says which
    skill acts on which node), each a :class:`Candidate` with its travel distance, in
    natural id order; unreachable nodes are left out."""
    of_type("graph", graph, SceneGraph, "a SceneGraph")
    if not graph.distances:
        return _actionable_without_distances(graph)
    return actionable_columns(graph).candidates()


def _actionable_without_distances(graph: SceneGraph) -> list[Candidate]:
    """:func:`actionable` of a graph without travel distances (straight lines)."""
    keyed: list[tuple[tuple, int, Candidate]] = []
    for group in (graph.rooms, graph.regions, graph.objects):
        for node in group:
            entry = _STATIC.memo.get(id(node))
            if entry is None or entry[0] is not node:
                entry = _STATIC.add(node)
            if entry[1] is None:
                continue
            d = _straight_line(graph, node)
            keyed.append((entry[3], len(keyed),
                          Candidate(entry[4], entry[1], entry[2], d, entry[5])))
    for door in graph.doors:
        if door_is_entrance(graph, door):
            d = _straight_line(graph, door)
            keyed.append((natural_key(door.id), len(keyed),
                          Candidate(door.id, "open", "door", d, node_xy(door))))
    keyed.sort()  # by natural key, then (equal ids) in graph order, as a stable sort
    return [c for _, _, c in keyed]


def find_target(graph: SceneGraph, query: str) -> ObjectNode | None:
    """The nearest observed object of the query category (exact name match), or None."""
    of_type("graph", graph, SceneGraph, "a SceneGraph")
    of_type("query", query, str, "the target's category name (text)")
    best: tuple[float, str, ObjectNode] | None = None
    for o in _of_query(graph.objects, query):
        d = distance_to(graph, o)
        key = (d if d is not None else math.inf, o.id, o)
        if best is None or key[:2] < best[:2]:
            best = key
    return None if best is None else best[2]


_QUERY_OBJECTS: list[tuple[tuple, str, list[ObjectNode]]] = []  # the last objects tuple's


def _of_query(objects: tuple[ObjectNode, ...], query: str) -> list[ObjectNode]:
    """The objects of the query category, in graph order; kept for the last (objects
    tuple, query), which an incremental graph passes again until its objects change."""
    last = _QUERY_OBJECTS[0] if _QUERY_OBJECTS else None
    if last is not None and last[0] is objects and last[1] == query:
        return last[2]
    want = category_text(query)
    cats = list(map(_CATEGORY, objects))
    if want in set(map(category_text, set(cats))):  # (mostly not: nothing in view)
        found = list(compress(objects, map(eq, map(category_text, cats), repeat(want))))
    else:
        found = []
    _QUERY_OBJECTS[:] = [(objects, query, found)]
    return found
