"""Validation of a parsed house-spec document into a :class:`~sgtool.house.spec.HouseSpec`.

Every rule of the conventions in :mod:`sgtool.house.spec` is checked here (the fields of
each entry, within :class:`~sgtool.house.spec.SpecLimits`), in
:mod:`sgtool.house.nesting` (parents, depth, placement of small objects) and in
:mod:`sgtool.house.consistency` (rooms, doors and furniture against each other); a
failure raises :class:`sgtool.errors.SpecError` whose message starts with the offending
field (``furniture[3].size: every side must be > 0``). Every JSON object may hold only
the keys its entry knows, each once (a typo is named with the nearest known key: a
misspelt optional key would otherwise fall back to its default silently); ids and names
follow :mod:`sgtool.house.names`. Every list is measured against its
limit before its entries are read and every number against ``limits.coordinate`` before
it is converted, so a hostile file is refused in time linear in its size. Numbers are
rounded to the canonical precision, so parsing the canonical text of a spec gives back the
same spec.
"""

from __future__ import annotations

import difflib
import math
import unicodedata
from collections.abc import Callable, Iterable, Mapping
from typing import Any

from sgtool.canonical import canonical_float
from sgtool.errors import SpecError
from sgtool.house.consistency import check_consistency
from sgtool.house.geometry import Point, Vec3, self_crossing, signed_area
from sgtool.house.migrate import upgrade
from sgtool.house.names import folder_id_problem, id_note, id_problem, name_problem
from sgtool.house.nesting import check_nesting, with_supporters
from sgtool.house.spec import (
    AFFORDANCES,
    LIMITS,
    RELATIONS,
    SPEC_VERSION,
    STATES,
    Door,
    Furniture,
    HouseSpec,
    Passage,
    Room,
    SmallObject,
    SpecLimits,
    StartPose,
    Wall,
)
from sgtool.semantics.text import category_text


def parse_house(d: Any, limits: SpecLimits = LIMITS) -> HouseSpec:
    """Validate a parsed JSON document (see the conventions of :mod:`sgtool.house.spec`)
    into a :class:`HouseSpec` of the current version (a version-1 document is migrated);
    raises :class:`SpecError` naming the offending field. Time is linear in the number
    of entries (rooms are compared pairwise, at most ``limits.rooms`` of them)."""
    doc, d = d, upgrade(d)
    _known_keys("top level", doc, _TOP_KEYS)  # the document as read (its repeated keys)
    own_id = _house_id(d["id"]) if "id" in d else None
    seed = d.get("seed", 0)
    if isinstance(seed, bool) or not isinstance(seed, int) or not 0 <= seed < 2 ** 63:
        raise SpecError("seed: expected an integer in [0, 2^63)")
    split = d.get("split", "eval")
    if split not in ("eval", "train"):
        raise SpecError(f"split: expected 'eval' or 'train', got {split!r}")
    p = _Parser(limits)
    rooms = p.section(d, "rooms", p.room, limits.rooms, "room_", min_len=1)
    p.room_ids = {r.id for r in rooms}
    walls = p.section(d, "walls", p.wall, limits.walls, "wall_")
    doors = p.section(d, "doors", p.door, limits.doors, "door_")
    passages = p.section(d, "passages", p.passage, limits.doors, "pass_", required=False)
    furniture = p.section(d, "furniture", p.furniture, limits.furniture, "furn_")
    objects = p.section(d, "objects", p.small_object, limits.objects, "obj_")
    starts = tuple(p.start(f"starts[{i}]", x)
                   for i, x in enumerate(p.entries(d, "starts", limits.starts,
                                                   required=False)))
    furniture, objects = with_supporters(furniture, objects)
    spec = HouseSpec(seed=seed, rooms=rooms, walls=walls, doors=doors, furniture=furniture,
                     objects=objects, starts=starts, passages=passages, split=split,
                     version=SPEC_VERSION, id=own_id)
    check_consistency(spec, limits)
    check_nesting(furniture, objects, limits.depth)
    return spec


_TOP_KEYS = frozenset({"version", "id", "seed", "split", "rooms", "walls", "doors", "passages",
                       "furniture", "objects", "starts"})
_ROOM_KEYS = frozenset({"id", "category", "polygon", "open_plan_group"})
_WALL_KEYS = frozenset({"id", "a", "b", "thickness", "height"})
_PASSAGE_KEYS = frozenset({"id", "center", "width", "yaw", "rooms"})
_DOOR_KEYS = _PASSAGE_KEYS | {"state", "height", "thickness"}
_FURNITURE_KEYS = frozenset({"id", "category", "synset", "room", "center", "size", "yaw",
                             "affordances", "state", "levels"})
_OBJECT_KEYS = frozenset({"id", "category", "synset", "parent", "relation", "room", "position",
                          "size", "affordances", "state"})
_START_KEYS = frozenset({"x", "y", "yaw", "room"})


class JsonObject(dict[str, Any]):
    """A JSON object read with :func:`json_object_pairs` that had a key more than once
    (the last value kept, as ``json`` does); the parser refuses it naming the field."""

    duplicates: tuple[str, ...] = ()


def json_object_pairs(pairs: list[tuple[str, Any]]) -> dict[str, Any]:
    """``object_pairs_hook`` for ``json.loads``: a plain dict, or a :class:`JsonObject`
    listing the keys given more than once."""
    d = dict(pairs)
    if len(d) == len(pairs):
        return d
    seen: set[str] = set()
    repeated = []
    for k, _ in pairs:
        if k in seen:
            repeated.append(k)
        seen.add(k)
    out = JsonObject(d)
    out.duplicates = tuple(repeated)
    return out


def _known_keys(where: str, x: Mapping[str, Any], known: frozenset[str]) -> None:
    """Refuse a key given twice or not in ``known`` (a typo would otherwise fall back to a
    default silently), suggesting the nearest known key."""
    dup = getattr(x, "duplicates", ())
    if dup:
        raise SpecError(f"{_field(where, dup[0])}: the key is given more than once")
    unknown = x.keys() - known
    if not unknown:
        return
    key = min(unknown, key=repr)
    near = difflib.get_close_matches(key, sorted(known), n=1) if len(key) <= 64 else []
    hint = f" (did you mean {near[0]!r}?)" if near else ""
    raise SpecError(f"{_field(where, key)}: unknown key{hint}; known keys: "
                    f"{', '.join(sorted(known))}")


def _field(where: str, key: Any) -> str:
    shown = key if isinstance(key, str) and len(key) <= 40 and key.isprintable() else _short(key)
    return shown if where == "top level" else f"{where}.{shown}"


def _house_id(v: Any) -> str:
    if not isinstance(v, str):
        raise SpecError(f"id: expected a string, got {_short(v)}")
    problem = folder_id_problem(v)
    if problem:
        raise SpecError(f"id: {_short(v)} {problem}")
    return v


# the lists whose entries are many and alike (hundreds of pieces of furniture in a house):
# a message about one of their entries names its id as well as its index
_NAMED_BY_ID = frozenset({"furniture"})


def _parse_entry(parse: Callable[[str, Any], Any], key: str, i: int, x: Any) -> Any:
    """``parse`` entry ``i`` of ``key``; for the lists of :data:`_NAMED_BY_ID`, its error
    names the entry's id as well (:func:`sgtool.house.names.id_note`)."""
    if key not in _NAMED_BY_ID:
        return parse(f"{key}[{i}]", x)
    try:
        return parse(f"{key}[{i}]", x)
    except SpecError as e:
        raw = x.get("id") if isinstance(x, Mapping) else None
        note = id_note(key, i, raw) if not str(e).startswith(f"{key}[{i}].id") else ""
        if not note:
            raise
        raise SpecError(f"{e}{note}") from None


class _Parser:
    """Field rules of each kind of entry, within ``limits``."""

    def __init__(self, limits: SpecLimits):
        self.limits = limits
        self.room_ids: set[str] = set()

    # ----- shapes and scalars ---------------------------------------------------------
    def section(self, d: Mapping[str, Any], key: str, parse: Callable[[str, Any], Any],
                limit: int, prefix: str, min_len: int = 0, required: bool = True
                ) -> tuple[Any, ...]:
        """The entries under ``key``, each parsed by ``parse(where, entry)``, with unique
        ids starting with ``prefix``."""
        items = tuple(_parse_entry(parse, key, i, x) for i, x in
                      enumerate(self.entries(d, key, limit, min_len, required)))
        _unique_ids(key, items, prefix)
        return items

    def entries(self, d: Mapping[str, Any], key: str, limit: int, min_len: int = 0,
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
            raise SpecError(f"{key}: needs at least {min_len} "
                            f"entr{'y' if min_len == 1 else 'ies'}")
        if len(v) > limit:
            raise SpecError(f"{key}: {len(v)} entries, more than the limit of {limit}")
        return v

    def string(self, where: str, x: Mapping[str, Any], key: str) -> str:
        return self.name(f"{where}.{key}", _required(where, x, key))

    def name(self, where: str, v: Any) -> str:
        if not isinstance(v, str) or not v:
            raise SpecError(f"{where}: expected a non-empty string")
        if len(v) > self.limits.name_length:
            raise SpecError(f"{where}: {len(v)} characters, more than the limit of "
                            f"{self.limits.name_length}")
        problem = name_problem(v)
        if problem:
            raise SpecError(f"{where}: {_short(v)} {problem}")
        return unicodedata.normalize("NFC", v)  # "café" typed or stored decomposed: one name

    def category(self, where: str, x: Mapping[str, Any]) -> str:
        """A category name: a name with at least one word in it once read as text
        (:func:`~sgtool.semantics.text.category_text`: "_" or "-" alone name nothing)."""
        v = self.string(where, x, "category")
        if not category_text(v) or not any(c.isalnum() for c in v):
            raise SpecError(f"{where}.category: {_short(v)} has no letters or digits to "
                            "name a category by")
        if any(unicodedata.category(c) == "Cf" for c in v):  # a zero-width space, ...
            raise SpecError(f"{where}.category: {_short(v)} holds an invisible character "
                            "(it would not match the category typed): remove it")
        return v

    def number(self, where: str, v: Any) -> float:
        if isinstance(v, bool) or not isinstance(v, (int, float)):
            raise SpecError(f"{where}: expected a finite number, got {_short(v)}")
        lim = self.limits.coordinate
        if isinstance(v, int) and abs(v) > lim:  # before float(): 10**400 overflows it
            raise SpecError(f"{where}: {_short(v)} is out of range (|x| <= {lim:g})")
        if not math.isfinite(v):
            raise SpecError(f"{where}: expected a finite number, got {v!r}")
        if abs(v) > lim:
            raise SpecError(f"{where}: {_short(v)} is out of range (|x| <= {lim:g})")
        return canonical_float(v)  # canonical precision, so load(to_json(spec)) == spec

    def numbers(self, where: str, v: Any, n: int) -> tuple[float, ...]:
        if not isinstance(v, (list, tuple)) or len(v) != n:
            raise SpecError(f"{where}: expected {n} numbers")
        lim = self.limits.coordinate
        if all(type(c) is float and -lim <= c <= lim for c in v):  # the common case, fast
            return tuple(canonical_float(c) for c in v)
        return tuple(self.number(f"{where}[{i}]", c) for i, c in enumerate(v))

    def point(self, where: str, v: Any) -> Point:
        """Two numbers (x, y) as :meth:`numbers` reads them."""
        x, y = self.numbers(where, v, 2)
        return x, y

    def vec3(self, where: str, v: Any) -> Vec3:
        """Three numbers (x, y, z) as :meth:`numbers` reads them."""
        x, y, z = self.numbers(where, v, 3)
        return x, y, z

    def positive(self, where: str, x: Mapping[str, Any], key: str, limit: float,
                 default: float | None = None) -> float:
        """The number in (0, limit] under ``key`` (required when there is no ``default``)."""
        v = _required(where, x, key) if default is None else x.get(key, default)
        v = self.number(f"{where}.{key}", v)
        if v <= 0:
            raise SpecError(f"{where}.{key}: must be > 0, got {v}")
        if v > limit:
            raise SpecError(f"{where}.{key}: {v} is more than the limit of {limit:g} m"
                            f"{_METRES}")
        return v

    def size(self, where: str, v: Any, limit: float) -> Vec3:
        size = self.vec3(where, v)
        if min(size) <= 0:
            raise SpecError(f"{where}: every side must be > 0, got {list(size)}")
        if max(size) > limit:
            raise SpecError(f"{where}: {list(size)} has a side over the limit of {limit:g} m"
                            f"{_METRES}")
        return size

    def room_ref(self, where: str, v: Any) -> str:
        if not isinstance(v, str) or v not in self.room_ids:
            raise SpecError(f"{where}: unknown room {_short(v)}")
        return v

    def room_pair(self, where: str, v: Any) -> tuple[str, str]:
        if not isinstance(v, list) or len(v) != 2 or not all(isinstance(r, str) for r in v):
            raise SpecError(f"{where}: expected two room ids")
        for r in v:
            self.room_ref(where, r)
        if v[0] == v[1]:
            raise SpecError(f"{where}: joins room {v[0]!r} to itself")
        return (v[0], v[1])

    def affordances(self, where: str, x: Mapping[str, Any]) -> tuple[tuple[str, ...], str | None]:
        """Affordances and state of a piece or a small object (a state only when openable)."""
        v = x.get("affordances", [])
        if not isinstance(v, list) or not all(isinstance(a, str) for a in v):
            raise SpecError(f"{where}.affordances: expected a list of strings")
        for a in v:
            if a not in AFFORDANCES:
                raise SpecError(f"{where}.affordances: unknown affordance {_short(a)} "
                                f"(known: {', '.join(AFFORDANCES)})")
        aff = tuple(sorted(set(v)))
        openable = "openable" in aff
        state = x.get("state")
        if not (state is None and not openable) and state not in STATES:
            raise SpecError(f"{where}.state: expected 'open' or 'closed', got {_short(state)}")
        if state is not None and not openable:
            raise SpecError(f"{where}.state: {state!r} given but the piece is not openable")
        return aff, state

    # ----- entries --------------------------------------------------------------------
    def room(self, where: str, x: Any) -> Room:
        x = _json_object(where, x, _ROOM_KEYS)
        poly_raw = _required(where, x, "polygon")
        if not isinstance(poly_raw, list):
            raise SpecError(f"{where}.polygon: expected a list of [x, y] points")
        if len(poly_raw) < 3:
            raise SpecError(f"{where}.polygon: needs at least 3 points, got {len(poly_raw)}")
        if len(poly_raw) > self.limits.polygon_points:
            raise SpecError(f"{where}.polygon: {len(poly_raw)} points, more than the limit "
                            f"of {self.limits.polygon_points}")
        poly = tuple(self.point(f"{where}.polygon[{i}]", q) for i, q in enumerate(poly_raw))
        crossing = self_crossing(poly)
        if abs(signed_area(poly)) < 1e-6 and (crossing is None or not crossing[2]):
            raise SpecError(f"{where}.polygon: has zero area")
        if crossing is not None:
            raise SpecError(f"{where}.polygon: edges cross (edges {crossing[0]} and "
                            f"{crossing[1]}); a room is a simple polygon")
        group = x.get("open_plan_group")
        if group is not None:
            self.name(f"{where}.open_plan_group", group)
        return Room(id=self.string(where, x, "id"), category=self.category(where, x),
                    polygon=poly, open_plan_group=group)

    def wall(self, where: str, x: Any) -> Wall:
        x = _json_object(where, x, _WALL_KEYS)
        a = self.point(f"{where}.a", _required(where, x, "a"))
        b = self.point(f"{where}.b", _required(where, x, "b"))
        if math.dist(a, b) < 1e-6:
            raise SpecError(f"{where}: has zero length (a == b)")
        lim = self.limits
        return Wall(id=self.string(where, x, "id"), a=a, b=b,
                    thickness=self.positive(where, x, "thickness", lim.wall_thickness, 0.1),
                    height=self.positive(where, x, "height", lim.wall_height, 2.5))

    def _opening(self, where: str, x: Mapping[str, Any], width: float) -> dict[str, Any]:
        """``id``, ``center``, ``width`` (up to ``width``), ``yaw`` and ``rooms`` of a door
        or a passage."""
        return {"id": self.string(where, x, "id"),
                "center": self.point(f"{where}.center", _required(where, x, "center")),
                "width": self.positive(where, x, "width", width),
                "yaw": self.number(f"{where}.yaw", x.get("yaw", 0.0)),
                "rooms": self.room_pair(f"{where}.rooms", _required(where, x, "rooms"))}

    def door(self, where: str, x: Any) -> Door:
        x = _json_object(where, x, _DOOR_KEYS)
        state = _required(where, x, "state")
        if state not in STATES:
            raise SpecError(f"{where}.state: expected 'open' or 'closed', got {_short(state)}")
        lim = self.limits
        return Door(**self._opening(where, x, lim.door_width), state=state,
                    height=self.positive(where, x, "height", lim.door_height, 2.1),
                    thickness=self.positive(where, x, "thickness", lim.wall_thickness, 0.1))

    def passage(self, where: str, x: Any) -> Passage:
        x = _json_object(where, x, _PASSAGE_KEYS)
        return Passage(**self._opening(where, x, self.limits.passage_width))

    def furniture(self, where: str, x: Any) -> Furniture:
        x = _json_object(where, x, _FURNITURE_KEYS)
        size = self.size(f"{where}.size", _required(where, x, "size"), self.limits.furniture_side)
        aff, state = self.affordances(where, x)
        center = self.vec3(f"{where}.center", _required(where, x, "center"))
        return Furniture(
            id=self.string(where, x, "id"), category=self.category(where, x),
            synset=self.string(where, x, "synset"),
            room=self.room_ref(f"{where}.room", _required(where, x, "room")),
            center=center,
            size=size,
            yaw=self.number(f"{where}.yaw", x.get("yaw", 0.0)),
            affordances=aff, state=state, levels=self.levels(f"{where}.levels", x, size[2]),
        )

    def levels(self, where: str, x: Mapping[str, Any], height: float) -> tuple[float, ...]:
        v = x.get("levels", [])
        if not isinstance(v, list):
            raise SpecError(f"{where}: expected a list of shelf heights")
        if len(v) > self.limits.levels:
            raise SpecError(f"{where}: {len(v)} levels, more than the limit of "
                            f"{self.limits.levels}")
        out = tuple(self.number(f"{where}[{i}]", h) for i, h in enumerate(v))
        for i, h in enumerate(out):
            if not 0 <= h < height:
                raise SpecError(f"{where}[{i}]: {h} is not within the piece's height "
                                f"[0, {height})")
            if i and h <= out[i - 1]:
                raise SpecError(f"{where}[{i}]: levels must be ascending")
        return out

    def small_object(self, where: str, x: Any) -> SmallObject:
        x = _json_object(where, x, _OBJECT_KEYS)
        rel = _required(where, x, "relation")
        if rel not in RELATIONS:
            raise SpecError(f"{where}.relation: expected 'inside' or 'ontop', got {_short(rel)}")
        aff, state = self.affordances(where, x)
        side = self.limits.object_side
        return SmallObject(
            id=self.string(where, x, "id"), category=self.category(where, x),
            synset=self.string(where, x, "synset"), parent=self.string(where, x, "parent"),
            relation=rel, room=self.room_ref(f"{where}.room", _required(where, x, "room")),
            position=self.vec3(f"{where}.position", _required(where, x, "position")),
            size=self.size(f"{where}.size", _required(where, x, "size"), side),
            affordances=aff, state=state)

    def start(self, where: str, x: Any) -> StartPose:
        x = _json_object(where, x, _START_KEYS)
        return StartPose(x=self.number(f"{where}.x", _required(where, x, "x")),
                         y=self.number(f"{where}.y", _required(where, x, "y")),
                         yaw=self.number(f"{where}.yaw", x.get("yaw", 0.0)),
                         room=self.room_ref(f"{where}.room", _required(where, x, "room")))


_METRES = " (lengths are in metres: a file written in centimetres? divide by 100)"


def _short(v: Any, n: int = 40) -> str:
    """``repr`` of a value cut to ``n`` characters (a 10^400 integer or a 100,000-character
    string is named, not printed)."""
    if isinstance(v, int) and not isinstance(v, bool) and abs(v) > 10 ** 30:
        return f"an integer of {len(str(abs(v))) if abs(v) < 10 ** 4000 else 'over 4000'} digits"
    r = repr(v) if not isinstance(v, (str, list, dict)) or len(v) < 1000 else \
        f"{type(v).__name__} of length {len(v)}"
    return r if len(r) <= n else r[:n - 3] + "..."


def _json_object(where: str, x: Any, known: frozenset[str]) -> Mapping[str, Any]:
    if not isinstance(x, Mapping):
        raise SpecError(f"{where}: expected a JSON object")
    _known_keys(where, x, known)
    return x


def _required(where: str, x: Mapping[str, Any], key: str) -> Any:
    if key not in x:
        raise SpecError(f"{where}.{key}: missing")
    return x[key]


def _unique_ids(key: str, items: Iterable[Any], prefix: str) -> set[str]:
    seen: set[str] = set()
    for i, it in enumerate(items):
        problem = id_problem(it.id)
        if problem:
            raise SpecError(f"{key}[{i}].id: {_short(it.id)} {problem}")
        if not it.id.startswith(prefix):
            raise SpecError(f"{key}[{i}].id: {it.id!r} should start with {prefix!r} (every "
                            "id starts with its section's prefix: room_, wall_, door_, pass_, "
                            "furn_, obj_; e.g. 'room_kitchen')")
        if it.id in seen:
            raise SpecError(f"{key}[{i}].id: duplicate id {it.id!r}")
        seen.add(it.id)
    return seen
