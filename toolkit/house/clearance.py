"""Room around what the robot must reach (pure geometry on a house spec): a container's or
shelf's front, and a start pose.

A container opens, and is looked into, through its front: the box's local +y face
(:mod:`sgtool.house.spec`). :func:`blocked_fronts` finds the pieces whose front a wall,
another piece or the room's border covers: the point :data:`FRONT_CLEAR` in front of the
middle of the front face is outside the piece's room, within a wall's body or inside
another piece's footprint (a cabinet set with its back to the room). :func:`cramped_starts`
finds the start poses nearer to a wall or a piece than the robot's radius (the simulator
then starts the robot overlapping it).
"""

from __future__ import annotations

import math

from sgtool.house.geometry import distance_to_polygon, point_in_polygon, segment_distance
from sgtool.house.spec import Furniture, HouseSpec

FRONT_CLEAR = 0.3  # m in front of a front face that must be open floor


def front_point(f: Furniture, clear: float = FRONT_CLEAR) -> tuple[float, float]:
    """The point ``clear`` metres in front of the middle of ``f``'s front (local +y) face."""
    d = f.size[1] / 2.0 + clear
    return (f.center[0] - math.sin(f.yaw) * d, f.center[1] + math.cos(f.yaw) * d)


def _covered(spec: HouseSpec, x: float, y: float, skip: int = -1) -> str | None:
    """What covers the floor point (x, y): a wall's id, a piece's id, or None."""
    for w in spec.walls:
        if segment_distance(x, y, w.a, w.b) <= w.thickness / 2.0:
            return w.id
    for k, g in enumerate(spec.furniture):
        if k != skip and point_in_polygon(x, y, g.footprint()):
            return g.id
    return None


def blocked_fronts(spec: HouseSpec) -> list[tuple[int, str]]:
    """(furniture index, what covers it: a wall's or piece's id, or "the room's border")
    for each container or shelved piece whose front is blocked (module doc), spec order."""
    out = []
    for k, f in enumerate(spec.furniture):
        if not (f.is_container or f.levels):
            continue
        x, y = front_point(f)
        if not point_in_polygon(x, y, spec.room(f.room).polygon):
            out.append((k, "the room's border"))
        elif (what := _covered(spec, x, y, skip=k)) is not None:
            out.append((k, what))
    return out


def cramped_starts(spec: HouseSpec, radius: float) -> list[tuple[int, float]]:
    """(start index, clearance in m) of the starts whose robot disc of ``radius`` overlaps
    a wall's body or a piece's footprint, in spec order."""
    out = []
    for i, s in enumerate(spec.starts):
        gaps = [segment_distance(s.x, s.y, w.a, w.b) - w.thickness / 2.0 for w in spec.walls]
        gaps += [distance_to_polygon(s.x, s.y, f.footprint()) for f in spec.furniture]
        gap = min(gaps, default=math.inf)
        if gap < radius:
            out.append((i, max(gap, 0.0)))
    return out

