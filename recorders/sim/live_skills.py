"""The robot's skills on its own map: no ground truth on the robot side.

In the closed loop (and ``sgtool record --explore frontier``) the robot plans every motion
on the occupancy grid of the scene graph it is building (the map layers of the latest
refresh, :attr:`sgtool.scenegraph.stream.SceneGraphStream.current`), made traversable by
:func:`sgtool.mapping.live_paths.traversable` (obstacles grown by the robot radius, unknown
blocked but for a short optimistic margin at frontiers). The simulator only executes
motion (:meth:`Simulation.drive`, which stops at a contact) and manipulation.

- **The guard.** The robot side holds a :class:`RobotBody`, a view of the simulation
  without the house: its pose, driving, turning on the spot, opening and closing by
  instance id. Anything else (the spec, the ground-truth occupancy, the privileged
  ``navigate``) raises :class:`PrivilegedAccess`.
- **Goals** (:mod:`sgtool.recorders.sim.live_goals`) come from the graph the planner
  decided on: an object or door node's position
  (stand within reach, nearest along the floor, facing it; at a container, in front of
  its opening when the map shows one, :func:`~sgtool.mapping.live_paths.front_goal`: from
  the side its boards hide the inside), a room or region node's
  position (the reachable cell nearest to it within ``snap``), a frontier's cluster (its
  nearest reachable cell, :func:`~sgtool.mapping.live_paths.nearest_reachable`).
- **Re-planning.** A path is followed frame by frame, turning while driving
  (:func:`~sgtool.recorders.sim.motion.drive_while_turning`: no stop-and-turn at each
  waypoint or re-plan); at every refresh of the map (every K frames) or at a contact the
  goal and the path are planned again on the newer map. A goal the map cannot reach is a
  failed skill whose reason says so; so are repeated contacts and a goal not reached
  after ``max_replans`` plans.
- **Bumps.** Where the base touched something the map does not show is marked blocked
  (:attr:`LiveSkills.bumps`, grown by the robot's radius like any obstacle) for the rest
  of the episode, unless they **wall the robot in or off**: when the marks leave it less
  than ``sealed_m2`` of reachable floor while the map without them leaves more (contacts
  at a door frame or a swinging panel can ring the robot in), or cut it off from more
  than ``sealed_m2`` of floor the map without them reaches (a mark is put one radius
  ahead of the move, so scraping a corner of a narrow passage marks the passage itself,
  and everything past it would stay unreachable for the rest of the episode), the
  oldest are dropped until neither holds. A way that is really blocked costs a skill its
  ``max_contacts`` again, and that goal is held back; the last mark of a skill that
  ended so is *held*: the cut-off rule keeps it (the robot would otherwise plan the same
  blocked way for every goal) until the robot is ``HOLD_M`` from where it was held, unless
  it walls the robot in; ``sealed_m2`` = 0 turns the rule off. When the marks wall off
  every goal of the graph while leaving more floor than that (a room whose only open door
  frame the robot brushed), the closed loop drops them all
  (:meth:`LiveSkills.forget_bumps`).
- **Looking around** (:meth:`LiveSkills.look_around`) turns only toward unknown space
  near the robot on its own map (:func:`~sgtool.recorders.sim.motion.sweep`), the shorter
  way, and stops when a refresh during the turn shows no cell known that was not before.
  With ``sight_lines`` (off by default) and ``sight`` (the map's voxel columns reaching
  above the camera, which it cannot see over, :func:`camera_sight`), unknown space behind
  them does not count: the room behind a wall is not turned to from here, the floor behind
  a table is. It saves frames and costs what the turns showed; how it was measured is in
  the project's experiment notes.
  Where a look-around ended so (not cut short by the target or the frame budget) is kept
  in :attr:`LiveSkills.looked`: looking again from there shows nothing new.
- **Looking in** (on by default, after opens from the side). After opening a container
  the robot stands within reach of it, too near for the tilted camera to see its lower
  shelves, and often beside its front, looking at a side board; with ``look_in`` > 0,
  :meth:`LiveSkills.look_in` drives it to ``look_in`` metres from the container's node
  in front of its opening as its map shows it
  (:func:`~sgtool.mapping.live_paths.view_goal`: the middle of the widest fan of open
  directions round the container), turns it to face the container and peeks, so the
  frames show what the opening revealed. With ``look_in_beyond`` > 0 only after an open
  made from more than that many degrees off the fan's bisector (where no stand in front
  was within reach, the side board hides the inside). On by default (the defaults of
  :class:`LiveNavConfig`); how they were chosen is in the project's experiment notes.
- **Peeking** (``peek``, on by default). The camera sits on a pan-tilt head: after
  opening a container, or walking up to one that stands open (examining it: a sink, a
  bookcase, a bucket), the robot tilts it down until the optical axis meets the point at
  half the height of the container's node above the floor
  (:func:`~sgtool.recorders.sim.motion.peek_tilt`; within reach, the fixed tilt leaves
  a floor-standing piece's lower shelves below the view) and back, at its turning
  speed, every tick a frame (an object needs points in two frames); no metres. The
  log's base -> camera transform moves on ``/tf`` while the head is tilted.
- **Exploring through** (``explore_through`` > 0, off by default). An explore drives to
  its frontier's nearest reachable cell; past a doorway the look-around from there sees
  the next room through the door frame only. With ``explore_through`` the robot drives
  that many metres on, straight on from where the explore set out (to the reachable cell
  nearest that point, within ``snap``; skipped when it came less than half as far or no
  such cell is reachable), and looks around there.
- **Stopping early.** ``stop_when`` (the closed loop's: the target is in the graph) is
  asked at every refresh during a skill; when it says so the skill ends there, a success
  with reason :data:`IN_VIEW`.
"""

from __future__ import annotations

import math
import weakref
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from sgtool.errors import SgtoolError
from sgtool.mapping.grid import OccupancyGrid
from sgtool.mapping.live_paths import (
    descend,
    nearest_reachable,
    point_goal,
    traversable,
)
from sgtool.mapping.occupancy import OccupancyMap, geodesic_distances
from sgtool.planning.base import Outcome
from sgtool.recorders.sim import navigation as nav
from sgtool.recorders.sim.events import SkillOutcome
from sgtool.recorders.sim.live_goals import Goal, room_fan, stand_cell
from sgtool.recorders.sim.motion import drive_while_turning, head_tilts, peek_tilt, sweep

if TYPE_CHECKING:
    from sgtool.recorders.sim.camera import CameraConfig
    from sgtool.recorders.sim.navigation import Pose2, RobotConfig
    from sgtool.recorders.sim.simulation import Simulation
    from sgtool.scenegraph.builder import MapLayers
    from sgtool.scenegraph.stream import Refresh, SceneGraphStream


IN_VIEW = "the target came into view"
HOLD_M = 1.0  # m from where a way failed on contacts beyond which its held marks go


class PrivilegedAccess(SgtoolError):
    """The robot side reached for what only the simulator may know."""


@dataclass(frozen=True)
class LiveNavConfig:
    """How the robot plans on its own map."""

    optimistic: float = 0.25  # m of unknown past known free floor a path may use
    snap: float = 1.0  # m: a room or region goal's reachable cell may be this far
    frontier_snap: float = 0.5  # m around a frontier's cells when none is reachable
    slack: float = 0.3  # m: stands this much farther from the thing than the nearest
    max_replans: int = 60
    max_contacts: int = 3
    # bump marks leaving the robot less floor, or taking more from it, are dropped, oldest
    # first (module doc); 0: kept
    sealed_m2: float = 2.0
    look_in: float = 1.4  # m from an opened container the robot backs off to (0: stays)
    # degrees: look in only from a stand more than this off the container's open fan
    # (0: after every open)
    look_in_beyond: float = 45.0
    peek: bool = True  # tilt the camera down into an opened container and back
    # look around only toward unknown space the camera can see over to (module doc)
    sight_lines: bool = False
    # m an explore drives on past the frontier it reached, straight on (module doc;
    # 0: stops at the frontier)
    explore_through: float = 0.0

    def __post_init__(self) -> None:
        if not 0 <= self.optimistic <= 2.0:
            raise SgtoolError(f"optimistic margin {self.optimistic} m: must be 0..2")
        if not 0.0 <= self.sealed_m2 <= 100.0:
            raise SgtoolError(f"sealed area {self.sealed_m2} m2: must be 0..100")
        if not (0.0 <= self.look_in <= 3.0):
            raise SgtoolError(f"look-in distance {self.look_in} m: must be 0..3")
        if not (0.0 <= self.look_in_beyond <= 180.0):
            raise SgtoolError(f"look-in angle {self.look_in_beyond} degrees: must be 0..180")
        if not (0.0 <= self.explore_through <= 5.0):
            raise SgtoolError(f"explore-through distance {self.explore_through} m: must be "
                              "0..5")
        if self.max_replans < 1 or self.max_contacts < 0:
            raise SgtoolError("max re-plans must be >= 1 and max contacts >= 0")

    def to_dict(self) -> dict[str, Any]:
        return {"optimistic": self.optimistic, "snap": self.snap,
                "frontier_snap": self.frontier_snap, "slack": self.slack,
                "max_replans": self.max_replans, "max_contacts": self.max_contacts,
                "sealed_m2": self.sealed_m2, "look_in": self.look_in,
                "look_in_beyond": self.look_in_beyond, "peek": self.peek,
                "sight_lines": self.sight_lines, "explore_through": self.explore_through}


class RobotBody:
    """What the robot side may use of a :class:`Simulation` (module doc: the guard).

    The body holds no reference to the simulation: it has no instance attributes at all
    (no ``__dict__``, no slots but the weak reference), the simulation is kept in a
    module-private table keyed by the body, and reading or setting any other attribute
    raises :class:`PrivilegedAccess`."""

    __slots__ = ("__weakref__",)

    def __init__(self, sim: Simulation) -> None:
        _BODIES[self] = sim

    def __getattr__(self, name: str) -> Any:
        raise PrivilegedAccess(f"the robot has no access to the simulator's {name!r}")

    def __setattr__(self, name: str, value: Any) -> None:
        raise PrivilegedAccess(f"the robot body cannot hold {name!r}")

    @property
    def base(self) -> Pose2:
        return _BODIES[self].base

    @property
    def config(self) -> RobotConfig:
        return _BODIES[self].robot

    @property
    def fps(self) -> float:
        return _BODIES[self].fps

    @property
    def hfov(self) -> float:
        """The camera's horizontal field of view (radians)."""
        k = _BODIES[self].intrinsics
        return 2.0 * math.atan(k.width / (2.0 * k.fx))

    @property
    def tick_index(self) -> int:
        return _BODIES[self].tick_index

    @property
    def travelled_m(self) -> float:
        return _BODIES[self].travelled_m

    @property
    def camera(self) -> CameraConfig:
        """The camera's mounting and optics (height, configured tilt, field of view)."""
        return _BODIES[self].camera

    @property
    def head_tilt(self) -> float:
        """The camera's tilt now (degrees down from the horizontal)."""
        return _BODIES[self].head_tilt_deg

    def drive(self, poses: list[Pose2]) -> tuple[float, bool]:
        return _BODIES[self].drive(poses)

    def tilt_head(self, tilts_deg: list[float]) -> None:
        _BODIES[self].tilt_head(tilts_deg)

    def look_around(self) -> SkillOutcome:
        return _BODIES[self].look_around()

    def open(self, instance: int) -> SkillOutcome:
        return _BODIES[self].open(int(instance))

    def close(self, instance: int) -> SkillOutcome:
        return _BODIES[self].close(int(instance))


# the simulation behind each body (RobotBody's doc): weak keys, so a body's entry goes
# with it
_BODIES: weakref.WeakKeyDictionary[RobotBody, Simulation] = weakref.WeakKeyDictionary()


class LiveSkills:
    """Navigate, explore, open and close on the robot's own map (module doc).
    ``current`` returns the latest refresh of the scene-graph stream."""

    def __init__(self, body: RobotBody, current: Callable[[], Refresh | None],
                 config: LiveNavConfig | None = None,
                 sight: Callable[[OccupancyGrid], np.ndarray] | None = None) -> None:
        self.body = body
        self.current = current
        self.config = config or LiveNavConfig()
        # what the camera cannot see over, as a mask over a grid (module doc: looking
        # around), used with ``config.sight_lines``; None: nothing hides unknown space
        self.sight = sight
        self.replans = 0  # plans made (for reports)
        self.contacts = 0
        self.bumps: list[tuple[float, float]] = []  # where the base touched something
        self.held: list[tuple[float, float]] = []  # held marks (module doc)
        self.held_from: list[tuple[float, float]] = []  # where each was held (same order)
        # where a look-around turned toward all the unknown it could (module doc), in order
        self.looked: list[tuple[float, float]] = []
        # asked at every refresh during a skill: True ends the skill (module doc)
        self.stop_when: Callable[[], bool] | None = None
        self._asked = -1  # index of the last refresh stop_when was asked on
        self._planned: tuple[tuple, tuple[OccupancyMap, np.ndarray] | None] | None = None

    def _stop(self) -> bool:
        """Whether ``stop_when`` says stop, asked once per refresh."""
        if self.stop_when is None:
            return False
        now = self.current()
        if now is None or now.index == self._asked:
            return False
        self._asked = now.index
        return self.stop_when()

    # ----- planning ---------------------------------------------------------------------
    def live_map(self, refresh: Refresh) -> OccupancyMap | None:
        if refresh.layers is None:
            return None
        bumps = np.array(self.held + self.bumps, dtype=np.float64).reshape(-1, 2)
        return traversable(refresh.layers.occupancy, self.body.config.radius,
                           self.config.optimistic, bumps)

    def plan_map(self, refresh: Refresh) -> tuple[OccupancyMap, np.ndarray] | None:
        """:meth:`live_map` of ``refresh`` and the geodesic distances on it from where
        the robot stands (None: no map). Kept for the last (refresh, pose, bumps), so the
        reachability check of a decision and the skill's first plan share one Dijkstra
        run; the arrays are shared: read them, never change them."""
        near = [math.dist(self.body.base[:2], p) <= HOLD_M for p in self.held_from]
        if not all(near):  # away from where a way failed: it may be tried again
            self.held = [m for m, k in zip(self.held, near, strict=True) if k]
            self.held_from = [p for p, k in zip(self.held_from, near, strict=True) if k]
        key = (refresh.index, id(refresh), self.body.base[:2], len(self.bumps),
               len(self.held))
        if self._planned is not None and self._planned[0] == key:
            return self._planned[1]
        occ = self.live_map(refresh)
        out = None if occ is None else (occ, geodesic_distances(occ, key[2]))
        if out is not None and (self.bumps or self.held) and self.config.sealed_m2 > 0:
            out, key = self._unsealed(refresh, out, key)
        self._planned = (key, out)
        return out

    def _unsealed(self, refresh: Refresh, planned: tuple[OccupancyMap, np.ndarray],
                  key: tuple) -> tuple[tuple[OccupancyMap, np.ndarray], tuple]:
        """``planned`` (the map with the bump marks and its distances) when the marks do
        not wall the robot in or off (module doc); else the oldest marks dropped from
        :attr:`bumps` until they do not, and the map and key without them."""
        kept = self.bumps
        self.bumps = []
        bare = self.live_map(refresh)
        self.bumps = kept
        assert bare is not None
        cell_m2 = bare.resolution ** 2
        floor = int(np.count_nonzero(np.isfinite(geodesic_distances(bare, key[2]))))

        def sealed(dist: np.ndarray) -> bool:
            cells = int(np.count_nonzero(np.isfinite(dist)))
            return (cells * cell_m2 < self.config.sealed_m2 < floor * cell_m2) or \
                (floor - cells) * cell_m2 > self.config.sealed_m2

        if not sealed(planned[1]):
            return self._unheld(refresh, planned, key)
        for k in range(1, len(kept) + 1):
            self.bumps = kept[k:]
            occ = self.live_map(refresh)
            assert occ is not None
            free = (occ, geodesic_distances(occ, key[2]))
            if not sealed(free[1]):
                return self._unheld(refresh, free, (*key[:3], len(self.bumps), len(self.held)))
        raise AssertionError("the map without bump marks walls nothing off")  # k = len

    def _unheld(self, refresh: Refresh, planned: tuple[OccupancyMap, np.ndarray],
                key: tuple) -> tuple[tuple[OccupancyMap, np.ndarray], tuple]:
        """``planned`` unless the held marks wall the robot in (less than ``sealed_m2``
        of floor while the map without any mark leaves more): then every mark is dropped."""
        if not self.held:
            return planned, key
        (held, self.held), (bumps, self.bumps) = (self.held, []), (self.bumps, [])
        bare = self.live_map(refresh)
        assert bare is not None
        a, d = bare.resolution ** 2, geodesic_distances(bare, key[2])
        if np.isfinite(planned[1]).sum() * a < self.config.sealed_m2 < np.isfinite(d).sum() * a:
            self.held_from = []
            return (bare, d), (*key[:3], 0, 0)
        self.held, self.bumps = held, bumps
        return planned, key

    def forget_bumps(self) -> int:
        """Drop every bump mark (the closed loop calls this when its view of the graph
        offers the planner nothing: marks at a door frame can wall off every goal while
        leaving the robot more than ``sealed_m2``); the number dropped."""
        n = len(self.bumps) + len(self.held)
        if n:
            self.bumps, self.held, self.held_from = [], [], []
            self._planned = None
        return n

    def select(self, goal: Goal, occ: OccupancyMap, dist: np.ndarray,
               layers: MapLayers | None = None) -> tuple[float, float] | None:
        """The cell to drive to for ``goal`` on ``occ`` (None: the map cannot reach it).
        A stand or view at an object of a known ``room`` is sought among the cells of that
        room first (``layers``' Voronoi nodes: :func:`~.live_goals.stand_cell`)."""
        cfg = self.config
        if goal.kind == "cells":
            return nearest_reachable(occ, dist, goal.points, cfg.frontier_snap)
        if goal.kind in ("stand", "front", "view"):
            return stand_cell(goal, occ, dist, layers, self.body.config.reach - 0.05,
                              cfg.slack, cfg.look_in)
        return point_goal(occ, dist, goal.points[0], cfg.snap)

    # ----- skills -----------------------------------------------------------------------
    def navigate(self, goal: Goal) -> tuple[Outcome, str, float]:
        """Drive to ``goal``, re-planning at every map refresh: (outcome, reason, metres)."""
        body, cfg = self.body, self.config
        step = body.config.speed / body.fps
        turn = body.config.turn_speed / body.fps
        driven, contacts = 0.0, 0
        for _ in range(cfg.max_replans):
            ref = self.current()
            planned = None if ref is None else self.plan_map(ref)
            if ref is None or planned is None:
                return "failure", "the robot has no map yet", driven
            here = body.base[:2]
            occ, dist = planned
            target = self.select(goal, occ, dist, ref.layers)
            path = None if target is None else descend(occ, dist, target)
            self.replans += 1
            if target is None or path is None:
                return "failure", _unreachable(goal, dist), driven
            pts = nav.smooth_path(occ, path)
            if pts and math.dist(pts[0], here) < occ.resolution:
                pts = pts[1:]
            face = goal.face()
            end = pts[-1] if pts else here
            yaw = None if face is None or math.dist(face, end) < 1e-6 else \
                math.atan2(face[1] - end[1], face[0] - end[0])
            poses = drive_while_turning(body.base, pts, step, turn, yaw)
            arrived = True
            for p in poses:
                d, hit = body.drive([p])
                driven += d
                if self._stop():
                    return "success", IN_VIEW, driven
                if hit:
                    contacts += 1
                    self.contacts += 1
                    self.bumps.append(_bumped(body.base, p, body.config.radius))
                    if contacts > cfg.max_contacts:
                        self.held.append(self.bumps.pop())  # the way is really blocked
                        self.held_from.append((float(body.base[0]), float(body.base[1])))
                        return ("failure", f"{goal.label}: the way is blocked by an obstacle "
                                "the robot's map does not show", driven)
                    arrived = False
                    break
                now = self.current()
                if now is not None and now.index != ref.index and p is not poses[-1]:
                    arrived = False  # the map grew: plan again on it
                    break
            if arrived:
                return "success", "", driven
        return ("failure", f"{goal.label} not reached after {cfg.max_replans} re-plans",
                driven)

    def look_in(self, at: tuple[float, float, float], label: str = "container",
                room: str | None = None) -> tuple[Outcome, str, float]:
        """Drive to where the opened container whose node is at ``at`` is seen whole
        (module doc: looking in), facing it, and peek into it there: (outcome, reason,
        metres); always a success (IN_VIEW when the target came into view), since the
        opening is done whether or not the robot gets there. With ``look_in_beyond`` > 0
        only when the robot stands more than that many degrees off the container's open
        fan (:func:`~sgtool.mapping.live_paths.open_fan`; in its ``room`` first, as
        :meth:`select`)."""
        cfg = self.config
        if cfg.look_in <= 0.0:  # off: no map needed
            return "success", "", 0.0
        ref = self.current()
        planned = None if ref is None else self.plan_map(ref)
        if ref is None or planned is None:
            return "success", "", 0.0
        here = self.body.base[:2]
        if cfg.look_in_beyond > 0.0:
            fan = room_fan(*planned, at[:2], cfg.look_in, ref.layers, room)
            if fan is None or off_bearing(at[:2], here, fan[0]) <= cfg.look_in_beyond:
                return "success", "", 0.0
        goal = Goal(f"a view into {label}", "view", np.array([at[:2]], dtype=np.float64),
                    room)
        there = self.select(goal, *planned, ref.layers)
        if there is None or math.dist(there, here) <= planned[0].resolution:
            return "success", "", 0.0
        outcome, why, driven = self.navigate(goal)
        if outcome == "success" and why == IN_VIEW:
            return "success", IN_VIEW, driven
        if outcome == "success":
            _, why, _ = self.peek(at)
            return "success", why, driven
        return "success", "", driven

    def peek(self, at: tuple[float, float, float]) -> tuple[Outcome, str, float]:
        """Tilt the camera down into the opened container whose node is at ``at`` and
        back (module doc: peeking): (outcome, reason, metres); always a success with no
        metres (IN_VIEW when the target came into view)."""
        body = self.body
        cam = body.camera
        goal = peek_tilt(cam.mount_height, cam.tilt_deg, body.base[:2], at) \
            if self.config.peek else None
        if goal is None:
            return "success", "", 0.0
        step = math.degrees(body.config.turn_speed / body.fps)
        found = False
        for t in head_tilts(body.head_tilt, goal, step):
            body.tilt_head([t])
            if self._stop():
                found = True
                break
        body.tilt_head(head_tilts(body.head_tilt, cam.tilt_deg, step))
        return "success", (IN_VIEW if found else ""), 0.0

    def explore(self, goal: Goal) -> tuple[Outcome, str, float]:
        """Go to ``goal``, on through it with ``explore_through`` (module doc), and look
        around there."""
        start = _xy(self.body.base)
        o, why, d = self.navigate(goal)
        if o == "success" and why != IN_VIEW and self.config.explore_through > 0.0:
            why, d2 = self._through(start)
            d += d2
        if o == "success" and why != IN_VIEW:
            o, why, _ = self.look_around()
        return o, why, d

    def _through(self, start: tuple[float, float]) -> tuple[str, float]:
        """After an explore reached its frontier from ``start``: drive ``explore_through``
        metres on in the direction it came (to the reachable cell nearest that point, within
        ``snap``): (reason, metres). Nothing when the robot came less than half that far
        or no cell there is reachable; a failed leg is no failure of the explore."""
        here = _xy(self.body.base)
        dx, dy = here[0] - start[0], here[1] - start[1]
        n = math.hypot(dx, dy)
        m = self.config.explore_through
        if n < m / 2.0:
            return "", 0.0
        at = np.array([[here[0] + dx / n * m, here[1] + dy / n * m]], dtype=np.float64)
        o, why, d = self.navigate(Goal("past the frontier", "point", at))
        return (why if o == "success" else ""), d

    def look_around(self) -> tuple[Outcome, str, float]:
        """Turn on the spot toward the unknown space around (module doc): the whole way
        round before the robot has a map."""
        body = self.body
        ref = self.current()
        if ref is None or ref.layers is None:
            angle = 2.0 * math.pi
        else:
            grid = ref.layers.occupancy
            angle = sweep(grid, body.base, body.hfov,
                          blockers=self.sight(grid) if self.sight is not None
                          and self.config.sight_lines else None)
        if angle == 0.0:
            self.looked.append(_xy(body.base))
            return "success", "nothing unknown around", 0.0
        turn = body.config.turn_speed / body.fps
        x, y, a = body.base
        pieces = max(1, math.ceil(abs(angle) / (math.pi / 2) - 1e-9))
        poses: list[Pose2] = []
        cur = body.base
        for q in range(1, pieces + 1):
            seg = nav.turn_poses(cur, a + angle * q / pieces, turn)
            poses += seg
            cur = seg[-1] if seg else cur
        seen_at = None if ref is None else ref.index
        known = None if ref is None or ref.layers is None else _known(ref.layers)
        for p in poses:
            body.drive([p])
            if self._stop():
                return "success", IN_VIEW, 0.0
            now = self.current()
            if now is None or now.layers is None or now.index == seen_at:
                continue
            k = _known(now.layers)
            if known is not None and k <= known:
                self.looked.append(_xy(body.base))
                return "success", "nothing new in view", 0.0
            seen_at, known = now.index, k
        self.looked.append(_xy(body.base))
        return "success", "", 0.0


def camera_sight(stream: SceneGraphStream, camera_height: float
                 ) -> Callable[[OccupancyGrid], np.ndarray]:
    """``sight`` for :class:`LiveSkills` from the robot's own voxel map: the columns of
    ``stream``'s map holding something from the camera's height up to the top of the
    occupancy band (a door's lintel above it does not hide the room behind the door)."""
    builder = stream.builder
    return lambda grid: builder.columns_between(grid, camera_height,
                                                builder.config.bev.band_top)


def off_bearing(at: tuple[float, float], here: tuple[float, float], bisector: float
                ) -> float:
    """Degrees between the bearing from ``at`` to ``here`` and ``bisector`` (radians),
    0..180."""
    b = math.atan2(here[1] - at[1], here[0] - at[0])
    return abs(math.degrees(math.remainder(b - bisector, 2.0 * math.pi)))


def _xy(pose: Pose2) -> tuple[float, float]:
    return float(pose[0]), float(pose[1])


def _known(layers: MapLayers) -> int:
    """Cells of the map that are known (free or occupied)."""
    return int(np.count_nonzero(layers.occupancy.grid != -1))


def _bumped(here: Pose2, to: Pose2, radius: float) -> tuple[float, float]:
    """Where the obstacle is that stopped a move from ``here`` to ``to``: one radius ahead
    of ``to`` along the move (the bumper's touch, the robot's own sense)."""
    dx, dy = to[0] - here[0], to[1] - here[1]
    n = math.hypot(dx, dy)
    if n < 1e-9:
        return float(to[0]), float(to[1])
    return float(to[0] + dx / n * radius), float(to[1] + dy / n * radius)


def _unreachable(goal: Goal, dist: np.ndarray) -> str:
    if not np.isfinite(dist).any():
        return f"{goal.label} is unreachable: the robot stands on no free cell of its map"
    return (f"{goal.label} is unreachable on the robot's map (no known free path; a closed "
            "door or unexplored space may be in the way)")
