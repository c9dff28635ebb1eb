"""Building a house spec as PyBullet bodies (DIRECT mode: no window, no GPU).

Everything is a box: the floor (one slab under the whole house, top at z = 0), the walls,
a lintel above every door opening, door panels, furniture and small objects. Containers
are hollow (five boards, open at the front) so that their contents are hidden behind the
door panels (:mod:`sgtool.recorders.sim.articulation`) until a door opens; a piece with
shelf ``levels`` (house spec 2) is hollow too, with one board under each level, so what
stands on a lower shelf rests on a board. A small object nested in another (house spec 2)
is a box at its position, turned like the furniture at the bottom of its chain; a small
container is hollow (a tray: bottom and four sides, and a lid when it is openable and
closed; small objects are not opened in the simulation). Every panel
is built closed; the simulation then opens what the spec says is open. Bodies have
collision shapes equal to their visual shapes so ray tests see what the camera sees; the
simulation is kinematic (no physics steps), so nothing moves unless the simulator moves it.

Colours are fixed per category (a hash of the name, not Python's salted ``hash``), so
renders are byte-identical across runs and machines.
"""

from __future__ import annotations

import hashlib
import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from types import ModuleType

import numpy as np

from sgtool.extras import quiet_import
from sgtool.house.spec import Furniture, HouseSpec
from sgtool.recorders.sim import articulation as art
from sgtool.recorders.sim.body_instances import Instance, initial_states, instance_table
from sgtool.recorders.sim.camera import uid_lut

FLOOR_MARGIN = 1.0  # floor slab beyond the house bounds (m)
FLOOR_T = 0.1
WALL_RGB = (0.86, 0.85, 0.80)
FLOOR_RGB = (0.55, 0.47, 0.38)
DOOR_RGB = (0.55, 0.36, 0.20)

_pybullet: ModuleType | None = None


def pybullet() -> ModuleType:
    """The ``pybullet`` module, imported once with its build-time banner (which it prints
    on the C-level stderr at import) silenced, so command output stays clean."""
    global _pybullet
    if _pybullet is None:
        _pybullet = quiet_import("pybullet")
    return _pybullet


def category_rgb(category: str) -> tuple[float, float, float]:
    """A fixed, fairly saturated colour for a category name."""
    h = hashlib.sha256(category.encode()).digest()
    hue = h[0] / 255.0
    sat = 0.35 + 0.4 * h[1] / 255.0
    val = 0.45 + 0.45 * h[2] / 255.0
    import colorsys

    return colorsys.hsv_to_rgb(hue, sat, val)


def _quat(yaw: float) -> tuple[float, float, float, float]:
    return (0.0, 0.0, math.sin(yaw / 2.0), math.cos(yaw / 2.0))


@dataclass
class PanelBody:
    """A door panel in the world: its body and current hinge configuration."""

    uid: int
    panel: art.Panel
    fraction: float = 0.0  # 0 closed .. 1 open
    removed: bool = False  # open by taking the panel away (when no swing fits)

    @property
    def blocks(self) -> bool:
        """Whether the panel stands out of its frame as an obstacle for the base."""
        return self.fraction > 0 and not self.removed and self.panel.z0 < 1.8


@dataclass
class World:
    """The built house: bodies, the instance table and the moving panels."""

    client: int
    spec: HouseSpec
    instances: tuple[Instance, ...]
    body_instance: dict[int, int]  # body uid -> instance id
    lut: np.ndarray  # uid -> instance id, see camera.uid_lut
    panels: dict[str, list[PanelBody]] = field(default_factory=dict)  # spec id -> panels
    states: dict[str, str] = field(default_factory=dict)  # spec id -> open/closed

    def __post_init__(self) -> None:
        self.by_id = {i.id: i for i in self.instances}
        self.by_spec = {i.spec_id: i for i in self.instances if i.spec_id is not None}


class _Builder:
    def __init__(self, pb: ModuleType, client: int) -> None:
        self.pb, self.client = pb, client
        self.body_instance: dict[int, int] = {}

    def boxes(self, iid: int, parts: Sequence[tuple[Sequence[float], Sequence[float]]],
              pos: Sequence[float], yaw: float, rgb: Sequence[float]) -> int:
        """One static body made of boxes ((local centre, size) pairs), all one colour."""
        pb, cid = self.pb, self.client
        half = [[s / 2.0 for s in size] for _, size in parts]
        centres = [list(c) for c, _ in parts]
        if len(parts) == 1 and not any(centres[0]):
            col = pb.createCollisionShape(pb.GEOM_BOX, halfExtents=half[0],
                                          physicsClientId=cid)
            vis = pb.createVisualShape(pb.GEOM_BOX, halfExtents=half[0],
                                       rgbaColor=[*rgb, 1.0], physicsClientId=cid)
        else:
            n = len(parts)
            col = pb.createCollisionShapeArray([pb.GEOM_BOX] * n, halfExtents=half,
                                               collisionFramePositions=centres,
                                               physicsClientId=cid)
            vis = pb.createVisualShapeArray([pb.GEOM_BOX] * n, halfExtents=half,
                                            visualFramePositions=centres,
                                            physicsClientId=cid)
        uid = pb.createMultiBody(baseMass=0.0, baseCollisionShapeIndex=col,
                                 baseVisualShapeIndex=vis, basePosition=list(pos),
                                 baseOrientation=_quat(yaw), physicsClientId=cid)
        if len(parts) > 1 or any(centres[0]):
            pb.changeVisualShape(uid, -1, rgbaColor=[*rgb, 1.0], physicsClientId=cid)
        self.body_instance[uid] = iid
        return uid

    def box(self, iid: int, center: Sequence[float], size: Sequence[float], yaw: float,
            rgb: Sequence[float]) -> int:
        return self.boxes(iid, [((0.0, 0.0, 0.0), size)], center, yaw, rgb)


def build_world(pb: ModuleType, client: int, spec: HouseSpec) -> World:
    """Create the bodies of ``spec`` in the connected PyBullet ``client``."""
    table = instance_table(spec)
    by_spec = {i.spec_id: i for i in table if i.spec_id is not None}
    b = _Builder(pb, client)
    # floor: one slab under the house
    x0, y0, x1, y1 = spec.bounds()
    m = FLOOR_MARGIN
    b.box(1, ((x0 + x1) / 2, (y0 + y1) / 2, -FLOOR_T / 2),
          (x1 - x0 + 2 * m, y1 - y0 + 2 * m, FLOOR_T), 0.0, FLOOR_RGB)
    wall_h = max((w.height for w in spec.walls), default=2.5)
    for w in spec.walls:
        cx, cy = (w.a[0] + w.b[0]) / 2, (w.a[1] + w.b[1]) / 2
        if w.length > 1e-6:
            b.box(by_spec[w.id].id, (cx, cy, w.height / 2), (w.length, w.thickness, w.height),
                  w.yaw, WALL_RGB)
    world = World(client, spec, table, b.body_instance, np.zeros(1, np.int32))
    world.states = initial_states(spec)
    lintel_ids = [i.id for i in table if i.kind == "structure" and i.category == "wall"
                  and i.spec_id is None]
    for d, lintel in zip(spec.doors, lintel_ids, strict=True):
        iid = by_spec[d.id].id
        # every door is built closed; the simulation swings the open ones open where they
        # block nothing (it needs the occupancy grid for that)
        panel = art.door_panel(d, -1, 1)
        (pos, yaw) = panel.pose(0.0)
        uid = b.box(iid, pos, (panel.width, panel.thickness, panel.height), yaw, DOOR_RGB)
        world.panels[d.id] = [PanelBody(uid, panel, 0.0)]
        if wall_h - d.height > 1e-3:
            b.box(lintel, (d.center[0], d.center[1], (d.height + wall_h) / 2),
                  (d.width, d.thickness, wall_h - d.height), d.yaw, WALL_RGB)
    for f in spec.furniture:
        iid = by_spec[f.id].id
        rgb = category_rgb(f.category)
        if f.is_container or f.levels:
            b.boxes(iid, art.carcass_boards(f) + shelf_boards(f), f.center, f.yaw, rgb)
        else:
            b.box(iid, f.center, f.size, f.yaw, rgb)
        if f.is_openable:  # built closed, like the doors
            shade = tuple(0.8 * c for c in rgb)
            bodies = []
            for p in art.container_panels(f):
                pos, yaw = p.pose(0.0)
                uid = b.box(iid, pos, (p.width, p.thickness, p.height), yaw, shade)
                bodies.append(PanelBody(uid, p, 0.0))
            world.panels[f.id] = bodies
    furn = spec.furniture_by_id()
    roots = spec.root_furniture()
    for o in spec.objects:
        yaw, rgb = furn[roots[o.id]].yaw, category_rgb(o.category)
        if o.is_container:
            b.boxes(by_spec[o.id].id, tray_boards(o.size, lid=o.state == "closed"),
                    o.position, yaw, rgb)
        else:
            b.box(by_spec[o.id].id, o.position, o.size, yaw, rgb)
    world.body_instance = b.body_instance
    world.lut = uid_lut(b.body_instance)
    return world


def shelf_boards(f: Furniture) -> tuple[
        tuple[tuple[float, float, float], tuple[float, float, float]], ...]:
    """One board per shelf level in the piece's local frame, its top at the level (the
    carcass's board thickness; a level within a board of the bottom has none)."""
    sx, sy, sz = f.size
    t = min(art.BOARD_T, sx / 4.0, sy / 4.0, sz / 4.0)
    return tuple(((0.0, 0.0, -sz / 2.0 + h - t / 2.0), (sx, sy, t))
                 for h in f.levels if h >= t)


def tray_boards(size: Sequence[float], lid: bool) -> tuple[
        tuple[tuple[float, float, float], tuple[float, float, float]], ...]:
    """Boards of a small hollow container in its local frame: bottom, four sides, and the
    lid when ``lid``."""
    sx, sy, sz = size
    t = min(art.BOARD_T / 2.0, sx / 4.0, sy / 4.0, sz / 4.0)
    boards = [((0.0, 0.0, -sz / 2.0 + t / 2.0), (sx, sy, t)),
              ((0.0, -sy / 2.0 + t / 2.0, 0.0), (sx, t, sz)),
              ((0.0, sy / 2.0 - t / 2.0, 0.0), (sx, t, sz)),
              ((-sx / 2.0 + t / 2.0, 0.0, 0.0), (t, sy, sz)),
              ((sx / 2.0 - t / 2.0, 0.0, 0.0), (t, sy, sz))]
    if lid:
        boards.append(((0.0, 0.0, sz / 2.0 - t / 2.0), (sx, sy, t)))
    return tuple(boards)


def door_obstacles(spec: HouseSpec) -> list[art.Box2]:
    """Footprints a door panel must not swing into: furniture on the floor and walls."""
    out: list[art.Box2] = []
    for f in spec.furniture:
        if f.bottom < 1.8:
            out.append((f.center[0], f.center[1], f.size[0], f.size[1], f.yaw))
    for w in spec.walls:
        out.append(((w.a[0] + w.b[0]) / 2, (w.a[1] + w.b[1]) / 2, w.length, w.thickness,
                    w.yaw))
    return out


def set_panel(pb: ModuleType, client: int, body: PanelBody, fraction: float) -> None:
    """Move a panel to ``fraction`` open (bringing a removed panel back)."""
    pos, yaw = body.panel.pose(fraction)
    pb.resetBasePositionAndOrientation(body.uid, pos, _quat(yaw), physicsClientId=client)
    body.fraction = fraction
    body.removed = False


def remove_panel(pb: ModuleType, client: int, body: PanelBody) -> None:
    """Open a panel by taking it out of the house (parked far below the floor)."""
    pb.resetBasePositionAndOrientation(body.uid, (0.0, 0.0, -100.0), _quat(0.0),
                                       physicsClientId=client)
    body.fraction = 1.0
    body.removed = True
