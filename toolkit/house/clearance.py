"""Room around what the robot must reach (pure geometry on a house spec): a container's or
shelf's front, and a start pose.

A container opens, and is looked into, through its front: the box's local +y face
(:mod:`sgtool.house.spec`). :func:`blocked_fronts` finds the pieces whose front a wall,
another piece or the room's border covers: the point :data:`FRONT_CLEAR` in front of the
middle of the front face is outside the piece's room, within a wall's body or inside
another piece's footprint (a cabinet set with its back to the room), not counting a piece
under it (the table a box stands on). :func:`cramped_starts` finds the start poses nearer
to a wall or a piece than the robot's radius, and :func:`clear_start` the nearest place
clear of them, where the simulator puts the robot. :func:`hidden_pieces` finds the pieces
no camera can see: a box whose top lies under the floor, or one inside another piece's box.
:func:`pieces_in_walls` finds the pieces whose footprint reaches through a wall, past its
far face (a piece through a wall stands in two rooms; set against a wall, or into its
body up to the middle line that is a room's border, it does not). :func:`walls_in_rooms`
finds the walls that run through a room's inside rather than along its border.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from sgtool.house.geometry import (
    box_corners,
    clip_convex,
    distance_to_border,
    distance_to_polygon,
    opening_segment,
    overlap_area,
    point_in_polygon,
    segment_distance,
    signed_area,
)
from sgtool.house.spec import Furniture, HouseSpec

FRONT_CLEAR = 0.3  # m in front of a front face that must be open floor
IN_WALL_AREA = 0.01  # m^2 of a footprint past a wall's far face that is more than touching
IN_WALL_DEPTH = 0.05  # m a footprint's corner past a wall's far face that is more than touching
THROUGH_STRIP = 0.5  # m beyond a wall's far face looked at for a piece reaching through
INSIDE_CLEAR = 0.15  # m from a room's border where a wall is inside the room
INSIDE_LEAST = 0.3  # m of a wall inside a room that is more than a corner's overlap
CLEAR_SEARCH = 1.0  # m around a cramped start searched for a clear place (clear_start)
CORNER_WALL = 0.1  # m of wall a door needs beside it at a room's corner (doors_at_corners)
IN_LINE_BEYOND = 0.15  # m past a door's end where a wall in line with it is looked for


def front_point(f: Furniture, clear: float = FRONT_CLEAR) -> tuple[float, float]:
    """The point ``clear`` metres in front of the middle of ``f``'s front (local +y) face."""
    d = f.size[1] / 2.0 + clear
    return (f.center[0] - math.sin(f.yaw) * d, f.center[1] + math.cos(f.yaw) * d)


class Covers:
    """What covers floor points of one house: walls' bodies and pieces' footprints, found
    through their bounding boxes first (numpy), then exactly."""

    def __init__(self, spec: HouseSpec) -> None:
        self.spec = spec
        self.feet = [f.footprint() for f in spec.furniture]
        self.fbox = np.array([(min(p[0] for p in c), min(p[1] for p in c),
                               max(p[0] for p in c), max(p[1] for p in c))
                              for c in self.feet], dtype=float).reshape(-1, 4)
        self.wbox = np.array([(min(w.a[0], w.b[0]) - w.thickness / 2,
                               min(w.a[1], w.b[1]) - w.thickness / 2,
                               max(w.a[0], w.b[0]) + w.thickness / 2,
                               max(w.a[1], w.b[1]) + w.thickness / 2)
                              for w in spec.walls], dtype=float).reshape(-1, 4)

    @staticmethod
    def _near(box: np.ndarray, x: float, y: float, pad: float = 0.0) -> np.ndarray:
        return np.flatnonzero((box[:, 0] - pad <= x) & (x <= box[:, 2] + pad)
                              & (box[:, 1] - pad <= y) & (y <= box[:, 3] + pad))

    def at(self, x: float, y: float, skip: int = -1,
           above: float | None = None) -> tuple[str, int] | None:
        """What covers the floor point (x, y): ("walls", index) of a wall whose body holds
        it, else ("furniture", index) of a piece whose footprint does (not ``skip``, nor,
        given ``above``, a piece whose top is at or under that height), else None."""
        for j in self._near(self.wbox, x, y):
            w = self.spec.walls[j]
            if segment_distance(x, y, w.a, w.b) <= w.thickness / 2.0:
                return "walls", int(j)
        for k in self._near(self.fbox, x, y):
            if k == skip or (above is not None and self.spec.furniture[k].top <= above):
                continue
            if point_in_polygon(x, y, self.feet[k]):
                return "furniture", int(k)
        return None

    def gap(self, x: float, y: float, radius: float) -> float:
        """Distance from (x, y) to the nearest wall body or footprint, ``radius`` when none
        is nearer."""
        walls = self.spec.walls
        gaps = [segment_distance(x, y, walls[j].a, walls[j].b) - walls[j].thickness / 2.0
                for j in self._near(self.wbox, x, y, radius)]
        gaps += [distance_to_polygon(x, y, self.feet[k])
                 for k in self._near(self.fbox, x, y, radius)]
        return min(gaps, default=radius)


def back_is_clear(spec: HouseSpec, k: int) -> bool:
    """Whether piece ``k`` turned about (yaw + pi) would face open floor of its room: the
    advice for a blocked front, which a piece backed against a wall cannot take."""
    f = spec.furniture[k]
    x, y = front_point(replace(f, yaw=f.yaw + math.pi))
    return point_in_polygon(x, y, spec.room(f.room).polygon) and \
        Covers(spec).at(x, y, skip=k) is None


def blocked_fronts(spec: HouseSpec) -> list[tuple[int, str]]:
    """(furniture index, what covers it: a wall's or piece's id, or "the room's border")
    for each container or shelved piece whose front is blocked (module doc), spec order."""
    covers = Covers(spec)
    out = []
    for k, f in enumerate(spec.furniture):
        if not (f.is_container or f.levels):
            continue
        x, y = front_point(f)
        if not point_in_polygon(x, y, spec.room(f.room).polygon):
            out.append((k, "the room's border"))
        elif (what := covers.at(x, y, skip=k, above=f.bottom + 1e-6)) is not None:
            kind, i = what
            out.append((k, spec.walls[i].id if kind == "walls" else spec.furniture[i].id))
    return out


def cramped_starts(spec: HouseSpec, radius: float) -> list[tuple[int, float]]:
    """(start index, clearance in m) of the starts whose robot disc of ``radius`` overlaps
    a wall's body or a piece's footprint, in spec order."""
    covers = Covers(spec)
    out = []
    for i, s in enumerate(spec.starts):
        gap = covers.gap(s.x, s.y, radius)
        if gap < radius:
            out.append((i, max(gap, 0.0)))
    return out


def clear_start(spec: HouseSpec, x: float, y: float, radius: float,
                search: float = CLEAR_SEARCH) -> tuple[float, float]:
    """Where the robot disc of ``radius`` at (x, y) overlaps no wall body or footprint:
    (x, y) itself when it does not, else the nearest such point within ``search`` metres
    (rings 1 cm apart, 64 directions from +x counter-clockwise: the first found) in the
    room holding (x, y), if any; (x, y) when there is none. A start set against a wall
    would put the camera's near plane past the wall (it would see through it)."""
    covers = Covers(spec)
    if covers.gap(x, y, radius) >= radius:
        return x, y
    room = next((r.polygon for r in spec.rooms if point_in_polygon(x, y, r.polygon)), None)
    angles = np.arange(64) * (2.0 * math.pi / 64)
    for d in np.arange(1, int(round(search / 0.01)) + 1) * 0.01:
        for a in angles:
            px, py = x + d * math.cos(a), y + d * math.sin(a)
            if (room is None or point_in_polygon(px, py, room)) and \
                    covers.gap(px, py, radius) >= radius:
                return float(px), float(py)
    return x, y


def hidden_pieces(spec: HouseSpec) -> list[tuple[int, str]]:
    """(furniture index, why) of the pieces the simulator shows nothing of, in spec order:
    a box whose top lies under the floor, or one inside another piece's box (its footprint
    within the other's, its height within the other's). What they hold is never seen in
    a recording, while the symbolic bench, which reads the spec, finds it."""
    covers = Covers(spec)
    out = []
    for k, f in enumerate(spec.furniture):
        if f.top <= 0.0:
            out.append((k, f"its box lies under the floor (top at z = {f.top:g} m)"))
            continue
        box = covers.fbox[k]
        near = np.flatnonzero((covers.fbox[:, 0] <= box[0]) & (covers.fbox[:, 1] <= box[1])
                              & (covers.fbox[:, 2] >= box[2]) & (covers.fbox[:, 3] >= box[3]))
        for j in near.tolist():
            g = spec.furniture[j]
            if j != k and g.bottom <= f.bottom + 1e-6 and f.top <= g.top + 1e-6 and all(
                    point_in_polygon(x, y, covers.feet[j]) for x, y in covers.feet[k]):
                out.append((k, f"its box lies inside furniture[{j}] ({g.id}, {g.category})"))
                break
    return out


def pieces_in_walls(spec: HouseSpec) -> list[tuple[int, str, float, float]]:
    """(furniture index, wall id, m^2 of its footprint past the wall's far face, m its
    farthest corner there lies past it) for each piece that reaches through a wall: at
    least ``IN_WALL_AREA`` of its footprint, or a corner ``IN_WALL_DEPTH`` deep (a piece
    turned against the wall pokes a small corner through), lies in the strip
    ``THROUGH_STRIP`` m deep beyond the face of the wall's body away from the piece's
    centre (along the wall but a thickness from either end, where it may meet another
    wall); in spec order. A piece set against a wall, or into its body up to its middle
    line (a room's border), reaches nothing there."""
    covers = Covers(spec)
    out = []
    for k, feet in enumerate(covers.feet):
        b = covers.fbox[k]
        near = np.flatnonzero((covers.wbox[:, 0] < b[2]) & (b[0] < covers.wbox[:, 2])
                              & (covers.wbox[:, 1] < b[3]) & (b[1] < covers.wbox[:, 3]))
        f = spec.furniture[k]
        for j in near.tolist():
            w = spec.walls[j]
            nx, ny = -math.sin(w.yaw), math.cos(w.yaw)  # the wall's normal
            mx, my = (w.a[0] + w.b[0]) / 2, (w.a[1] + w.b[1]) / 2
            side = 1.0 if (f.center[0] - mx) * nx + (f.center[1] - my) * ny > 0 else -1.0
            shift = -side * (w.thickness + THROUGH_STRIP) / 2
            # not the ends, where the wall may meet another (a T), whose body it enters
            inner = w.length - 2.0 * w.thickness
            if inner <= 0.0:
                continue
            strip = box_corners((mx + nx * shift, my + ny * shift), (inner, THROUGH_STRIP),
                                w.yaw)
            area = overlap_area(feet, strip)
            if area <= 0.0:
                continue
            # how far past the far face the footprint reaches within the strip
            ccw = strip if signed_area(strip) > 0 else strip[::-1]
            depth = max((-side * ((x - mx) * nx + (y - my) * ny) - w.thickness / 2
                         for x, y in clip_convex(feet, ccw)), default=0.0)
            if area >= IN_WALL_AREA or depth >= IN_WALL_DEPTH:
                out.append((k, w.id, area, depth))
    return out


def walls_in_rooms(spec: HouseSpec, step: float = 0.05
                   ) -> list[tuple[str, tuple[int, ...], float]]:
    """(room id, wall indices, metres of those walls inside the room) for each room that
    walls run through, at least ``INSIDE_LEAST`` m of them in all (a wall drawn as short
    pieces counts whole) farther than ``INSIDE_CLEAR`` from its border (the middles of
    pieces about ``step`` m long), in room order: walls that cut a room in two, or stand
    in its middle, where walls run along rooms' borders."""
    out = []
    for r in spec.rooms:
        poly = r.polygon
        px, py = [p[0] for p in poly], [p[1] for p in poly]
        walls, total = [], 0.0
        for i, w in enumerate(spec.walls):
            n = max(1, int(round(w.length / step)))
            t = (np.arange(n) + 0.5) / n  # the middles of n equal pieces
            xs = w.a[0] + (w.b[0] - w.a[0]) * t
            ys = w.a[1] + (w.b[1] - w.a[1]) * t
            if xs.max() < min(px) or xs.min() > max(px) or ys.max() < min(py) or \
                    ys.min() > max(py):
                continue
            inside = sum(point_in_polygon(x, y, poly) and
                         distance_to_border(x, y, poly) > INSIDE_CLEAR
                         for x, y in zip(xs.tolist(), ys.tolist(), strict=True))
            if inside:
                walls.append(i)
                total += inside * w.length / n
        if total >= INSIDE_LEAST:
            out.append((r.id, tuple(walls), total))
    return out


def doors_at_corners(spec: HouseSpec) -> list[tuple[int, str, float]]:
    """(door index, room, metres of wall left) of each door whose opening ends within
    :data:`CORNER_WALL` of a corner of one of its rooms: the replay's door finding then has
    no wall end beyond the opening there, and takes the wall across for one only when
    nothing near the swung leaf decides otherwise; else the two rooms merge in the scene
    graph."""
    covers = Covers(spec)
    out = []
    for i, d in enumerate(spec.doors):
        tips = opening_segment(d.center, d.width, d.yaw)
        # a wall in line with the door beyond an end (another room's, a neighbour's
        # border) gives the replay its wall end there, corner or not
        bare = [tip for tip in tips if not _wall_in_line(covers, d.center, tip)]
        for rid in d.rooms:
            corners = spec.room(rid).polygon
            left = min((math.dist(tip, c) for tip in bare for c in corners), default=math.inf)
            if left < CORNER_WALL - 1e-6:  # (0.1 m of wall, read as 0.0999...)
                out.append((i, rid, left))
                break
    return out


def _wall_in_line(covers: Covers, center: tuple[float, float, float] | tuple[float, float],
                  tip: tuple[float, float], beyond: float = IN_LINE_BEYOND) -> bool:
    """Whether a wall body holds the point ``beyond`` metres past ``tip`` on the line
    from the opening's ``center`` through it (past a side wall's half thickness)."""
    dx, dy = tip[0] - center[0], tip[1] - center[1]
    n = math.hypot(dx, dy) or 1.0
    hit = covers.at(tip[0] + dx / n * beyond, tip[1] + dy / n * beyond)
    return hit is not None and hit[0] == "walls"
