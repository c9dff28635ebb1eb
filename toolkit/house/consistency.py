"""Geometric consistency of a house spec, checked after its entries are valid one by one:
the house fits :attr:`SpecLimits.extent`, rooms do not overlap (beyond
:attr:`SpecLimits.room_overlap`), walls lie at the rooms, every door and passage lies on
the border of both its rooms (within :attr:`SpecLimits.opening_offset`), furniture stands
in its room (centre inside, corners within :attr:`SpecLimits.furniture_outside`), start
poses are in their rooms and on free floor (outside every piece of furniture's footprint).
Messages name the field (``doors[0].center: ...``).

Doors and walls agree, so the simulator (walls) and the symbolic benchmark (the room
graph of doors and passages) see the same house: no wall covers a door's or a passage's
opening (the spec's rule "walls have gaps where doors and passages are"; the ends of an
opening may touch a wall within :data:`_OPENING_EDGE`), and when a house has walls, a gap
of :data:`_MIN_GAP` or more in the walls along the border of two rooms needs a door or a
passage joining them. A house without walls is not checked for gaps (walls are
optional), and a room walled off completely is consistent (both see it unreachable).

Rooms are compared pairwise (at most ``limits.rooms``, bounding boxes first); openings
against walls and starts against furniture with a bounding-box filter first (numpy);
everything else is linear in the number of entries times the polygon sizes.
"""

from __future__ import annotations

import math
from collections.abc import Iterator

import numpy as np

from sgtool.errors import SpecError
from sgtool.house.geometry import (
    distance_to_polygon,
    length_in_strip,
    longest_uncovered,
    nearest_edge_direction,
    opening_segment,
    overlap_area,
    shared_borders,
)
from sgtool.house.names import id_note
from sgtool.house.spec import HouseSpec, Opening, SpecLimits

_WALL_MARGIN = 1.0  # m a wall end may lie outside the rooms' bounding box
_OPENING_EDGE = 0.05  # m at each end of an opening a wall may reach into (rounded corners)
_COVERED = 1e-6  # m of an opening inside a wall's body that count as covered
_BORDER_TOL = 0.05  # m two room edges may lie apart and still be one border
_MIN_GAP = 0.3  # m of a border without a wall that connect two rooms (the robot is 0.4 m wide)
_MAX_SKEW_DEG = 10.0  # degrees an opening may lie off the border it sits on


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
                                f"outside the rooms{id_note('walls', i, w.id)}")
    by_room = {r.id: r for r in spec.rooms}
    for key, openings in _openings(spec):
        for i, d in enumerate(openings):
            for rid in d.rooms:  # both rooms first: the yaw is judged only on a shared border
                off = distance_to_polygon(d.center[0], d.center[1], by_room[rid].polygon)
                if off > limits.opening_offset:
                    raise SpecError(f"{key}[{i}].center: ({d.center[0]}, {d.center[1]}) is "
                                    f"{off:.2f} m from its room {rid} (more than "
                                    f"{limits.opening_offset:g} m)"
                                    f"{id_note(key, i, d.id)}")
            for rid in d.rooms:
                # the opening runs along the border (yaw: the wall's direction), so both
                # its ends lie at each of its rooms, not one end inside the other room
                poly = by_room[rid].polygon
                for tip in opening_segment(d.center, d.width, d.yaw):
                    off = distance_to_polygon(tip[0], tip[1], poly)
                    if off <= limits.opening_offset:
                        continue
                    turned = opening_segment(d.center, d.width, d.yaw + math.pi / 2)
                    if max(distance_to_polygon(x, y, poly) for x, y in turned) <= \
                            limits.opening_offset:  # the other direction fits: the yaw
                        raise SpecError(f"{key}[{i}].yaw: {d.yaw:g} rad sets the opening "
                                        f"across the border of {rid}, not along it (an end "
                                        f"{off:.2f} m from the room; yaw is the direction "
                                        f"of the wall it sits in){id_note(key, i, d.id)}")
                    raise SpecError(f"{key}[{i}].center: the opening runs {off:.2f} m past "
                                    f"the room {rid} (a corner, or the end of its border): "
                                    f"move its center along the wall"
                                    f"{id_note(key, i, d.id)}")
                wall = nearest_edge_direction(d.center[0], d.center[1], poly)
                skew = abs(math.remainder(d.yaw - wall, math.pi))
                if math.degrees(skew) > _MAX_SKEW_DEG:
                    raise SpecError(f"{key}[{i}].yaw: {d.yaw:g} rad lies "
                                    f"{math.degrees(skew):.0f} degrees off the border of "
                                    f"{rid} it sits on ({wall:.4g} rad); yaw is the "
                                    f"direction of its wall, in radians"
                                    f"{' (degrees given?)' if abs(d.yaw) > 2 * math.pi else ''}"
                                    f"{id_note(key, i, d.id)}")
    for i, f in enumerate(spec.furniture):
        room = by_room[f.room]
        if not room.contains(f.center[0], f.center[1]):
            raise SpecError(f"furniture[{i}].center: ({f.center[0]}, {f.center[1]}) is outside "
                            f"its room {f.room}{id_note('furniture', i, f.id)}")
        for cx, cy in f.footprint():
            off = distance_to_polygon(cx, cy, room.polygon)
            if off > limits.furniture_outside:
                raise SpecError(f"furniture[{i}].size: a corner ({cx:.2f}, {cy:.2f}) is "
                                f"{off:.2f} m outside its room {f.room} (more than "
                                f"{limits.furniture_outside:g} m)"
                                f"{id_note('furniture', i, f.id)}")
    for i, s in enumerate(spec.starts):
        if not by_room[s.room].contains(s.x, s.y):
            raise SpecError(f"starts[{i}]: ({s.x}, {s.y}) is outside its room {s.room}")
    _starts_on_free_floor(spec)
    _openings_clear(spec)
    _gaps_have_openings(spec)


def _openings(spec: HouseSpec) -> tuple[tuple[str, tuple[Opening, ...]], ...]:
    """The spec's doors and passages, each list with its key for messages."""
    return (("doors", spec.doors), ("passages", spec.passages))


def _boxes(boxes: list[tuple[float, float, float, float]]) -> np.ndarray:
    return np.asarray(boxes, dtype=np.float64).reshape(-1, 4)


def _starts_on_free_floor(spec: HouseSpec) -> None:
    """No start pose inside a wall's body, a closed door's leaf or a piece of furniture's
    footprint (the robot could not move, or the simulator pushes it out of the house)."""
    from sgtool.house.clearance import Covers
    from sgtool.house.geometry import segment_distance

    if not spec.starts:
        return
    covers = Covers(spec)
    for i, s in enumerate(spec.starts):
        what = covers.at(s.x, s.y)
        if what is not None and what[0] == "walls":
            w = spec.walls[what[1]]
            raise SpecError(f"starts[{i}]: ({s.x}, {s.y}) is inside walls[{what[1]}] ({w.id}); "
                            "a start pose must be on free floor")
        if what is not None:
            f = spec.furniture[what[1]]
            raise SpecError(f"starts[{i}]: ({s.x}, {s.y}) is inside furniture[{what[1]}] "
                            f"({f.id}, {f.category}); a start pose must be on free floor")
        for j, d in enumerate(spec.doors):
            if not d.is_open and segment_distance(s.x, s.y, *d.segment) <= d.thickness / 2:
                raise SpecError(f"starts[{i}]: ({s.x}, {s.y}) is inside doors[{j}] ({d.id}, "
                                "closed); a start pose must be on free floor")


def _openings_clear(spec: HouseSpec) -> None:
    """No wall body covers a door's or a passage's opening (but its ends)."""
    if not spec.walls:
        return
    walls = spec.walls
    boxes = _boxes([(min(w.a[0], w.b[0]) - w.thickness / 2, min(w.a[1], w.b[1]) - w.thickness / 2,
                     max(w.a[0], w.b[0]) + w.thickness / 2, max(w.a[1], w.b[1]) + w.thickness / 2)
                    for w in walls])
    for key, openings in _openings(spec):
        for i, d in enumerate(openings):
            p, q = opening_segment(d.center, d.width, d.yaw)
            x0, x1 = min(p[0], q[0]), max(p[0], q[0])
            y0, y1 = min(p[1], q[1]), max(p[1], q[1])
            near = np.flatnonzero((boxes[:, 0] <= x1) & (x0 <= boxes[:, 2])
                                  & (boxes[:, 1] <= y1) & (y0 <= boxes[:, 3]))
            for k in near:
                w = walls[k]
                # a wall meeting the opening's end (a corner, a jamb) reaches in by half its
                # thickness: only the opening's inner part counts (at least its middle half)
                edge = _OPENING_EDGE + w.thickness / 2
                a, b = opening_segment(d.center, max(d.width - 2 * edge, d.width / 2), d.yaw)
                if length_in_strip(a, b, w.a, w.b, w.thickness / 2) > _COVERED:
                    covered = length_in_strip(p, q, w.a, w.b, w.thickness / 2)
                    raise SpecError(f"{key}[{i}]: its opening ({d.id}) is covered by "
                                    f"walls[{k}] ({w.id}) over {covered:.2f} m of its "
                                    f"{d.width:.2f} m; walls have gaps where doors and "
                                    "passages are")


def _gaps_have_openings(spec: HouseSpec) -> None:
    """A gap in the walls between two rooms is a door or a passage of the spec."""
    for j, i, gap, (gx, gy) in wall_gaps(spec):
        raise SpecError(f"rooms[{j}]: the walls between {spec.rooms[j].id} and "
                        f"{spec.rooms[i].id} have a {gap:.2f} m gap at ({gx:.2f}, "
                        f"{gy:.2f}) but no door or passage joins them")


def wall_gaps(spec: HouseSpec, beside: float | None = None
              ) -> Iterator[tuple[int, int, float, tuple[float, float]]]:
    """The gaps of at least 0.3 m in the walls along the shared border of two rooms, as
    (room index j, room index i < j, the longest gap's length in m, its centre): between
    rooms no door or passage joins (``beside`` None), else between joined rooms beside
    their openings (each of the pair's doors and passages covering the border within
    ``beside`` m of its segment): a hole in the wall a closed door does not close."""
    if not spec.walls:
        return
    rooms, graph = spec.rooms, spec.room_graph()
    walls = [(w.a, w.b, w.thickness / 2) for w in spec.walls]
    boxes = _boxes([(min(a[0], b[0]) - h, min(a[1], b[1]) - h, max(a[0], b[0]) + h,
                     max(a[1], b[1]) + h) for a, b, h in walls])
    near_by = [r.bounds for r in rooms]
    openings = [o for _, ops in _openings(spec) for o in ops]
    t = _BORDER_TOL
    for j in range(len(rooms)):
        for i in range(j):
            a, b = near_by[i], near_by[j]
            if a[0] > b[2] + t or b[0] > a[2] + t or a[1] > b[3] + t or b[1] > a[3] + t \
                    or (rooms[i].id in graph[rooms[j].id]) != (beside is not None):
                continue
            pair = {rooms[i].id, rooms[j].id}
            spans = [] if beside is None else [
                (*o.segment, beside) for o in openings if set(o.rooms) == pair]
            for p, q in shared_borders(rooms[j].polygon, rooms[i].polygon, t):
                x0, x1 = min(p[0], q[0]) - t, max(p[0], q[0]) + t
                y0, y1 = min(p[1], q[1]) - t, max(p[1], q[1]) + t
                near = np.flatnonzero((boxes[:, 0] <= x1) & (x0 <= boxes[:, 2])
                                      & (boxes[:, 1] <= y1) & (y0 <= boxes[:, 3]))
                gap, where = longest_uncovered(p, q, [walls[k] for k in near] + spans, t)
                if gap >= _MIN_GAP:
                    yield j, i, gap, where


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
