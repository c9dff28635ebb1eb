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
from itertools import compress, repeat
from operator import attrgetter, ge, is_, is_not, ne
from typing import TypedDict, TypeVar, Unpack

import numpy as np

from sgtool.scenegraph.graph import ObjectNode, SceneGraph
from sgtool.semantics.priors import RelationScorer, can_score_room

UNKNOWN_ROOM = frozenset({"", "unknown", "none"})
_ID, _CATEGORY, _ROOM, _POSITION = (attrgetter(a) for a in ("id", "category", "room",
                                                              "position"))


class UtilityOptions(TypedDict, total=False):
    """Keyword arguments of :meth:`UtilityParams.scout` and :meth:`UtilityParams.sbert`:
    any of the :class:`UtilityParams` fields."""

    default_room: float
    default_frontier: float
    delta: float
    room_weight: float
    room_influence: bool
    frontier_radius: float


@dataclass(frozen=True)
class UtilityParams:
    default_room: float = 0.7  # Table II: default room exploration score
    default_frontier: float = 0.6  # Table II: default frontier exploration score
    delta: float = 0.1  # Table II: utility margin
    room_weight: float = 0.3  # Table II: room influence weight w
    room_influence: bool = True  # Eq. 4 on/off ("w/o RI" ablation)
    frontier_radius: float = 2.0  # metres; objects this close inform a frontier

    @classmethod
    def scout(cls, **kw: Unpack[UtilityOptions]) -> UtilityParams:
        return cls(**kw)

    @classmethod
    def sbert(cls, **kw: Unpack[UtilityOptions]) -> UtilityParams:
        """Table VI, SBERT row."""
        base: UtilityOptions = {"default_room": 0.3, "default_frontier": 0.25, "delta": 0.05,
                                "room_weight": 0.3}
        base.update(kw)
        return cls(**base)


_Score = TypeVar("_Score", float, np.ndarray)


def room_influence(room_score: _Score, object_score: _Score, w: float) -> _Score:
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
    if not len(utilities) == len(distances) == len(ids):
        raise ValueError("utilities, distances and ids differ in length")
    u_max = max(utilities)
    # tolerance: scores computed in float32 can differ in the last bits
    eps = 1e-9
    near = list(compress(range(len(utilities)),
                         map(ge, utilities, repeat(u_max - delta - eps))))
    # the first of the smallest (distance, id): min() keeps the first of equal keys
    return min(near, key=lambda i: (distances[i], ids[i]))


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


class ObjectTable:
    """The object nodes of a graph as arrays: ids, categories, room ids, x and y, with the
    row of each id (built once per ``graph.objects`` tuple: :func:`object_table`)."""

    def __init__(self, objects: Sequence[ObjectNode]) -> None:
        self.objects = objects
        self.ids = list(map(_ID, objects))
        self.row = dict(zip(self.ids, range(len(self.ids)), strict=True))
        self.categories = list(map(_CATEGORY, objects))
        rooms = list(map(_ROOM, objects))
        self.room_ids = sorted(set(rooms))
        where = dict(zip(self.room_ids, range(len(self.room_ids)), strict=True))
        self.room_of = np.array(list(map(where.__getitem__, rooms)), dtype=np.intp)
        xy = _xy(list(map(_POSITION, objects)))
        self.x, self.y = xy[:, 0], xy[:, 1]
        self._scores: tuple[object, str, np.ndarray] | None = None

    def same_rows(self, objects: Sequence[ObjectNode]) -> bool:
        """Whether ``objects`` give this table's rows: the same nodes, or nodes with the same
        id, category, room and position object (a state change, as an incremental graph
        makes when a container is opened)."""
        if len(objects) != len(self.objects):
            return False
        mine = self.objects
        for k in compress(range(len(objects)), map(is_not, mine, objects)):
            a, b = mine[k], objects[k]
            if a.id != b.id or a.category != b.category or a.room != b.room \
                    or a.position is not b.position:
                return False
        return True

    def with_objects(self, objects: Sequence[ObjectNode]) -> ObjectTable:
        """This table for ``objects`` (:meth:`same_rows`), sharing its arrays and scores."""
        table = object.__new__(ObjectTable)
        table.__dict__.update(self.__dict__)
        table.objects = objects
        return table

    def raw_scores(self, scorer: RelationScorer, query: str) -> np.ndarray:
        """u_q(o) of every object (Eq. 3), asked of the scorer once per (scorer, query)."""
        hit = self._scores
        if hit is not None and hit[0] is scorer and hit[1] == query:
            return hit[2]
        raw = np.asarray(scorer.objects(self.categories, query), dtype=np.float64)
        self._scores = (scorer, query, raw)
        return raw

    def within(self, positions: Sequence[tuple[float, float]], radius: float) -> np.ndarray:
        """(positions x objects) mask of the objects within ``radius`` of each position:
        exactly the ids :func:`objects_within` gives (distances within a relative 1e-9 of
        the radius are recomputed the same way, so a last-bit difference of the vectorised
        squares cannot change the set)."""
        p = np.asarray(positions, dtype=np.float64).reshape(-1, 2)
        fx, fy = p[:, :1], p[:, 1:]
        r2 = radius ** 2
        d2 = (self.x[None, :] - fx) ** 2 + (self.y[None, :] - fy) ** 2
        inside = d2 <= r2 * (1.0 - 1e-9)
        for i, k in zip(*np.nonzero(~inside & (d2 <= r2 * (1.0 + 1e-9) + 1e-300)),
                        strict=True):
            x, y = float(self.x[k]), float(self.y[k])
            qx, qy = positions[i]
            inside[i, k] = (x - qx) ** 2 + (y - qy) ** 2 <= r2
        return inside


def _xy(positions: list[tuple]) -> np.ndarray:
    """(n, 2) float64 array of the first two coordinates of each position."""
    try:
        xyz = np.array(positions, dtype=np.float64)
    except ValueError:  # positions of different lengths
        xyz = None
    if xyz is None or xyz.ndim != 2 or xyz.shape[1] < 2:
        return np.array([p[:2] for p in positions], dtype=np.float64).reshape(-1, 2)
    return xyz[:, :2]


_TABLE: list[ObjectTable] = []  # the table of the last objects tuple seen


def object_table(graph: SceneGraph) -> ObjectTable:
    """The :class:`ObjectTable` of ``graph.objects``, reused while the same tuple comes back
    (an incremental graph passes the same tuple until its objects change)."""
    last = _TABLE[0] if _TABLE else None
    if last is not None and last.objects is graph.objects:
        return last
    table = ObjectTable(graph.objects)
    _TABLE[:] = [table]
    return table


class EpisodeCache:
    """What :func:`column_utilities` may reuse between the decisions of one episode: the
    room utilities of the last rooms tuple and the object table of the last objects tuple
    (:meth:`ObjectTable.same_rows`: reused, with its scores, when only states changed).

    The scorer is asked nothing it was not asked before in the episode, so its answers
    are the ones it would give again (a scorer forgets its scores only between units of
    work; make a new cache for each episode)."""

    def __init__(self) -> None:
        self._rooms: tuple[tuple, object, str, UtilityParams, dict[str, float]] | None = None
        self._table: ObjectTable | None = None
        self._objects: tuple[tuple, np.ndarray, dict[str, float]] | None = None
        self._nearby: tuple[np.ndarray, np.ndarray, list, float, list[list[float]]] | None = \
            None

    def rooms(self, graph: SceneGraph, query: str, scorer: RelationScorer,
              params: UtilityParams) -> dict[str, float]:
        hit = self._rooms
        if hit is not None and hit[0] is graph.rooms and hit[1] is scorer and \
                hit[2] == query and hit[3] == params:
            return hit[4]
        out = room_utilities(graph, query, scorer, params)
        self._rooms = (graph.rooms, scorer, query, params, out)
        return out

    def table(self, graph: SceneGraph) -> ObjectTable:
        last = self._table
        if last is not None and last.objects is graph.objects:
            return last
        if last is not None and last.same_rows(graph.objects):
            table = last.with_objects(graph.objects)
        else:
            table = ObjectTable(graph.objects)
        self._table = table
        return table

    def object_utilities(self, table: ObjectTable, query: str, scorer: RelationScorer,
                         params: UtilityParams, rooms: dict[str, float]
                         ) -> tuple[np.ndarray, dict[str, float]]:
        """:func:`object_utility_array` of ``table`` (and by object id), kept while the
        table's rows and the room utilities are the same."""
        key = (table.x, scorer, query, params, rooms)
        hit = self._objects
        if hit is not None and all(map(is_, hit[0], key)):
            return hit[1], hit[2]
        u = object_utility_array(table, query, scorer, params, rooms) if len(table.ids) \
            else np.zeros(0)
        self._objects = (key, u, dict(zip(table.ids, u.tolist(), strict=True)))
        return u, self._objects[2]

    def nearby_best(self, table: ObjectTable, u: np.ndarray,
                    positions: list[tuple[float, float]], radius: float
                    ) -> list[list[float]]:
        """:func:`_nearby_best`, kept while the table's rows, the utilities, the frontier
        positions and the radius are the same."""
        hit = self._nearby
        if hit is not None and hit[0] is table.x and hit[1] is u and hit[2] == positions \
                and hit[3] == radius:
            return hit[4]
        out = _nearby_best(table, u, positions, radius)
        self._nearby = (table.x, u, positions, radius, out)
        return out


def object_utility_array(table: ObjectTable, query: str, scorer: RelationScorer,
                         params: UtilityParams, rooms: dict[str, float]) -> np.ndarray:
    """Eqs. 3-4 for every row of ``table``, in one vectorised pass (the same float64
    operations as :func:`room_influence` on each object)."""
    raw = table.raw_scores(scorer, query)
    if not params.room_influence:
        return raw
    room = np.array([rooms.get(r, params.default_room) for r in table.room_ids],
                    dtype=np.float64)
    return room_influence(room[table.room_of], raw, params.room_weight)


def object_utilities(graph: SceneGraph, query: str, scorer: RelationScorer,
                     params: UtilityParams, rooms: dict[str, float]) -> dict[str, float]:
    """Eqs. 3-4 for every object node of the graph."""
    if not graph.objects:
        return {}
    table = object_table(graph)
    u = object_utility_array(table, query, scorer, params, rooms)
    return dict(zip(table.ids, u.tolist(), strict=True))


def column_utilities(
    graph: SceneGraph,
    ids: Sequence[str],
    kinds: Sequence[str],
    positions: Sequence[tuple[float, float]],
    query: str,
    scorer: RelationScorer,
    params: UtilityParams,
    cache: EpisodeCache | None = None,
) -> list[float]:
    """u_q(n) for each candidate, in order (module doc for each node type), the candidates
    given as columns (their ids, kinds and positions:
    :class:`~sgtool.planning.candidates.CandidateColumns`). ``cache``: an
    :class:`EpisodeCache` kept for the decisions of one episode."""
    if cache is None:
        rooms = room_utilities(graph, query, scorer, params)
        table = object_table(graph)
        u = object_utility_array(table, query, scorer, params, rooms) if graph.objects \
            else np.zeros(0)
        by_id = dict(zip(table.ids, u.tolist(), strict=True))
    else:
        rooms, table = cache.rooms(graph, query, scorer, params), cache.table(graph)
        u, by_id = cache.object_utilities(table, query, scorer, params, rooms)
    out: list = list(map(by_id.get, ids))  # objects' (the others are set below)
    frontiers: list[int] = []
    for k in compress(range(len(kinds)), map(ne, kinds, repeat("object"))):
        kind = kinds[k]
        if kind == "room":
            out[k] = rooms.get(ids[k], params.default_room)
        elif kind == "door":
            out[k] = params.default_room
        else:  # frontier: filled below
            frontiers.append(k)
    if frontiers:
        regions = _regions_by_id(graph.regions)
        where = [positions[k] for k in frontiers]
        nearby = _nearby_best(table, u, where, params.frontier_radius) if cache is None \
            else cache.nearby_best(table, u, where, params.frontier_radius)
        for k, best in zip(frontiers, nearby, strict=True):
            region = regions.get(ids[k])
            room_id = getattr(region, "room", None)
            if getattr(region, "frontier_type", None) == "leading out" or room_id is None:
                fallback = params.default_frontier
            else:
                fallback = rooms.get(room_id, params.default_room)
            out[k] = frontier_utility(best, fallback)
    if any(map(math.isnan, out)):
        return [0.0 if math.isnan(v) else v for v in out]
    return out


_REGIONS: list[tuple[tuple, dict]] = []  # the last regions tuple's nodes by id


def _regions_by_id(regions: tuple) -> dict:
    """``{r.id: r}`` of a regions tuple, kept for the last one (an incremental graph passes
    the same tuple until its regions change)."""
    if _REGIONS and _REGIONS[0][0] is regions:
        return _REGIONS[0][1]
    out = {r.id: r for r in regions}
    _REGIONS[:] = [(regions, out)]
    return out


def _nearby_best(table: ObjectTable, u: np.ndarray, positions: list[tuple[float, float]],
                 radius: float) -> list[list[float]]:
    """Per position, the utilities of the objects within ``radius`` (their maximum only,
    when no utility is NaN: all :func:`frontier_utility` needs)."""
    if not len(u):
        return [[] for _ in positions]
    inside = table.within(positions, radius)
    if math.isnan(np.add.reduce(u)):  # a NaN (or +inf and -inf: the same answer)
        values = u.tolist()
        return [[values[k] for k in np.flatnonzero(row).tolist()] for row in inside]
    best = np.maximum.reduce(np.where(inside, u[None, :], -np.inf), axis=1).tolist()
    return [[b] if b != -math.inf else [] for b in best]
