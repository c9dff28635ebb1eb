"""Scripted exploration: visit every room of the house, through its doors, so that a
recording without a planner still covers the whole house.

The script uses only the public skills of :class:`~sgtool.recorders.sim.simulation.
Simulation`, so every step is a logged action:

1. look around where the robot starts;
2. repeatedly pick the unvisited room whose viewpoint is nearest along the floor (with
   closed doors counted as passable), ties by room id; while closed doors are in the way
   (on that shortest path), ``navigate`` to the first one and ``open`` it; then
   ``navigate`` to the room;
3. in each room reached: ``look_around``; while a further place in the room would show at
   least ``view_gain_m2`` of its floor that no look-around there has shown (an L- or
   U-shaped room, one longer than the camera reaches: :mod:`.room_views`), up to
   ``views`` times, ``navigate`` there and ``look_around`` again; then (optionally) go to
   every closed openable container of the room, nearest first, and ``open`` it, so its
   contents are seen.

Rooms that cannot be reached (or whose doors fail to open) are reported, not retried
forever. The order depends only on the house and the start pose, so the same inputs give
the same run.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from sgtool.house.spec import spec_id_key
from sgtool.mapping.occupancy import geodesic_distances, world_to_cell
from sgtool.recorders.sim import navigation as nav
from sgtool.recorders.sim import room_views
from sgtool.recorders.sim.simulation import Simulation, SkillOutcome


@dataclass(frozen=True)
class ScriptOptions:
    """The scripted tour's choices (module doc): open the closed doors in the way and the
    closed containers of each room; ``max_door_attempts`` doors opened on the way to one
    room before it is given up; ``views`` further look-arounds per room at most (0: one,
    at its viewpoint), each where it newly shows at least ``view_gain_m2`` of the room's
    floor. A bad value is one :class:`~sgtool.errors.SgtoolError` line."""

    open_doors: bool = True
    open_containers: bool = True
    max_door_attempts: int = 6
    views: int = 3
    view_gain_m2: float = 1.0

    def __post_init__(self) -> None:
        from sgtool.arg_checks import number, typed_fields, whole

        typed_fields(self)
        whole("max_door_attempts", self.max_door_attempts, 0)
        whole("views", self.views, 0)
        object.__setattr__(self, "view_gain_m2", number("view_gain_m2", self.view_gain_m2,
                                                        0.01))


@dataclass
class ExplorationReport:
    visited: list[str] = field(default_factory=list)
    missed: dict[str, str] = field(default_factory=dict)  # room id -> reason
    opened: list[str] = field(default_factory=list)
    looked_again: list[str] = field(default_factory=list)  # a room per further look-around
    outcomes: list[SkillOutcome] = field(default_factory=list)

    @property
    def complete(self) -> bool:
        return not self.missed


def explore_house(sim: Simulation, options: ScriptOptions | None = None,
                  report: ExplorationReport | None = None) -> ExplorationReport:
    """Run the scripted exploration on ``sim`` (see the module docstring). ``report`` is
    filled as the run goes, so a caller that stops the run early (an observer raising
    :class:`~sgtool.recorders.sim.simulation.StopSimulation`) still has what happened."""
    opts = options or ScriptOptions()
    rep = report if report is not None else ExplorationReport()

    def do(out: SkillOutcome) -> SkillOutcome:
        rep.outcomes.append(out)
        return out

    here = sim.room_of_base()
    do(sim.look_around())
    if here is not None:
        rep.visited.append(here)
        _look_further(sim, here, opts, rep, do)
        if opts.open_containers:
            _open_containers(sim, here, rep, do)
    todo = [r.id for r in sim.spec.rooms if r.id not in rep.visited]
    while todo:
        room = _nearest_room(sim, todo)
        if room is None:
            for r in todo:
                rep.missed[r] = "not reachable from the rooms visited"
            break
        todo.remove(room)
        reason = _go_to_room(sim, room, opts, rep, do)
        if reason is not None:
            rep.missed[room] = reason
            continue
        rep.visited.append(room)
        do(sim.look_around())
        _look_further(sim, room, opts, rep, do)
        if opts.open_containers:
            _open_containers(sim, room, rep, do)
    return rep


def _nearest_room(sim: Simulation, rooms: list[str]) -> str | None:
    """The room of ``rooms`` whose viewpoint is nearest along the floor, doors passable."""
    occ = sim.occupancy(doors_passable=True)
    geo = geodesic_distances(occ, sim.base[:2])
    best: tuple[float, str] | None = None
    for rid in sorted(rooms, key=spec_id_key):
        vp = nav.room_viewpoint(occ, geo, sim.spec.room(rid))
        if vp is None:
            continue
        r, c = world_to_cell(occ, vp[0], vp[1])
        d = float(geo[r, c])
        if math.isfinite(d) and (best is None or d < best[0] - 1e-9):
            best = (d, rid)
    return None if best is None else best[1]


def _go_to_room(sim: Simulation, room: str, opts: ScriptOptions, rep: ExplorationReport,
                do: Callable[[SkillOutcome], SkillOutcome]) -> str | None:
    """Navigate to ``room``, opening the closed doors in the way; None on arrival, else
    the reason it failed."""
    for _ in range(opts.max_door_attempts + 1):
        doors = sim.closed_doors_on_way(room)
        if doors is None:
            return "not reachable"
        if not doors or not opts.open_doors:
            out = do(sim.navigate(room))
            return None if out.success else out.reason
        door = doors[0]
        out = do(sim.navigate(door))
        if not out.success:
            return f"cannot get to {door}: {out.reason}"
        out = do(sim.open(door))
        if not out.success:
            return f"cannot open {door}: {out.reason}"
        rep.opened.append(door)
    return f"more than {opts.max_door_attempts} closed doors in the way"


VIEW_STRIDE = 0.5  # m between the places a further look-around is weighed at
VIEW_REACH = 0.75  # share of the camera's depth range a look-around counts as seen
VIEW_REACH_MAX = 4.5  # m, and at most this far (a small object farther is a few pixels)


def _look_further(sim: Simulation, room: str, opts: ScriptOptions, rep: ExplorationReport,
                  do: Callable[[SkillOutcome], SkillOutcome]) -> None:
    """Look around again from the places of ``room`` that show the most of its floor not
    shown yet, while one shows ``opts.view_gain_m2`` (module doc, step 3)."""
    if opts.views <= 0:
        return
    occ = sim.occupancy()
    res, origin = occ.resolution, occ.origin
    blocked = room_views.blockers(sim.spec, res, sim.camera.mount_height)
    inroom = nav.room_mask(occ, sim.spec.room(room))  # (the grids of one spec: one shape)
    floor = inroom & ~occ.occupied
    reach = min(VIEW_REACH * sim.camera.depth_max, VIEW_REACH_MAX)
    seen = room_views.visible(blocked, origin, res, sim.base[:2], reach)
    for _ in range(opts.views):
        occ = sim.occupancy()
        places = room_views.places(inroom & np.isfinite(geodesic_distances(occ, sim.base[:2])),
                                   origin, res, VIEW_STRIDE)
        best = room_views.best_view(blocked, origin, res, floor, seen, places, reach)
        if best is None or best[1] * res * res < opts.view_gain_m2:
            return
        if not do(sim.navigate(best[0])).success:
            return
        do(sim.look_around())
        rep.looked_again.append(room)
        seen |= room_views.visible(blocked, origin, res, sim.base[:2], reach)


def _open_containers(sim: Simulation, room: str, rep: ExplorationReport,
                     do: Callable[[SkillOutcome], SkillOutcome]) -> None:
    """Open every closed openable container of ``room``, nearest (straight line) first."""
    todo = [f for f in sim.spec.furniture
            if f.room == room and f.is_openable and sim.states.get(f.id) == "closed"]
    while todo:
        x, y = sim.base[:2]
        dists = [math.hypot(f.center[0] - x, f.center[1] - y) for f in todo]
        f = todo.pop(int(np.argmin(dists)))
        if not do(sim.navigate(f.id)).success:
            continue
        if do(sim.open(f.id)).success:
            rep.opened.append(f.id)

