"""Hinged panels: house doors and the doors of containers (pure geometry).

A panel is a flat box turning about a vertical hinge axis by up to 90 degrees. When
closed it lies along ``closed_dir`` from the hinge; opening turns it by ``swing`` (+1
counter-clockwise, -1 clockwise seen from above) so that its free end moves to the
opening side. ``offset`` shifts the panel off the hinge line by that distance towards
the side it does *not* open to (a container door sits just behind the front face of the
carcass; a house door is centred in the wall, offset 0).

House doors: the opening between the two wall ends is filled by one panel of the door's
width when closed. Which end carries the hinge and which room it swings into is chosen
when the door opens (:func:`swing_choices` ranks the four ways; the simulator keeps the
first that leaves every room as reachable as before): into a room rather than into a
corridor, else away from the robot, and where the open panel does not cut through
furniture or walls.

Containers (openable furniture): the front face is the box's local +y side (the side
that faces the room, see :mod:`sgtool.datasets.small_objects`). Fronts up to
:data:`DOUBLE_DOOR_WIDTH` wide get one door hinged on the left, wider ones two doors hinged
on either side, so an open door sticks out at most half the front's width.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

from sgtool.house.spec import Door, Furniture

DOUBLE_DOOR_WIDTH = 0.9  # fronts wider than this get two doors (m)
CONTAINER_PANEL_T = 0.02  # container door thickness (m)
BOARD_T = 0.02  # container carcass board thickness (m); the generator keeps 0.03 clear
HOUSE_DOOR_T = 0.05  # house door panel thickness (m), thinner than the 0.1 m walls

Box2 = tuple[float, float, float, float, float]  # centre x, y, size x, y, yaw


@dataclass(frozen=True)
class Panel:
    hinge: tuple[float, float]
    closed_dir: float  # direction (rad) from the hinge along the closed panel
    swing: int  # +1 / -1
    width: float
    thickness: float
    z0: float  # bottom height
    height: float
    offset: float = 0.0

    def direction(self, fraction: float) -> float:
        """Direction of the panel from its hinge when ``fraction`` open (1 = 90 deg)."""
        return self.closed_dir + self.swing * fraction * (math.pi / 2.0)

    def pose(self, fraction: float) -> tuple[tuple[float, float, float], float]:
        """((x, y, z) of the panel box centre, yaw of the box's x axis)."""
        a = self.direction(fraction)
        dx, dy = math.cos(a), math.sin(a)
        # the side the panel does not open to: its direction turned by -swing * 90 deg
        nx, ny = self.swing * dy, -self.swing * dx
        h = self.width / 2.0
        x = self.hinge[0] + dx * h + nx * self.offset
        y = self.hinge[1] + dy * h + ny * self.offset
        return (x, y, self.z0 + self.height / 2.0), a

    def footprint(self, fraction: float) -> Box2:
        (x, y, _), yaw = self.pose(fraction)
        return (x, y, self.width, self.thickness, yaw)


# ----------------------------------------------------------------------------------------
# house doors
# ----------------------------------------------------------------------------------------
def door_panel(door: Door, hinge_end: int, side: int) -> Panel:
    """The panel of ``door`` hinged at the opening's end ``hinge_end`` (-1: the end at
    ``center - width/2 * u``, +1 the other; ``u`` = the wall direction) and opening
    towards ``side`` (+1: the half-plane left of ``u``, -1: right of it)."""
    if hinge_end not in (-1, 1) or side not in (-1, 1):
        raise ValueError("hinge_end and side are -1 or +1")
    ux, uy = math.cos(door.yaw), math.sin(door.yaw)
    h = door.width / 2.0
    hinge = (door.center[0] + hinge_end * h * ux, door.center[1] + hinge_end * h * uy)
    closed_dir = door.yaw if hinge_end < 0 else door.yaw + math.pi
    t = min(HOUSE_DOOR_T, door.thickness)
    return Panel(hinge, _wrap(closed_dir), -hinge_end * side, door.width, t, 0.0, door.height)


def side_of_door(door: Door, x: float, y: float) -> int:
    """+1 when (x, y) is left of the door's wall direction, -1 when right (or on it)."""
    ux, uy = math.cos(door.yaw), math.sin(door.yaw)
    cross = ux * (y - door.center[1]) - uy * (x - door.center[0])
    return 1 if cross > 0 else -1


def swing_choices(door: Door, preferred_side: int,
                  obstacles: Sequence[Box2]) -> list[tuple[int, int]]:
    """The four (hinge_end, side) ways to open ``door``, best first: those whose open
    panel (outside the wall it sits in) overlaps none of ``obstacles`` before those that
    do; within each group the preferred side first, then the hinge at the -1 end."""
    choices = [(e, s) for s in (preferred_side, -preferred_side) for e in (-1, 1)]
    clear = []
    for e, s in choices:
        p = door_panel(door, e, s)
        x, y, w, t, yaw = p.footprint(1.0)
        # only the part beyond the wall's half thickness (plus 1 cm) may not collide
        cut = door.thickness / 2.0 + 0.01
        dx, dy = math.cos(yaw), math.sin(yaw)
        shrunk = (x + dx * cut / 2.0, y + dy * cut / 2.0, max(w - cut, 1e-3), t, yaw)
        clear.append(not any(boxes_overlap(shrunk, o) for o in obstacles))
    return [c for c, ok in zip(choices, clear, strict=True) if ok] + \
        [c for c, ok in zip(choices, clear, strict=True) if not ok]


# ----------------------------------------------------------------------------------------
# containers
# ----------------------------------------------------------------------------------------
def container_panels(f: Furniture, hinge: int = -1) -> tuple[Panel, ...]:
    """The door panels of an openable piece, hinged on the front (local +y) face. A single
    door is hinged at local ``x = hinge * sx / 2`` (the simulator picks the side away from
    the robot, so the open door does not stand between the robot and the shelves); double
    doors are hinged on both sides. Closed, both hinge choices give the same panel."""
    sx, sy, sz = f.size
    c, s = math.cos(f.yaw), math.sin(f.yaw)

    def world(lx: float, ly: float) -> tuple[float, float]:
        return (f.center[0] + c * lx - s * ly, f.center[1] + s * lx + c * ly)

    z0 = f.center[2] - sz / 2.0
    t = min(CONTAINER_PANEL_T, sy / 4.0)
    left = Panel(world(-sx / 2.0, sy / 2.0), _wrap(f.yaw), 1, sx, t, z0, sz, t / 2.0)
    right = Panel(world(sx / 2.0, sy / 2.0), _wrap(f.yaw + math.pi), -1, sx, t, z0, sz, t / 2.0)
    if sx <= DOUBLE_DOOR_WIDTH:
        return (left,) if hinge < 0 else (right,)
    w = sx / 2.0
    return (_with_width(left, w), _with_width(right, w))


def _with_width(p: Panel, w: float) -> Panel:
    return Panel(p.hinge, p.closed_dir, p.swing, w, p.thickness, p.z0, p.height, p.offset)


def carcass_boards(f: Furniture, front_open: bool = True) -> tuple[
        tuple[tuple[float, float, float], tuple[float, float, float]], ...]:
    """Boards of a hollow container in the piece's local frame: ((x, y, z) centre,
    (sx, sy, sz) size) for bottom, top, back, left and right (and the front when the
    front is not open). Containers are hollow so that what is inside is hidden by the
    door and appears when it opens."""
    sx, sy, sz = f.size
    t = min(BOARD_T, sx / 4.0, sy / 4.0, sz / 4.0)
    boards = [
        ((0.0, 0.0, -sz / 2.0 + t / 2.0), (sx, sy, t)),
        ((0.0, 0.0, sz / 2.0 - t / 2.0), (sx, sy, t)),
        ((0.0, -sy / 2.0 + t / 2.0, 0.0), (sx, t, sz)),
        ((-sx / 2.0 + t / 2.0, 0.0, 0.0), (t, sy, sz)),
        ((sx / 2.0 - t / 2.0, 0.0, 0.0), (t, sy, sz)),
    ]
    if not front_open:
        boards.append(((0.0, sy / 2.0 - t / 2.0, 0.0), (sx, t, sz)))
    return tuple(boards)


# ----------------------------------------------------------------------------------------
# 2-D oriented boxes
# ----------------------------------------------------------------------------------------
def box_corners(b: Box2) -> list[tuple[float, float]]:
    x, y, sx, sy, yaw = b
    c, s = math.cos(yaw), math.sin(yaw)
    out = []
    for lx, ly in ((-sx / 2, -sy / 2), (sx / 2, -sy / 2), (sx / 2, sy / 2), (-sx / 2, sy / 2)):
        out.append((x + c * lx - s * ly, y + s * lx + c * ly))
    return out


def boxes_overlap(a: Box2, b: Box2, eps: float = 1e-6) -> bool:
    """Separating-axis test of two oriented rectangles (touching is not overlapping)."""
    ca, cb = box_corners(a), box_corners(b)
    for yaw in (a[4], a[4] + math.pi / 2, b[4], b[4] + math.pi / 2):
        ax, ay = math.cos(yaw), math.sin(yaw)
        pa = [ax * p[0] + ay * p[1] for p in ca]
        pb = [ax * p[0] + ay * p[1] for p in cb]
        if max(pa) <= min(pb) + eps or max(pb) <= min(pa) + eps:
            return False
    return True


def point_box_distance(x: float, y: float, b: Box2) -> float:
    """Distance from (x, y) to the rectangle ``b`` (0 inside)."""
    cx, cy, sx, sy, yaw = b
    c, s = math.cos(yaw), math.sin(yaw)
    dx, dy = x - cx, y - cy
    lx, ly = c * dx + s * dy, -s * dx + c * dy
    ex = max(abs(lx) - sx / 2.0, 0.0)
    ey = max(abs(ly) - sy / 2.0, 0.0)
    return math.hypot(ex, ey)


def _wrap(a: float) -> float:
    return math.atan2(math.sin(a), math.cos(a))
