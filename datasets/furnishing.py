"""Furniture of a generated house (step 3 of :mod:`sgtool.datasets.generator`): per room,
the categories of that room type's real inventories drawn with their frequencies, placed
against walls, in the open (tables) or around tables (chairs), stacked pieces on a base,
each kept only if the room stays crossable and its containers reachable, and no floor piece
stands in front of a container's front (:func:`front_zone`: the robot opens and looks in
there; :func:`sgtool.house.clearance.blocked_fronts` checks the same in a spec)."""

from __future__ import annotations

import math

import numpy as np

from sgtool.datasets.first_level import FLOOR_HOLDERS, extra_holders, holder_size
from sgtool.datasets.house_inventory import Inventory
from sgtool.datasets.house_plan import Piece, Plan, PlanRoom, Rect, snap
from sgtool.datasets.presets import PRESETS, GeneratorPreset
from sgtool.datasets.room_space import RoomSpace
from sgtool.datasets.sizes import (
    CENTRAL,
    DEFAULT_MAX_PER_ROOM,
    MAX_PER_ROOM,
    SEATS,
    STACKED_ON,
    furniture_size,
)
from sgtool.datasets.synsets import ancestors
from sgtool.house.clearance import FRONT_CLEAR

EXTRA_ATTEMPTS = 8  # positions tried for an extra holder (first_level module)
TOP_MAX_HEIGHT = 1.2  # m, highest top face an extra holder is stood on
FRONT_TOUCH = 0.01  # m: a piece this near a container's front zone stands in it


def _furniture_list(rng: np.random.Generator, room_type: str, inv: Inventory,
                    preset: GeneratorPreset) -> list[str]:
    rows = inv.furniture.get(room_type, ())
    out: list[str] = []
    for f in rows:
        if rng.random() >= min(1.0, f.frequency * preset.furniture_frequency_scale):
            continue
        cap = MAX_PER_ROOM.get(f.synset, DEFAULT_MAX_PER_ROOM) * preset.furniture_cap_scale
        mean = f.mean_count * preset.furniture_count_scale
        n = 1 + int(rng.poisson(max(mean - 1.0, 0.0)))
        out += [f.synset] * min(n, cap)
    if room_type != "corridor" and not any(_holds_things(s, inv) for s in out):
        useful = [f.synset for f in rows if _holds_things(f.synset, inv)]
        if useful:
            out.append(useful[0])
    return out


def _holds_things(synset: str, inv: Inventory) -> bool:
    a = inv.knowledge.affordances.get(synset, ())
    return "container" in a or "supporter" in a


def _jittered_size(rng: np.random.Generator, size: tuple[float, float, float]
            ) -> tuple[float, float, float]:
    f = rng.uniform(0.92, 1.08, size=3)
    sx, sy, sz = size
    return (round(float(sx * f[0]), 2), round(float(sy * f[1]), 2), round(float(sz * f[2]), 2))


def _footprint(cx: float, cy: float, w: float, d: float, yaw: float) -> Rect:
    if abs(math.sin(yaw)) > 0.5:  # rotated by +-90 degrees
        w, d = d, w
    return Rect(round(cx - w / 2, 4), round(cy - d / 2, 4), round(cx + w / 2, 4),
                 round(cy + d / 2, 4))


def front_zone(box: Rect, yaw: float, clear: float = FRONT_CLEAR) -> Rect:
    """The floor strip ``clear`` metres deep in front of the front (local +y) face of a
    piece with footprint ``box`` turned by ``yaw`` (a multiple of 90 degrees), as wide as
    that face."""
    dx, dy = round(-math.sin(yaw)), round(math.cos(yaw))
    if dy > 0:
        return Rect(box.x0, box.y1, box.x1, box.y1 + clear)
    if dy < 0:
        return Rect(box.x0, box.y0 - clear, box.x1, box.y0)
    if dx > 0:
        return Rect(box.x1, box.y0, box.x1 + clear, box.y1)
    return Rect(box.x0 - clear, box.y0, box.x0, box.y1)


def _blocks_a_front(box: Rect, yaw: float, container: bool, mine: list[Piece]) -> bool:
    """Whether a floor piece at ``box`` would stand in front of a container of ``mine``
    (on the floor or on another piece), or, being a ``container``, have one of ``mine``
    in front of its own front."""
    if container and any(front_zone(box, yaw).overlaps(p.box, FRONT_TOUCH) for p in mine):
        return True
    return any(box.overlaps(front_zone(p.box, p.yaw), FRONT_TOUCH) for p in mine
               if "container" in p.affordances)


def _centred(base: Piece, size: tuple[float, float, float]) -> Rect:
    """The footprint of a piece of ``size`` stood in the middle of ``base``'s top."""
    cx, cy = (base.box.x0 + base.box.x1) / 2, (base.box.y0 + base.box.y1) / 2
    return _footprint(cx, cy, size[0], size[1], base.yaw)


def _front_covered(box: Rect, base: Piece, container: bool, mine: list[Piece]) -> bool:
    """Whether a ``container`` stood at ``box`` on ``base`` (facing as it does) would have
    a floor piece of ``mine`` other than its base in front of its front."""
    zone = front_zone(box, base.yaw)
    return container and any(zone.overlaps(p.box, FRONT_TOUCH) for p in mine
                             if p.on is None and p is not base)


def _wall_candidate(rng: np.random.Generator, inner: Rect, w: float,
                    d: float) -> tuple[float, float, float] | None:
    """(cx, cy, yaw) of a piece of width w (along the wall) and depth d against a wall; the
    piece's front (local +y) faces into the room."""
    side = int(rng.integers(4))
    if side in (0, 1):  # south / north wall: runs along x
        if inner.width < w:
            return None
        cx = snap(float(rng.uniform(inner.x0 + w / 2, inner.x1 - w / 2)), 0.01)
        cx = min(max(cx, inner.x0 + w / 2), inner.x1 - w / 2)
        if side == 0:
            return (cx, inner.y0 + d / 2, 0.0)
        return (cx, inner.y1 - d / 2, math.pi)
    if inner.height < w:
        return None
    cy = snap(float(rng.uniform(inner.y0 + w / 2, inner.y1 - w / 2)), 0.01)
    cy = min(max(cy, inner.y0 + w / 2), inner.y1 - w / 2)
    if side == 2:  # west wall, front faces +x
        return (inner.x0 + d / 2, cy, -math.pi / 2)
    return (inner.x1 - d / 2, cy, math.pi / 2)


def furnish_room(rng: np.random.Generator, room: PlanRoom, plan: Plan, inv: Inventory,
                 pieces: list[Piece], preset: GeneratorPreset = PRESETS["default"]
                 ) -> list[int]:
    """Draw and place the furniture of ``room``, appending the kept pieces to ``pieces``
    (whose length gives the index of the room's first piece); ``preset`` scales how many
    pieces are drawn and adds extra holders (:mod:`sgtool.datasets.first_level`), whose
    indices in ``pieces`` are returned."""
    space = RoomSpace(room, plan.openings)
    wanted = _furniture_list(rng, room.type, inv, preset)
    floor = [s for s in wanted if s not in STACKED_ON]
    stacked = [s for s in wanted if s in STACKED_ON]

    def order_key(s: str) -> tuple[int, float, str]:
        w, d, _ = furniture_size(s)
        group = 2 if s in SEATS else (1 if s in CENTRAL else 0)
        return (group, -w * d, s)

    floor.sort(key=order_key)
    mine: list[Piece] = []
    for s in floor:
        _place_floor(rng, s, furniture_size(s), room, space, inv, mine, 24)
    for s in stacked:
        bases = [p for p in mine if p.on is None and not p.top_used
                 and any(a in ancestors(p.synset) for a in STACKED_ON[s])]
        size = _jittered_size(rng, furniture_size(s))
        aff = inv.knowledge.affordances.get(s, ())
        bases = [p for p in bases if p.size[0] >= size[0] and p.size[1] >= size[1]
                 and not _front_covered(_centred(p, size), p, "container" in aff, mine)]
        if not bases:
            continue
        base = bases[int(rng.integers(len(bases)))]
        base.top_used = True
        mine.append(Piece(s, room.idx, _centred(base, size),
                           base.z0 + base.size[2], size, base.yaw,
                           len(pieces) + mine.index(base), True, aff,
                           _initial_state(rng, aff)))
    first_extra = len(mine)
    top_width: dict[int, float] = {}
    for s in extra_holders(rng, room, inv, preset):
        if not _place_floor(rng, s, holder_size(s), room, space, inv, mine, EXTRA_ATTEMPTS):
            _place_on_top(rng, s, room, space, inv, mine, len(pieces), top_width)
    extras = list(range(len(pieces) + first_extra, len(pieces) + len(mine)))
    pieces.extend(mine)
    return extras


def _place_floor(rng: np.random.Generator, s: str, base_size: tuple[float, float, float],
                 room: PlanRoom, space: RoomSpace, inv: Inventory, mine: list[Piece],
                 attempts: int) -> bool:
    """Try ``attempts`` positions for a floor piece ``s`` (against a wall, in the open for
    a table, at a table for a seat); the first that keeps the room crossable and every
    holder reachable is appended to ``mine`` (True), else False."""
    size = _jittered_size(rng, base_size)
    w, d, h = size
    cand: tuple[float, float, float] | None
    for _ in range(attempts):
        if s in SEATS and any(p.synset in CENTRAL for p in mine):
            cand = _seat_candidate(rng, [p for p in mine if p.synset in CENTRAL], w, d)
        elif s in CENTRAL and _ < 12:
            m = 0.75
            x0, x1 = space.inner.x0 + m + w / 2, space.inner.x1 - m - w / 2
            y0, y1 = space.inner.y0 + m + d / 2, space.inner.y1 - m - d / 2
            if x1 < x0 or y1 < y0:
                cand = _wall_candidate(rng, space.inner, w, d)
            else:
                cand = (snap(float(rng.uniform(x0, x1)), 0.01),
                        snap(float(rng.uniform(y0, y1)), 0.01), 0.0)
        else:
            cand = _wall_candidate(rng, space.inner, w, d)
        if cand is None:
            continue
        cx, cy, yaw = cand
        box = _footprint(cx, cy, w, d, yaw)
        if not box.inside(space.inner):
            continue
        if any(box.overlaps(p.box, 0.05) for p in mine):
            continue
        if any(box.overlaps(k) for k in space.keepouts):
            continue
        aff = inv.knowledge.affordances.get(s, ())
        if _blocks_a_front(box, yaw, "container" in aff, mine):
            continue
        reach = [p.box for p in mine if p.affordances]
        if aff:
            reach.append(box)
        if not space.free_ok(reach, box):
            continue
        placed = Piece(s, room.idx, box, 0.0, size, yaw % (2 * math.pi), None, False,
                       aff, _initial_state(rng, aff))
        space.add(placed.box)
        mine.append(placed)
        return True
    return False


def _place_on_top(rng: np.random.Generator, s: str, room: PlanRoom, space: RoomSpace,
                  inv: Inventory, mine: list[Piece], offset: int, used: dict[int, float]
                  ) -> bool:
    """Stand a small extra holder ``s`` on the top face of a low supporter of ``mine`` (a
    table, counter, cabinet), next to the holders already there (``used``: the width taken
    on each base, by index in ``mine``) at its front edge, if the robot can reach it there;
    ``offset`` is the index of ``mine[0]`` in the house. The base's top face then holds no
    small objects. Returns whether the holder was placed."""
    size = _jittered_size(rng, holder_size(s))
    w, d, _ = size
    aff = inv.knowledge.affordances.get(s, ())

    def at_front(i: int) -> Rect:  # along the base's width, at its front edge (local +y)
        base = mine[i]
        lx = -base.size[0] / 2 + used.get(i, 0.0) + w / 2
        ly = base.size[1] / 2 - d / 2
        c, sn = math.cos(base.yaw), math.sin(base.yaw)
        cx = (base.box.x0 + base.box.x1) / 2 + c * lx - sn * ly
        cy = (base.box.y0 + base.box.y1) / 2 + sn * lx + c * ly
        return _footprint(cx, cy, w, d, base.yaw)

    bases = [i for i, p in enumerate(mine)
             if p.on is None and "supporter" in p.affordances and p.size[2] <= TOP_MAX_HEIGHT
             and (p.top_used == (i in used)) and p.size[1] >= d
             and used.get(i, 0.0) + w <= p.size[0]
             and not _front_covered(at_front(i), p, "container" in aff, mine)]
    if s not in FLOOR_HOLDERS or not bases:
        return False
    i = bases[int(rng.integers(len(bases)))]
    base = mine[i]
    box = at_front(i)
    if not space.free_ok([box], None):
        return False
    used[i] = used.get(i, 0.0) + w + 0.02
    base.top_used = True
    mine.append(Piece(s, room.idx, box, base.z0 + base.size[2], size, base.yaw, offset + i,
                      True, aff, _initial_state(rng, aff)))
    return True


def _seat_candidate(rng: np.random.Generator, tables: list[Piece], w: float,
                    d: float) -> tuple[float, float, float]:
    t = tables[int(rng.integers(len(tables)))]
    side = int(rng.integers(4))
    b = t.box
    gap = 0.05
    if side == 0:  # south of the table, facing +y (north)
        x = float(rng.uniform(b.x0 + w / 2, max(b.x1 - w / 2, b.x0 + w / 2)))
        return (snap(x, 0.01), b.y0 - gap - d / 2, 0.0)
    if side == 1:
        x = float(rng.uniform(b.x0 + w / 2, max(b.x1 - w / 2, b.x0 + w / 2)))
        return (snap(x, 0.01), b.y1 + gap + d / 2, math.pi)
    y = float(rng.uniform(b.y0 + w / 2, max(b.y1 - w / 2, b.y0 + w / 2)))
    if side == 2:  # west of the table, facing +x
        return (b.x0 - gap - d / 2, snap(y, 0.01), -math.pi / 2)
    return (b.x1 + gap + d / 2, snap(y, 0.01), math.pi / 2)


def _initial_state(rng: np.random.Generator, aff: tuple[str, ...]) -> str | None:
    if "openable" not in aff:
        return None
    return "open" if rng.random() < 0.1 else "closed"
