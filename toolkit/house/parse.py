"""Validation of a parsed house-spec document into a :class:`~sgtool.house.spec.HouseSpec`.

Every rule of the conventions in :mod:`sgtool.house.spec` is checked here; a failure raises
:class:`sgtool.errors.SpecError` whose message starts with the offending field
(``furniture[3].size: every side must be > 0``). Numbers are rounded to the canonical
precision, so parsing the canonical text of a spec gives back the same spec.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping
from typing import Any

from sgtool.canonical import canonical_float
from sgtool.errors import SpecError
from sgtool.house.geometry import signed_area
from sgtool.house.spec import (
    AFFORDANCES,
    RELATIONS,
    SPEC_VERSION,
    STATES,
    Door,
    Furniture,
    HouseSpec,
    Passage,
    Room,
    SmallObject,
    StartPose,
    Wall,
    placement_problem,
)


def parse_house(d: Any) -> HouseSpec:
    """Validate a parsed JSON document (see the conventions of :mod:`sgtool.house.spec`)
    into a :class:`HouseSpec`; raises :class:`SpecError` naming the offending field."""
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

    rooms = tuple(_parse_room(f"rooms[{i}]", r)
                  for i, r in enumerate(_entries(d, "rooms", min_len=1)))
    room_ids = _unique_ids("rooms", rooms, "room_")
    walls = tuple(_parse_wall(f"walls[{i}]", w) for i, w in enumerate(_entries(d, "walls")))
    _unique_ids("walls", walls, "wall_")
    doors = tuple(_parse_door(f"doors[{i}]", x, room_ids)
                  for i, x in enumerate(_entries(d, "doors")))
    _unique_ids("doors", doors, "door_")
    passages = tuple(_parse_passage(f"passages[{i}]", x, room_ids)
                     for i, x in enumerate(_entries(d, "passages", required=False)))
    _unique_ids("passages", passages, "pass_")
    furniture = tuple(_parse_furniture(f"furniture[{i}]", x, room_ids)
                      for i, x in enumerate(_entries(d, "furniture")))
    furn = {f.id: f for f in furniture}
    _unique_ids("furniture", furniture, "furn_")
    by_room = {r.id: r for r in rooms}
    for i, f in enumerate(furniture):
        if not by_room[f.room].contains(f.center[0], f.center[1]):
            raise SpecError(f"furniture[{i}].center: ({f.center[0]}, {f.center[1]}) is outside "
                            f"its room {f.room}")
    objects = tuple(_parse_object(f"objects[{i}]", x, furn, room_ids)
                    for i, x in enumerate(_entries(d, "objects")))
    _unique_ids("objects", objects, "obj_")
    starts = tuple(_parse_start(f"starts[{i}]", x, room_ids)
                   for i, x in enumerate(_entries(d, "starts")))
    for i, s in enumerate(starts):
        if not by_room[s.room].contains(s.x, s.y):
            raise SpecError(f"starts[{i}]: ({s.x}, {s.y}) is outside its room {s.room}")
    return HouseSpec(seed=seed, rooms=rooms, walls=walls, doors=doors, furniture=furniture,
                     objects=objects, starts=starts, passages=passages, split=split,
                     version=version)


def _entries(d: Mapping[str, Any], key: str, min_len: int = 0,
             required: bool = True) -> list[Any]:
    """The list under ``key`` (an empty list when absent and not ``required``)."""
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


def _json_object(where: str, x: Any) -> Mapping[str, Any]:
    if not isinstance(x, Mapping):
        raise SpecError(f"{where}: expected a JSON object")
    return x


def _required(where: str, x: Mapping[str, Any], key: str) -> Any:
    if key not in x:
        raise SpecError(f"{where}.{key}: missing")
    return x[key]


def _string(where: str, x: Mapping[str, Any], key: str) -> str:
    v = _required(where, x, key)
    if not isinstance(v, str) or not v:
        raise SpecError(f"{where}.{key}: expected a non-empty string")
    return v


def _number(where: str, v: Any) -> float:
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
        raise SpecError(f"{where}: expected a finite number, got {v!r}")
    return canonical_float(v)  # canonical precision, so load(to_json(spec)) == spec


def _numbers(where: str, v: Any, n: int) -> tuple[float, ...]:
    if not isinstance(v, (list, tuple)) or len(v) != n:
        raise SpecError(f"{where}: expected {n} numbers")
    return tuple(_number(f"{where}[{i}]", c) for i, c in enumerate(v))


def _positive(where: str, v: float) -> float:
    if v <= 0:
        raise SpecError(f"{where}: must be > 0, got {v}")
    return v


def _positive_field(where: str, x: Mapping[str, Any], key: str,
                    default: float | None = None) -> float:
    """The number > 0 under ``key`` (required when there is no ``default``)."""
    v = _required(where, x, key) if default is None else x.get(key, default)
    return _positive(f"{where}.{key}", _number(f"{where}.{key}", v))


def _open_or_closed(where: str, v: Any, allow_none: bool) -> str | None:
    if v is None and allow_none:
        return None
    if v not in STATES:
        raise SpecError(f"{where}: expected 'open' or 'closed', got {v!r}")
    return v


def _room_pair(where: str, v: Any, room_ids: set[str]) -> tuple[str, str]:
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


def _parse_room(where: str, x: Any) -> Room:
    x = _json_object(where, x)
    poly_raw = _required(where, x, "polygon")
    if not isinstance(poly_raw, list):
        raise SpecError(f"{where}.polygon: expected a list of [x, y] points")
    if len(poly_raw) < 3:
        raise SpecError(f"{where}.polygon: needs at least 3 points, got {len(poly_raw)}")
    poly = tuple(_numbers(f"{where}.polygon[{i}]", p, 2) for i, p in enumerate(poly_raw))
    if abs(signed_area(poly)) < 1e-6:  # type: ignore[arg-type]
        raise SpecError(f"{where}.polygon: has zero area")
    group = x.get("open_plan_group")
    if group is not None and (not isinstance(group, str) or not group):
        raise SpecError(f"{where}.open_plan_group: expected a string or null")
    return Room(id=_string(where, x, "id"), category=_string(where, x, "category"),
                polygon=poly, open_plan_group=group)  # type: ignore[arg-type]


def _parse_wall(where: str, x: Any) -> Wall:
    x = _json_object(where, x)
    a = _numbers(f"{where}.a", _required(where, x, "a"), 2)
    b = _numbers(f"{where}.b", _required(where, x, "b"), 2)
    if math.dist(a, b) < 1e-6:
        raise SpecError(f"{where}: has zero length (a == b)")
    return Wall(id=_string(where, x, "id"), a=a, b=b,  # type: ignore[arg-type]
                thickness=_positive_field(where, x, "thickness", 0.1),
                height=_positive_field(where, x, "height", 2.5))


def _opening_geometry(where: str, x: Mapping[str, Any]) -> dict[str, Any]:
    """``id``, ``center``, ``width`` and ``yaw`` of a door or a passage."""
    return {"id": _string(where, x, "id"),
            "center": _numbers(f"{where}.center", _required(where, x, "center"), 2),
            "width": _positive_field(where, x, "width"),
            "yaw": _number(f"{where}.yaw", x.get("yaw", 0.0))}


def _parse_door(where: str, x: Any, room_ids: set[str]) -> Door:
    x = _json_object(where, x)
    return Door(
        **_opening_geometry(where, x),
        state=_open_or_closed(f"{where}.state", _required(where, x, "state"), allow_none=False),  # type: ignore[arg-type]
        rooms=_room_pair(f"{where}.rooms", _required(where, x, "rooms"), room_ids),
        height=_positive_field(where, x, "height", 2.1),
        thickness=_positive_field(where, x, "thickness", 0.1),
    )


def _parse_passage(where: str, x: Any, room_ids: set[str]) -> Passage:
    x = _json_object(where, x)
    return Passage(**_opening_geometry(where, x),
                   rooms=_room_pair(f"{where}.rooms", _required(where, x, "rooms"), room_ids))


def _affordance_list(where: str, v: Any) -> tuple[str, ...]:
    if not isinstance(v, list) or not all(isinstance(a, str) for a in v):
        raise SpecError(f"{where}: expected a list of strings")
    for a in v:
        if a not in AFFORDANCES:
            raise SpecError(f"{where}: unknown affordance {a!r} (known: {', '.join(AFFORDANCES)})")
    return tuple(sorted(set(v)))


def _parse_furniture(where: str, x: Any, room_ids: set[str]) -> Furniture:
    x = _json_object(where, x)
    size = _numbers(f"{where}.size", _required(where, x, "size"), 3)
    if min(size) <= 0:
        raise SpecError(f"{where}.size: every side must be > 0, got {list(size)}")
    aff = _affordance_list(f"{where}.affordances", x.get("affordances", []))
    openable = "openable" in aff
    state = _open_or_closed(f"{where}.state", x.get("state"), allow_none=not openable)
    if state is not None and not openable:
        raise SpecError(f"{where}.state: {state!r} given but the piece is not openable")
    return Furniture(
        id=_string(where, x, "id"), category=_string(where, x, "category"),
        synset=_string(where, x, "synset"),
        room=_room_ref(f"{where}.room", _required(where, x, "room"), room_ids),
        center=_numbers(f"{where}.center", _required(where, x, "center"), 3),  # type: ignore[arg-type]
        size=size,  # type: ignore[arg-type]
        yaw=_number(f"{where}.yaw", x.get("yaw", 0.0)),
        affordances=aff, state=state,
    )


def _parse_object(where: str, x: Any, furn: Mapping[str, Furniture],
                  room_ids: set[str]) -> SmallObject:
    x = _json_object(where, x)
    parent_id = _string(where, x, "parent")
    parent = furn.get(parent_id)
    if parent is None:
        raise SpecError(f"{where}.parent: unknown furniture {parent_id!r}")
    rel = _required(where, x, "relation")
    if rel not in RELATIONS:
        raise SpecError(f"{where}.relation: expected 'inside' or 'ontop', got {rel!r}")
    if rel == "inside" and not parent.is_container:
        raise SpecError(f"{where}.parent: {parent_id} ({parent.category}) is not a container, "
                        "so nothing can be inside it")
    size = _numbers(f"{where}.size", _required(where, x, "size"), 3)
    if min(size) <= 0:
        raise SpecError(f"{where}.size: every side must be > 0, got {list(size)}")
    pos = _numbers(f"{where}.position", _required(where, x, "position"), 3)
    room = _room_ref(f"{where}.room", _required(where, x, "room"), room_ids)
    if room != parent.room:
        raise SpecError(f"{where}.room: {room!r} differs from its parent's room {parent.room!r}")
    obj = SmallObject(id=_string(where, x, "id"), category=_string(where, x, "category"),
                      synset=_string(where, x, "synset"), parent=parent_id, relation=rel,
                      room=room, position=pos, size=size)  # type: ignore[arg-type]
    problem = placement_problem(obj, parent)
    if problem:
        raise SpecError(f"{where}.position: {problem}")
    return obj


def _parse_start(where: str, x: Any, room_ids: set[str]) -> StartPose:
    x = _json_object(where, x)
    return StartPose(x=_number(f"{where}.x", _required(where, x, "x")),
                     y=_number(f"{where}.y", _required(where, x, "y")),
                     yaw=_number(f"{where}.yaw", x.get("yaw", 0.0)),
                     room=_room_ref(f"{where}.room", _required(where, x, "room"), room_ids))


def _unique_ids(key: str, items: Iterable[Any], prefix: str) -> set[str]:
    seen: set[str] = set()
    for i, it in enumerate(items):
        if not it.id.startswith(prefix):
            raise SpecError(f"{key}[{i}].id: {it.id!r} should start with {prefix!r}")
        if it.id in seen:
            raise SpecError(f"{key}[{i}].id: duplicate id {it.id!r}")
        seen.add(it.id)
    return seen
