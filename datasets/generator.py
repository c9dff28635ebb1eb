"""Seeded multi-room houses furnished from BEHAVIOR-1K knowledge.

``generate_house(seed, rooms=(4, 12), split="eval")`` builds a :class:`HouseSpec`:

1. **Programme.** The number of rooms is drawn from ``rooms`` (corridors included). A
   house always has a kitchen, a living room and a bathroom (and a bedroom from five rooms
   on); further rooms are drawn with the frequencies of the room types of the real
   household scenes of the chosen knowledge split, with caps (one kitchen, at most three
   bedrooms, ...).
2. **Floor plan.** A double-loaded corridor (1.3-1.7 m wide; two corridor rooms joined by
   an open passage from eight rooms on) with rooms on both sides, each 2.5-6 m a side
   (sizes per room type), plus "back rooms" reached only through another room (a closet or
   bathroom behind a bedroom, a pantry behind the kitchen). The kitchen may share an open
   plan with the living or dining room: no wall between them, only stubs either side of
   a wide passage. Every other connection is a 0.9 m door that may be closed (bedrooms,
   bathrooms, closets more often). Walls are 0.1 m thick and 2.5 m high, with gaps at
   doors and passages.
3. **Furniture.** Per room, each furniture category of that room type's real inventories
   (:attr:`Knowledge.room_furniture` over the split's household scenes) is included with
   its frequency, in a count drawn around its mean count; pieces stand against walls
   (tables in the open, chairs at tables, microwaves and televisions on a counter or
   cabinet), never in front of a door, and a piece is only kept if the robot (radius
   0.2 m) can still cross the room between all its doors and stand within 1 m of every
   container and supporter.
4. **Small objects.** Containers are filled and supporters dressed with objects drawn
   by the room type of the piece. A category is a candidate for a piece when (a) some
   activity of the split relates it ``inside``/``ontop`` the piece's synset or one of its
   hypernyms, in any room type (it can sit there), and (b) the piece's room type knows it:
   at least :data:`MIN_SUPPORT` (2) sources of the split put it in a room of that type -
   real rooms of that type holding it, activities placing it there (the counts of
   ``Knowledge.room_objects``) - so one odd activity (pennies cleaned with salt in a bowl
   on a bathroom sink) or one odd scan does not bring a category into a room type that
   has better evidence for that piece. Only when no related category reaches two sources
   for the piece does a single source of that room type admit (the room type's own
   inventory: toilet tissue on a toilet, a blouse in a closet's wardrobe). The weight comes
   from that room type only: the share of the type's real rooms holding the category,
   plus the share of the activities placing objects in the type that place it there, plus
   :data:`LOCAL_BONUS` times the share that relate it to this parent there. Relations
   stated in other room types only admit a candidate and never weigh in, so the many
   kitchen activities with a bowl in a cabinet do not fill bathroom cabinets. A piece
   whose (parent, relation, room type) has no candidate at all stays empty: objects of
   other room types are never imported (in the evaluation split corridors, entryways and
   most storage-room pieces have no evidence and stay empty). With fewer than
   :data:`FULL_POOL` candidates the mean count is scaled down by the pool size, so thin
   evidence gives fewer objects rather than many copies of one category. Each object
   gets a slot (a shelf level inside a container, a spot on a top face) so objects never
   overlap and lie really inside (within the box) or on top (bottom on the top face).
5. **Checks.** The spec is validated (:func:`load_house`) and the whole house is checked
   on its occupancy grid with closed doors passable: every room is reachable from the
   first corridor and every container can be approached within 1 m. A failed attempt is
   redrawn from the same random stream, so the result still depends on the seed only.

The same seed gives the same bytes (numpy PCG64 stream, sorted iteration, 4-decimal
canonical JSON).
"""

from __future__ import annotations

import functools
import math
from collections import Counter
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
from scipy import ndimage

from sgtool.datasets.knowledge import (
    FurnitureFreq,
    Knowledge,
    ancestors,
    build_knowledge,
    readable_name,
)
from sgtool.datasets.sizes import (
    CENTRAL,
    DEFAULT_MAX_PER_ROOM,
    MAX_PER_ROOM,
    SEATS,
    STACKED_ON,
    furniture_size,
    object_size,
)
from sgtool.datasets.split import is_household_scene, knowledge_for
from sgtool.errors import SgtoolError
from sgtool.house.spec import HouseSpec, load_house
from sgtool.mapping.occupancy import geodesic_distances, house_occupancy

WALL_T = 0.1
WALL_H = 2.5
DOOR_W = 0.9
DOOR_H = 2.1
ROBOT_RADIUS = 0.2
REACH = 1.0  # the robot must be able to stand within this of every container (m)
SNAP = 0.05
_RES = 0.05  # resolution of the in-room free-space checks

# room type -> ((width range along the corridor), (depth range away from it)) in metres
ROOM_DIMS: dict[str, tuple[tuple[float, float], tuple[float, float]]] = {
    "kitchen": ((3.2, 5.0), (3.2, 5.0)),
    "living_room": ((4.0, 6.0), (3.8, 6.0)),
    "dining_room": ((3.2, 5.0), (3.2, 4.5)),
    "bedroom": ((3.2, 4.6), (3.2, 4.6)),
    "childs_room": ((3.0, 4.0), (3.0, 4.0)),
    "bathroom": ((2.5, 3.4), (2.5, 3.2)),
    "closet": ((2.5, 3.0), (2.5, 2.8)),
    "storage_room": ((2.5, 3.5), (2.5, 3.2)),
    "pantry_room": ((2.5, 3.0), (2.5, 3.0)),
    "utility_room": ((2.5, 3.5), (2.5, 3.5)),
    "private_office": ((3.0, 4.2), (3.0, 4.0)),
    "playroom": ((3.2, 4.6), (3.2, 4.5)),
    "television_room": ((3.2, 4.6), (3.2, 4.5)),
    "exercise_room": ((3.2, 4.6), (3.2, 4.5)),
    "entryway": ((2.5, 3.5), (2.5, 3.5)),
    "garage": ((4.0, 6.0), (5.0, 6.0)),
}
HOUSE_ROOM_TYPES = tuple(sorted(ROOM_DIMS))
MAX_OF_TYPE = {"kitchen": 1, "living_room": 1, "dining_room": 1, "garage": 1, "entryway": 1,
               "bedroom": 3, "bathroom": 3, "childs_room": 2, "closet": 2}
CORE = ("kitchen", "living_room", "bathroom", "bedroom")
P_CLOSED = {"bedroom": 0.35, "bathroom": 0.4, "closet": 0.45, "storage_room": 0.45,
            "pantry_room": 0.35, "utility_room": 0.35, "garage": 0.45, "childs_room": 0.3,
            "private_office": 0.3}
P_CLOSED_DEFAULT = 0.15
# back rooms: type -> host types
BACK_HOSTS = {"closet": ("bedroom", "childs_room"), "bathroom": ("bedroom",),
              "pantry_room": ("kitchen",), "storage_room": ("garage", "utility_room", "kitchen")}
OPEN_PLAN_PARTNERS = ("living_room", "dining_room")
# mean number of small objects per piece (Poisson), for containers and for top faces
LAMBDA_INSIDE = 2.2
LAMBDA_ONTOP = 1.3
# small objects (module docstring, step 4): a category must be held by / put in rooms of
# the piece's room type by at least this many sources (real rooms + activities, the counts
# of Knowledge.room_objects) to be placed there
MIN_SUPPORT = 2
LOCAL_BONUS = 2  # weight of relating the object to this parent in this room type
# fewer objects on thin evidence: the mean count is scaled by min(1, pool size / this)
FULL_POOL = 3


# shop and school fittings that some room inventories hold but a home generator skips
NOT_IN_HOMES = frozenset({
    "shopping_cart.n.01", "checkout.n.03", "cash_register.n.01", "grocery_shelf.n.01",
    "grocery_fridge.n.01", "display_panel.n.01", "blackboard.n.01",
})


class _Retry(Exception):
    """This attempt painted itself into a corner; draw again from the same stream."""


# ----------------------------------------------------------------------------------------
# knowledge views per split
# ----------------------------------------------------------------------------------------
@dataclass(frozen=True)
class _Inventory:
    knowledge: Knowledge
    furniture: dict[str, tuple[FurnitureFreq, ...]]
    type_weights: dict[str, float]


@functools.cache
def _inventory(split: str) -> _Inventory:
    k = knowledge_for(split)
    household = [r for r in k.rooms if is_household_scene(r.scene)]
    kh = build_knowledge(k.scenes, (), household, (), ())
    furniture: dict[str, tuple[FurnitureFreq, ...]] = {}
    for rt in HOUSE_ROOM_TYPES + ("corridor",):
        rows = kh.room_furniture.get(rt) or k.room_furniture.get(rt) or ()
        furniture[rt] = tuple(f for f in rows if f.synset not in NOT_IN_HOMES)
    counts = Counter(r.room_type for r in household)
    weights = {rt: float(counts.get(rt, 0)) for rt in HOUSE_ROOM_TYPES}
    return _Inventory(k, furniture, weights)


@dataclass(frozen=True)
class _RoomEvidence:
    """Per room type of one split: how many real rooms of that type hold each small-object
    category, and how many activities put it in a room of that type."""

    rooms: dict[str, Counter[str]]  # room type -> synset -> rooms holding it
    n_rooms: Counter[str]  # room type -> rooms of that type
    acts: dict[str, Counter[str]]  # room type -> synset -> activities placing it there
    n_acts: Counter[str]  # room type -> activities placing any small object there


@functools.cache
def _room_evidence(split: str) -> _RoomEvidence:
    k = knowledge_for(split)
    rooms: dict[str, Counter[str]] = {}
    n_rooms: Counter[str] = Counter()
    for r in k.rooms:
        n_rooms[r.room_type] += 1
        c = rooms.setdefault(r.room_type, Counter())
        c.update(s for s, _ in r.items if k.kind(s) == "object")
    placed: set[tuple[str, str, str]] = set()  # (room type, synset, activity)
    for rel in k.relations:
        if rel.room_type is not None and k.kind(rel.child) == "object":
            placed.add((rel.room_type, rel.child, rel.activity))
    for ir in k.inroom:
        if k.kind(ir.synset) == "object":
            placed.add((ir.room_type, ir.synset, ir.activity))
    acts: dict[str, Counter[str]] = {}
    for rt, s, _ in placed:
        acts.setdefault(rt, Counter())[s] += 1
    n_acts = Counter({rt: len({a for t, _, a in placed if t == rt}) for rt in acts})
    return _RoomEvidence(rooms, n_rooms, acts, n_acts)


@functools.cache
def _candidates(split: str, parent: str, relation: str,
                room_type: str) -> tuple[tuple[str, ...], np.ndarray]:
    """Small objects that may be ``relation`` ``parent`` (or a hypernym of it) in a room of
    ``room_type``, with sampling weights (see "Small objects" in the module docstring).

    Admitted: an object some activity of the split relates to the parent (in any room
    type) that at least :data:`MIN_SUPPORT` sources of the split put in this room type
    (real rooms of the type holding it + activities placing it there, the counts of
    ``Knowledge.room_objects``); when no related object reaches that, the related objects
    with one source there. Weight, from this room type only: the share of its real rooms
    holding the object + the share of the activities placing objects in it that place
    this one + :data:`LOCAL_BONUS` times the share relating it to the parent here.
    Relations stated in other room types only admit, they add no weight; nothing admitted
    gives an empty pool (the piece stays empty)."""
    k = knowledge_for(split)
    ev = _room_evidence(split)
    anc = ancestors(parent)
    related: set[str] = set()
    local: Counter[str] = Counter()
    seen_local: set[tuple[str, str]] = set()
    for r in k.relations:
        if r.relation != relation or r.parent not in anc or k.kind(r.child) != "object":
            continue
        related.add(r.child)
        if r.room_type == room_type and (r.activity, r.child) not in seen_local:
            seen_local.add((r.activity, r.child))
            local[r.child] += 1
    rooms = ev.rooms.get(room_type, Counter())
    acts = ev.acts.get(room_type, Counter())
    nr = max(ev.n_rooms[room_type], 1)
    na = max(ev.n_acts[room_type], 1)
    support = {c: rooms[c] + acts[c] for c in related}
    need = MIN_SUPPORT if any(n >= MIN_SUPPORT for n in support.values()) else 1
    pool = {c: rooms[c] / nr + (acts[c] + LOCAL_BONUS * local[c]) / na
            for c, n in support.items() if n >= need}
    names = tuple(sorted(pool))
    w = np.array([pool[n] for n in names], float)
    return names, (w / w.sum() if w.size else w)


# ----------------------------------------------------------------------------------------
# plan records
# ----------------------------------------------------------------------------------------
@dataclass
class _Rect:
    x0: float
    y0: float
    x1: float
    y1: float

    @property
    def w(self) -> float:
        return self.x1 - self.x0

    @property
    def h(self) -> float:
        return self.y1 - self.y0

    def shrink(self, m: float) -> _Rect:
        return _Rect(self.x0 + m, self.y0 + m, self.x1 - m, self.y1 - m)

    def overlaps(self, o: _Rect, gap: float = 0.0) -> bool:
        return (self.x0 < o.x1 + gap - 1e-9 and o.x0 < self.x1 + gap - 1e-9
                and self.y0 < o.y1 + gap - 1e-9 and o.y0 < self.y1 + gap - 1e-9)

    def inside(self, o: _Rect) -> bool:
        return (self.x0 >= o.x0 - 1e-9 and self.x1 <= o.x1 + 1e-9
                and self.y0 >= o.y0 - 1e-9 and self.y1 <= o.y1 + 1e-9)


@dataclass
class _PRoom:
    idx: int
    type: str
    rect: _Rect
    side: str  # "c" corridor, "n"/"s" front rooms, "nb"/"sb" back rooms
    group: str | None = None
    host: int | None = None  # back rooms: the room they open into

    @property
    def id(self) -> str:
        return f"room_{self.idx}"


@dataclass
class _Opening:
    kind: str  # "door" | "passage"
    center: tuple[float, float]
    width: float
    horizontal: bool  # lies along x (yaw 0) or along y (yaw pi/2)
    rooms: tuple[int, int]
    state: str = "open"


@dataclass
class _Piece:
    synset: str
    room: int
    box: _Rect  # axis-aligned footprint
    z0: float
    size: tuple[float, float, float]  # (sx, sy, sz) in the piece's own frame
    yaw: float
    on: int | None = None  # index of the piece it stands on
    top_used: bool = False
    affordances: tuple[str, ...] = ()
    state: str | None = None


@dataclass
class _Plan:
    rooms: list[_PRoom] = field(default_factory=list)
    openings: list[_Opening] = field(default_factory=list)


def _snap(v: float, step: float = SNAP) -> float:
    return round(round(v / step) * step, 4)


def _uniform_snap(rng: np.random.Generator, lo: float, hi: float, step: float = 0.1) -> float:
    return _snap(float(rng.uniform(lo, hi)), step)


# ----------------------------------------------------------------------------------------
# programme and floor plan
# ----------------------------------------------------------------------------------------
def _programme(rng: np.random.Generator, m: int, inv: _Inventory) -> list[str]:
    types = [t for t in CORE if inv.type_weights.get(t, 0) > 0 or t in inv.furniture][:m]
    counts = Counter(types)
    pool = [t for t in HOUSE_ROOM_TYPES if inv.type_weights.get(t, 0) > 0]
    while len(types) < m:
        ok = [t for t in pool if counts[t] < MAX_OF_TYPE.get(t, 2)]
        if not ok:
            ok = ["bedroom"]
        w = np.array([inv.type_weights[t] for t in ok], float)
        t = ok[int(rng.choice(len(ok), p=w / w.sum()))]
        types.append(t)
        counts[t] += 1
    return types


def _floor_plan(rng: np.random.Generator, n_rooms: int, inv: _Inventory) -> _Plan:
    n_corr = 1 if n_rooms <= 7 else 2
    types = _programme(rng, n_rooms - n_corr, inv)
    order = [types[i] for i in rng.permutation(len(types))]
    # open plan: the kitchen with the living or dining room
    group: tuple[str, str] | None = None
    if "kitchen" in order and rng.random() < 0.55:
        partners = [p for p in OPEN_PLAN_PARTNERS if p in order]
        if partners:
            group = ("kitchen", partners[int(rng.integers(len(partners)))])
    # back rooms: at most one per host, never the only bathroom, hosts outside the group
    back: list[tuple[str, str]] = []  # (type, host type)
    front = list(order)
    for t in list(order):
        hosts = BACK_HOSTS.get(t)
        if not hosts or (group and t in group) or rng.random() >= 0.45:
            continue
        if t == "bathroom" and sum(1 for x in front if x == "bathroom") < 2:
            continue
        used_hosts = Counter(h for _, h in back)
        avail = [h for h in hosts if front.count(h) > used_hosts[h]
                 and not (group and h in group)]
        if not avail or len(front) <= 2:
            continue
        front.remove(t)
        back.append((t, avail[int(rng.integers(len(avail)))]))
    dims: dict[int, tuple[float, float]] = {}
    blocks: list[list[int]] = []  # indices into front, kept adjacent
    done: set[int] = set()
    for i, t in enumerate(front):
        if i in done:
            continue
        if group and t in group:
            j = next(j for j, u in enumerate(front) if u == (group[1] if t == group[0] else
                                                              group[0]) and j != i)
            blocks.append([i, j] if rng.random() < 0.5 else [j, i])
            done |= {i, j}
        else:
            blocks.append([i])
            done.add(i)
    for i, t in enumerate(front):
        (wl, wh), (dl, dh) = ROOM_DIMS[t]
        dims[i] = (_uniform_snap(rng, wl, wh), _uniform_snap(rng, dl, dh))
    if group:
        gi = [i for b in blocks if len(b) == 2 for i in b]
        d = max(dims[i][1] for i in gi)
        for i in gi:
            dims[i] = (dims[i][0], d)
    # sides: each block to the side with less length so far
    sides: dict[str, list[int]] = {"n": [], "s": []}
    for b in blocks:
        ln = sum(dims[i][0] for i in sides["n"])
        ls = sum(dims[i][0] for i in sides["s"])
        sides["n" if ln <= ls else "s"].extend(b)
    total = {s: sum(dims[i][0] for i in sides[s]) for s in sides}
    length = max(total.values())
    # stretch the shorter side's rooms (up to 6 m each) towards the corridor's length
    for s in sides:
        extra = length - total[s]
        for i in sides[s]:
            if extra <= 1e-9:
                break
            grow = min(extra, 6.0 - dims[i][0])
            grow = math.floor(grow * 10 + 1e-9) / 10
            if grow > 0:
                dims[i] = (round(dims[i][0] + grow, 4), dims[i][1])
                extra -= grow
    wc = _uniform_snap(rng, 1.3, 1.7)
    plan = _Plan()
    # corridor rooms
    split_x: list[float] = []
    if n_corr == 2:
        xs, acc = [], 0.0
        for i in sides["n"][:-1]:
            acc += dims[i][0]
            xs.append(round(acc, 4))
        if not xs:
            raise _Retry
        split_x = [min(xs, key=lambda x: (abs(x - length / 2), x))]
    bounds = [0.0, *split_x, round(length, 4)]
    for a, b in zip(bounds[:-1], bounds[1:], strict=True):
        plan.rooms.append(_PRoom(len(plan.rooms), "corridor", _Rect(a, 0.0, b, wc), "c"))
    for a, b in zip(plan.rooms[:-1], plan.rooms[1:], strict=True):
        x = a.rect.x1
        plan.openings.append(_Opening("passage", (x, wc / 2), wc, False, (a.idx, b.idx)))
    # front rooms
    front_room: dict[int, _PRoom] = {}
    for s in ("n", "s"):
        x = 0.0
        for i in sides[s]:
            w, d = dims[i]
            rect = _Rect(x, wc, x + w, wc + d) if s == "n" else _Rect(x, -d, x + w, 0.0)
            r = _PRoom(len(plan.rooms), front[i], _rect_round(rect), s)
            plan.rooms.append(r)
            front_room[i] = r
            x = round(x + w, 4)
    if group:
        for b in blocks:
            if len(b) == 2:
                for i in b:
                    front_room[i].group = "open_0"
    # back rooms behind their hosts (no host twice)
    used: set[int] = set()
    for t, host_type in back:
        hosts = [r for r in front_room.values() if r.type == host_type and r.idx not in used
                 and r.group is None]
        if not hosts:
            raise _Retry
        host = hosts[int(rng.integers(len(hosts)))]
        used.add(host.idx)
        (wl, wh), (dl, dh) = ROOM_DIMS[t]
        w = min(_uniform_snap(rng, wl, wh), host.rect.w)
        d = _uniform_snap(rng, dl, dh)
        left = rng.random() < 0.5
        x0 = host.rect.x0 if left else round(host.rect.x1 - w, 4)
        if host.side == "n":
            rect = _Rect(x0, host.rect.y1, x0 + w, host.rect.y1 + d)
        else:
            rect = _Rect(x0, host.rect.y0 - d, x0 + w, host.rect.y0)
        plan.rooms.append(_PRoom(len(plan.rooms), t, _rect_round(rect), host.side + "b",
                                 host=host.idx))
    _openings(rng, plan)
    return plan


def _rect_round(r: _Rect) -> _Rect:
    return _Rect(round(r.x0, 4), round(r.y0, 4), round(r.x1, 4), round(r.y1, 4))


def _door_center(rng: np.random.Generator, lo: float, hi: float) -> float | None:
    """A door centre on [lo, hi] keeping 0.3 m of wall either side of the opening."""
    a, b = lo + 0.3 + DOOR_W / 2, hi - 0.3 - DOOR_W / 2
    if b < a - 1e-9:
        return None
    return _snap(float(rng.uniform(a, b))) if b > a else _snap(a)


def _openings(rng: np.random.Generator, plan: _Plan) -> None:
    corridors = [r for r in plan.rooms if r.side == "c"]
    wc = corridors[0].rect.y1
    by_idx = {r.idx: r for r in plan.rooms}
    groups: dict[str, list[_PRoom]] = {}
    for r in plan.rooms:
        if r.group:
            groups.setdefault(r.group, []).append(r)
    skip_corridor_door: set[int] = set()
    for members in groups.values():
        a, b = sorted(members, key=lambda r: r.rect.x0)
        x = a.rect.x1
        lo, hi = max(a.rect.y0, b.rect.y0), min(a.rect.y1, b.rect.y1)  # shared wall
        stub = 0.3
        width = round(hi - lo - 2 * stub, 4)
        plan.openings.append(_Opening("passage", (x, round((lo + hi) / 2, 4)), width, False,
                                      (a.idx, b.idx)))
        if rng.random() < 0.5:
            skip_corridor_door.add((a if rng.random() < 0.5 else b).idx)
    for r in plan.rooms:
        if r.side in ("n", "s"):
            if r.idx in skip_corridor_door:
                continue
            y = wc if r.side == "n" else 0.0
            # the corridor room sharing the longest stretch of this room's wall
            best = None
            for c in corridors:
                lo, hi = max(r.rect.x0, c.rect.x0), min(r.rect.x1, c.rect.x1)
                if best is None or hi - lo > best[2] - best[1]:
                    best = (c, lo, hi)
            assert best is not None
            c, lo, hi = best
            x = _door_center(rng, lo, hi)
            if x is None:
                raise _Retry
            state = "closed" if rng.random() < P_CLOSED.get(r.type, P_CLOSED_DEFAULT) else "open"
            plan.openings.append(_Opening("door", (x, y), DOOR_W, True, (c.idx, r.idx), state))
        elif r.side in ("nb", "sb"):
            host = by_idx[r.host]  # type: ignore[index]
            y = r.rect.y0 if r.side == "nb" else r.rect.y1
            x = _door_center(rng, r.rect.x0, r.rect.x1)
            if x is None:
                raise _Retry
            state = "closed" if rng.random() < P_CLOSED.get(r.type, P_CLOSED_DEFAULT) else "open"
            plan.openings.append(_Opening("door", (x, y), DOOR_W, True, (host.idx, r.idx),
                                          state))


def _walls(plan: _Plan) -> list[tuple[tuple[float, float], tuple[float, float]]]:
    """Wall segments: the union of all room edges minus door and passage openings."""
    lines: dict[tuple[bool, float], list[tuple[float, float]]] = {}
    for r in plan.rooms:
        x0, y0, x1, y1 = r.rect.x0, r.rect.y0, r.rect.x1, r.rect.y1
        for horiz, c, a, b in ((True, y0, x0, x1), (True, y1, x0, x1),
                               (False, x0, y0, y1), (False, x1, y0, y1)):
            lines.setdefault((horiz, round(c, 4)), []).append((a, b))
    cuts: dict[tuple[bool, float], list[tuple[float, float]]] = {}
    for o in plan.openings:
        if o.horizontal:
            key = (True, round(o.center[1], 4))
            c = o.center[0]
        else:
            key = (False, round(o.center[0], 4))
            c = o.center[1]
        cuts.setdefault(key, []).append((c - o.width / 2, c + o.width / 2))
    out = []
    for key in sorted(lines):
        horiz, c = key
        merged = _union(lines[key])
        for a, b in _subtract(merged, cuts.get(key, [])):
            if b - a < 0.05 - 1e-9:
                continue
            a, b = round(a, 4), round(b, 4)
            out.append(((a, c), (b, c)) if horiz else ((c, a), (c, b)))
    return out


def _union(iv: list[tuple[float, float]]) -> list[tuple[float, float]]:
    iv = sorted(iv)
    out: list[list[float]] = []
    for a, b in iv:
        if out and a <= out[-1][1] + 1e-9:
            out[-1][1] = max(out[-1][1], b)
        else:
            out.append([a, b])
    return [(a, b) for a, b in out]


def _subtract(iv: list[tuple[float, float]],
              cuts: list[tuple[float, float]]) -> list[tuple[float, float]]:
    out = []
    for a, b in iv:
        pieces = [(a, b)]
        for ca, cb in sorted(cuts):
            nxt = []
            for pa, pb in pieces:
                if cb <= pa + 1e-9 or ca >= pb - 1e-9:
                    nxt.append((pa, pb))
                    continue
                if ca > pa:
                    nxt.append((pa, ca))
                if cb < pb:
                    nxt.append((cb, pb))
            pieces = nxt
        out += pieces
    return out


# ----------------------------------------------------------------------------------------
# furniture
# ----------------------------------------------------------------------------------------
class _RoomSpace:
    """Free-space bookkeeping of one room for the placement checks."""

    def __init__(self, room: _PRoom, openings: list[_Opening]):
        self.room = room
        self.inner = room.rect.shrink(WALL_T / 2)
        self.cols = int(round(self.inner.w / _RES))
        self.rows = int(round(self.inner.h / _RES))
        self.occ = np.zeros((self.rows, self.cols), bool)
        self.keepouts: list[_Rect] = []
        self.approach: list[tuple[int, int]] = []
        for o in openings:
            if room.idx not in o.rooms:
                continue
            c, half = o.center, o.width / 2 + 0.15
            depth = 1.0
            if o.horizontal:
                inward = 1.0 if c[1] <= room.rect.y0 + 1e-6 else -1.0
                y_in = c[1] + inward * depth
                self.keepouts.append(_Rect(c[0] - half, min(c[1], y_in), c[0] + half,
                                           max(c[1], y_in)))
                ap = (c[0], c[1] + inward * 0.4)
            else:
                inward = 1.0 if c[0] <= room.rect.x0 + 1e-6 else -1.0
                x_in = c[0] + inward * depth
                self.keepouts.append(_Rect(min(c[0], x_in), c[1] - half, max(c[0], x_in),
                                           c[1] + half))
                ap = (c[0] + inward * 0.4, c[1])
            self.approach.append(self.cell(*ap))

    def cell(self, x: float, y: float) -> tuple[int, int]:
        r = int(math.floor((y - self.inner.y0) / _RES))
        c = int(math.floor((x - self.inner.x0) / _RES))
        return (min(max(r, 0), self.rows - 1), min(max(c, 0), self.cols - 1))

    def _mask(self, box: _Rect) -> tuple[slice, slice]:
        c0 = max(int(math.floor((box.x0 - self.inner.x0) / _RES + 1e-6)), 0)
        c1 = min(int(math.ceil((box.x1 - self.inner.x0) / _RES - 1e-6)), self.cols)
        r0 = max(int(math.floor((box.y0 - self.inner.y0) / _RES + 1e-6)), 0)
        r1 = min(int(math.ceil((box.y1 - self.inner.y0) / _RES - 1e-6)), self.rows)
        return slice(r0, r1), slice(c0, c1)

    def free_ok(self, boxes_to_reach: Sequence[_Rect], extra: _Rect | None) -> bool:
        """Can the robot cross between all openings and reach every box within REACH?"""
        occ = self.occ.copy()
        if extra is not None:
            occ[self._mask(extra)] = True
        padded = np.pad(occ, 1, constant_values=True)  # the walls
        dist = ndimage.distance_transform_edt(~padded, sampling=_RES)[1:-1, 1:-1]
        free = dist >= ROBOT_RADIUS + _RES / 2 - 1e-9
        labels, _ = ndimage.label(free, structure=np.ones((3, 3), bool))
        if not self.approach:
            return True
        lab = {int(labels[a]) for a in self.approach}
        if 0 in lab or len(lab) != 1:
            return False
        main = labels == lab.pop()
        if not boxes_to_reach:
            return True
        ys = self.inner.y0 + (np.arange(self.rows) + 0.5) * _RES
        xs = self.inner.x0 + (np.arange(self.cols) + 0.5) * _RES
        for b in boxes_to_reach:
            dx = np.maximum(np.maximum(b.x0 - xs, xs - b.x1), 0.0)
            dy = np.maximum(np.maximum(b.y0 - ys, ys - b.y1), 0.0)
            near = (dy[:, None] ** 2 + dx[None, :] ** 2) <= (REACH - ROBOT_RADIUS) ** 2
            # the robot centre within REACH - radius of the box: its body within REACH
            if not (near & main).any():
                return False
        return True

    def add(self, box: _Rect) -> None:
        self.occ[self._mask(box)] = True


def _furniture_list(rng: np.random.Generator, room_type: str, inv: _Inventory) -> list[str]:
    rows = inv.furniture.get(room_type, ())
    out: list[str] = []
    for f in rows:
        if rng.random() >= f.frequency:
            continue
        cap = MAX_PER_ROOM.get(f.synset, DEFAULT_MAX_PER_ROOM)
        n = 1 + int(rng.poisson(max(f.mean_count - 1.0, 0.0)))
        out += [f.synset] * min(n, cap)
    if room_type != "corridor" and not any(_useful(s, inv) for s in out):
        useful = [f.synset for f in rows if _useful(f.synset, inv)]
        if useful:
            out.append(useful[0])
    return out


def _useful(synset: str, inv: _Inventory) -> bool:
    a = inv.knowledge.affordances.get(synset, ())
    return "container" in a or "supporter" in a


def _jitter(rng: np.random.Generator, size: tuple[float, float, float]
            ) -> tuple[float, float, float]:
    f = rng.uniform(0.92, 1.08, size=3)
    return tuple(round(float(s * k), 2) for s, k in zip(size, f, strict=True))  # type: ignore[return-value]


def _footprint(cx: float, cy: float, w: float, d: float, yaw: float) -> _Rect:
    if abs(math.sin(yaw)) > 0.5:  # rotated by +-90 degrees
        w, d = d, w
    return _Rect(round(cx - w / 2, 4), round(cy - d / 2, 4), round(cx + w / 2, 4),
                 round(cy + d / 2, 4))


def _wall_candidate(rng: np.random.Generator, inner: _Rect, w: float,
                    d: float) -> tuple[float, float, float] | None:
    """(cx, cy, yaw) of a piece of width w (along the wall) and depth d against a wall; the
    piece's front (local +y) faces into the room."""
    side = int(rng.integers(4))
    if side in (0, 1):  # south / north wall: runs along x
        if inner.w < w:
            return None
        cx = _snap(float(rng.uniform(inner.x0 + w / 2, inner.x1 - w / 2)), 0.01)
        cx = min(max(cx, inner.x0 + w / 2), inner.x1 - w / 2)
        if side == 0:
            return (cx, inner.y0 + d / 2, 0.0)
        return (cx, inner.y1 - d / 2, math.pi)
    if inner.h < w:
        return None
    cy = _snap(float(rng.uniform(inner.y0 + w / 2, inner.y1 - w / 2)), 0.01)
    cy = min(max(cy, inner.y0 + w / 2), inner.y1 - w / 2)
    if side == 2:  # west wall, front faces +x
        return (inner.x0 + d / 2, cy, -math.pi / 2)
    return (inner.x1 - d / 2, cy, math.pi / 2)


def _furnish_room(rng: np.random.Generator, room: _PRoom, plan: _Plan, inv: _Inventory,
                  pieces: list[_Piece]) -> None:
    space = _RoomSpace(room, plan.openings)
    wanted = _furniture_list(rng, room.type, inv)
    floor = [s for s in wanted if s not in STACKED_ON]
    stacked = [s for s in wanted if s in STACKED_ON]

    def order_key(s: str) -> tuple[int, float, str]:
        w, d, _ = furniture_size(s)
        group = 2 if s in SEATS else (1 if s in CENTRAL else 0)
        return (group, -w * d, s)

    floor.sort(key=order_key)
    mine: list[_Piece] = []
    for s in floor:
        size = _jitter(rng, furniture_size(s))
        w, d, h = size
        placed = None
        for _ in range(24):
            if s in SEATS and any(p.synset in CENTRAL for p in mine):
                cand = _seat_candidate(rng, [p for p in mine if p.synset in CENTRAL], w, d)
            elif s in CENTRAL and _ < 12:
                m = 0.75
                x0, x1 = space.inner.x0 + m + w / 2, space.inner.x1 - m - w / 2
                y0, y1 = space.inner.y0 + m + d / 2, space.inner.y1 - m - d / 2
                if x1 < x0 or y1 < y0:
                    cand = _wall_candidate(rng, space.inner, w, d)
                else:
                    cand = (_snap(float(rng.uniform(x0, x1)), 0.01),
                            _snap(float(rng.uniform(y0, y1)), 0.01), 0.0)
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
            reach = [p.box for p in mine if p.affordances]
            if aff:
                reach.append(box)
            if not space.free_ok(reach, box):
                continue
            placed = _Piece(s, room.idx, box, 0.0, size, yaw % (2 * math.pi), None, False,
                            aff, _initial_state(rng, aff))
            break
        if placed is not None:
            space.add(placed.box)
            mine.append(placed)
    for s in stacked:
        bases = [p for p in mine if p.on is None and not p.top_used
                 and any(a in ancestors(p.synset) for a in STACKED_ON[s])]
        size = _jitter(rng, furniture_size(s))
        bases = [p for p in bases if p.size[0] >= size[0] and p.size[1] >= size[1]]
        if not bases:
            continue
        base = bases[int(rng.integers(len(bases)))]
        base.top_used = True
        cx, cy = (base.box.x0 + base.box.x1) / 2, (base.box.y0 + base.box.y1) / 2
        aff = inv.knowledge.affordances.get(s, ())
        mine.append(_Piece(s, room.idx, _footprint(cx, cy, size[0], size[1], base.yaw),
                           base.z0 + base.size[2], size, base.yaw,
                           len(pieces) + mine.index(base), True, aff,
                           _initial_state(rng, aff)))
    pieces.extend(mine)


def _seat_candidate(rng: np.random.Generator, tables: list[_Piece], w: float,
                    d: float) -> tuple[float, float, float]:
    t = tables[int(rng.integers(len(tables)))]
    side = int(rng.integers(4))
    b = t.box
    gap = 0.05
    if side == 0:  # south of the table, facing +y (north)
        x = float(rng.uniform(b.x0 + w / 2, max(b.x1 - w / 2, b.x0 + w / 2)))
        return (_snap(x, 0.01), b.y0 - gap - d / 2, 0.0)
    if side == 1:
        x = float(rng.uniform(b.x0 + w / 2, max(b.x1 - w / 2, b.x0 + w / 2)))
        return (_snap(x, 0.01), b.y1 + gap + d / 2, math.pi)
    y = float(rng.uniform(b.y0 + w / 2, max(b.y1 - w / 2, b.y0 + w / 2)))
    if side == 2:  # west of the table, facing +x
        return (b.x0 - gap - d / 2, _snap(y, 0.01), -math.pi / 2)
    return (b.x1 + gap + d / 2, _snap(y, 0.01), math.pi / 2)


def _initial_state(rng: np.random.Generator, aff: tuple[str, ...]) -> str | None:
    if "openable" not in aff:
        return None
    return "open" if rng.random() < 0.1 else "closed"


# ----------------------------------------------------------------------------------------
# small objects
# ----------------------------------------------------------------------------------------
def _slots(p: _Piece, relation: str) -> list[tuple[float, float, float, float, float, float]]:
    """Slots (cx, cy, z_floor, sx, sy, sz_max) in world coordinates for a piece."""
    sx, sy, sz = p.size
    out = []
    if relation == "inside":
        wall = 0.03
        ix, iy = sx - 2 * wall, sy - 2 * wall
        ih = sz - 2 * wall
        levels = max(1, int(ih // 0.4))
        lh = ih / levels
        nx, ny = max(1, int(ix // 0.22)), max(1, int(iy // 0.22))
        for lv in range(levels):
            z = p.z0 + wall + lv * lh
            for i in range(nx):
                for j in range(ny):
                    lx = -ix / 2 + (i + 0.5) * ix / nx
                    ly = -iy / 2 + (j + 0.5) * iy / ny
                    out.append((*_to_world(p, lx, ly), z, ix / nx, iy / ny, lh - 0.01))
    else:
        nx, ny = max(1, int(sx // 0.25)), max(1, int(sy // 0.25))
        for i in range(nx):
            for j in range(ny):
                lx = -sx / 2 + (i + 0.5) * sx / nx
                ly = -sy / 2 + (j + 0.5) * sy / ny
                out.append((*_to_world(p, lx, ly), p.z0 + sz, sx / nx, sy / ny, 0.6))
    return out


def _to_world(p: _Piece, lx: float, ly: float) -> tuple[float, float]:
    cx, cy = (p.box.x0 + p.box.x1) / 2, (p.box.y0 + p.box.y1) / 2
    c, s = math.cos(p.yaw), math.sin(p.yaw)
    return (cx + c * lx - s * ly, cy + s * lx + c * ly)


def _place_objects(rng: np.random.Generator, split: str, pieces: list[_Piece],
                   room_types: dict[int, str]) -> list[dict]:
    objs: list[dict] = []
    for pi, p in enumerate(pieces):
        for relation in ("inside", "ontop"):
            if relation == "inside" and "container" not in p.affordances:
                continue
            if relation == "ontop" and ("supporter" not in p.affordances or p.top_used
                                        or p.size[2] > 1.7):
                continue
            names, w = _candidates(split, p.synset, relation, room_types[p.room])
            if not names:
                continue
            lam = LAMBDA_INSIDE if relation == "inside" else LAMBDA_ONTOP
            lam *= min(1.0, len(names) / FULL_POOL)
            slots = _slots(p, relation)
            n = min(int(rng.poisson(lam)), len(slots))
            if n == 0:
                continue
            chosen_slots = sorted(rng.choice(len(slots), size=n, replace=False).tolist())
            for si in chosen_slots:
                cx, cy, z, ssx, ssy, szmax = slots[si]
                syn = names[int(rng.choice(len(names), p=w))]
                bx, by, bz = object_size(syn)
                k = rng.uniform(0.9, 1.1)
                # objects keep the piece's orientation; clip them to the slot
                ox = round(min(bx * k, ssx - 0.02), 3)
                oy = round(min(by * k, ssy - 0.02), 3)
                oz = round(min(bz * k, szmax - 0.01), 3)
                if min(ox, oy, oz) <= 0.005:
                    continue
                objs.append({
                    "category": readable_name(syn), "synset": syn, "parent": f"furn_{pi}",
                    "relation": relation, "room": f"room_{p.room}",
                    "position": [round(cx, 4), round(cy, 4), round(z + oz / 2, 4)],
                    "size": [ox, oy, oz],
                })
    return objs


# ----------------------------------------------------------------------------------------
# assembly
# ----------------------------------------------------------------------------------------
def _spec_dict(seed: int, split: str, plan: _Plan, pieces: list[_Piece], objs: list[dict],
               starts: list[dict]) -> dict:
    rooms = []
    for r in plan.rooms:
        x0, y0, x1, y1 = r.rect.x0, r.rect.y0, r.rect.x1, r.rect.y1
        rooms.append({"id": r.id, "category": r.type,
                      "polygon": [[x0, y0], [x1, y0], [x1, y1], [x0, y1]],
                      "open_plan_group": r.group})
    walls = [{"id": f"wall_{i}", "a": list(a), "b": list(b), "thickness": WALL_T,
              "height": WALL_H} for i, (a, b) in enumerate(_walls(plan))]
    doors, passages = [], []
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
            "size": list(p.size), "yaw": _wrap(p.yaw), "affordances": list(p.affordances),
            "state": p.state,
        })
    objects = [{"id": f"obj_{i}", **o} for i, o in enumerate(objs)]
    return {"version": "1.0", "seed": int(seed), "split": split, "rooms": rooms,
            "walls": walls, "doors": doors, "passages": passages, "furniture": furniture,
            "objects": objects, "starts": starts}


def _wrap(a: float) -> float:
    a = (a + math.pi) % (2 * math.pi) - math.pi
    return math.pi if abs(a + math.pi) < 1e-9 else a


def _starts_and_check(rng: np.random.Generator, spec: HouseSpec) -> list[dict]:
    """A start pose per room (free cell nearest the room's centre, reachable from the
    first corridor with closed doors passable); raises _Retry when a room or a container
    cannot be reached."""
    occ = house_occupancy(spec, closed_doors_free=True, robot_radius=ROBOT_RADIUS)
    c0 = spec.rooms[0].centroid
    dist = geodesic_distances(occ, c0, max_snap=1.0)
    reach = np.isfinite(dist)
    if not reach.any():
        raise _Retry
    rows, cols = occ.shape
    xs = occ.origin[0] + (np.arange(cols) + 0.5) * occ.resolution
    ys = occ.origin[1] + (np.arange(rows) + 0.5) * occ.resolution
    X, Y = np.meshgrid(xs, ys)
    starts = []
    for r in spec.rooms:
        x0, y0, x1, y1 = r.bounds
        inside = (X > x0) & (X < x1) & (Y > y0) & (Y < y1) & reach
        if not inside.any():
            raise _Retry
        cx, cy = r.centroid
        d2 = np.where(inside, (X - cx) ** 2 + (Y - cy) ** 2, np.inf)
        i = int(np.argmin(d2))
        yaw = round(float(rng.uniform(-math.pi, math.pi)), 4)
        starts.append({"x": round(float(X.ravel()[i]), 4), "y": round(float(Y.ravel()[i]), 4),
                       "yaw": yaw, "room": r.id})
    for f in spec.furniture:
        if not f.affordances:
            continue
        (ax, ay), (bx, by) = f.footprint()[0], f.footprint()[2]
        bx0, bx1 = min(ax, bx), max(ax, bx)
        by0, by1 = min(ay, by), max(ay, by)
        dx = np.maximum(np.maximum(bx0 - X, X - bx1), 0.0)
        dy = np.maximum(np.maximum(by0 - Y, Y - by1), 0.0)
        if not ((dx ** 2 + dy ** 2 <= (REACH - ROBOT_RADIUS) ** 2) & reach).any():
            raise _Retry
    return starts


def generate_house(seed: int, rooms: tuple[int, int] = (4, 12), split: str = "eval",
                   max_attempts: int = 40) -> HouseSpec:
    """A furnished house for ``seed`` (see the module docstring). ``rooms`` is the range
    of the room count, corridors included (inclusive, 4..16)."""
    lo, hi = int(rooms[0]), int(rooms[1])
    if not 4 <= lo <= hi <= 16:
        raise SgtoolError(f"rooms: need 4 <= min <= max <= 16, got {lo}-{hi}")
    if split not in ("eval", "train"):
        raise SgtoolError(f"split: expected 'eval' or 'train', got {split!r}")
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0:
        raise SgtoolError(f"seed: expected an integer >= 0, got {seed!r}")
    inv = _inventory(split)
    rng = np.random.default_rng(int(seed))
    n_rooms = int(rng.integers(lo, hi + 1))
    for _ in range(max_attempts):
        try:
            plan = _floor_plan(rng, n_rooms, inv)
            pieces: list[_Piece] = []
            for r in plan.rooms:
                _furnish_room(rng, r, plan, inv, pieces)
            room_types = {r.idx: r.type for r in plan.rooms}
            objs = _place_objects(rng, split, pieces, room_types)
            draft = load_house(_spec_dict(seed, split, plan, pieces, objs, []))
            starts = _starts_and_check(rng, draft)
            return load_house(_spec_dict(seed, split, plan, pieces, objs, starts))
        except _Retry:
            continue
    raise SgtoolError(f"could not build a house for seed {seed} in {max_attempts} attempts")
