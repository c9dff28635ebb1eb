"""Depth and instance ids of box worlds from a small numpy ray-caster.

The mapping pipeline is tested and benchmarked without a simulator: a world is a floor
plane plus oriented boxes (walls, door panels and lintels, furniture, objects), each with an
instance id, and :func:`render` intersects every pixel ray with them (slab test in each
box's frame). Depth is along the optical axis, as :class:`~sgtool.log.frame.Frame` wants,
because rays are ``(u', v', 1)`` in the camera frame, so the ray parameter is the depth.

:func:`world_of_house` turns a :class:`~sgtool.house.spec.HouseSpec` into such a world
and an instance table (floor and walls "structure", doors with a lintel above the opening
and a panel: in the opening when closed, swung by 90 degrees into the door's second
room when open; furniture; small
objects with their parent and relation); :func:`camera_pose` and :func:`make_frame` give
posed frames of a robot with a camera at a height and pitch.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from sgtool.log.frame import CameraIntrinsics, Frame
from sgtool.scenegraph.instances import InstanceInfo, table_of


@dataclass(frozen=True)
class Box:
    """An oriented box: centre (x, y, z), size along its own axes, yaw about z."""

    center: tuple[float, float, float]
    size: tuple[float, float, float]
    instance: int
    yaw: float = 0.0


@dataclass(frozen=True)
class BoxWorld:
    boxes: tuple[Box, ...]
    floor_instance: int = 0  # id of the floor plane z = floor_z (0: no floor)
    floor_z: float = 0.0
    floor_extent: tuple[float, float, float, float] | None = None  # xmin, ymin, xmax, ymax

    def arrays(self) -> dict[str, np.ndarray]:
        c = np.array([b.center for b in self.boxes], dtype=np.float64).reshape(-1, 3)
        s = np.array([b.size for b in self.boxes], dtype=np.float64).reshape(-1, 3)
        yaw = np.array([b.yaw for b in self.boxes], dtype=np.float64)
        ids = np.array([b.instance for b in self.boxes], dtype=np.int32)
        return {"c": c, "h": s / 2.0, "cos": np.cos(yaw), "sin": np.sin(yaw), "ids": ids,
                "r": np.linalg.norm(s / 2.0, axis=1)}


def camera_pose(x: float, y: float, yaw: float, height: float = 1.2,
                pitch: float = 0.0) -> np.ndarray:
    """world_T_camera (optical frame: x right, y down, z forward) of a camera at (x, y,
    height) looking along ``yaw``, tilted down by ``pitch`` radians."""
    cy, sy, cp, sp = math.cos(yaw), math.sin(yaw), math.cos(pitch), math.sin(pitch)
    zc = np.array([cy * cp, sy * cp, -sp])
    xc = np.array([sy, -cy, 0.0])
    yc = np.cross(zc, xc)
    T = np.eye(4)  # noqa: N806
    T[:3, 0], T[:3, 1], T[:3, 2] = xc, yc, zc
    T[:3, 3] = (x, y, height)
    return T


def base_pose(x: float, y: float, yaw: float) -> np.ndarray:
    T = np.eye(4)  # noqa: N806
    c, s = math.cos(yaw), math.sin(yaw)
    T[:2, :2] = [[c, -s], [s, c]]
    T[:2, 3] = (x, y)
    return T


def render(world: BoxWorld, pose: np.ndarray, intrinsics: CameraIntrinsics,
           max_range: float = 8.0, chunk: int = 8) -> tuple[np.ndarray, np.ndarray]:
    """(depth float32 (H, W) metres along the optical axis, 0 = no hit within
    ``max_range``; ids int32 (H, W), 0 = nothing) of ``world`` seen from ``pose``."""
    k = intrinsics
    h, w = k.height, k.width
    u = (np.arange(w, dtype=np.float64) - k.cx) / k.fx
    v = (np.arange(h, dtype=np.float64) - k.cy) / k.fy
    dc = np.stack([np.tile(u, h), np.repeat(v, w), np.ones(h * w)], axis=1)
    R, o = pose[:3, :3], pose[:3, 3]  # noqa: N806
    d = dc @ R.T  # world ray directions; parameter t = depth
    n = h * w
    best = np.full(n, np.inf)
    ids = np.zeros(n, dtype=np.int32)
    if world.floor_instance:
        with np.errstate(divide="ignore", invalid="ignore"):
            t = (world.floor_z - o[2]) / d[:, 2]
        ok = (d[:, 2] < -1e-9) & (t > 1e-6)
        if world.floor_extent is not None:
            x0, y0, x1, y1 = world.floor_extent
            px, py = o[0] + t * d[:, 0], o[1] + t * d[:, 1]
            ok &= (px >= x0) & (px <= x1) & (py >= y0) & (py <= y1)
        best = np.where(ok, t, best)
        ids[ok] = world.floor_instance
    a = world.arrays()
    if len(a["ids"]):
        # cull boxes out of range or entirely behind the camera
        rel = a["c"] - o
        dist = np.linalg.norm(rel, axis=1) - a["r"]
        fwd = rel @ R[:, 2] + a["r"]
        sel = np.flatnonzero((dist < max_range) & (fwd > 0))
        for s0 in range(0, len(sel), chunk):
            b = sel[s0:s0 + chunk]
            c, s = a["cos"][b][:, None], a["sin"][b][:, None]
            ox, oy, oz = (o - a["c"][b]).T
            # into each box frame (rotation by -yaw)
            lox = c[:, 0] * ox + s[:, 0] * oy
            loy = -s[:, 0] * ox + c[:, 0] * oy
            ldx = c * d[None, :, 0] + s * d[None, :, 1]
            ldy = -s * d[None, :, 0] + c * d[None, :, 1]
            ldz = np.broadcast_to(d[None, :, 2], ldx.shape)
            tmin = np.zeros_like(ldx)
            tmax = np.full_like(ldx, np.inf)
            for lo, ld, hh in ((lox, ldx, a["h"][b, 0]), (loy, ldy, a["h"][b, 1]),
                               (oz, ldz, a["h"][b, 2])):
                with np.errstate(divide="ignore", invalid="ignore"):
                    inv = 1.0 / ld
                    t1 = (-hh[:, None] - lo[:, None]) * inv
                    t2 = (hh[:, None] - lo[:, None]) * inv
                lo_t = np.minimum(t1, t2)
                hi_t = np.maximum(t1, t2)
                # parallel rays: inside the slab -> no constraint, outside -> miss
                par = ld == 0
                if par.any():
                    inside = np.abs(lo)[:, None] <= hh[:, None]
                    lo_t = np.where(par, np.where(inside, -np.inf, np.inf), lo_t)
                    hi_t = np.where(par, np.where(inside, np.inf, -np.inf), hi_t)
                tmin = np.maximum(tmin, lo_t)
                tmax = np.minimum(tmax, hi_t)
            hit = (tmax >= tmin) & (tmin > 1e-6)
            t = np.where(hit, tmin, np.inf)
            j = np.argmin(t, axis=0)
            tb = t[j, np.arange(n)]
            closer = tb < best
            best = np.where(closer, tb, best)
            ids[closer] = a["ids"][b][j[closer]]
    far = ~(best <= max_range)
    best[far] = 0.0
    ids[far] = 0
    return best.reshape(h, w).astype(np.float32), ids.reshape(h, w)


def make_frame(world: BoxWorld, x: float, y: float, yaw: float, intrinsics: CameraIntrinsics,
               index: int = 0, height: float = 1.2, pitch: float = 0.0,
               max_range: float = 8.0, with_ids: bool = True, with_rgb: bool = False) -> Frame:
    """A posed frame of a robot at (x, y, yaw) with its camera ``height`` m up."""
    pose = camera_pose(x, y, yaw, height, pitch)
    depth, ids = render(world, pose, intrinsics, max_range)
    rgb = None
    if with_rgb:
        rgb = np.stack([(ids * 37) % 256, (ids * 91) % 256, (ids * 151) % 256],
                       axis=-1).astype(np.uint8)
    return Frame(index=index, time_ns=index * 100_000_000, rgb=rgb, depth=depth,
                 ids=ids if with_ids else None, pose=pose, intrinsics=intrinsics,
                 base_pose=base_pose(x, y, yaw))


# ----------------------------------------------------------------------------------------
# house specs
# ----------------------------------------------------------------------------------------
@dataclass(frozen=True)
class HouseWorld:
    world: BoxWorld
    instances: dict[int, InstanceInfo]
    spec_ids: dict[str, int]  # spec id (room_0, door_3, furn_7, obj_2, wall_1) -> instance


def world_of_house(spec: Any, panel_thickness: float = 0.05) -> HouseWorld:
    """Boxes and instance table of a :class:`~sgtool.house.spec.HouseSpec` (module doc).
    Instance ids: 1 floor, then walls, doors, furniture, small objects in spec order."""
    boxes: list[Box] = []
    infos: list[InstanceInfo] = [InstanceInfo(1, "floor", "structure", spec_id="floor")]
    spec_ids: dict[str, int] = {"floor": 1}
    nxt = 2
    wall_h = max((w.height for w in spec.walls), default=2.5)
    rooms = {r.id: r.centroid for r in spec.rooms}
    for wl in spec.walls:
        cx, cy = (wl.a[0] + wl.b[0]) / 2.0, (wl.a[1] + wl.b[1]) / 2.0
        boxes.append(Box((cx, cy, wl.height / 2.0), (wl.length + wl.thickness, wl.thickness,
                                                     wl.height), nxt, wl.yaw))
        infos.append(InstanceInfo(nxt, "wall", "structure", spec_id=wl.id))
        spec_ids[wl.id] = nxt
        nxt += 1
    for dr in spec.doors:
        cx, cy = dr.center
        ux, uy = math.cos(dr.yaw), math.sin(dr.yaw)
        lintel_h = wall_h - dr.height
        if lintel_h > 0:
            boxes.append(Box((cx, cy, dr.height + lintel_h / 2.0),
                             (dr.width, dr.thickness, lintel_h), nxt, dr.yaw))
        if dr.state == "closed":
            boxes.append(Box((cx, cy, dr.height / 2.0), (dr.width, panel_thickness, dr.height),
                             nxt, dr.yaw))
        else:  # hinged at one end, swung by 90 degrees into the door's second room
            hx, hy = cx - ux * dr.width / 2.0, cy - uy * dr.width / 2.0
            nx, ny = -uy, ux
            into = rooms.get(dr.rooms[1])
            if into is not None and (into[0] - cx) * nx + (into[1] - cy) * ny < 0:
                nx, ny = -nx, -ny
            px = hx + nx * dr.width / 2.0 + ux * panel_thickness / 2.0
            py = hy + ny * dr.width / 2.0 + uy * panel_thickness / 2.0
            boxes.append(Box((px, py, dr.height / 2.0), (dr.width, panel_thickness, dr.height),
                             nxt, dr.yaw + math.pi / 2.0))
        infos.append(InstanceInfo(nxt, "door", "door", state=dr.state,
                                  affordances=("openable",), spec_id=dr.id))
        spec_ids[dr.id] = nxt
        nxt += 1
    for f in spec.furniture:
        boxes.append(Box(f.center, f.size, nxt, f.yaw))
        spec_ids[f.id] = nxt
        infos.append(InstanceInfo(nxt, f.category, "furniture", state=f.state,
                                  affordances=tuple(f.affordances), synset=f.synset,
                                  spec_id=f.id))
        nxt += 1
    furn = {f.id: f for f in spec.furniture}
    for ob in spec.objects:
        parent = furn.get(ob.parent)
        yaw = parent.yaw if parent is not None else 0.0
        boxes.append(Box(ob.position, ob.size, nxt, yaw))
        spec_ids[ob.id] = nxt
        infos.append(InstanceInfo(nxt, ob.category, "object", synset=ob.synset,
                                  parent=spec_ids.get(ob.parent), relation=ob.relation,
                                  spec_id=ob.id))
        nxt += 1
    xmin, ymin, xmax, ymax = spec.bounds()
    world = BoxWorld(tuple(boxes), floor_instance=1, floor_z=0.0,
                     floor_extent=(xmin - 0.5, ymin - 0.5, xmax + 0.5, ymax + 0.5))
    return HouseWorld(world, table_of(infos), spec_ids)


def look_around(x: float, y: float, yaw0: float, steps: int) -> list[tuple[float, float, float]]:
    """Poses turning in place through a full circle."""
    return [(x, y, yaw0 + 2.0 * math.pi * i / steps) for i in range(steps)]


def walk(points: Sequence[tuple[float, float]], step: float = 0.1
         ) -> list[tuple[float, float, float]]:
    """Poses every ``step`` metres along a polyline, facing the direction of travel."""
    out: list[tuple[float, float, float]] = []
    for (x0, y0), (x1, y1) in zip(points[:-1], points[1:], strict=True):
        seg = math.hypot(x1 - x0, y1 - y0)
        if seg < 1e-9:
            continue
        yaw = math.atan2(y1 - y0, x1 - x0)
        n = max(1, int(round(seg / step)))
        for i in range(n):
            f = i / n
            out.append((x0 + f * (x1 - x0), y0 + f * (y1 - y0), yaw))
    return out


def two_room_house(opening: str = "open") -> Any:
    """A small :class:`~sgtool.house.spec.HouseSpec` for tests: a kitchen [0, 4] x
    [0, 3] and a bedroom [4, 8] x [0, 3] joined at x = 4 (y 1.05-1.95) by an open door
    (``opening="open"``), a closed door (``"closed"``) or a doorless open-plan passage
    (``"passage"``). Kitchen: a closed refrigerator in the corner (0, 0) holding an apple, a
    countertop by the dividing wall at (3.6, 2.6) with a cup on top. Bedroom: a bed along
    the far wall, a closed wardrobe with a sweater inside."""
    from sgtool.house.io import load_house

    def wall(i: int, a: list[float], b: list[float]) -> dict[str, Any]:
        return {"id": f"wall_{i}", "a": a, "b": b, "thickness": 0.1, "height": 2.5}

    def furn(i: int, cat: str, synset: str, room: str, center: list[float],
             size: list[float], aff: list[str], state: str | None) -> dict[str, Any]:
        return {"id": f"furn_{i}", "category": cat, "synset": synset, "room": room,
                "center": center, "size": size, "yaw": 0, "affordances": aff, "state": state}

    def obj(i: int, cat: str, parent: str, rel: str, room: str, pos: list[float]
            ) -> dict[str, Any]:
        return {"id": f"obj_{i}", "category": cat, "synset": f"{cat}.n.01", "parent": parent,
                "relation": rel, "room": room, "position": pos, "size": [0.1, 0.1, 0.1]}

    group = "open_0" if opening == "passage" else None
    spec: dict[str, Any] = {
        "version": "1.0", "seed": 0,
        "rooms": [
            {"id": "room_0", "category": "kitchen", "polygon": [[0, 0], [4, 0], [4, 3], [0, 3]],
             "open_plan_group": group},
            {"id": "room_1", "category": "bedroom", "polygon": [[4, 0], [8, 0], [8, 3], [4, 3]],
             "open_plan_group": group},
        ],
        "walls": [
            wall(0, [0, 0], [8, 0]), wall(1, [0, 3], [8, 3]), wall(2, [0, 0], [0, 3]),
            wall(3, [8, 0], [8, 3]), wall(4, [4, 0], [4, 1.05]), wall(5, [4, 1.95], [4, 3]),
        ],
        "doors": [],
        "passages": [],
        "furniture": [
            furn(0, "refrigerator", "electric_refrigerator.n.01", "room_0", [0.45, 0.4, 0.9],
                 [0.7, 0.6, 1.8], ["container", "openable"], "closed"),
            furn(1, "countertop", "countertop.n.01", "room_0", [3.6, 2.6, 0.45],
                 [0.6, 0.6, 0.9], ["supporter"], None),
            furn(2, "bed", "bed.n.01", "room_1", [7.0, 1.5, 0.3], [1.6, 2.0, 0.6],
                 ["supporter"], None),
            furn(3, "wardrobe", "wardrobe.n.01", "room_1", [4.6, 2.65, 1.0], [1.0, 0.5, 2.0],
                 ["container", "openable"], "closed"),
        ],
        "objects": [
            obj(0, "apple", "furn_0", "inside", "room_0", [0.45, 0.4, 1.0]),
            obj(1, "cup", "furn_1", "ontop", "room_0", [3.6, 2.6, 0.95]),
            obj(2, "sweater", "furn_3", "inside", "room_1", [4.6, 2.65, 1.2]),
        ],
        "starts": [{"x": 2.0, "y": 1.5, "yaw": 0, "room": "room_0"}],
    }
    if opening == "passage":
        spec["passages"] = [{"id": "pass_0", "center": [4, 1.5], "width": 0.9,
                             "yaw": math.pi / 2, "rooms": ["room_0", "room_1"]}]
    elif opening in ("open", "closed"):
        spec["doors"] = [{"id": "door_0", "center": [4, 1.5], "width": 0.9, "yaw": math.pi / 2,
                          "state": opening, "rooms": ["room_0", "room_1"]}]
    else:
        raise ValueError(f"opening must be open, closed or passage, got {opening!r}")
    return load_house(spec)
