"""How a door or container opens in the simulation: which of its candidate panel layouts
to swing, so that the open panels leave every room as connected as before, stay clear of
the robot's base disc and leave the robot free to leave (else the panels are taken away
instead of swung).

Doors: into a room rather than a corridor, else away from the robot, clear of furniture
and walls (:func:`~sgtool.recorders.sim.articulation.swing_choices`). Container doors:
single ones hinged on the side away from the robot first; a layout whose open panel would
stand in a wall, in another piece of furniture or in front of another container (where
that one's doors swing and its inside is seen from), at the panel's height, is never
taken: such a panel would cut through the piece or hide what is in it.
"""

from __future__ import annotations

import math

import numpy as np
from scipy import ndimage

from sgtool.house.spec import Door, Furniture, HouseSpec, room_at
from sgtool.mapping.occupancy import nearest_free_cell
from sgtool.recorders.sim import articulation as art
from sgtool.recorders.sim import navigation as nav
from sgtool.recorders.sim.body_instances import DOOR
from sgtool.recorders.sim.build import World, door_obstacles
from sgtool.recorders.sim.navigation import RobotConfig

MAX_OBSTACLE_HEIGHT = 1.8  # panels starting above this do not block the base (m)


class OpeningPlanner:
    """Chooses panel layouts for the house of ``world`` (the room masks are cached)."""

    def __init__(self, spec: HouseSpec, world: World, robot: RobotConfig) -> None:
        self.spec = spec
        self.world = world
        self.robot = robot
        self._room_masks: dict[str, np.ndarray] | None = None

    def layout(self, sid: str, base: tuple[float, float, float]) -> list[art.Panel] | None:
        """How to open ``sid``'s panels with the robot at ``base``: the first candidate
        layout that keeps the rooms connected and the robot free (module doc); None when
        none does."""
        inst = self.world.by_spec[sid]
        bodies = self.world.panels[sid]
        x, y = base[:2]
        options: list[list[art.Panel]]
        if inst.kind == DOOR:
            d = next(d for d in self.spec.doors if d.id == sid)
            pref = room_side(self.spec, d) or -art.side_of_door(d, x, y)
            options = [[art.door_panel(d, e, s)]
                       for e, s in art.swing_choices(d, pref, door_obstacles(self.spec))]
        else:
            f = self.spec.furniture_by_id()[sid]
            if len(bodies) == 1:
                away = 1 if f.to_local(x, y)[0] < 0 else -1
                options = [list(art.container_panels(f, away)),
                           list(art.container_panels(f, -away))]
            else:
                options = [list(art.container_panels(f))]
            options = [o for o in options if not self._in_furniture(sid, o)]
        before, blocked0, _ = self._room_floor(sid, [], base)
        for opt in options:
            fps = [p.footprint(1.0) for p in opt if p.z0 < MAX_OBSTACLE_HEIGHT]
            if any(art.point_box_distance(x, y, fp) < self.robot.radius for fp in fps):
                continue  # the open panel would stand on the robot's base
            after, blocked1, robot_ok = self._room_floor(sid, fps, base)
            added = blocked1 - blocked0
            if robot_ok and all(after[r] >= before[r] - added for r in before):
                return opt
        return None

    def _in_furniture(self, sid: str, layout: list[art.Panel]) -> bool:
        """Whether an open panel of ``layout`` (a container's) overlaps a wall, another
        piece of furniture whose height range meets the panel's, or the space in front of
        another container (:func:`front_zone`) at such a height."""
        boxes = [p.footprint(1.0) for p in layout]
        for f in self.spec.furniture:
            if f.id == sid:
                continue
            zones = [(f.center[0], f.center[1], f.size[0], f.size[1], f.yaw)]
            if f.is_container:
                zones.append(front_zone(f))
            for p, b in zip(layout, boxes, strict=True):
                if f.bottom < p.z0 + p.height and p.z0 < f.top and \
                        any(art.boxes_overlap(b, z) for z in zones):
                    return True
        walls = [((w.a[0] + w.b[0]) / 2, (w.a[1] + w.b[1]) / 2, w.length, w.thickness, w.yaw)
                 for w in self.spec.walls]
        return any(art.boxes_overlap(b, wb) for b in boxes for wb in walls)

    def _room_floor(self, skip: str, extra: list[art.Box2], base: tuple[float, float, float]
                    ) -> tuple[dict[str, int], int, bool]:
        """With the open panels except ``skip``'s plus ``extra`` (doors passable): per room,
        the free cells of the largest connected free region; the number of blocked cells;
        whether the robot's cell is in that region."""
        panels = [b.panel.footprint(b.fraction) for sid, bodies in self.world.panels.items()
                  if sid != skip for b in bodies if b.blocks]
        door_states = {d.id: self.world.states[d.id] for d in self.spec.doors}
        occ = nav.occupancy_with(self.spec, door_states, panels + extra, self.robot, True)
        labels, n = ndimage.label(~occ.blocked)
        if n == 0:
            return {r.id: 0 for r in self.spec.rooms}, int(occ.blocked.sum()), False
        big = int(np.argmax(np.bincount(labels.ravel())[1:])) + 1
        main = labels == big
        if self._room_masks is None:
            self._room_masks = {r.id: nav.room_mask(occ, r) for r in self.spec.rooms}
        cell = nearest_free_cell(occ, base[0], base[1], max_snap=0.5)
        robot_ok = cell is not None and bool(main[cell])
        return ({rid: int((m & main).sum()) for rid, m in self._room_masks.items()},
                int(occ.blocked.sum()), robot_ok)


def front_zone(f: Furniture) -> art.Box2:
    """The floor in front of container ``f`` (its front is the local +y face) that its own
    doors sweep and from which what is inside is seen: as wide as the piece, as deep as
    one of its door panels (half the width for double doors)."""
    sx, sy = f.size[0], f.size[1]
    depth = sx if sx <= art.DOUBLE_DOOR_WIDTH else sx / 2.0
    c, s = math.cos(f.yaw), math.sin(f.yaw)
    ly = sy / 2.0 + depth / 2.0
    return (f.center[0] - s * ly, f.center[1] + c * ly, sx, depth, f.yaw)


def room_side(spec: HouseSpec, d: Door) -> int | None:
    """The side (+1 left of the door's wall direction, -1 right) of the door's room that is
    not a corridor, when exactly one of its two rooms is a corridor."""
    nx, ny = -math.sin(d.yaw), math.cos(d.yaw)
    off = d.thickness / 2 + 0.2
    cats = {}
    for s in (1, -1):
        rid = room_at(spec, d.center[0] + s * off * nx, d.center[1] + s * off * ny)
        cats[s] = spec.room(rid).category if rid else None
    corridor = {s for s, c in cats.items() if c is not None and "corridor" in c}
    if len(corridor) == 1:
        return -next(iter(corridor))
    return None
