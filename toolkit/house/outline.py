"""Walls along the outer outline of a house that gives none.

A house file may leave out its walls (the symbolic bench needs none: outside every room is
blocked). A camera in the simulator would then see no border where the robot cannot go,
and its map would offer frontiers into the void. :func:`outline_walls` stands a wall along
every stretch of a room's border that no other room lies beyond (the house's outer
outline), outside the room (its floor stays whole) and with a gap at every door there;
inside, rooms meet on open floor (open plan). Pure geometry.
"""

from __future__ import annotations

import math

from sgtool.house.geometry import signed_area
from sgtool.house.spec import HouseSpec, Room, Wall

THICKNESS = 0.1  # m, the spec's default wall
HEIGHT = 2.5  # m
STEP = 0.05  # m between the points of a border tested
PROBE = 0.06  # m beyond the border where another room is looked for


def outline_walls(spec: HouseSpec) -> tuple[Wall, ...]:
    """Walls ``outline_0``, ``outline_1``, ... along the house's outer outline (module
    doc), in room and edge order."""
    walls: list[Wall] = []
    for room in spec.rooms:
        poly = room.polygon
        turn = 1.0 if signed_area(poly) > 0 else -1.0  # outward: right of a CCW edge
        for k, p in enumerate(poly):
            q = poly[(k + 1) % len(poly)]
            length = math.dist(p, q)
            if length < 1e-6:
                continue
            ux, uy = (q[0] - p[0]) / length, (q[1] - p[1]) / length
            nx, ny = turn * uy, -turn * ux
            for s0, s1 in _outer_runs(spec, room, p, (ux, uy), (nx, ny), length):
                half = THICKNESS / 2  # the inner face on the border: no floor is covered
                a = (p[0] + ux * s0 + nx * half, p[1] + uy * s0 + ny * half)
                b = (p[0] + ux * s1 + nx * half, p[1] + uy * s1 + ny * half)
                walls.append(Wall(f"outline_{len(walls)}", a, b, THICKNESS, HEIGHT))
    return tuple(walls)


def _outer_runs(spec: HouseSpec, room: Room, p: tuple[float, float],
                u: tuple[float, float], n: tuple[float, float],
                length: float) -> list[tuple[float, float]]:
    """The stretches (from, to, metres along the edge) of one border edge with no room
    beyond it and no door on it."""
    count = max(1, math.ceil(length / STEP))
    runs: list[tuple[float, float]] = []
    start: float | None = None
    for i in range(count + 1):
        s = min(length, i * length / count)
        x, y = p[0] + u[0] * s, p[1] + u[1] * s
        outer = not _beyond(spec, room, x + n[0] * PROBE, y + n[1] * PROBE) and \
            not _on_door(spec, x, y)
        if outer and start is None:
            start = s
        elif not outer and start is not None:
            runs.append((start, s))
            start = None
    if start is not None and length - start > 1e-6:
        runs.append((start, length))
    return [(a, b) for a, b in runs if b - a > 1e-6]


def _beyond(spec: HouseSpec, room: Room, x: float, y: float) -> bool:
    """Another room holds the point (x, y)."""
    for other in spec.rooms:
        if other is room:
            continue
        x0, y0, x1, y1 = other.bounds
        if x0 <= x <= x1 and y0 <= y <= y1 and other.contains(x, y):
            return True
    return False


def _on_door(spec: HouseSpec, x: float, y: float) -> bool:
    """(x, y) lies in a door's opening (within its half width of its centre)."""
    return any(math.dist((x, y), d.center) <= d.width / 2 for d in spec.doors)
