"""Skill targets: spec ids (``room_2``, ``door_0``, ``furn_5``, ``obj_9``), instance ids
(ints of the instances table) or points ``(x, y)``, resolved to something to go to -- a
point, the footprint to come within reach of, and the footprint whose front (local +y) to
approach -- or to the reason why they are invalid."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from sgtool.house.spec import HouseSpec
from sgtool.recorders.sim import articulation as art
from sgtool.recorders.sim.body_instances import DOOR, FURNITURE, OBJECT, Instance
from sgtool.recorders.sim.build import World

Target = str | int | tuple[float, float] | Sequence[float]


@dataclass(frozen=True)
class Resolved:
    label: str  # what the action record calls the target
    kind: str  # point | room | door | furniture | object | structure
    point: tuple[float, float]
    box: art.Box2 | None = None
    instance: Instance | None = None
    front: art.Box2 | None = None  # the footprint whose front (local +y) to approach


def resolve_target(spec: HouseSpec, world: World, base: tuple[float, float, float],
                   target: Target) -> Resolved | str:
    """A target as something to go to from ``base``, or a reason why it is invalid."""
    if isinstance(target, (tuple, list, np.ndarray)) and len(target) == 2:
        x, y = float(target[0]), float(target[1])
        if not (math.isfinite(x) and math.isfinite(y)):
            return f"point {target!r} is not finite"
        return Resolved(f"({x:.2f}, {y:.2f})", "point", (x, y))
    inst: Instance | None = None
    if isinstance(target, (int, np.integer)) and not isinstance(target, bool):
        inst = world.by_id.get(int(target))
        if inst is None:
            return f"no instance {int(target)}"
    elif isinstance(target, str):
        if target.startswith("room_"):
            try:
                room = spec.room(target)
            except KeyError:
                return f"no room {target!r}"
            return Resolved(target, "room", room.centroid)
        inst = world.by_spec.get(target)
        if inst is None:
            return f"no room, door, furniture or object {target!r}"
    else:
        return f"cannot go to {target!r}"
    return resolve_instance(spec, inst, base)


def resolve_instance(spec: HouseSpec, inst: Instance,
                     base: tuple[float, float, float]) -> Resolved | str:
    label = inst.spec_id or f"{inst.category} {inst.id}"
    sid = inst.spec_id
    front: art.Box2 | None
    if inst.kind == DOOR and sid:
        d = next(d for d in spec.doors if d.id == sid)
        box = (d.center[0], d.center[1], d.width, d.thickness, d.yaw)
        # approach square on, from the side the robot is on (local +y = that side)
        side = art.side_of_door(d, base[0], base[1])
        front = box if side > 0 else (*box[:4], d.yaw + math.pi)
        return Resolved(label, "door", d.center, box, inst, front)
    if inst.kind == FURNITURE and sid:
        f = spec.furniture_by_id()[sid]
        box = (f.center[0], f.center[1], f.size[0], f.size[1], f.yaw)
        front = box if f.is_container else None
        return Resolved(label, "furniture", (f.center[0], f.center[1]), box, inst, front)
    if inst.kind == OBJECT and sid:
        o = spec.object_by_id()[sid]
        parent = spec.furniture_by_id()[spec.root_furniture()[o.id]]
        box = (o.position[0], o.position[1], o.size[0], o.size[1], parent.yaw)
        pbox = (parent.center[0], parent.center[1], parent.size[0], parent.size[1],
                parent.yaw)
        front = pbox if o.relation == "inside" else None
        return Resolved(label, "object", (o.position[0], o.position[1]), box, inst, front)
    return f"{label} ({inst.category}) is part of the building, not a target"


def target_label(target: Target, r: Resolved | str) -> str:
    """What the action record calls ``target``."""
    if not isinstance(r, str):
        return r.label
    if isinstance(target, (tuple, list, np.ndarray)):
        return "(" + ", ".join(str(v) for v in target) + ")"
    return str(target)
