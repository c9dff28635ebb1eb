"""Seeded multi-room houses furnished from BEHAVIOR-1K knowledge.

``generate_house(seed, rooms=(4, 12), split="eval")`` builds a :class:`HouseSpec`:

1. **Programme.** The number of rooms is drawn from ``rooms`` (corridors included). A
   house always has a kitchen, a living room and a bathroom (and a bedroom from five rooms
   on); further rooms are drawn with the frequencies of the room types of the real
   household scenes of the chosen knowledge split, with caps (one kitchen, at most three
   bedrooms, ...); once every type is at its cap (from 25 rooms with the evaluation
   split) further rooms are bedrooms.
2. **Floor plan.** A double-loaded corridor (1.3-1.7 m wide; two corridor rooms joined by
   an open passage from eight rooms on, three from 17; at most 30 rooms) with rooms on both
   sides, each 2.5-6 m a side (sizes per room type), plus "back rooms" reached only
   through another room (a closet or bathroom behind a bedroom, a pantry behind the
   kitchen). The kitchen may share an open plan with the living or dining room: no wall
   between them, only stubs either side of a wide passage. Every other connection is a
   0.9 m door that may be closed (bedrooms, bathrooms, closets more often). Walls are
   0.1 m thick and 2.5 m high, with gaps at doors and passages.
3. **Furniture.** Per room, each furniture category of that room type's real inventories
   (:attr:`Knowledge.room_furniture` over the split's household scenes) is included with
   its frequency, in a count drawn around its mean count; pieces stand against walls
   (tables in the open, chairs at tables, microwaves and televisions on a counter or
   cabinet), never in front of a door nor within 0.3 m of a container's front (where the
   robot opens it and looks in), and a piece is only kept if the robot (radius 0.2 m) can
   still cross the room between all its doors and stand within 1 m of every container
   and supporter.
4. **Small objects.** Containers are filled and supporters dressed with objects drawn
   by the room type of the piece. A category is a candidate for a piece when (a) some
   activity of the split relates it ``inside``/``ontop`` the piece's synset or one of its
   hypernyms, in any room type (it can sit there), and (b) the piece's room type knows it:
   at least ``MIN_SUPPORT`` (2) sources of the split put it in a room of that type -
   real rooms of that type holding it, activities placing it there (the counts of
   ``Knowledge.room_objects``) - so one odd activity (pennies cleaned with salt in a bowl
   on a bathroom sink) or one odd scan does not bring a category into a room type that
   has better evidence for that piece. Only when no related category reaches two sources
   for the piece does a single source of that room type admit (the room type's own
   inventory: toilet tissue on a toilet, a blouse in a closet's wardrobe). The weight comes
   from that room type only: the share of the type's real rooms holding the category,
   plus the share of the activities placing objects in the type that place it there, plus
   ``LOCAL_BONUS`` times the share that relate it to this parent there. Relations
   stated in other room types only admit a candidate and never weigh in, so the many
   kitchen activities with a bowl in a cabinet do not fill bathroom cabinets. A piece
   whose (parent, relation, room type) has no candidate at all stays empty: objects of
   other room types are never imported (in the evaluation split corridors, entryways and
   most storage-room pieces have no evidence and stay empty). With fewer than
   ``FULL_POOL`` candidates the mean count is scaled down by the pool size, so thin
   evidence gives fewer objects rather than many copies of one category. Each object
   gets a slot (a shelf level inside a container, a spot on a top face) so objects never
   overlap and lie really inside (within the box) or on top (bottom on the top face).
5. **Checks.** The spec is validated (:func:`~sgtool.house.io.load_house`) and the whole
   house is checked on its occupancy grid with closed doors passable: every room is
   reachable from the first corridor and every container can be approached within 1 m.
   A failed attempt is redrawn from the same random stream, so the result still depends
   on the seed only.

**Presets** (:mod:`sgtool.datasets.presets`): the steps above are the ``default`` preset;
``symsearch`` runs the same steps with more furniture per room, extra first-level holders
(baskets, boxes, bins, side tables, shelves, mostly empty:
:mod:`~sgtool.datasets.first_level`), more small objects per container and top face, and
small objects from the long tail of the split (categories whose home is the room type,
even on one source, drawn evenly, most draws going to categories unseen in training), for
houses as dense as SymSearch's InteriorGS scenes.

The same seed gives the same bytes (numpy PCG64 stream, sorted iteration, 4-decimal
canonical JSON).

The steps live in their own modules; this one runs them in order and assembles the spec:
:mod:`~sgtool.datasets.house_inventory` (what a split furnishes from),
:mod:`~sgtool.datasets.house_plan` (dimensions and the plan records),
:mod:`~sgtool.datasets.floor_plan` (1, 2), :mod:`~sgtool.datasets.openings` (doors and
passages), :mod:`~sgtool.datasets.walls`, :mod:`~sgtool.datasets.furnishing` and
:mod:`~sgtool.datasets.room_space` (3), :mod:`~sgtool.datasets.object_candidates` and
:mod:`~sgtool.datasets.small_objects` (4), :mod:`~sgtool.datasets.robot_clearance`
(start poses and 5).
"""


from __future__ import annotations

import dataclasses
import math

import numpy as np

from sgtool.canonical import canonical_float
from sgtool.datasets.floor_plan import floor_plan
from sgtool.datasets.furnishing import furnish_room
from sgtool.datasets.house_inventory import house_inventory
from sgtool.datasets.house_plan import (
    DOOR_H,
    HOUSE_ROOM_TYPES,
    WALL_H,
    WALL_T,
    Piece,
    Plan,
    PlanRetry,
)
from sgtool.datasets.presets import get_preset
from sgtool.datasets.robot_clearance import start_poses
from sgtool.datasets.small_objects import place_objects
from sgtool.datasets.synsets import readable_name
from sgtool.datasets.walls import wall_segments
from sgtool.errors import SgtoolError
from sgtool.house.io import load_house
from sgtool.house.spec import HouseSpec, StartPose

MAX_ROOMS = 30  # corridors included; a third corridor room from 17 rooms on

__all__ = ["HOUSE_ROOM_TYPES", "generate_house"]


def _with_starts(draft: HouseSpec, starts: list[dict]) -> HouseSpec:
    """``draft`` (loaded from :func:`_spec_dict` without starts) with ``starts``: what
    loading :func:`_spec_dict` with them gives (numbers made canonical as the parser does;
    the poses lie inside their rooms by construction), without parsing the house twice."""
    poses = tuple(StartPose(x=canonical_float(s["x"]), y=canonical_float(s["y"]),
                            yaw=canonical_float(s["yaw"]), room=s["room"]) for s in starts)
    return dataclasses.replace(draft, starts=poses)


def _spec_dict(seed: int, split: str, plan: Plan, pieces: list[Piece], objs: list[dict],
               starts: list[dict]) -> dict:
    rooms = []
    for r in plan.rooms:
        x0, y0, x1, y1 = r.rect.x0, r.rect.y0, r.rect.x1, r.rect.y1
        rooms.append({"id": r.id, "category": r.type,
                      "polygon": [[x0, y0], [x1, y0], [x1, y1], [x0, y1]],
                      "open_plan_group": r.group})
    walls = [{"id": f"wall_{i}", "a": list(a), "b": list(b), "thickness": WALL_T,
              "height": WALL_H} for i, (a, b) in enumerate(wall_segments(plan))]
    doors: list[dict[str, object]] = []
    passages: list[dict[str, object]] = []
    for o in plan.openings:
        rec = {"center": list(o.center), "width": o.width,
               "yaw": 0.0 if o.horizontal else math.pi / 2,
               "rooms": [f"room_{o.rooms[0]}", f"room_{o.rooms[1]}"]}
        if o.kind == "door":
            doors.append({"id": f"door_{len(doors)}", **rec, "state": o.state,
                          "height": DOOR_H, "thickness": WALL_T})
        else:
            passages.append({"id": f"pass_{len(passages)}", **rec})
    furniture = []
    for i, p in enumerate(pieces):
        cx, cy = (p.box.x0 + p.box.x1) / 2, (p.box.y0 + p.box.y1) / 2
        furniture.append({
            "id": f"furn_{i}", "category": readable_name(p.synset), "synset": p.synset,
            "room": f"room_{p.room}", "center": [cx, cy, p.z0 + p.size[2] / 2],
            "size": list(p.size), "yaw": _wrap_angle(p.yaw), "affordances": list(p.affordances),
            "state": p.state,
        })
    objects = [{"id": f"obj_{i}", **o} for i, o in enumerate(objs)]
    return {"version": "1.0", "seed": int(seed), "split": split, "rooms": rooms,
            "walls": walls, "doors": doors, "passages": passages, "furniture": furniture,
            "objects": objects, "starts": starts}


def _wrap_angle(a: float) -> float:
    a = (a + math.pi) % (2 * math.pi) - math.pi
    return math.pi if abs(a + math.pi) < 1e-9 else a


def generate_house(seed: int, rooms: tuple[int, int] = (4, 12), split: str = "eval",
                   max_attempts: int = 40, preset: str = "default") -> HouseSpec:
    """A furnished house for ``seed`` (see the module docstring). ``rooms`` is the range
    of the room count, corridors included (inclusive, 4..30); ``preset`` names a
    :mod:`sgtool.datasets.presets` entry ("default": as documented here; "symsearch":
    InteriorGS-dense houses with long-tail small objects)."""
    try:
        lo, hi = rooms
        if not all(isinstance(r, int | np.integer) and not isinstance(r, bool)
                   for r in (lo, hi)):
            raise TypeError
    except (TypeError, ValueError):
        raise SgtoolError(f"rooms={rooms!r}: give (MIN, MAX), two whole numbers, e.g. "
                          "(4, 12)") from None
    lo, hi = int(lo), int(hi)
    if not 4 <= lo <= hi <= MAX_ROOMS:
        raise SgtoolError(f"rooms: need 4 <= min <= max <= {MAX_ROOMS}, got {lo}-{hi}")
    if split not in ("eval", "train"):
        raise SgtoolError(f"split: expected 'eval' or 'train', got {split!r}")
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0:
        raise SgtoolError(f"seed: expected an integer >= 0, got {seed!r}")
    pre = get_preset(preset)
    inv = house_inventory(split)
    rng = np.random.default_rng(int(seed))
    n_rooms = int(rng.integers(lo, hi + 1))
    for _ in range(max_attempts):
        try:
            plan = floor_plan(rng, n_rooms, inv)
            pieces: list[Piece] = []
            extras: set[int] = set()
            for r in plan.rooms:
                extras.update(furnish_room(rng, r, plan, inv, pieces, pre))
            room_types = {r.idx: r.type for r in plan.rooms}
            objs = place_objects(rng, split, pieces, room_types, pre, frozenset(extras))
            draft = load_house(_spec_dict(seed, split, plan, pieces, objs, []))
            starts = start_poses(rng, draft)
            return _with_starts(draft, starts)
        except PlanRetry:
            continue
    raise SgtoolError(f"could not build a house for seed {seed} in {max_attempts} attempts")
