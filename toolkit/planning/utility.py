"""SCOUT's utility of scene-graph nodes and its selection rule, as pure functions.

- rooms (Eq. 2): u_q(r) = p_contains(r, q) for an explored, categorised room; unexplored or
  uncategorised rooms get the default room exploration score, and so do rooms of a category
  the scorer cannot score (:func:`~sgtool.semantics.priors.can_score_room`: a room type the
  distilled prior's training data hardly covers, where its ~0 is an absence of data);
- objects (Eq. 3-4): u_q(o) = p_co-occur(o, q), with room influence
  u'_q(o) = u_q(r_o) * (w + (1 - w) * u_q(o)) where r_o is the object's room;
- frontiers (sec. IV-B c): the aggregate of the utilities of objects within a radius; with
  no informative object nearby, the room's score for an "unexplored area" inside a room, the
  default frontier score for one "leading out". We read "informative" as "scoring above the
  fallback", so a frontier scores max(fallback, best nearby object);
- closed doors to unexplored rooms: the default room score (they stand for the room);
- selection (Eqs. 12-13): keep the actionable nodes within ``delta`` of the best utility and
  take the nearest; node id breaks remaining ties so the choice is deterministic.

Defaults are SCOUT's Table II (learned priors) and Table VI (SBERT similarity).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from sgtool.planning.candidates import Candidate
from sgtool.scenegraph.graph import SceneGraph
from sgtool.semantics.priors import RelationScorer, can_score_room

UNKNOWN_ROOM = frozenset({"", "unknown", "none"})


@dataclass(frozen=True)
class UtilityParams:
    default_room: float = 0.7  # Table II: default room exploration score
    default_frontier: float = 0.6  # Table II: default frontier exploration score
    delta: float = 0.1  # Table II: utility margin
    room_weight: float = 0.3  # Table II: room influence weight w
    room_influence: bool = True  # Eq. 4 on/off ("w/o RI" ablation)
    frontier_radius: float = 2.0  # metres; objects this close inform a frontier

    @classmethod
    def scout(cls, **kw: float | bool) -> UtilityParams:
        return cls(**kw)  # type: ignore[arg-type]

    @classmethod
    def sbert(cls, **kw: float | bool) -> UtilityParams:
        """Table VI, SBERT row."""
        base = {"default_room": 0.3, "default_frontier": 0.25, "delta": 0.05,
                "room_weight": 0.3}
        base.update(kw)
        return cls(**base)  # type: ignore[arg-type]


def room_influence(room_score: float | np.ndarray, object_score: float | np.ndarray,
                   w: float) -> float | np.ndarray:
    """Eq. 4: u_q(r_o) * (w + (1 - w) * u_q(o))."""
    return room_score * (w + (1.0 - w) * object_score)


def frontier_utility(nearby: Sequence[float], fallback: float) -> float:
    """Aggregate of nearby object utilities, never below the fallback (module doc)."""
    return float(max([fallback, *nearby]))


def objects_within(obj_xy: Sequence[tuple[str, float, float]], position: tuple[float, float],
                   radius: float) -> list[str]:
    """Ids of the ``(id, x, y)`` objects within ``radius`` of ``position`` (in order)."""
    fx, fy = position
    r2 = radius ** 2
    return [i for i, x, y in obj_xy if (x - fx) ** 2 + (y - fy) ** 2 <= r2]


def select_with_margin(
    utilities: Sequence[float], distances: Sequence[float], ids: Sequence[str], delta: float
) -> int:
    """Eq. 12: among nodes with u >= U_max - delta, the nearest (then the smallest id).

    With ``delta == 0`` this is Eq. 13 (argmax utility), ties still broken by distance.
    Returns an index into the sequences; they must be non-empty.
    """
    if not utilities:
        raise ValueError("no actionable node to select from")
    u_max = max(utilities)
    # tolerance: scores computed in float32 can differ in the last bits
    eps = 1e-9
    best = None
    for i, (u, d, nid) in enumerate(zip(utilities, distances, ids, strict=True)):
        if u >= u_max - delta - eps:
            key = (d, nid)
            if best is None or key < best[0]:
                best = (key, i)
    assert best is not None
    return best[1]


def room_utilities(graph: SceneGraph, query: str, scorer: RelationScorer,
                   params: UtilityParams) -> dict[str, float]:
    """Eq. 2 for every room node of the graph (module doc)."""
    out: dict[str, float] = {}
    known = [r for r in graph.rooms if r.explored and r.category.lower() not in UNKNOWN_ROOM
             and can_score_room(scorer, r.category)]
    scores = scorer.rooms([r.category for r in known], query) if known else np.zeros(0)
    for r, s in zip(known, scores, strict=True):
        out[r.id] = float(s)
    for r in graph.rooms:
        out.setdefault(r.id, params.default_room)
    return out


def object_utilities(graph: SceneGraph, query: str, scorer: RelationScorer,
                     params: UtilityParams, rooms: dict[str, float]) -> dict[str, float]:
    """Eqs. 3-4 for every object node of the graph."""
    objs = list(graph.objects)
    if not objs:
        return {}
    raw = scorer.objects([o.category for o in objs], query)
    out: dict[str, float] = {}
    for o, s in zip(objs, raw, strict=True):
        if params.room_influence:
            r = rooms.get(o.room, params.default_room)
            out[o.id] = float(room_influence(r, float(s), params.room_weight))
        else:
            out[o.id] = float(s)
    return out


def candidate_utilities(
    graph: SceneGraph,
    candidates: Sequence[Candidate],
    query: str,
    scorer: RelationScorer,
    params: UtilityParams,
) -> list[float]:
    """u_q(n) for each candidate, in order (module doc for each node type)."""
    rooms = room_utilities(graph, query, scorer, params)
    objects = object_utilities(graph, query, scorer, params, rooms)
    obj_xy = [(o.id, float(o.position[0]), float(o.position[1])) for o in graph.objects]
    out: list[float] = []
    for c in candidates:
        if c.kind == "room":
            out.append(rooms.get(c.node_id, params.default_room))
        elif c.kind == "door":
            out.append(params.default_room)
        elif c.kind == "object":
            out.append(objects[c.node_id])
        else:  # frontier
            region = graph.node(c.node_id)
            nearby = [objects[i] for i in objects_within(obj_xy, c.position,
                                                         params.frontier_radius)]
            room_id = getattr(region, "room", None)
            if getattr(region, "frontier_type", None) == "leading out" or room_id is None:
                fallback = params.default_frontier
            else:
                fallback = rooms.get(room_id, params.default_room)
            out.append(frontier_utility(nearby, fallback))
    return [0.0 if math.isnan(u) else u for u in out]
