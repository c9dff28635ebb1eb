"""The house generator's programme and floor plan (step 1 and 2 of
:mod:`sgtool.datasets.generator`): which rooms, their sizes, a double-loaded corridor with
rooms on both sides, back rooms behind their hosts, an optional open-plan kitchen."""

from __future__ import annotations

import math
from collections import Counter

import numpy as np

from sgtool.datasets.house_inventory import Inventory
from sgtool.datasets.house_plan import (
    HOUSE_ROOM_TYPES,
    ROOM_DIMS,
    Opening,
    Plan,
    PlanRetry,
    PlanRoom,
    Rect,
    uniform_snap,
)
from sgtool.datasets.openings import place_openings

MAX_OF_TYPE = {"kitchen": 1, "living_room": 1, "dining_room": 1, "garage": 1, "entryway": 1,
               "bedroom": 3, "bathroom": 3, "childs_room": 2, "closet": 2}
CORE = ("kitchen", "living_room", "bathroom", "bedroom")
# back rooms: type -> host types
BACK_HOSTS = {"closet": ("bedroom", "childs_room"), "bathroom": ("bedroom",),
              "pantry_room": ("kitchen",), "storage_room": ("garage", "utility_room", "kitchen")}
OPEN_PLAN_PARTNERS = ("living_room", "dining_room")


def _programme(rng: np.random.Generator, m: int, inv: Inventory) -> list[str]:
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


def floor_plan(rng: np.random.Generator, n_rooms: int, inv: Inventory) -> Plan:
    """Rooms and openings of an ``n_rooms`` house (corridors included) for ``inv``'s
    split; raises :class:`PlanRetry` when the draw cannot be laid out."""
    n_corr = 1 if n_rooms <= 7 else 2 if n_rooms <= 16 else 3
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
        host_types = BACK_HOSTS.get(t)
        if not host_types or (group and t in group) or rng.random() >= 0.45:
            continue
        if t == "bathroom" and sum(1 for x in front if x == "bathroom") < 2:
            continue
        used_hosts = Counter(h for _, h in back)
        avail = [h for h in host_types if front.count(h) > used_hosts[h]
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
        dims[i] = (uniform_snap(rng, wl, wh), uniform_snap(rng, dl, dh))
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
    wc = uniform_snap(rng, 1.3, 1.7)
    plan = Plan()
    # corridor rooms
    split_x: list[float] = []
    if n_corr > 1:
        xs, acc = [], 0.0
        for i in sides["n"][:-1]:
            acc += dims[i][0]
            xs.append(round(acc, 4))
        if not xs:
            raise PlanRetry
        for k in range(1, n_corr):
            left = [x for x in xs if not split_x or x > split_x[-1]]
            if not left:
                raise PlanRetry
            target = length * k / n_corr
            split_x.append(min(left, key=lambda x: (abs(x - target), x)))
    bounds = [0.0, *split_x, round(length, 4)]
    for lo, hi in zip(bounds[:-1], bounds[1:], strict=True):
        plan.rooms.append(PlanRoom(len(plan.rooms), "corridor", Rect(lo, 0.0, hi, wc), "c"))
    for west, east in zip(plan.rooms[:-1], plan.rooms[1:], strict=True):
        x = west.rect.x1
        plan.openings.append(Opening("passage", (x, wc / 2), wc, False, (west.idx, east.idx)))
    # front rooms
    front_room: dict[int, PlanRoom] = {}
    for s in ("n", "s"):
        x = 0.0
        for i in sides[s]:
            w, d = dims[i]
            rect = Rect(x, wc, x + w, wc + d) if s == "n" else Rect(x, -d, x + w, 0.0)
            r = PlanRoom(len(plan.rooms), front[i], _rounded_rect(rect), s)
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
            raise PlanRetry
        host = hosts[int(rng.integers(len(hosts)))]
        used.add(host.idx)
        (wl, wh), (dl, dh) = ROOM_DIMS[t]
        w = min(uniform_snap(rng, wl, wh), host.rect.width)
        d = uniform_snap(rng, dl, dh)
        flush_left = rng.random() < 0.5
        x0 = host.rect.x0 if flush_left else round(host.rect.x1 - w, 4)
        if host.side == "n":
            rect = Rect(x0, host.rect.y1, x0 + w, host.rect.y1 + d)
        else:
            rect = Rect(x0, host.rect.y0 - d, x0 + w, host.rect.y0)
        plan.rooms.append(PlanRoom(len(plan.rooms), t, _rounded_rect(rect), host.side + "b",
                                 host=host.idx))
    place_openings(rng, plan)
    return plan


def _rounded_rect(r: Rect) -> Rect:
    return Rect(round(r.x0, 4), round(r.y0, 4), round(r.x1, 4), round(r.y1, 4))
