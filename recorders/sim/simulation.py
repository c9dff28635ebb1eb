"""The PyBullet house simulation: a kinematic base with an RGB-D + instance camera and the
skills planners call (navigate, open, close, explore, look around).

:class:`Simulation` is the one object both the scripted recorder and the closed loop drive.
It owns a PyBullet DIRECT session with the house built from a :class:`HouseSpec`, the
instance table (body uid -> instance), the current open/closed states and the base pose.

Time is counted in *ticks*: every motion increment (a step of at most ``speed / fps``
metres or ``turn_speed / fps`` radians, one step of a door animation) is one tick, and
tick ``k`` happens at log time ``k * 1e9 / fps`` ns. The simulation renders nothing on
its own: on every tick it calls its observers (:class:`SimObserver`), and an observer that
wants images calls :meth:`Simulation.render`. Observers also hear of state changes and of
every finished skill (a :class:`SkillOutcome`), which is how the recorder logs actions.
An observer stops a run by raising :class:`StopSimulation` (e.g. a frame budget).

Skill targets are spec ids (``room_2``, ``door_0``, ``furn_5``, ``obj_9``), instance ids
(ints of the instances table) or points ``(x, y)``. Outcomes follow the log's
``sgtool.Action``: ``success``; ``failure`` with a reason (no path, out of reach, not
openable, already open); ``invalid`` for a target that does not exist.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from fractions import Fraction
from typing import Any

import numpy as np
from scipy import ndimage

from sgtool.errors import SgtoolError
from sgtool.house.spec import Door, HouseSpec, StartPose, room_at
from sgtool.log.frame import Frame
from sgtool.mapping.occupancy import OccupancyMap, astar, geodesic_distances, nearest_free_cell
from sgtool.recorders.sim import articulation as art
from sgtool.recorders.sim import navigation as nav
from sgtool.recorders.sim.build import (
    World,
    build_world,
    door_obstacles,
    pybullet,
    remove_panel,
    set_panel,
)
from sgtool.recorders.sim.camera import (
    CameraConfig,
    base_T_camera,
    depth_from_buffer,
    ids_from_segmentation,
    pixel_ray,
    projection_matrix,
    se2_matrix,
    view_matrix,
)
from sgtool.recorders.sim.instances import DOOR, FURNITURE, OBJECT, Instance
from sgtool.recorders.sim.navigation import Pose2, RobotConfig

LIGHT_DIRECTION = (0.4, 0.25, 1.0)
MAX_OBSTACLE_HEIGHT = 1.8  # panels starting above this do not block the base (m)

Target = str | int | tuple[float, float] | Sequence[float]


class StopSimulation(Exception):  # noqa: N818 (a control-flow signal, not an error)
    """Raised by an observer to end the current run (frame budget reached)."""


@dataclass(frozen=True)
class SkillOutcome:
    """What a skill did: the log's ``sgtool.Action`` fields."""

    skill: str
    target: str | None
    outcome: str  # success | failure | invalid
    reason: str = ""
    travelled_m: float = 0.0
    ticks: int = 0

    @property
    def success(self) -> bool:
        return self.outcome == "success"


class SimObserver:
    """Receives the simulation's events; override what you need."""

    def on_tick(self, sim: Simulation) -> None:
        """A new frame: the base and the doors are where they are at ``sim.tick_index``."""

    def on_state(self, sim: Simulation, spec_id: str, state: str) -> None:
        """A door or container changed to ``state`` (at the current tick)."""

    def on_skill(self, sim: Simulation, outcome: SkillOutcome) -> None:
        """A top-level skill finished (at the last tick it took)."""


@dataclass(frozen=True)
class _Resolved:
    label: str  # what the action record calls the target
    kind: str  # point | room | door | furniture | object | structure
    point: tuple[float, float]
    box: art.Box2 | None = None
    instance: Instance | None = None
    front: art.Box2 | None = None  # the footprint whose front (local +y) to approach


class Simulation:
    """A house in PyBullet with a kinematic camera robot. Use as a context manager or call
    :meth:`disconnect` when done (each instance owns one PyBullet DIRECT client)."""

    def __init__(self, house: HouseSpec, *, camera: CameraConfig | None = None,
                 robot: RobotConfig | None = None, fps: float = 10.0,
                 start: int | Pose2 | StartPose = 0) -> None:
        if not 0.1 <= fps <= 1000:
            raise SgtoolError(f"fps {fps}: must be 0.1..1000")
        self.spec = house
        self.camera = camera or CameraConfig()
        self.robot = robot or RobotConfig()
        self.fps = float(fps)
        self._dt = Fraction(fps).limit_denominator(1_000_000)
        self.base: Pose2 = self._start_pose(start)
        self._pb = pybullet()
        self.client = self._pb.connect(self._pb.DIRECT)
        try:
            self.world: World = build_world(self._pb, self.client, house)
        except BaseException:
            self._pb.disconnect(physicsClientId=self.client)
            raise
        self._connected = True
        self.intrinsics = self.camera.intrinsics()
        self._proj = projection_matrix(self.camera)
        self._base_T_cam = base_T_camera(self.camera.mount_height, self.camera.tilt_deg)
        self.tick_index = 0
        self.travelled_m = 0.0
        self.observers: list[SimObserver] = []
        self._depth = 0  # nesting of skills; only top-level ones are reported
        self._occ_cache: dict[tuple[Any, ...], OccupancyMap] = {}
        self._room_masks: dict[str, np.ndarray] | None = None
        for sid in sorted(self.world.panels, key=_id_key):  # open what the spec says is open
            if self.world.states[sid] == "open":
                self._set_open(sid, 1.0, self._layout_for_opening(sid))

    # ----- life cycle -------------------------------------------------------------------
    def disconnect(self) -> None:
        if self._connected:
            self._pb.disconnect(physicsClientId=self.client)
            self._connected = False

    def __enter__(self) -> Simulation:
        return self

    def __exit__(self, *exc: Any) -> None:
        self.disconnect()

    def _start_pose(self, start: int | Pose2 | StartPose) -> Pose2:
        if isinstance(start, StartPose):
            return (start.x, start.y, start.yaw)
        if isinstance(start, int):
            if not self.spec.starts:
                raise SgtoolError("the house spec has no start poses; give one")
            if not 0 <= start < len(self.spec.starts):
                raise SgtoolError(f"start {start}: the house has {len(self.spec.starts)} "
                                  f"start poses (0..{len(self.spec.starts) - 1})")
            s = self.spec.starts[start]
            return (s.x, s.y, s.yaw)
        x, y, yaw = start
        return (float(x), float(y), float(yaw))

    # ----- state ------------------------------------------------------------------------
    @property
    def instances(self) -> tuple[Instance, ...]:
        return self.world.instances

    @property
    def states(self) -> dict[str, str]:
        """spec id -> "open"/"closed" for doors and openable furniture (a copy)."""
        return dict(self.world.states)

    def state_of(self, instance: Instance) -> str | None:
        return self.world.states.get(instance.spec_id or "")

    def instance_records(self) -> list[dict[str, Any]]:
        """The ``sgtool.Instances`` items with the current states."""
        return [i.record(self.state_of(i)) for i in self.world.instances]

    def time_ns(self, tick: int | None = None) -> int:
        """Log time of ``tick`` (default: the current one): ``tick * 1e9 / fps`` ns."""
        k = self.tick_index if tick is None else tick
        return int(k * 1_000_000_000 / self._dt)

    def base_matrix(self, pose: Pose2 | None = None) -> np.ndarray:
        x, y, yaw = self.base if pose is None else pose
        return se2_matrix(x, y, yaw)

    def camera_matrix(self, pose: Pose2 | None = None) -> np.ndarray:
        """world_T_camera (optical frame) for the base at ``pose`` (default: now)."""
        return self.base_matrix(pose) @ self._base_T_cam

    def room_of_base(self) -> str | None:
        return room_at(self.spec, self.base[0], self.base[1])

    # ----- sensing ----------------------------------------------------------------------
    def render(self) -> Frame:
        """Render the camera at the current tick: rgb (H, W, 3) uint8, depth float32 metres
        (0 = no return), ids int32 instance ids (0 = background), poses, intrinsics."""
        pb, cfg = self._pb, self.camera
        pose = self.camera_matrix()
        _, _, rgba, buf, seg = pb.getCameraImage(
            cfg.width, cfg.height, view_matrix(pose), self._proj,
            renderer=pb.ER_TINY_RENDERER, flags=pb.ER_SEGMENTATION_MASK_OBJECT_AND_LINKINDEX,
            shadow=0, lightDirection=list(LIGHT_DIRECTION), physicsClientId=self.client)
        h, w = cfg.height, cfg.width
        rgba = np.asarray(rgba, dtype=np.uint8).reshape(h, w, 4)
        depth = depth_from_buffer(np.asarray(buf, dtype=np.float32).reshape(h, w), cfg)
        ids = ids_from_segmentation(np.asarray(seg, dtype=np.int32).reshape(h, w),
                                    self.world.lut)
        return Frame(index=self.tick_index, time_ns=self.time_ns(), rgb=rgba[..., :3],
                     depth=depth, ids=ids, pose=pose, intrinsics=self.intrinsics,
                     base_pose=self.base_matrix())

    def ray_depth(self, u: float, v: float) -> float:
        """Depth along the optical axis of the first surface through pixel (u, v), by a
        PyBullet ray test against the collision shapes (0 when nothing is within range)."""
        pose = self.camera_matrix()
        d = pixel_ray(self.intrinsics, u, v)  # z = 1: the ray's end lies at z = depth_max
        origin = pose[:3, 3]
        end = origin + pose[:3, :3] @ (d * self.camera.depth_max)
        hit = self._pb.rayTest(origin.tolist(), end.tolist(), physicsClientId=self.client)[0]
        if hit[0] < 0:
            return 0.0
        return float(hit[2]) * self.camera.depth_max  # hit fraction of the way to z = max

    # ----- clock ------------------------------------------------------------------------
    def tick(self) -> None:
        """One frame: tell the observers, then advance the clock."""
        for o in self.observers:
            o.on_tick(self)
        self.tick_index += 1

    def teleport(self, pose: Pose2) -> None:
        """Put the base at ``pose`` without moving through the world (no tick)."""
        self.base = (float(pose[0]), float(pose[1]), nav.wrap_angle(float(pose[2])))

    def _move(self, poses: Sequence[Pose2]) -> float:
        """Follow per-tick poses; returns the distance driven."""
        dist = 0.0
        for p in poses:
            dist += math.dist(self.base[:2], p[:2])
            self.travelled_m += math.dist(self.base[:2], p[:2])
            self.base = p
            self.tick()
        return dist

    # ----- maps -------------------------------------------------------------------------
    def occupancy(self, doors_passable: bool = False) -> OccupancyMap:
        """Occupancy in the current door states with open panels as obstacles (cached)."""
        panels = [b.panel.footprint(b.fraction) for bodies in self.world.panels.values()
                  for b in bodies if b.blocks]
        door_states = {d.id: self.world.states[d.id] for d in self.spec.doors}
        key = (doors_passable, tuple(sorted(door_states.items())), tuple(panels))
        occ = self._occ_cache.get(key)
        if occ is None:
            if len(self._occ_cache) > 64:
                self._occ_cache.clear()
            occ = nav.occupancy_with(self.spec, door_states, panels, self.robot, doors_passable)
            self._occ_cache[key] = occ
        return occ

    # ----- targets ----------------------------------------------------------------------
    def resolve(self, target: Target) -> _Resolved | str:
        """A target as something to go to, or a reason why it is invalid."""
        if isinstance(target, (tuple, list, np.ndarray)) and len(target) == 2:
            x, y = float(target[0]), float(target[1])
            if not (math.isfinite(x) and math.isfinite(y)):
                return f"point {target!r} is not finite"
            return _Resolved(f"({x:.2f}, {y:.2f})", "point", (x, y))
        inst: Instance | None = None
        if isinstance(target, (int, np.integer)) and not isinstance(target, bool):
            inst = self.world.by_id.get(int(target))
            if inst is None:
                return f"no instance {int(target)}"
        elif isinstance(target, str):
            if target.startswith("room_"):
                try:
                    room = self.spec.room(target)
                except KeyError:
                    return f"no room {target!r}"
                return _Resolved(target, "room", room.centroid)
            inst = self.world.by_spec.get(target)
            if inst is None:
                return f"no room, door, furniture or object {target!r}"
        else:
            return f"cannot go to {target!r}"
        return self._resolve_instance(inst)

    def _resolve_instance(self, inst: Instance) -> _Resolved | str:
        label = inst.spec_id or f"{inst.category} {inst.id}"
        sid = inst.spec_id
        if inst.kind == DOOR and sid:
            d = next(d for d in self.spec.doors if d.id == sid)
            box = (d.center[0], d.center[1], d.width, d.thickness, d.yaw)
            # approach square on, from the side the robot is on (local +y = that side)
            side = art.side_of_door(d, self.base[0], self.base[1])
            front = box if side > 0 else (*box[:4], d.yaw + math.pi)
            return _Resolved(label, "door", d.center, box, inst, front)
        if inst.kind == FURNITURE and sid:
            f = self.spec.furniture_by_id()[sid]
            box = (f.center[0], f.center[1], f.size[0], f.size[1], f.yaw)
            front = box if f.is_container else None
            return _Resolved(label, "furniture", (f.center[0], f.center[1]), box, inst, front)
        if inst.kind == OBJECT and sid:
            o = self.spec.object_by_id()[sid]
            parent = self.spec.furniture_by_id()[o.parent]
            box = (o.position[0], o.position[1], o.size[0], o.size[1], parent.yaw)
            pbox = (parent.center[0], parent.center[1], parent.size[0], parent.size[1],
                    parent.yaw)
            front = pbox if o.relation == "inside" else None
            return _Resolved(label, "object", (o.position[0], o.position[1]), box, inst, front)
        return f"{label} ({inst.category}) is part of the building, not a target"

    # ----- skills -----------------------------------------------------------------------
    def _report(self, outcome: SkillOutcome) -> SkillOutcome:
        if self._depth == 0:
            for o in self.observers:
                o.on_skill(self, outcome)
        return outcome

    def navigate(self, target: Target) -> SkillOutcome:
        """Drive to ``target`` along a collision-free A* path: a room's viewpoint (free,
        clear of obstacles, nearest its centroid), a point's nearest free cell, or a stand
        within reach of a door, piece of furniture or object, facing it."""
        t0 = self.tick_index
        r = self.resolve(target)
        label = _label(target, r)
        if isinstance(r, str):
            return self._report(SkillOutcome("navigate", label, "invalid", r))
        dist, reason = self._go_to(r)
        outcome = "success" if reason is None else "failure"
        return self._report(SkillOutcome("navigate", label, outcome, reason or "", dist,
                                         self.tick_index - t0))

    def _go_to(self, r: _Resolved) -> tuple[float, str | None]:
        occ = self.occupancy()
        here = self.base[:2]
        final_yaw: float | None = None
        if r.kind == "room":
            geo = geodesic_distances(occ, here)
            goal = nav.room_viewpoint(occ, geo, self.spec.room(r.label))
            if goal is None:
                return 0.0, self._unreachable_reason(r)
        elif r.kind == "point":
            cell = nearest_free_cell(occ, r.point[0], r.point[1], max_snap=0.5)
            if cell is None:
                return 0.0, f"{r.label} is not on free floor"
            goal = (occ.origin[0] + (cell[1] + 0.5) * occ.resolution,
                    occ.origin[1] + (cell[0] + 0.5) * occ.resolution)
        else:
            assert r.box is not None
            geo = geodesic_distances(occ, here)
            goal = nav.approach_goal(occ, geo, r.box, self.robot, r.front)
            if goal is None:
                return 0.0, self._unreachable_reason(r)
            final_yaw = math.atan2(r.point[1] - goal[1], r.point[0] - goal[0])
        path = astar(occ, here, goal)
        if path is None:
            return 0.0, self._unreachable_reason(r)
        pts = nav.smooth_path(occ, path)
        if len(pts) >= 1 and math.dist(pts[0], here) < occ.resolution:
            pts = pts[1:]  # the start cell's centre: no need to go there first
        if final_yaw is not None and math.dist(goal, here) < 1e-6:
            pts = []
        poses = nav.follow_poses(self.base, pts, self._step(), self._turn_step(), final_yaw)
        return self._move(poses), None

    def closed_doors_on_way(self, target: Target) -> list[str] | None:
        """The closed doors (spec ids, in the order met) on a shortest path to ``target``
        with every door passable; [] when none is in the way, None when the target cannot
        be reached even through closed doors (or does not exist)."""
        r = self.resolve(target)
        if isinstance(r, str):
            return None
        return self._closed_doors_towards(r)

    def _closed_doors_towards(self, r: _Resolved) -> list[str] | None:
        occ = self.occupancy(doors_passable=True)
        goal: tuple[float, float] | None = r.point
        if r.kind == "room":
            geo = geodesic_distances(occ, self.base[:2])
            goal = nav.room_viewpoint(occ, geo, self.spec.room(r.label))
            if goal is None:
                return None
        path = astar(occ, self.base[:2], goal, max_snap=1.5)
        if path is None:
            return None
        hits: list[tuple[int, str]] = []
        for d in self.spec.doors:
            if self.world.states[d.id] != "closed":
                continue
            box = (d.center[0], d.center[1], d.width, max(d.thickness, 2 * occ.resolution),
                   d.yaw)
            for i, p in enumerate(path):
                if art.point_box_distance(p[0], p[1], box) <= occ.resolution:
                    hits.append((i, d.id))
                    break
        return [d for _, d in sorted(hits)]

    def _unreachable_reason(self, r: _Resolved) -> str:
        """Why ``r`` cannot be reached: behind closed doors (named) or not at all."""
        closed = self._closed_doors_towards(r)
        if closed:
            return f"{r.label} is behind closed door(s) {', '.join(closed)}"
        return f"no collision-free path to {r.label}"

    def _layout_for_opening(self, sid: str) -> list[art.Panel] | None:
        """How to open ``sid``'s panels: the first of the candidate layouts whose open
        panels leave every room as connected as before and the robot free to leave; None
        when none does (the panels are then taken away instead of swung).

        Doors: into a room rather than a corridor, else away from the robot, clear of
        furniture and walls (:func:`~sgtool.recorders.sim.articulation.swing_choices`).
        Single container doors: hinged on the side away from the robot first."""
        inst = self.world.by_spec[sid]
        bodies = self.world.panels[sid]
        x, y = self.base[:2]
        options: list[list[art.Panel]]
        if inst.kind == DOOR:
            d = next(d for d in self.spec.doors if d.id == sid)
            pref = _room_side(self.spec, d) or -art.side_of_door(d, x, y)
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
        before, blocked0, _ = self._room_floor(sid, [])
        for opt in options:
            fps = [p.footprint(1.0) for p in opt if p.z0 < MAX_OBSTACLE_HEIGHT]
            after, blocked1, robot_ok = self._room_floor(sid, fps)
            added = blocked1 - blocked0
            if robot_ok and all(after[r] >= before[r] - added for r in before):
                return opt
        return None

    def _room_floor(self, skip: str, extra: list[art.Box2]
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
        cell = nearest_free_cell(occ, self.base[0], self.base[1], max_snap=0.5)
        robot_ok = cell is not None and bool(main[cell])
        return ({rid: int((m & main).sum()) for rid, m in self._room_masks.items()},
                int(occ.blocked.sum()), robot_ok)

    def _set_open(self, sid: str, fraction: float, layout: list[art.Panel] | None) -> None:
        """Put ``sid``'s panels at ``fraction`` open in ``layout`` (None: taken away, which
        happens at fraction 1; until then they stay closed)."""
        for i, b in enumerate(self.world.panels[sid]):
            if layout is None:
                if fraction >= 1.0:
                    remove_panel(self._pb, self.client, b)
                elif not b.removed:
                    set_panel(self._pb, self.client, b, 0.0)
            else:
                b.panel = layout[i]
                set_panel(self._pb, self.client, b, fraction)

    def _change_state(self, sid: str, state: str) -> None:
        self.world.states[sid] = state
        for o in self.observers:
            o.on_state(self, sid, state)

    def _step(self) -> float:
        return self.robot.speed / self.fps

    def _turn_step(self) -> float:
        return self.robot.turn_speed / self.fps

    def _reach_problem(self, r: _Resolved) -> str | None:
        assert r.box is not None
        d = art.point_box_distance(self.base[0], self.base[1], r.box)
        if d > self.robot.reach + 1e-9:
            return (f"{r.label} is out of reach: {d:.2f} m from the robot (reach "
                    f"{self.robot.reach:.2f} m)")
        return None

    def open(self, target: Target) -> SkillOutcome:
        """Open a door or an openable container within reach: turn to face it, swing its
        panel(s) open over ``robot.open_time`` seconds. House doors swing away from the
        robot, into the other room."""
        return self._open_close(target, "open")

    def close(self, target: Target) -> SkillOutcome:
        """Close a door or an openable container within reach."""
        return self._open_close(target, "closed")

    def _open_close(self, target: Target, to: str) -> SkillOutcome:
        skill = "open" if to == "open" else "close"
        t0 = self.tick_index
        r = self.resolve(target)
        label = _label(target, r)
        if isinstance(r, str):
            return self._report(SkillOutcome(skill, label, "invalid", r))
        inst = r.instance
        if inst is None or not inst.openable or inst.spec_id not in self.world.panels:
            what = r.label if inst is None else f"{r.label} ({inst.category})"
            return self._report(SkillOutcome(skill, label, "failure",
                                             f"{what} cannot be opened or closed"))
        sid = inst.spec_id
        assert sid is not None
        if self.world.states[sid] == to:
            return self._report(SkillOutcome(skill, label, "failure",
                                             f"{r.label} is already {to}"))
        problem = self._reach_problem(r)
        if problem:
            return self._report(SkillOutcome(skill, label, "failure", problem))
        bodies = self.world.panels[sid]
        if to == "closed":
            for b in bodies:
                closed = b.panel.footprint(0.0)
                if art.point_box_distance(self.base[0], self.base[1], closed) < self.robot.radius:
                    return self._report(SkillOutcome(
                        skill, label, "failure", f"the robot stands in the way of {r.label}"))
        # face the target, then animate
        yaw = math.atan2(r.point[1] - self.base[1], r.point[0] - self.base[0])
        self._move(nav.turn_poses(self.base, yaw, self._turn_step()))
        n = max(1, round(self.robot.open_time * self.fps))
        if to == "open":
            layout = self._layout_for_opening(sid)
            for k in range(1, n + 1):
                self._set_open(sid, k / n, layout)
                if k == n:
                    self._change_state(sid, to)
                self.tick()
        else:
            for k in range(1, n + 1):
                for b in bodies:
                    if b.removed and k < n:
                        continue  # a taken-away panel comes back closed at the end
                    set_panel(self._pb, self.client, b, 1.0 - k / n if not b.removed else 0.0)
                if k == n:
                    self._change_state(sid, to)
                self.tick()
        return self._report(SkillOutcome(skill, label, "success", "", 0.0,
                                         self.tick_index - t0))

    def look_around(self) -> SkillOutcome:
        """Turn once around on the spot (four quarter turns, so the frames are spread
        evenly whatever the turn speed)."""
        t0 = self.tick_index
        x, y, a = self.base
        poses: list[Pose2] = []
        cur = self.base
        for q in range(1, 5):
            seg = nav.turn_poses(cur, a + q * math.pi / 2, self._turn_step())
            poses += seg
            cur = seg[-1] if seg else cur
        self._move(poses)
        return self._report(SkillOutcome("look_around", None, "success", "", 0.0,
                                         self.tick_index - t0))

    def explore(self, target: Target) -> SkillOutcome:
        """Go to ``target`` (a room, a point, an object) and look around there."""
        t0 = self.tick_index
        self._depth += 1
        try:
            nav_out = self.navigate(target)
            if nav_out.success:
                self.look_around()
        finally:
            self._depth -= 1
        if not nav_out.success:
            return self._report(SkillOutcome("explore", nav_out.target, nav_out.outcome,
                                             nav_out.reason, nav_out.travelled_m,
                                             self.tick_index - t0))
        return self._report(SkillOutcome("explore", nav_out.target, "success", "",
                                         nav_out.travelled_m, self.tick_index - t0))


def _room_side(spec: HouseSpec, d: Door) -> int | None:
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


def _id_key(s: str) -> tuple[str, int]:
    head, _, num = s.rpartition("_")
    return (head, int(num)) if num.isdigit() else (s, -1)


def _label(target: Target, r: _Resolved | str) -> str:
    if not isinstance(r, str):
        return r.label
    if isinstance(target, (tuple, list, np.ndarray)):
        return "(" + ", ".join(str(v) for v in target) + ")"
    return str(target)
