"""The versioned JSON house spec: rooms, walls, doors, furniture, small objects, start poses.

One house is one :class:`HouseSpec`. It is what the PyBullet recorder builds, what the
symbolic benchmark turns into scene graphs and what the episode lister searches in, so it
is a frozen contract, validated on load (:func:`sgtool.house.io.load_house`, rules in
:mod:`sgtool.house.parse` and :mod:`sgtool.house.consistency`) with messages that name the
offending field (``rooms[2].polygon: needs at least 3 points``).

Conventions (checked on load, all but one: rooms a passage joins need not share an
``open_plan_group``, which labels and draws them only: the merged scores join the rooms
passages join, group or not, and keep rooms a door parts apart):

- metres, z up, yaw counter-clockwise from +x in radians;
- ids are strings with a kind prefix, usually followed by a running number: ``room_0``,
  ``door_3``, ``pass_1`` (an open-plan passage: a gap in the wall without a door),
  ``wall_7``, ``furn_12`` (furniture and containers), ``obj_40`` (small objects); any
  other suffix is allowed (``furn_shelf``); an id (and the optional house ``id``) is a
  safe file-name component and table cell, names hold no control characters
  (:mod:`sgtool.house.names`); unknown and repeated keys are refused;
- a room is a simple polygon (counter-clockwise or not) with a category ("kitchen");
  rooms of one open-plan space (kitchen + living room without a door between them) share
  ``open_plan_group``; rooms do not overlap;
- a wall is a straight segment ``a``-``b`` with a thickness (centred on the segment) and a
  height; walls have gaps where doors and passages are, and (when a house has walls) a
  gap between two rooms is a door or a passage;
- a door is an opening of ``width`` centred at ``center``, lying along direction ``yaw``
  (the direction of the wall it sits in), joining two rooms whose borders it lies on;
  ``state`` is "open" or "closed"; a closed door is a panel of the wall's thickness
  filling the opening;
- furniture (including containers) is an oriented box inside its room: ``center`` (x, y, z
  of the box centre; a floor-standing piece has z = sz / 2), ``size`` (sx, sy, sz along the
  box's own axes before rotation), ``yaw``; a container's front (where it opens, and what
  the robot looks in through; also a shelf's open side) is the box's local +y face, so a
  piece against a wall faces away from it: ``yaw`` (radians, as every angle of the spec) =
  the direction of its front minus pi/2; ``affordances`` is a sorted tuple from
  {"container", "openable", "supporter"}; ``state`` is "open"/"closed" for openable
  pieces and None otherwise; ``levels`` (version 2) are the heights above the box's bottom
  of its lower support surfaces (shelves), ascending, each inside the box;
- a small object has a ``parent`` (a furniture id or, version 2, another small object's
  id: containment to any depth up to :attr:`SpecLimits.depth`) and a ``relation``
  "inside" (its box lies within the parent's box; the parent must be a container) or
  "ontop" (its bottom rests on a support surface of the parent: the parent's top face or
  one of a furniture's ``levels``, within :data:`ONTOP_TOL`; its centre is over the
  parent's footprint; a parent that is neither a supporter nor a container is read as a
  supporter, with every piece of its category:
  :func:`sgtool.house.nesting.with_supporters`); ``position`` is its box centre and
  ``size`` its extent along the parent's axes (small objects share their furniture's
  yaw); its ``room`` is its furniture's; a small object may itself be a container (a
  bowl) or openable (a lidded box: ``affordances`` and ``state`` as for furniture,
  version 2);
- ``starts`` are robot start poses (x, y, yaw) on free floor, each in a named room; the
  key may be left out (no starts: the commands that need them add one per reachable room).

**Version 2** (:data:`SPEC_VERSION`) adds nesting, ``levels`` and small-object
affordances; a version-1 file is a version-2 file without them and loads as one
(:mod:`sgtool.house.migrate`). **Limits** (:class:`SpecLimits`) bound counts, sizes, name
lengths and nesting depth so that a spec that loads can be built, rasterised and searched.

The canonical text (:meth:`HouseSpec.to_json`) sorts keys, rounds floats to 4 decimals and
keeps list order (ids in creation order), so one spec always gives the same bytes; the
version-2 fields are written only when they are not empty, so a house without them has the
text of version 1 but for its version. Plane geometry (polygon containment, centroids,
box corners) is in :mod:`sgtool.house.geometry`.
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
from sgtool.house.names import decimal_int

SPEC_VERSION = "2.0"
AFFORDANCES = ("container", "openable", "supporter")
RELATIONS = ("inside", "ontop")
STATES = ("open", "closed")
_CONTAINMENT_TOL = 1e-3  # tolerance (m) of the containment checks, above the 4-decimal rounding
ONTOP_TOL = 0.01  # how far (m) an "ontop" object's bottom may be from its support surface


@dataclass(frozen=True)
class SpecLimits:
    """What a house spec may hold (checked on load; a spec beyond them is refused).

    They keep every consumer bounded: the occupancy grid of a house is at most
    ``(extent / 0.05 m)^2`` = 4 M cells, the PyBullet world at most ``walls + furniture +
    objects`` bodies, the scene graph at most ``furniture + objects`` object nodes."""

    coordinate: float = 1000.0  # |any number| (m, rad) before the other checks
    extent: float = 100.0  # width and depth of the rooms' bounding box (m)
    rooms: int = 100
    polygon_points: int = 64  # per room
    walls: int = 2000
    doors: int = 300  # doors, and passages, each
    furniture: int = 1000
    objects: int = 5000
    starts: int = 1000
    levels: int = 16  # shelf levels per piece of furniture
    depth: int = 8  # small objects in a chain from a piece of furniture (1: on the furniture)
    name_length: int = 128  # ids, categories, synsets, open-plan groups
    furniture_side: float = 20.0  # m, every side of a piece of furniture
    object_side: float = 5.0  # m, every side of a small object
    wall_thickness: float = 1.0
    wall_height: float = 10.0
    door_width: float = 5.0
    passage_width: float = 30.0  # open-plan passages are wide (5.2 m in generated houses)
    door_height: float = 5.0
    room_overlap: float = 0.01  # m^2 two rooms may share (rounding of shared borders)
    opening_offset: float = 0.3  # m a door or passage centre may lie off each room's border
    furniture_outside: float = 0.1  # m a furniture corner may stick out of its room


LIMITS = SpecLimits()


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


Opening = Door | Passage  # a gap in the walls between two rooms


class _Affordances:
    """``is_container`` / ``is_openable`` of anything with ``affordances``."""

    affordances: tuple[str, ...]

    @property
    def is_container(self) -> bool:
        return "container" in self.affordances

    @property
    def is_openable(self) -> bool:
        return "openable" in self.affordances


@dataclass(frozen=True)
class Furniture(_Affordances):
    id: str
    category: str
    synset: str
    room: str
    center: Vec3
    size: Vec3
    yaw: float = 0.0
    affordances: tuple[str, ...] = ()
    state: str | None = None
    levels: tuple[float, ...] = ()  # heights of lower shelves above the bottom (version 2)

    @property
    def supports(self) -> tuple[float, ...]:
        """World z of every support surface, lowest first: the shelves, then the top."""
        return tuple(self.bottom + h for h in self.levels) + (self.top,)

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
class SmallObject(_Affordances):
    """A small object ``inside``/``ontop`` of its ``parent``: a furniture id or (version 2)
    another small object's id. It may be a container or openable itself (version 2)."""

    id: str
    category: str
    synset: str
    parent: str
    relation: str
    room: str
    position: Vec3
    size: Vec3
    affordances: tuple[str, ...] = ()
    state: str | None = None

    @property
    def top(self) -> float:
        return self.position[2] + self.size[2] / 2.0

    @property
    def bottom(self) -> float:
        return self.position[2] - self.size[2] / 2.0

    @property
    def supports(self) -> tuple[float, ...]:
        return (self.top,)


@dataclass(frozen=True)
class StartPose:
    x: float
    y: float
    yaw: float
    room: str


@dataclass(frozen=True)
class HouseSpec:
    """A house (DESIGN.md, "House spec"): rooms, walls, doors, passages, furniture, small
    objects and start poses; immutable, checked when loaded
    (:func:`sgtool.house.io.load_house`), written as canonical JSON by ``to_json()``.
    ``seed`` is the generator's seed (or the file's), ``split`` the knowledge split that
    furnished it, ``id`` the file's own id (None: the file name names the house)."""

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
    id: str | None = None

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

    def holder_by_id(self) -> dict[str, Furniture | SmallObject]:
        """Every id a small object's ``parent`` may name: furniture and small objects."""
        return {**self.furniture_by_id(), **self.object_by_id()}

    def root_furniture(self) -> dict[str, str]:
        """Small object id -> id of the furniture at the bottom of its chain of parents
        (its own parent when that is furniture); linear time."""
        parent = {o.id: o.parent for o in self.objects}
        root: dict[str, str] = {f.id: f.id for f in self.furniture}
        for o in self.objects:
            path = []
            cur = o.id
            while cur not in root:
                path.append(cur)
                cur = parent[cur]
            for k in path:
                root[k] = root[cur]
        return {o.id: root[o.id] for o in self.objects}

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
        openings: tuple[Opening, ...] = (*self.doors, *self.passages)
        for d in openings:
            a, b = d.rooms
            nb[a].add(b)
            nb[b].add(a)
        return {k: tuple(sorted(v)) for k, v in sorted(nb.items())}

    # ----- canonical form -------------------------------------------------------------
    def to_dict(self) -> dict[str, Any]:
        own_id = {} if self.id is None else {"id": self.id}
        return {
            **own_id,
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
                 "affordances": list(f.affordances), "state": f.state,
                 **({"levels": canonical_floats(f.levels)} if f.levels else {})}
                for f in self.furniture
            ],
            "objects": [
                {"id": o.id, "category": o.category, "synset": o.synset, "parent": o.parent,
                 "relation": o.relation, "room": o.room, "position": canonical_floats(o.position),
                 "size": canonical_floats(o.size),
                 **({"affordances": list(o.affordances), "state": o.state}
                    if o.affordances or o.state else {})}
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


def enclosed(obj: SmallObject, parent: Furniture | SmallObject) -> bool:
    """Whether ``obj`` is within its parent's walls rather than on its top face: "inside",
    or "ontop" of a lower shelf (so a closed parent hides it)."""
    return obj.relation == "inside" or obj.bottom < parent.top - ONTOP_TOL


def hidden_objects(spec: HouseSpec) -> set[str]:
    """Ids of the small objects one must open something to see, in the spec's initial
    states: somewhere on the chain from the object to its furniture, a link is
    :func:`enclosed` in a closed parent (the reveal rule of the symbolic environment:
    walking up shows what is on top, opening shows what is inside). Linear time."""
    holders = spec.holder_by_id()
    objects = spec.object_by_id()
    hidden: dict[str, bool] = {f.id: False for f in spec.furniture}
    for o in spec.objects:
        path = []
        cur: str = o.id
        while cur not in hidden:  # not furniture: a small object
            path.append(cur)
            cur = objects[cur].parent
        for k in reversed(path):
            child = objects[k]
            parent = holders[child.parent]
            hidden[k] = hidden[parent.id] or (parent.state == "closed" and
                                              enclosed(child, parent))
    return {o.id for o in spec.objects if hidden[o.id]}


def placement_problem(obj: SmallObject, parent: Furniture | SmallObject,
                      yaw: float = 0.0) -> str | None:
    """Why ``obj`` is not where its relation says (None when it is): "inside" needs its
    box within the parent's box, "ontop" needs its bottom on a support surface of the
    parent (its top face or a shelf level, within :data:`ONTOP_TOL`) and its centre over
    the parent's footprint. A small object parent shares the yaw of its furniture,
    ``yaw``."""
    if isinstance(parent, Furniture):
        lx, ly = parent.to_local(obj.position[0], obj.position[1])
    else:
        c, s = math.cos(yaw), math.sin(yaw)
        dx, dy = obj.position[0] - parent.position[0], obj.position[1] - parent.position[1]
        lx, ly = c * dx + s * dy, -s * dx + c * dy
    hx, hy = parent.size[0] / 2.0, parent.size[1] / 2.0
    # the object's own footprint may be rotated relative to the parent: bound by its radius
    r = math.hypot(obj.size[0], obj.size[1]) / 2.0
    z0, z1 = obj.bottom, obj.top
    if obj.relation == "inside":
        if abs(lx) + min(r, obj.size[0] / 2.0) > hx + _CONTAINMENT_TOL or \
           abs(ly) + min(r, obj.size[1] / 2.0) > hy + _CONTAINMENT_TOL:
            return f"{obj.id} sticks out of {parent.id} sideways"
        if z0 < parent.bottom - _CONTAINMENT_TOL or z1 > parent.top + _CONTAINMENT_TOL:
            return f"{obj.id} sticks out of {parent.id} vertically"
        return None
    if abs(lx) > hx + _CONTAINMENT_TOL or abs(ly) > hy + _CONTAINMENT_TOL:
        return f"{obj.id} is not over the top face of {parent.id}"
    supports = parent.supports
    if min(abs(z0 - z) for z in supports) > ONTOP_TOL:
        if len(supports) == 1:
            return f"{obj.id} bottom z={z0:.3f} is not on {parent.id}'s top z={parent.top:.3f}"
        shelves = ", ".join(f"{z:.3f}" for z in supports)
        return f"{obj.id} bottom z={z0:.3f} is on none of {parent.id}'s surfaces z={shelves}"
    return None


def spec_id_key(spec_id: str) -> tuple[str, int]:
    """Sort key of a spec id in natural order: ``obj_2`` before ``obj_10`` (the number
    read by :func:`sgtool.house.names.decimal_int`; ``obj_²`` sorts as a plain name)."""
    head, _, num = spec_id.rpartition("_")
    n = decimal_int(num)
    return (head, n) if n is not None else (spec_id, -1)
