"""The versioned JSON house spec: rooms, walls, doors, furniture, small objects, start poses.

One house is one :class:`HouseSpec`. It is what the PyBullet recorder builds, what the
symbolic benchmark turns into scene graphs and what the episode lister searches in, so it
is a frozen contract, validated on load (:func:`sgtool.house.io.load_house`, rules in
:mod:`sgtool.house.parse`) with messages that name the offending field
(``rooms[2].polygon: needs at least 3 points``).

Conventions (all of them are checked on load):

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
Plane geometry (polygon containment, centroids, box corners) is in
:mod:`sgtool.house.geometry`.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from typing import Any

from sgtool.canonical import canonical_float, canonical_floats
from sgtool.house.geometry import (
    Point,
    Vec3,
    box_corners,
    opening_segment,
    point_in_polygon,
    polygon_centroid,
    signed_area,
)

SPEC_VERSION = "1.0"
AFFORDANCES = ("container", "openable", "supporter")
RELATIONS = ("inside", "ontop")
STATES = ("open", "closed")
_CONTAINMENT_TOL = 1e-3  # tolerance (m) of the containment checks, above the 4-decimal rounding


@dataclass(frozen=True)
class Room:
    id: str
    category: str
    polygon: tuple[Point, ...]
    open_plan_group: str | None = None

    @property
    def area(self) -> float:
        return abs(signed_area(self.polygon))

    @property
    def bounds(self) -> tuple[float, float, float, float]:
        """(xmin, ymin, xmax, ymax)."""
        xs = [p[0] for p in self.polygon]
        ys = [p[1] for p in self.polygon]
        return (min(xs), min(ys), max(xs), max(ys))

    @property
    def centroid(self) -> Point:
        return polygon_centroid(self.polygon)

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
        return opening_segment(self.center, self.width, self.yaw)

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
        return opening_segment(self.center, self.width, self.yaw)


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
        return box_corners(self.center[:2], self.size[:2], self.yaw)

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


def room_at(spec: HouseSpec, x: float, y: float) -> str | None:
    """Id of the room whose polygon holds (x, y) (first in id order on a shared border),
    None outside every room."""
    for r in spec.rooms:
        if r.contains(x, y):
            return r.id
    return None


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
        if abs(lx) + min(r, obj.size[0] / 2.0) > hx + _CONTAINMENT_TOL or \
           abs(ly) + min(r, obj.size[1] / 2.0) > hy + _CONTAINMENT_TOL:
            return f"{obj.id} sticks out of {parent.id} sideways"
        if z0 < parent.bottom - _CONTAINMENT_TOL or z1 > parent.top + _CONTAINMENT_TOL:
            return f"{obj.id} sticks out of {parent.id} vertically"
        return None
    if abs(lx) > hx + _CONTAINMENT_TOL or abs(ly) > hy + _CONTAINMENT_TOL:
        return f"{obj.id} is not over the top face of {parent.id}"
    if abs(z0 - parent.top) > 0.01:
        return f"{obj.id} bottom z={z0:.3f} is not on {parent.id}'s top z={parent.top:.3f}"
    return None


def spec_id_key(spec_id: str) -> tuple[str, int]:
    """Sort key of a spec id in natural order: ``obj_2`` before ``obj_10``."""
    head, _, num = spec_id.rpartition("_")
    return (head, int(num)) if num.isdigit() else (spec_id, -1)
