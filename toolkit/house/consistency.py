"""Geometric consistency of a house spec, checked after its entries are valid one by one:
the house fits :attr:`SpecLimits.extent`, rooms do not overlap (beyond
:attr:`SpecLimits.room_overlap`), walls lie at the rooms, every door and passage lies on
the border of both its rooms (within :attr:`SpecLimits.opening_offset`), furniture stands
in its room (centre inside, corners within :attr:`SpecLimits.furniture_outside`), start
poses are in their rooms. Messages name the field (``doors[0].center: ...``).

Rooms are compared pairwise (at most ``limits.rooms``, bounding boxes first); everything
else is linear in the number of entries times the polygon sizes.
"""

from __future__ import annotations

from sgtool.errors import SpecError
from sgtool.house.geometry import distance_to_polygon, overlap_area
from sgtool.house.spec import HouseSpec, SpecLimits

_WALL_MARGIN = 1.0  # m a wall end may lie outside the rooms' bounding box


def check_consistency(spec: HouseSpec, limits: SpecLimits) -> None:
    """Raise :class:`SpecError` naming the first inconsistent field."""
    x0, y0, x1, y1 = spec.bounds()
    if x1 - x0 > limits.extent or y1 - y0 > limits.extent:
        raise SpecError(f"rooms: the house spans {x1 - x0:g} m x {y1 - y0:g} m, more than "
                        f"the limit of {limits.extent:g} m")
    _rooms_apart(spec, limits.room_overlap)
    for i, w in enumerate(spec.walls):
        for end, (x, y) in (("a", w.a), ("b", w.b)):
            if not (x0 - _WALL_MARGIN <= x <= x1 + _WALL_MARGIN
                    and y0 - _WALL_MARGIN <= y <= y1 + _WALL_MARGIN):
                raise SpecError(f"walls[{i}].{end}: ({x}, {y}) is more than {_WALL_MARGIN:g} m "
                                "outside the rooms")
    by_room = {r.id: r for r in spec.rooms}
    for key, openings in (("doors", spec.doors), ("passages", spec.passages)):
        for i, d in enumerate(openings):
            for rid in d.rooms:
                off = distance_to_polygon(d.center[0], d.center[1], by_room[rid].polygon)
                if off > limits.opening_offset:
                    raise SpecError(f"{key}[{i}].center: ({d.center[0]}, {d.center[1]}) is "
                                    f"{off:.2f} m from its room {rid} (more than "
                                    f"{limits.opening_offset:g} m)")
    for i, f in enumerate(spec.furniture):
        room = by_room[f.room]
        if not room.contains(f.center[0], f.center[1]):
            raise SpecError(f"furniture[{i}].center: ({f.center[0]}, {f.center[1]}) is outside "
                            f"its room {f.room}")
        for cx, cy in f.footprint():
            off = distance_to_polygon(cx, cy, room.polygon)
            if off > limits.furniture_outside:
                raise SpecError(f"furniture[{i}].size: a corner ({cx:.2f}, {cy:.2f}) is "
                                f"{off:.2f} m outside its room {f.room} (more than "
                                f"{limits.furniture_outside:g} m)")
    for i, s in enumerate(spec.starts):
        if not by_room[s.room].contains(s.x, s.y):
            raise SpecError(f"starts[{i}]: ({s.x}, {s.y}) is outside its room {s.room}")


def _rooms_apart(spec: HouseSpec, tolerance: float) -> None:
    rooms = spec.rooms
    boxes = [r.bounds for r in rooms]
    for j in range(len(rooms)):
        for i in range(j):
            a, b = boxes[i], boxes[j]
            if a[0] >= b[2] or b[0] >= a[2] or a[1] >= b[3] or b[1] >= a[3]:
                continue
            shared = overlap_area(rooms[i].polygon, rooms[j].polygon)
            if shared > tolerance:
                raise SpecError(f"rooms[{j}].polygon: overlaps rooms[{i}] ({rooms[i].id}) by "
                                f"{shared:.2f} m^2 (more than {tolerance:g} m^2)")
