"""The versioned JSON house spec: rooms, walls, doors, furniture, small objects, start poses.

One house is one :class:`HouseSpec`. It is what the PyBullet recorder builds, what the
symbolic benchmark turns into scene graphs and what the episode lister searches in, so it
is a frozen contract, validated on load with messages that name the offending field
(``rooms[2].polygon: needs at least 3 points``).

Conventions (all of them are checked by :func:`load_house`):

- metres, z up, yaw counter-clockwise from +x in radians;
- ids are strings with a kind prefix and a running number: ``room_0``, ``door_3``,
  ``pass_1`` (an open-plan passage: a gap in the wall without a door), ``wall_7``,
  ``furn_12`` (furniture and containers), ``obj_40`` (small objects);
- a room is a simple polygon (counter-clockwise or not) with a category ("kitchen");
  rooms of one open-plan space (kitchen + living room without a door between them) share
  ``open_plan_group``;
- a wall is a straight segment ``a``-``b`` with a thickness (centred on the segment) and a
  height; walls have gaps where doors and passages are;
- a door is an opening of ``width`` centred at ``center``, lying along direction ``yaw``
  (the direction of the wall it sits in), joining two rooms; ``state`` is "open" or
  "closed"; a closed door is a panel of the wall's thickness filling the opening;
- furniture (including containers) is an oriented box: ``center`` (x, y, z of the box
  centre; a floor-standing piece has z = sz / 2), ``size`` (sx, sy, sz along the box's own
  axes before rotation), ``yaw``; ``affordances`` is a sorted tuple from
  {"container", "openable", "supporter"}; ``state`` is "open"/"closed" for openable
  pieces and None otherwise;
- a small object has a ``parent`` furniture id and a ``relation`` "inside" (its box lies
  within the parent's box; the parent must be a container) or "ontop" (its box rests on
  the parent's top face: position z = parent top + sz / 2); ``position`` is its box centre
  and ``size`` its extent along the parent's axes (small objects share the parent's yaw);
- ``starts`` are robot start poses (x, y, yaw) on free floor, each in a named room.

The canonical text (:meth:`HouseSpec.to_json`) sorts keys, rounds floats to 4 decimals and
keeps list order (ids in creation order), so one spec always gives the same bytes.
"""

from __future__ import annotations

import json
import math
import os
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from sgtool.canonical import canonical_float, canonical_floats
from sgtool.errors import SpecError
from sgtool.files import atomic_write

SPEC_VERSION = "1.0"
AFFORDANCES = ("container", "openable", "supporter")
RELATIONS = ("inside", "ontop")
STATES = ("open", "closed")
_EPS = 1e-3  # tolerance (m) of the containment checks, above the 4-decimal rounding

Point = tuple[float, float]
Vec3 = tuple[float, float, float]


# ----------------------------------------------------------------------------------------
# records
# ----------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Room:
    id: str
    category: str
    polygon: tuple[Point, ...]
    open_plan_group: str | None = None

    @property
    def area(self) -> float:
        return abs(_signed_area(self.polygon))

    @property
    def bounds(self) -> tuple[float, float, float, float]:
        """(xmin, ymin, xmax, ymax)."""
        xs = [p[0] for p in self.polygon]
        ys = [p[1] for p in self.polygon]
        return (min(xs), min(ys), max(xs), max(ys))

    @property
    def centroid(self) -> Point:
        return _centroid(self.polygon)

    def contains(self, x: float, y: float) -> bool:
        return point_in_polygon(x, y, self.polygon)


@dataclass(frozen=True)
class Wall:
    id: str
    a: Point
    b: Point
    thickness: float = 0.1
    height: float = 2.5

    @property
    def length(self) -> float:
        return math.dist(self.a, self.b)

    @property
    def yaw(self) -> float:
        return math.atan2(self.b[1] - self.a[1], self.b[0] - self.a[0])


@dataclass(frozen=True)
class Door:
    """A door in a wall. ``yaw`` is the wall's direction, so the opening spans
    ``center +- width / 2 * (cos yaw, sin yaw)``."""

    id: str
    center: Point
    width: float
    yaw: float
    state: str
    rooms: tuple[str, str]
    height: float = 2.1
    thickness: float = 0.1

    @property
    def segment(self) -> tuple[Point, Point]:
        return _segment(self.center, self.width, self.yaw)

    @property
    def is_open(self) -> bool:
        return self.state == "open"


@dataclass(frozen=True)
class Passage:
    """A doorless opening between two rooms of one open-plan space (same geometry
    convention as :class:`Door`)."""

    id: str
    center: Point
    width: float
    yaw: float
    rooms: tuple[str, str]

    @property
    def segment(self) -> tuple[Point, Point]:
        return _segment(self.center, self.width, self.yaw)


@dataclass(frozen=True)
class Furniture:
    id: str
    category: str
    synset: str
    room: str
    center: Vec3
    size: Vec3
    yaw: float = 0.0
    affordances: tuple[str, ...] = ()
    state: str | None = None

    @property
    def is_container(self) -> bool:
        return "container" in self.affordances

    @property
    def is_openable(self) -> bool:
        return "openable" in self.affordances

    @property
    def top(self) -> float:
        return self.center[2] + self.size[2] / 2.0

    @property
    def bottom(self) -> float:
        return self.center[2] - self.size[2] / 2.0

    def footprint(self) -> tuple[Point, Point, Point, Point]:
        """The four corners of the box seen from above, counter-clockwise."""
        return _box_corners(self.center[:2], self.size[:2], self.yaw)

    def to_local(self, x: float, y: float) -> Point:
        """World (x, y) in the box frame (origin at the centre, axes along the box)."""
        c, s = math.cos(self.yaw), math.sin(self.yaw)
        dx, dy = x - self.center[0], y - self.center[1]
        return (c * dx + s * dy, -s * dx + c * dy)


@dataclass(frozen=True)
class SmallObject:
    id: str
    category: str
    synset: str
    parent: str
    relation: str
    room: str
    position: Vec3
    size: Vec3


@dataclass(frozen=True)
class StartPose:
    x: float
    y: float
    yaw: float
    room: str


@dataclass(frozen=True)
class HouseSpec:
    seed: int
    rooms: tuple[Room, ...]
    walls: tuple[Wall, ...]
    doors: tuple[Door, ...]
    furniture: tuple[Furniture, ...]
    objects: tuple[SmallObject, ...]
    starts: tuple[StartPose, ...]
    passages: tuple[Passage, ...] = ()
    split: str = "eval"
    version: str = SPEC_VERSION

    # ----- look-ups -------------------------------------------------------------------
    def room(self, room_id: str) -> Room:
        for r in self.rooms:
            if r.id == room_id:
                return r
        raise KeyError(room_id)

    def furniture_by_id(self) -> dict[str, Furniture]:
        return {f.id: f for f in self.furniture}

    def object_by_id(self) -> dict[str, SmallObject]:
        return {o.id: o for o in self.objects}

    def containers(self) -> tuple[Furniture, ...]:
        return tuple(f for f in self.furniture if f.is_container)

    def bounds(self) -> tuple[float, float, float, float]:
        """(xmin, ymin, xmax, ymax) over all room polygons."""
        bs = [r.bounds for r in self.rooms]
        return (min(b[0] for b in bs), min(b[1] for b in bs),
                max(b[2] for b in bs), max(b[3] for b in bs))

    def room_graph(self) -> dict[str, tuple[str, ...]]:
        """Room id -> sorted neighbour ids, joined by doors (open or closed) or passages."""
        nb: dict[str, set[str]] = {r.id: set() for r in self.rooms}
        for d in (*self.doors, *self.passages):
            a, b = d.rooms
            nb[a].add(b)
            nb[b].add(a)
        return {k: tuple(sorted(v)) for k, v in sorted(nb.items())}

    # ----- canonical form -------------------------------------------------------------
    def to_dict(self) -> dict[str, Any]:
        return {
            "version": self.version,
            "seed": int(self.seed),
            "split": self.split,
            "rooms": [
                {"id": r.id, "category": r.category,
                 "polygon": [canonical_floats(p) for p in r.polygon],
                 "open_plan_group": r.open_plan_group}
                for r in self.rooms
            ],
            "walls": [
                {"id": w.id, "a": canonical_floats(w.a), "b": canonical_floats(w.b),
                 "thickness": canonical_float(w.thickness),
                 "height": canonical_float(w.height)}
                for w in self.walls
            ],
            "doors": [
                {"id": d.id, "center": canonical_floats(d.center),
                 "width": canonical_float(d.width), "yaw": canonical_float(d.yaw),
                 "state": d.state, "rooms": list(d.rooms), "height": canonical_float(d.height),
                 "thickness": canonical_float(d.thickness)}
                for d in self.doors
            ],
            "passages": [
                {"id": p.id, "center": canonical_floats(p.center),
                 "width": canonical_float(p.width), "yaw": canonical_float(p.yaw),
                 "rooms": list(p.rooms)}
                for p in self.passages
            ],
            "furniture": [
                {"id": f.id, "category": f.category, "synset": f.synset, "room": f.room,
                 "center": canonical_floats(f.center), "size": canonical_floats(f.size),
                 "yaw": canonical_float(f.yaw),
                 "affordances": list(f.affordances), "state": f.state}
                for f in self.furniture
            ],
            "objects": [
                {"id": o.id, "category": o.category, "synset": o.synset, "parent": o.parent,
                 "relation": o.relation, "room": o.room, "position": canonical_floats(o.position),
                 "size": canonical_floats(o.size)}
                for o in self.objects
            ],
            "starts": [
                {"x": canonical_float(s.x), "y": canonical_float(s.y),
                 "yaw": canonical_float(s.yaw), "room": s.room}
                for s in self.starts
            ],
        }

    def to_json(self) -> str:
        """Canonical JSON text (sorted keys, 4-decimal floats, one trailing newline)."""
        return json.dumps(self.to_dict(), sort_keys=True, indent=1) + "\n"


# ----------------------------------------------------------------------------------------
# I/O
# ----------------------------------------------------------------------------------------
def save_house(spec: HouseSpec, path: str | os.PathLike[str]) -> Path:
    """Write the canonical JSON atomically (temp file beside ``path``, then rename)."""
    return atomic_write(path, spec.to_json())


def load_house(source: str | os.PathLike[str] | Mapping[str, Any]) -> HouseSpec:
    """Read and validate a house spec from a path, a JSON string or an already parsed dict.

    Raises :class:`sgtool.errors.SpecError` whose message starts with the offending field
    (``furniture[3].size: every side must be > 0``).
    """
    if isinstance(source, Mapping):
        data: Any = source
        where = "house spec"
    else:
        text_or_path = os.fspath(source)
        if isinstance(source, str) and text_or_path.lstrip().startswith("{"):
            raw, where = text_or_path, "house spec"
        else:
            p = Path(text_or_path)
            where = str(p)
            try:
                raw = p.read_text(encoding="utf-8")
            except FileNotFoundError:
                raise SpecError(f"{p}: no such house spec file") from None
            except (OSError, UnicodeDecodeError) as e:
                raise SpecError(f"{p}: cannot read house spec: {e}") from None
        try:
            data = json.loads(raw)
        except json.JSONDecodeError as e:
            raise SpecError(f"{where}: not valid JSON ({e.msg} at line {e.lineno})") from None
    try:
        return _parse(data)
    except SpecError as e:
        if where != "house spec":
            raise SpecError(f"{where}: {e}") from None
        raise


def room_at(spec: HouseSpec, x: float, y: float) -> str | None:
    """Id of the room whose polygon holds (x, y) (first in id order on a shared border),
    None outside every room."""
    for r in spec.rooms:
        if r.contains(x, y):
            return r.id
    return None


# ----------------------------------------------------------------------------------------
# validation
# ----------------------------------------------------------------------------------------
def _parse(d: Any) -> HouseSpec:
    if not isinstance(d, Mapping):
        raise SpecError("top level: expected a JSON object")
    version = d.get("version")
    if version is None:
        raise SpecError("version: missing")
    if not isinstance(version, str) or version.split(".")[0] != SPEC_VERSION.split(".")[0]:
        raise SpecError(f"version: {version!r} is not supported (this sgtool reads "
                        f"{SPEC_VERSION.split('.')[0]}.x)")
    seed = d.get("seed", 0)
    if isinstance(seed, bool) or not isinstance(seed, int):
        raise SpecError("seed: expected an integer")
    split = d.get("split", "eval")
    if split not in ("eval", "train"):
        raise SpecError(f"split: expected 'eval' or 'train', got {split!r}")

    rooms = tuple(_room(f"rooms[{i}]", r) for i, r in enumerate(_list(d, "rooms", min_len=1)))
    room_ids = _unique_ids("rooms", rooms, "room_")
    walls = tuple(_wall(f"walls[{i}]", w) for i, w in enumerate(_list(d, "walls")))
    _unique_ids("walls", walls, "wall_")
    doors = tuple(_door(f"doors[{i}]", x, room_ids) for i, x in enumerate(_list(d, "doors")))
    _unique_ids("doors", doors, "door_")
    passages = tuple(_passage(f"passages[{i}]", x, room_ids)
                     for i, x in enumerate(_list(d, "passages", required=False)))
    _unique_ids("passages", passages, "pass_")
    furniture = tuple(_furniture(f"furniture[{i}]", x, room_ids)
                      for i, x in enumerate(_list(d, "furniture")))
    furn = {f.id: f for f in furniture}
    _unique_ids("furniture", furniture, "furn_")
    by_room = {r.id: r for r in rooms}
    for i, f in enumerate(furniture):
        if not by_room[f.room].contains(f.center[0], f.center[1]):
            raise SpecError(f"furniture[{i}].center: ({f.center[0]}, {f.center[1]}) is outside "
                            f"its room {f.room}")
    objects = tuple(_object(f"objects[{i}]", x, furn, room_ids)
                    for i, x in enumerate(_list(d, "objects")))
    _unique_ids("objects", objects, "obj_")
    starts = tuple(_start(f"starts[{i}]", x, room_ids) for i, x in enumerate(_list(d, "starts")))
    for i, s in enumerate(starts):
        if not by_room[s.room].contains(s.x, s.y):
            raise SpecError(f"starts[{i}]: ({s.x}, {s.y}) is outside its room {s.room}")
    return HouseSpec(seed=seed, rooms=rooms, walls=walls, doors=doors, furniture=furniture,
                     objects=objects, starts=starts, passages=passages, split=split,
                     version=version)


def _list(d: Mapping[str, Any], key: str, min_len: int = 0, required: bool = True) -> list[Any]:
    if key not in d:
        if required:
            raise SpecError(f"{key}: missing")
        return []
    v = d[key]
    if not isinstance(v, list):
        raise SpecError(f"{key}: expected a list")
    if len(v) < min_len:
        raise SpecError(f"{key}: needs at least {min_len} entr{'y' if min_len == 1 else 'ies'}")
    return v


def _obj(where: str, x: Any) -> Mapping[str, Any]:
    if not isinstance(x, Mapping):
        raise SpecError(f"{where}: expected a JSON object")
    return x


def _field(where: str, x: Mapping[str, Any], key: str) -> Any:
    if key not in x:
        raise SpecError(f"{where}.{key}: missing")
    return x[key]


def _str(where: str, x: Mapping[str, Any], key: str) -> str:
    v = _field(where, x, key)
    if not isinstance(v, str) or not v:
        raise SpecError(f"{where}.{key}: expected a non-empty string")
    return v


def _num(where: str, v: Any) -> float:
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
        raise SpecError(f"{where}: expected a finite number, got {v!r}")
    return canonical_float(v)  # canonical precision, so load(to_json(spec)) == spec


def _vec(where: str, v: Any, n: int) -> tuple[float, ...]:
    if not isinstance(v, (list, tuple)) or len(v) != n:
        raise SpecError(f"{where}: expected {n} numbers")
    return tuple(_num(f"{where}[{i}]", c) for i, c in enumerate(v))


def _positive(where: str, v: float) -> float:
    if v <= 0:
        raise SpecError(f"{where}: must be > 0, got {v}")
    return v


def _state(where: str, v: Any, allow_none: bool) -> str | None:
    if v is None and allow_none:
        return None
    if v not in STATES:
        raise SpecError(f"{where}: expected 'open' or 'closed', got {v!r}")
    return v


def _rooms_pair(where: str, v: Any, room_ids: set[str]) -> tuple[str, str]:
    if not isinstance(v, list) or len(v) != 2 or not all(isinstance(r, str) for r in v):
        raise SpecError(f"{where}: expected two room ids")
    for r in v:
        if r not in room_ids:
            raise SpecError(f"{where}: unknown room {r!r}")
    if v[0] == v[1]:
        raise SpecError(f"{where}: joins room {v[0]!r} to itself")
    return (v[0], v[1])


def _room_ref(where: str, v: Any, room_ids: set[str]) -> str:
    if not isinstance(v, str) or v not in room_ids:
        raise SpecError(f"{where}: unknown room {v!r}")
    return v


def _room(where: str, x: Any) -> Room:
    x = _obj(where, x)
    poly_raw = _field(where, x, "polygon")
    if not isinstance(poly_raw, list):
        raise SpecError(f"{where}.polygon: expected a list of [x, y] points")
    if len(poly_raw) < 3:
        raise SpecError(f"{where}.polygon: needs at least 3 points, got {len(poly_raw)}")
    poly = tuple(_vec(f"{where}.polygon[{i}]", p, 2) for i, p in enumerate(poly_raw))
    if abs(_signed_area(poly)) < 1e-6:  # type: ignore[arg-type]
        raise SpecError(f"{where}.polygon: has zero area")
    group = x.get("open_plan_group")
    if group is not None and (not isinstance(group, str) or not group):
        raise SpecError(f"{where}.open_plan_group: expected a string or null")
    return Room(id=_str(where, x, "id"), category=_str(where, x, "category"),
                polygon=poly, open_plan_group=group)  # type: ignore[arg-type]


def _wall(where: str, x: Any) -> Wall:
    x = _obj(where, x)
    a = _vec(f"{where}.a", _field(where, x, "a"), 2)
    b = _vec(f"{where}.b", _field(where, x, "b"), 2)
    if math.dist(a, b) < 1e-6:
        raise SpecError(f"{where}: has zero length (a == b)")
    return Wall(id=_str(where, x, "id"), a=a, b=b,  # type: ignore[arg-type]
                thickness=_positive(f"{where}.thickness",
                                    _num(f"{where}.thickness", x.get("thickness", 0.1))),
                height=_positive(f"{where}.height", _num(f"{where}.height", x.get("height", 2.5))))


def _door(where: str, x: Any, room_ids: set[str]) -> Door:
    x = _obj(where, x)
    return Door(
        id=_str(where, x, "id"),
        center=_vec(f"{where}.center", _field(where, x, "center"), 2),  # type: ignore[arg-type]
        width=_positive(f"{where}.width", _num(f"{where}.width", _field(where, x, "width"))),
        yaw=_num(f"{where}.yaw", x.get("yaw", 0.0)),
        state=_state(f"{where}.state", _field(where, x, "state"), allow_none=False),  # type: ignore[arg-type]
        rooms=_rooms_pair(f"{where}.rooms", _field(where, x, "rooms"), room_ids),
        height=_positive(f"{where}.height", _num(f"{where}.height", x.get("height", 2.1))),
        thickness=_positive(f"{where}.thickness",
                            _num(f"{where}.thickness", x.get("thickness", 0.1))),
    )


def _passage(where: str, x: Any, room_ids: set[str]) -> Passage:
    x = _obj(where, x)
    return Passage(
        id=_str(where, x, "id"),
        center=_vec(f"{where}.center", _field(where, x, "center"), 2),  # type: ignore[arg-type]
        width=_positive(f"{where}.width", _num(f"{where}.width", _field(where, x, "width"))),
        yaw=_num(f"{where}.yaw", x.get("yaw", 0.0)),
        rooms=_rooms_pair(f"{where}.rooms", _field(where, x, "rooms"), room_ids),
    )


def _affordances(where: str, v: Any) -> tuple[str, ...]:
    if not isinstance(v, list) or not all(isinstance(a, str) for a in v):
        raise SpecError(f"{where}: expected a list of strings")
    for a in v:
        if a not in AFFORDANCES:
            raise SpecError(f"{where}: unknown affordance {a!r} (known: {', '.join(AFFORDANCES)})")
    return tuple(sorted(set(v)))


def _furniture(where: str, x: Any, room_ids: set[str]) -> Furniture:
    x = _obj(where, x)
    size = _vec(f"{where}.size", _field(where, x, "size"), 3)
    if min(size) <= 0:
        raise SpecError(f"{where}.size: every side must be > 0, got {list(size)}")
    aff = _affordances(f"{where}.affordances", x.get("affordances", []))
    openable = "openable" in aff
    state = _state(f"{where}.state", x.get("state"), allow_none=not openable)
    if state is not None and not openable:
        raise SpecError(f"{where}.state: {state!r} given but the piece is not openable")
    return Furniture(
        id=_str(where, x, "id"), category=_str(where, x, "category"),
        synset=_str(where, x, "synset"),
        room=_room_ref(f"{where}.room", _field(where, x, "room"), room_ids),
        center=_vec(f"{where}.center", _field(where, x, "center"), 3),  # type: ignore[arg-type]
        size=size,  # type: ignore[arg-type]
        yaw=_num(f"{where}.yaw", x.get("yaw", 0.0)),
        affordances=aff, state=state,
    )


def _object(where: str, x: Any, furn: Mapping[str, Furniture], room_ids: set[str]) -> SmallObject:
    x = _obj(where, x)
    parent_id = _str(where, x, "parent")
    parent = furn.get(parent_id)
    if parent is None:
        raise SpecError(f"{where}.parent: unknown furniture {parent_id!r}")
    rel = _field(where, x, "relation")
    if rel not in RELATIONS:
        raise SpecError(f"{where}.relation: expected 'inside' or 'ontop', got {rel!r}")
    if rel == "inside" and not parent.is_container:
        raise SpecError(f"{where}.parent: {parent_id} ({parent.category}) is not a container, "
                        "so nothing can be inside it")
    size = _vec(f"{where}.size", _field(where, x, "size"), 3)
    if min(size) <= 0:
        raise SpecError(f"{where}.size: every side must be > 0, got {list(size)}")
    pos = _vec(f"{where}.position", _field(where, x, "position"), 3)
    room = _room_ref(f"{where}.room", _field(where, x, "room"), room_ids)
    if room != parent.room:
        raise SpecError(f"{where}.room: {room!r} differs from its parent's room {parent.room!r}")
    obj = SmallObject(id=_str(where, x, "id"), category=_str(where, x, "category"),
                      synset=_str(where, x, "synset"), parent=parent_id, relation=rel,
                      room=room, position=pos, size=size)  # type: ignore[arg-type]
    problem = placement_problem(obj, parent)
    if problem:
        raise SpecError(f"{where}.position: {problem}")
    return obj


def _start(where: str, x: Any, room_ids: set[str]) -> StartPose:
    x = _obj(where, x)
    return StartPose(x=_num(f"{where}.x", _field(where, x, "x")),
                     y=_num(f"{where}.y", _field(where, x, "y")),
                     yaw=_num(f"{where}.yaw", x.get("yaw", 0.0)),
                     room=_room_ref(f"{where}.room", _field(where, x, "room"), room_ids))


def _unique_ids(key: str, items: Iterable[Any], prefix: str) -> set[str]:
    seen: set[str] = set()
    for i, it in enumerate(items):
        if not it.id.startswith(prefix):
            raise SpecError(f"{key}[{i}].id: {it.id!r} should start with {prefix!r}")
        if it.id in seen:
            raise SpecError(f"{key}[{i}].id: duplicate id {it.id!r}")
        seen.add(it.id)
    return seen


def placement_problem(obj: SmallObject, parent: Furniture) -> str | None:
    """Why ``obj`` is not where its relation says (None when it is): "inside" needs its
    box within the parent's box, "ontop" needs its bottom on the parent's top face and its
    centre over the top face."""
    lx, ly = parent.to_local(obj.position[0], obj.position[1])
    hx, hy = parent.size[0] / 2.0, parent.size[1] / 2.0
    # the object's own footprint may be rotated relative to the parent: bound by its radius
    r = math.hypot(obj.size[0], obj.size[1]) / 2.0
    z0 = obj.position[2] - obj.size[2] / 2.0
    z1 = obj.position[2] + obj.size[2] / 2.0
    if obj.relation == "inside":
        if abs(lx) + min(r, obj.size[0] / 2.0) > hx + _EPS or \
           abs(ly) + min(r, obj.size[1] / 2.0) > hy + _EPS:
            return f"{obj.id} sticks out of {parent.id} sideways"
        if z0 < parent.bottom - _EPS or z1 > parent.top + _EPS:
            return f"{obj.id} sticks out of {parent.id} vertically"
        return None
    if abs(lx) > hx + _EPS or abs(ly) > hy + _EPS:
        return f"{obj.id} is not over the top face of {parent.id}"
    if abs(z0 - parent.top) > 0.01:
        return f"{obj.id} bottom z={z0:.3f} is not on {parent.id}'s top z={parent.top:.3f}"
    return None


# ----------------------------------------------------------------------------------------
# geometry helpers
# ----------------------------------------------------------------------------------------
def _signed_area(poly: Sequence[Point]) -> float:
    s = 0.0
    n = len(poly)
    for i in range(n):
        x0, y0 = poly[i]
        x1, y1 = poly[(i + 1) % n]
        s += x0 * y1 - x1 * y0
    return s / 2.0


def _centroid(poly: Sequence[Point]) -> Point:
    a = _signed_area(poly)
    if abs(a) < 1e-12:
        return (sum(p[0] for p in poly) / len(poly), sum(p[1] for p in poly) / len(poly))
    cx = cy = 0.0
    n = len(poly)
    for i in range(n):
        x0, y0 = poly[i]
        x1, y1 = poly[(i + 1) % n]
        k = x0 * y1 - x1 * y0
        cx += (x0 + x1) * k
        cy += (y0 + y1) * k
    return (cx / (6 * a), cy / (6 * a))


def point_in_polygon(x: float, y: float, poly: Sequence[Point]) -> bool:
    """Even-odd rule; points on an edge count as inside."""
    n = len(poly)
    inside = False
    for i in range(n):
        x0, y0 = poly[i]
        x1, y1 = poly[(i + 1) % n]
        # on the edge?
        cross = (x1 - x0) * (y - y0) - (y1 - y0) * (x - x0)
        if abs(cross) < 1e-9 and min(x0, x1) - 1e-9 <= x <= max(x0, x1) + 1e-9 \
                and min(y0, y1) - 1e-9 <= y <= max(y0, y1) + 1e-9:
            return True
        if (y0 > y) != (y1 > y):
            xi = x0 + (y - y0) * (x1 - x0) / (y1 - y0)
            if x < xi:
                inside = not inside
    return inside


def _segment(center: Sequence[float], width: float, yaw: float) -> tuple[Point, Point]:
    dx, dy = math.cos(yaw) * width / 2.0, math.sin(yaw) * width / 2.0
    return ((center[0] - dx, center[1] - dy), (center[0] + dx, center[1] + dy))


def _box_corners(center: Sequence[float], size: Sequence[float],
                 yaw: float) -> tuple[Point, Point, Point, Point]:
    c, s = math.cos(yaw), math.sin(yaw)
    hx, hy = size[0] / 2.0, size[1] / 2.0
    out = []
    for lx, ly in ((-hx, -hy), (hx, -hy), (hx, hy), (-hx, hy)):
        out.append((center[0] + c * lx - s * ly, center[1] + s * lx + c * ly))
    return tuple(out)  # type: ignore[return-value]
