"""Doors and passages of a generated floor plan: an open-plan passage between grouped
rooms, a door from each front room to the corridor it shares most wall with, a door from
each back room to its host; doors are closed with a per-room-type probability."""

from __future__ import annotations

import numpy as np

from sgtool.datasets.house_plan import DOOR_W, Opening, Plan, PlanRetry, PlanRoom, snap

P_CLOSED = {"bedroom": 0.35, "bathroom": 0.4, "closet": 0.45, "storage_room": 0.45,
            "pantry_room": 0.35, "utility_room": 0.35, "garage": 0.45, "childs_room": 0.3,
            "private_office": 0.3}
P_CLOSED_DEFAULT = 0.15


def _door_center(rng: np.random.Generator, lo: float, hi: float) -> float | None:
    """A door centre on [lo, hi] keeping 0.3 m of wall either side of the opening."""
    a, b = lo + 0.3 + DOOR_W / 2, hi - 0.3 - DOOR_W / 2
    if b < a - 1e-9:
        return None
    return snap(float(rng.uniform(a, b))) if b > a else snap(a)


def place_openings(rng: np.random.Generator, plan: Plan) -> None:
    """Add the open-plan passages and the doors of every front and back room to ``plan``;
    raises :class:`PlanRetry` when a wall is too short for a door."""
    corridors = [r for r in plan.rooms if r.side == "c"]
    wc = corridors[0].rect.y1
    by_idx = {r.idx: r for r in plan.rooms}
    groups: dict[str, list[PlanRoom]] = {}
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
        plan.openings.append(Opening("passage", (x, round((lo + hi) / 2, 4)), width, False,
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
            door_x = _door_center(rng, lo, hi)
            if door_x is None:
                raise PlanRetry
            state = "closed" if rng.random() < P_CLOSED.get(r.type, P_CLOSED_DEFAULT) else "open"
            plan.openings.append(Opening("door", (door_x, y), DOOR_W, True, (c.idx, r.idx),
                                          state))
        elif r.side in ("nb", "sb"):
            assert r.host is not None, "a back room names its host"
            host = by_idx[r.host]
            y = r.rect.y0 if r.side == "nb" else r.rect.y1
            door_x = _door_center(rng, r.rect.x0, r.rect.x1)
            if door_x is None:
                raise PlanRetry
            state = "closed" if rng.random() < P_CLOSED.get(r.type, P_CLOSED_DEFAULT) else "open"
            plan.openings.append(Opening("door", (door_x, y), DOOR_W, True, (host.idx, r.idx),
                                          state))
