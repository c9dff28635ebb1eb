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

This module holds the world state (house, instance table, door and container states, base
pose), the clock, the maps and the sensing; the skills are in :mod:`.skills`, their targets
in :mod:`.targets`, the choice of how a door swings open in :mod:`.opening`, and the
outcomes and observer callbacks in :mod:`.events`.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence
from dataclasses import replace
from fractions import Fraction
from typing import Any

import numpy as np

from sgtool.errors import SgtoolError
from sgtool.house.outline import outline_walls
from sgtool.house.spec import HouseSpec, StartPose, room_at, spec_id_key
from sgtool.log.codec import compose
from sgtool.log.frame import Frame
from sgtool.mapping.occupancy import OccupancyMap
from sgtool.recorders.sim import articulation as art
from sgtool.recorders.sim import navigation as nav
from sgtool.recorders.sim.body_instances import Instance
from sgtool.recorders.sim.build import World, build_world, pybullet, remove_panel, set_panel
from sgtool.recorders.sim.camera import (
    TILT_MAX,
    TILT_MIN,
    CameraConfig,
    base_T_camera,
    depth_from_buffer,
    ids_from_segmentation,
    pixel_ray,
    projection_matrix,
    se2_matrix,
    view_matrix,
)
from sgtool.recorders.sim.culling import FAR_MARGIN_M, ViewCulling
from sgtool.recorders.sim.events import SimObserver, SkillOutcome, StopSimulation
from sgtool.recorders.sim.navigation import Pose2, RobotConfig
from sgtool.recorders.sim.opening import OpeningPlanner
from sgtool.recorders.sim.skills import Skills
from sgtool.recorders.sim.targets import Resolved, Target, resolve_target

__all__ = ["LIGHT_DIRECTION", "SimObserver", "Simulation", "SkillOutcome", "StopSimulation",
           "Target"]

LIGHT_DIRECTION = (0.4, 0.25, 1.0)


FPS_RANGE = (0.1, 1000.0)  # frames per second of log time a simulation runs at


class Simulation(Skills):
    """A house in PyBullet with a kinematic camera robot. Use as a context manager or call
    :meth:`disconnect` when done (each instance owns one PyBullet DIRECT client)."""

    def __init__(self, house: HouseSpec, *, camera: CameraConfig | None = None,
                 robot: RobotConfig | None = None, fps: float = 10.0,
                 start: int | Pose2 | StartPose = 0, cull: bool = True) -> None:
        if not FPS_RANGE[0] <= fps <= FPS_RANGE[1]:
            raise SgtoolError(f"fps {fps}: must be {FPS_RANGE[0]:g}..{FPS_RANGE[1]:g}")
        if not house.walls:  # (a house file may give none: its outer outline gets walls)
            house = dataclasses.replace(house, walls=outline_walls(house))
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
        self.head_tilt_deg = self.camera.tilt_deg  # the head's tilt now (tilt_head)
        self._base_T_cam = base_T_camera(self.camera.mount_height, self.camera.tilt_deg)
        self.tick_index = 0
        self.travelled_m = 0.0
        self.observers: list[SimObserver] = []
        self._depth = 0  # nesting of skills; only top-level ones are reported
        self._occ_cache: dict[tuple[Any, ...], OccupancyMap] = {}
        self._layouts = 0  # bumped whenever a panel gets a new layout (the cache key)
        self._contact_map: tuple[tuple[Any, ...], OccupancyMap] | None = None
        self._opening = OpeningPlanner(house, self.world, self.robot)
        for sid in sorted(self.world.panels, key=spec_id_key):  # open what the spec says is open
            if self.world.states[sid] == "open":
                self._set_open(sid, 1.0, self._layout_for_opening(sid))
        # ``cull``: the renderer draws only the bodies the image can show (:mod:`.culling`,
        # the same images in less time); otherwise every body
        self.culling = ViewCulling(
            self._pb, self.client, list(self.world.body_instance),
            [b.uid for bodies in self.world.panels.values() for b in bodies]) if cull else None

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
        """The pose the robot starts at: ``start`` (an index of the house's start poses, a
        StartPose or (x, y, yaw)) moved to the nearest place where the robot's disc
        overlaps no wall or piece (:func:`~sgtool.house.clearance.clear_start`), so the
        camera never starts inside a wall."""
        from sgtool.house.clearance import clear_start

        x, y, yaw = self._given_start(start)
        return (*clear_start(self.spec, x, y, self.robot.radius), yaw)

    def _given_start(self, start: int | Pose2 | StartPose) -> Pose2:
        if isinstance(start, StartPose):
            return (start.x, start.y, start.yaw)
        if isinstance(start, int):
            if not self.spec.starts:
                raise SgtoolError("the house spec has no start poses: add a \"starts\" entry, "
                                  "or give a start pose (x, y, yaw)")
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
        return compose(self.base_matrix(pose), self._base_T_cam)

    def room_of_base(self) -> str | None:
        return room_at(self.spec, self.base[0], self.base[1])

    # ----- sensing ----------------------------------------------------------------------
    def render(self) -> Frame:
        """Render the camera at the current tick: rgb (H, W, 3) uint8, depth float32 metres
        (0 = no return), ids int32 instance ids (0 = background), poses, intrinsics."""
        pb, cfg = self._pb, self.camera
        pose = self.camera_matrix()
        if self.culling is not None:
            self.culling.show_only_visible(pose, self.intrinsics, cfg.far + FAR_MARGIN_M)
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

    def tilt_head(self, tilts_deg: Sequence[float]) -> None:
        """Tilt the camera (a pan-tilt head on the mast) through ``tilts_deg``, downward
        degrees from the horizontal, one tick each; the base stays. The camera keeps the
        last tilt until the next call (at first the configured ``camera.tilt_deg``)."""
        for t in tilts_deg:
            t = float(t)
            if not (math.isfinite(t) and TILT_MIN <= t <= TILT_MAX):
                raise SgtoolError(f"head tilt {t} deg: must be {TILT_MIN:g}..{TILT_MAX:g}")
            if t != self.head_tilt_deg:
                self.head_tilt_deg = t
                self._base_T_cam = base_T_camera(self.camera.mount_height, t)
            self.tick()

    # ----- maps -------------------------------------------------------------------------
    def occupancy(self, doors_passable: bool = False) -> OccupancyMap:
        """Occupancy in the current door states with open panels as obstacles (cached): the
        ground truth the scripted recorder plans on. The closed loop's robot never calls
        it (it plans on its own map, :mod:`.live_skills`)."""
        return self._truth_map(doors_passable, self.robot)

    def _panel_key(self) -> tuple[Any, ...]:
        """What the truth maps depend on besides the robot: the door states and every
        panel's opening (its layout by :attr:`_layouts`), cheap to build per tick."""
        return (self._layouts, tuple(self.world.states[d.id] for d in self.spec.doors),
                tuple((b.fraction, b.removed) for bodies in self.world.panels.values()
                      for b in bodies))

    def _truth_map(self, doors_passable: bool, robot: RobotConfig) -> OccupancyMap:
        panels = [b.panel.footprint(b.fraction) for bodies in self.world.panels.values()
                  for b in bodies if b.blocks]
        door_states = {d.id: self.world.states[d.id] for d in self.spec.doors}
        key = (doors_passable, robot.radius, tuple(sorted(door_states.items())),
               tuple(panels))
        occ = self._occ_cache.get(key)
        if occ is None:
            if len(self._occ_cache) > 64:
                self._occ_cache.clear()
            occ = nav.occupancy_with(self.spec, door_states, panels, robot, doors_passable)
            self._occ_cache[key] = occ
        return occ

    # ----- motion with contacts ---------------------------------------------------------
    def in_contact(self, pose: Pose2 | None = None) -> bool:
        """Whether the base disc at ``pose`` (default: now) touches a wall, a piece of
        furniture, a closed door or an open panel: the simulator's physics (ground truth,
        with one map cell of tolerance for the grid), never given to the robot."""
        x, y = (self.base if pose is None else pose)[:2]
        key = self._panel_key()
        if self._contact_map is None or self._contact_map[0] != key:
            tol = replace(self.robot,
                          radius=max(self.robot.radius - self.robot.resolution, 0.0))
            self._contact_map = (key, self._truth_map(False, tol))
        occ = self._contact_map[1]
        r = int(math.floor((y - occ.origin[1]) / occ.resolution))
        c = int(math.floor((x - occ.origin[0]) / occ.resolution))
        return not occ.in_bounds(r, c) or bool(occ.blocked[r, c])

    def drive(self, poses: Sequence[Pose2]) -> tuple[float, bool]:
        """Follow per-tick poses until one would bring the base into contact (from a pose
        that is not): (distance driven, whether a contact stopped it). The blocked pose is
        not taken (no tick)."""
        dist = 0.0
        touching = self.in_contact()
        for p in poses:
            if not touching and self.in_contact(p):
                return dist, True
            dist += self._move((p,))
        return dist, False

    # ----- targets and doors ------------------------------------------------------------
    def resolve(self, target: Target) -> Resolved | str:
        """A target as something to go to, or a reason why it is invalid (:mod:`.targets`)."""
        return resolve_target(self.spec, self.world, self.base, target)

    def _layout_for_opening(self, sid: str) -> list[art.Panel] | None:
        """How to open ``sid``'s panels from where the robot is (:mod:`.opening`); None:
        they are taken away instead of swung."""
        return self._opening.layout(sid, self.base)

    def _set_open(self, sid: str, fraction: float, layout: list[art.Panel] | None) -> None:
        """Put ``sid``'s panels at ``fraction`` open in ``layout`` (None: taken away, which
        happens at fraction 1; until then they stay closed)."""
        self._layouts += 1
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

