"""The skills planners call on the simulation: navigate, open, close, look around,
explore. :class:`Skills` is mixed into :class:`~sgtool.recorders.sim.simulation.Simulation`
and drives it through its world state, clock and maps.

Outcomes follow the log's ``sgtool.Action``: ``success``; ``failure`` with a reason (no
path, out of reach, not openable, already open); ``invalid`` for a target that does not
exist (:mod:`.targets`). Only top-level skills are reported to the observers (``explore``
navigates and looks around as one skill).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np

from sgtool.house.geometry import segments_cross
from sgtool.mapping.occupancy import astar, geodesic_distances, nearest_free_cell
from sgtool.planning.base import Outcome
from sgtool.recorders.sim import articulation as art
from sgtool.recorders.sim import navigation as nav
from sgtool.recorders.sim.build import set_panel
from sgtool.recorders.sim.events import SkillOutcome
from sgtool.recorders.sim.navigation import Pose2
from sgtool.recorders.sim.targets import Resolved, Target, target_label

if TYPE_CHECKING:
    from types import ModuleType

    from sgtool.house.spec import HouseSpec
    from sgtool.mapping.occupancy import OccupancyMap
    from sgtool.recorders.sim.build import World
    from sgtool.recorders.sim.events import SimObserver
    from sgtool.recorders.sim.navigation import RobotConfig


class Skills:
    """The skills of :class:`~sgtool.recorders.sim.simulation.Simulation` (module doc)."""

    if TYPE_CHECKING:  # provided by Simulation
        spec: HouseSpec
        robot: RobotConfig
        fps: float
        world: World
        base: Pose2
        tick_index: int
        observers: list[SimObserver]
        client: int
        _pb: ModuleType
        _depth: int

        def occupancy(self, doors_passable: bool = False) -> OccupancyMap: ...
        def resolve(self, target: Target) -> Resolved | str: ...
        def tick(self) -> None: ...
        def _move(self, poses: Sequence[Pose2]) -> float: ...
        def _layout_for_opening(self, sid: str) -> list[art.Panel] | None: ...
        def _set_open(self, sid: str, fraction: float,
                      layout: list[art.Panel] | None) -> None: ...
        def _change_state(self, sid: str, state: str) -> None: ...

    def _report(self, outcome: SkillOutcome) -> SkillOutcome:
        from sgtool.recorders.sim.simulation import Simulation  # the class this is mixed into

        assert isinstance(self, Simulation)
        if self._depth == 0:
            for o in self.observers:
                o.on_skill(self, outcome)
        return outcome

    def _step(self) -> float:
        return self.robot.speed / self.fps

    def _turn_step(self) -> float:
        return self.robot.turn_speed / self.fps

    # ----- navigate ---------------------------------------------------------------------
    def navigate(self, target: Target) -> SkillOutcome:
        """Drive to ``target`` along a collision-free A* path: a room's viewpoint (free,
        clear of obstacles, nearest its centroid), a point's nearest free cell, or a stand
        within reach of a door, piece of furniture or object, facing it."""
        t0 = self.tick_index
        r = self.resolve(target)
        label = target_label(target, r)
        if isinstance(r, str):
            return self._report(SkillOutcome("navigate", label, "invalid", r))
        dist, reason = self._go_to(r)
        outcome: Outcome = "success" if reason is None else "failure"
        return self._report(SkillOutcome("navigate", label, outcome, reason or "", dist,
                                         self.tick_index - t0))

    def _go_to(self, r: Resolved) -> tuple[float, str | None]:
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
            goal = nav.approach_goal(occ, geo, r.box, self.robot, r.front,
                                     self._room_of(r, occ))
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

    def _room_of(self, r: Resolved, occ: OccupancyMap) -> np.ndarray | None:
        """The cells of the room of the piece or object ``r`` (None: a door, or no room):
        its stand is sought there first, where no wall stands between (:meth:`open`)."""
        sid = None if r.instance is None else r.instance.spec_id
        thing = self.spec.holder_by_id().get(sid) if sid is not None and \
            r.kind in ("furniture", "object") else None
        if thing is None:
            return None
        try:
            return nav.room_mask(occ, self.spec.room(thing.room))
        except KeyError:
            return None

    def closed_doors_on_way(self, target: Target) -> list[str] | None:
        """The closed doors (spec ids, in the order met) on a shortest path to ``target``
        with every door passable; [] when none is in the way, None when the target cannot
        be reached even through closed doors (or does not exist)."""
        r = self.resolve(target)
        if isinstance(r, str):
            return None
        return self._closed_doors_towards(r)

    def _closed_doors_towards(self, r: Resolved) -> list[str] | None:
        occ = self.occupancy(doors_passable=True)
        goal = r.point
        if r.kind == "room":
            geo = geodesic_distances(occ, self.base[:2])
            viewpoint = nav.room_viewpoint(occ, geo, self.spec.room(r.label))
            if viewpoint is None:
                return None
            goal = viewpoint
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

    def _unreachable_reason(self, r: Resolved) -> str:
        """Why ``r`` cannot be reached: behind closed doors (named) or not at all."""
        closed = self._closed_doors_towards(r)
        if closed:
            return f"{r.label} is behind closed door(s) {', '.join(closed)}"
        return f"no collision-free path to {r.label}"

    # ----- open / close -----------------------------------------------------------------
    def _reach_problem(self, r: Resolved) -> str | None:
        """Why the robot cannot work on ``r`` from where it stands: farther than its reach,
        or (a piece or object) a wall or closed door between the base and the thing's
        centre: an arm does not open a cabinet from the room behind its wall."""
        assert r.box is not None
        d = art.point_box_distance(self.base[0], self.base[1], r.box)
        if d > self.robot.reach + 1e-9:
            return (f"{r.label} is out of reach: {d:.2f} m from the robot (reach "
                    f"{self.robot.reach:.2f} m)")
        if r.kind == "door":
            return None
        here, there = (self.base[0], self.base[1]), (r.box[0], r.box[1])
        for w in self.spec.walls:
            if segments_cross(here, there, w.a, w.b):
                return f"{r.label} is out of reach: {w.id} stands between it and the robot"
        for door in self.spec.doors:
            if self.world.states[door.id] == "closed" and \
                    segments_cross(here, there, *door.segment):
                return (f"{r.label} is out of reach: closed door {door.id} stands between "
                        "it and the robot")
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
        label = target_label(target, r)
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

    # ----- look around / explore --------------------------------------------------------
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
