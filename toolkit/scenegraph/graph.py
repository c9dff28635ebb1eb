
"""The hierarchical scene graph: the one structure every planner sees.

Five layers, as in SCOUT (section III): root -> rooms -> regions/frontiers -> objects ->
nested objects. Every node has exactly one parent in the layer above (objects nested in or
on another object have that object as parent). Rooms are joined by intra-layer edges (doors
or open passages). States and affordances are attributes.

The same type comes out of the replayer (from a log), the live closed loop, and the
symbolic benchmark (``sgtool.recorders.symbolic_environment``). Its canonical JSON form
(:meth:`SceneGraph.to_json`) is byte-stable: sorted keys, fixed float rounding, nodes in
id order, so two replays of one log give identical bytes.

Node ids are strings with a layer prefix: ``room:3``, ``region:3.1``, ``frontier:7``,
``obj:42`` (42 is the instance id of the log), ``door:5``.
"""

from __future__ import annotations

import functools
import json
import math
import numbers
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass, field, fields
from typing import Any, Literal, TypeVar, cast

from sgtool.canonical import canonical_float, canonical_floats
from sgtool.errors import ArgumentError
from sgtool.vocabulary import OpenState, Relation

_N = TypeVar("_N")

SCENE_GRAPH_VERSION = "1.0"

RegionKind = Literal["region", "frontier"]
FrontierType = Literal["unexplored area", "leading out"]



@dataclass(frozen=True)
class RoomNode:
    """A room. ``explored`` is False for rooms known only through a door (SCOUT: unexplored
    room nodes, all attributes hidden: category "unknown", no children)."""

    id: str
    category: str = "unknown"
    position: tuple[float, float] = (0.0, 0.0)
    explored: bool = True
    # category -> probability, best first; empty when unknown
    category_scores: tuple[tuple[str, float], ...] = ()
    neighbours: tuple[str, ...] = ()


@dataclass(frozen=True)
class RegionNode:
    """A region of a room: a visited place ("region") or a place whose contents are not yet
    revealed ("frontier"). Frontiers carry MoMa-LLM's type: "unexplored area" (inside the
    room) or "leading out" (towards unknown space outside it)."""

    id: str
    room: str
    position: tuple[float, float]
    kind: RegionKind = "region"
    frontier_type: FrontierType | None = None
    size: float = 0.0  # frontier length in metres (0 for regions)


@dataclass(frozen=True)
class ObjectNode:
    """An object, container, or nested object. ``parent`` is a region id for first-level
    objects, an object id for nested ones (with ``relation``). ``state`` is "open" or
    "closed" for openable things, None otherwise. ``explored`` is True once its contents
    have been revealed (opened or looked into)."""

    id: str
    category: str
    parent: str
    room: str
    position: tuple[float, float, float]
    instance: int = -1
    relation: Relation | None = None
    state: OpenState | None = None
    affordances: tuple[str, ...] = ()
    explored: bool = False


@dataclass(frozen=True)
class DoorNode:
    """A door between rooms. A closed door leading to an unexplored room is an entrance to
    unexplored space; ``rooms`` names the rooms it joins (one of them may be unexplored)."""

    id: str
    position: tuple[float, float]
    state: OpenState
    rooms: tuple[str, ...] = ()
    instance: int = -1


@dataclass(frozen=True)
class RobotState:
    """Where the robot is: ``position`` (x, y) in metres and ``yaw`` in radians in the
    world frame, and the ``room`` and ``region`` node ids it stands in (None when none)."""

    position: tuple[float, float]
    yaw: float = 0.0
    room: str | None = None
    region: str | None = None


class Distances(dict[str, float]):
    """A read-only dict: a scene graph's ``distances``. A planner is handed the graph that
    is logged and handed to the next planner, so changing it in place would change both;
    every method that would change it raises :class:`TypeError` (copy it with
    ``dict(graph.distances)``). Compares, pickles and serialises as a dict, and hashes (so
    a scene graph, frozen, can key a planner's cache)."""

    def _read_only(self, *args: Any, **kwargs: Any) -> Any:
        raise TypeError("SceneGraph.distances is read-only (the graph is logged and shared): "
                        "change a copy, dict(graph.distances)")

    __setitem__ = __delitem__ = __ior__ = _read_only
    clear = pop = popitem = setdefault = update = _read_only

    def __reduce__(self) -> tuple[type, tuple[dict[str, float]]]:
        return (type(self), (dict(self),))

    def __hash__(self) -> int:  # type: ignore[override]  # (read-only: its graph hashes)
        return hash(frozenset(self.items()))

    def copy(self) -> dict[str, float]:
        return dict(self)


@dataclass(frozen=True)
class SceneGraph:
    """One observation of the world at ``time_ns`` (log time; 0 in the symbolic benchmark).

    ``distances`` holds the travel distance in metres from the robot to every node it could
    act on (rooms, regions, frontiers, objects, doors), as computed by whoever built the
    graph (Voronoi graph paths in the replayer, geodesics on the occupancy grid in the
    symbolic benchmark). A node missing from it is unreachable. It is read-only
    (:class:`Distances`: a mapping given is copied into one).
    """

    robot: RobotState
    rooms: tuple[RoomNode, ...] = ()
    regions: tuple[RegionNode, ...] = ()
    objects: tuple[ObjectNode, ...] = ()
    doors: tuple[DoorNode, ...] = ()
    distances: dict[str, float] = field(default_factory=Distances)
    time_ns: int = 0
    version: str = SCENE_GRAPH_VERSION

    def __post_init__(self) -> None:
        if type(self.distances) is not Distances:
            object.__setattr__(self, "distances", Distances(self.distances))

    # ----- look-ups -------------------------------------------------------------------
    def node(self, node_id: str) -> RoomNode | RegionNode | ObjectNode | DoorNode | None:
        """The room, region, object or door of id ``node_id``; None when there is none."""
        for group in (self.rooms, self.regions, self.objects, self.doors):
            for n in group:
                if n.id == node_id:
                    return n
        return None

    def node_ids(self) -> set[str]:
        """The ids of every room, region, object and door."""
        return {n.id for g in (self.rooms, self.regions, self.objects, self.doors) for n in g}

    def room(self, room_id: str) -> RoomNode | None:
        """The room of id ``room_id`` (``room:0``); None when there is none."""
        return next((r for r in self.rooms if r.id == room_id), None)

    def objects_in(self, room_id: str) -> tuple[ObjectNode, ...]:
        """The objects assigned to room ``room_id`` (their ``room``), furniture and small
        objects alike, in graph order."""
        return tuple(o for o in self.objects if o.room == room_id)

    def children(self, node_id: str) -> tuple[ObjectNode, ...]:
        """The objects whose ``parent`` is the object ``node_id`` (what lies on or in a
        piece of furniture); a room's objects are :meth:`objects_in`."""
        return tuple(o for o in self.objects if o.parent == node_id)

    def frontiers(self) -> tuple[RegionNode, ...]:
        """The regions of kind ``frontier``: where known free floor meets unexplored
        space."""
        return tuple(r for r in self.regions if r.kind == "frontier")

    def categories(self) -> set[str]:
        """The categories of the graph's objects."""
        return {o.category for o in self.objects}

    # ----- canonical form -------------------------------------------------------------
    def to_dict(self) -> dict[str, Any]:
        """The graph as a JSON object (floats rounded, lists sorted: :meth:`to_json`)."""

        def room(n: RoomNode) -> dict[str, Any]:
            d = _shallow(n)
            d["position"] = canonical_floats(n.position)
            d["category_scores"] = [[c, canonical_float(p)] for c, p in n.category_scores]
            d["neighbours"] = sorted(n.neighbours)
            return d

        def region(n: RegionNode) -> dict[str, Any]:
            d = _shallow(n)
            d["position"] = canonical_floats(n.position)
            d["size"] = canonical_float(n.size)
            return d

        def obj(n: ObjectNode) -> dict[str, Any]:
            d = _shallow(n)
            d["position"] = canonical_floats(n.position)
            d["affordances"] = sorted(n.affordances)
            return d

        def door(n: DoorNode) -> dict[str, Any]:
            d = _shallow(n)
            d["position"] = canonical_floats(n.position)
            d["rooms"] = sorted(n.rooms)
            return d

        return {
            "version": self.version,
            "time_ns": int(self.time_ns),
            "robot": {
                "position": canonical_floats(self.robot.position),
                "yaw": canonical_float(self.robot.yaw),
                "room": self.robot.room,
                "region": self.robot.region,
            },
            "rooms": [room(n) for n in sorted(self.rooms, key=_by_id)],
            "regions": [region(n) for n in sorted(self.regions, key=_by_id)],
            "objects": [obj(n) for n in sorted(self.objects, key=_by_id)],
            "doors": [door(n) for n in sorted(self.doors, key=_by_id)],
            "distances": {k: canonical_float(v) for k, v in sorted(self.distances.items())},
        }

    def canonical(self) -> SceneGraph:
        """This graph as its canonical JSON reads back (floats rounded as
        :meth:`to_json` writes them): the graph a reader of the log gets."""
        return SceneGraph.from_json(self.to_json())

    def to_json(self) -> str:
        """Canonical JSON: byte-identical for equal graphs."""
        return json.dumps(self.to_dict(), sort_keys=True, separators=(",", ":"))

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> SceneGraph:
        """The graph of a :meth:`to_dict` object; anything else is one
        :class:`~sgtool.errors.ArgumentError` line (a ``ValueError``) naming what is wrong."""
        if not isinstance(d, Mapping):
            raise ArgumentError(f"scene graph: a JSON object, got {type(d).__name__}")
        try:
            return cls._from_dict(d)
        except KeyError as e:
            raise ArgumentError(f"scene graph: field {e.args[0]!r} missing") from None
        except (TypeError, AttributeError, ValueError) as e:
            if isinstance(e, ArgumentError):
                raise
            raise ArgumentError(f"scene graph: {e}") from None

    @classmethod
    def _from_dict(cls, d: dict[str, Any]) -> SceneGraph:
        major = str(d.get("version", "0")).split(".")[0]
        if major != SCENE_GRAPH_VERSION.split(".")[0]:
            raise ArgumentError(
                f"scene graph version {d.get('version')} is not readable by this sgtool "
                f"(reads {SCENE_GRAPH_VERSION.split('.')[0]}.x)"
            )
        rb = d["robot"]
        return cls(
            robot=RobotState(
                position=_xy(rb["position"], "robot.position"),
                yaw=_number(rb.get("yaw", 0.0), "robot.yaw"),
                room=rb.get("room"), region=rb.get("region"),
            ),
            rooms=_nodes(d, "rooms", lambda r: RoomNode(
                id=r["id"], category=r["category"], position=_xy(r["position"]),
                explored=r["explored"],
                category_scores=tuple((c, p) for c, p in r.get("category_scores", [])),
                neighbours=tuple(r.get("neighbours", [])))),
            regions=_nodes(d, "regions", lambda r: RegionNode(
                id=r["id"], room=r["room"], position=_xy(r["position"]), kind=r["kind"],
                frontier_type=r.get("frontier_type"), size=r.get("size", 0.0))),
            objects=_nodes(d, "objects", lambda o: ObjectNode(
                id=o["id"], category=o["category"], parent=o["parent"], room=o["room"],
                position=_xyz(o["position"]), instance=o.get("instance", -1),
                relation=o.get("relation"), state=o.get("state"),
                affordances=tuple(o.get("affordances", [])),
                explored=o.get("explored", False))),
            doors=_nodes(d, "doors", lambda x: DoorNode(
                id=x["id"], position=_xy(x["position"]), state=x["state"],
                rooms=tuple(x.get("rooms", [])), instance=x.get("instance", -1))),
            distances=_distances(d.get("distances", {})),
            time_ns=int(d.get("time_ns", 0)),
            version=str(d.get("version", SCENE_GRAPH_VERSION)),
        )

    @classmethod
    def from_json(cls, text: str | bytes) -> SceneGraph:
        """The graph of :meth:`to_json`'s text; anything else is one
        :class:`~sgtool.errors.ArgumentError` line, as for :meth:`from_dict`."""
        try:
            d = json.loads(text)
        except ValueError as e:  # JSONDecodeError, UnicodeDecodeError
            raise ArgumentError(f"scene graph: not JSON ({e})") from None
        return cls.from_dict(d)


def _number(v: Any, what: str) -> float:
    """``v`` as read (a finite real number, not a bool; ints stay ints, so the canonical
    JSON of a graph read back is the same bytes); else the ValueError naming it that
    :meth:`SceneGraph.from_dict` turns into its one line."""
    if (type(v) is float or type(v) is int) and math.isfinite(v):  # the usual: fast
        return v
    if isinstance(v, bool) or not isinstance(v, numbers.Real) or not math.isfinite(v):
        raise ValueError(f"{what}: {v!r} is not a finite number")
    return cast(float, v)


def _numbers(v: Any, n: int, what: str) -> tuple[float, ...]:
    """``n`` finite numbers (a position), else a ValueError naming ``what``."""
    if hasattr(v, "tolist") and not isinstance(v, (list, tuple)):  # a numpy array
        v = v.tolist()
    if not isinstance(v, (list, tuple)) or len(v) != n:
        raise ValueError(f"{what} {v!r}: give {n} numbers")
    if _finite_sum(v):  # the usual, checked at once
        return tuple(v)
    return tuple(_number(x, what) for x in v)


def _distances(v: Any) -> dict[str, float]:
    """The ``distances`` map, each a finite number (:func:`_number`)."""
    out = dict(v)
    if _finite_sum(out.values()):  # the usual, checked at once
        return out
    return {k: _number(x, f"distances[{k!r}]") for k, x in out.items()}


def _finite_sum(values: Iterable[Any]) -> bool:
    """Whether ``values`` are numbers whose sum is finite (text raises, inf or nan is not):
    every one of them a finite number, but for an overflow (then each is checked)."""
    try:
        return math.isfinite(sum(values))
    except TypeError:
        return False


def _xy(v: Any, what: str = "position") -> tuple[float, float]:
    """An (x, y) position (:func:`_numbers`)."""
    return cast("tuple[float, float]", _numbers(v, 2, what))


def _xyz(v: Any) -> tuple[float, float, float]:
    """An (x, y, z) position."""
    return cast("tuple[float, float, float]", _numbers(v, 3, "position"))


def _nodes(d: Mapping[str, Any], key: str, build: Callable[[Any], _N]) -> tuple[_N, ...]:
    """``build`` of each item of ``d[key]``; a fault names the item (``objects[3]
    ('object:7'): field 'room' missing``), not only the field."""
    out = []
    for i, item in enumerate(d.get(key, [])):
        try:
            out.append(build(item))
        except (KeyError, TypeError, AttributeError, ValueError) as e:
            ident = item.get("id") if isinstance(item, Mapping) else None
            where = f"{key}[{i}]" + (f" ({ident!r})" if isinstance(ident, str) else "")
            why = f"field {e.args[0]!r} missing" if isinstance(e, KeyError) else str(e)
            raise ArgumentError(f"scene graph: {where}: {why}") from None
    return tuple(out)


_FIELD_NAMES: dict[type, tuple[str, ...]] = {}


def _field_names(cls: type) -> tuple[str, ...]:
    """The field names of a dataclass, computed once per class."""
    names = _FIELD_NAMES.get(cls)
    if names is None:
        names = _FIELD_NAMES[cls] = tuple(f.name for f in fields(cls))
    return names


def _by_id(node: RoomNode | RegionNode | ObjectNode | DoorNode) -> NaturalKey:
    return natural_key(node.id)


def _shallow(node: object) -> dict[str, Any]:
    """The fields of a node as a dict: ``dataclasses.asdict`` without its deep copy (node
    fields are immutable: strings, numbers, tuples)."""
    return {name: getattr(node, name) for name in _field_names(type(node))}


NaturalKey = tuple[str, tuple[tuple[int, int | str], ...]]


@functools.lru_cache(maxsize=65536)
def natural_key(node_id: str) -> NaturalKey:
    """The sort key of a node id in natural order: ``room:2`` before ``room:10``,
    ``region:3.1`` before ``region:3.12``. The layer prefix (text before the first ``:``)
    sorts as text, then each ``.``-separated part: decimal digits of any script
    (``str.isdecimal``) by value, before any other part, which sorts as text."""
    prefix, _, rest = node_id.partition(":")
    return prefix, tuple((0, int(p)) if p.isdecimal() else (1, p) for p in rest.split("."))
