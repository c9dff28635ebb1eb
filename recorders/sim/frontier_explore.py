"""Frontier exploration on the robot's own map (``sgtool record --explore frontier``).

The robot knows nothing of the house: a :class:`LiveMap` observer feeds every frame, as the
log holds it, to a :class:`~sgtool.scenegraph.stream.SceneGraphStream` (refreshing every K
frames), and :func:`explore_frontiers` repeats:

1. look around;
2. of the frontiers of the latest refresh, go to the one whose nearest reachable cell is
   nearest along the floor (:class:`~sgtool.recorders.sim.live_skills.LiveSkills`,
   re-planning as the map grows), and look around there;
3. when no frontier is reachable, go to the nearest closed door of the scene graph and
   open it (a door tried once is not tried again);

until nothing is left (or the frame budget ends the run). A frontier whose goal cell lies
within ``forget`` metres of a goal gone to (or tried) before is skipped, since looking
from there did not clear it. Every
navigation is logged as an action (``navigate`` of ``frontier:N``/``door:N``) with its
outcome, the looks around and opens by the recorder as in the scripted tour.

Coverage (:mod:`.coverage`) is sampled at every refresh: the share of the house's floor
(the ground truth, for the report only) that the robot's map holds as known.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from sgtool.log.echo import as_logged
from sgtool.recorders.sim.events import SimObserver, SkillOutcome
from sgtool.recorders.sim.live_goals import Goal, frontier_points
from sgtool.recorders.sim.live_skills import LiveSkills
from sgtool.scenegraph.stream import Refresh, SceneGraphStream

if TYPE_CHECKING:
    from sgtool.recorders.sim.recording import LogRecorder


class LiveMap(SimObserver):
    """Feeds the stream what ``recorder`` writes (frames as logged, instance tables), after
    the recorder in the observers; ``on_refresh`` hears of every refresh."""

    def __init__(self, recorder: LogRecorder, stream: SceneGraphStream,
                 on_refresh: Callable[[Refresh], None] | None = None) -> None:
        self.recorder = recorder
        self.stream = stream
        self.on_refresh = on_refresh

    def on_tick(self, sim: object) -> None:
        frame = self.recorder.last_frame
        assert frame is not None, "the recorder, before this observer, wrote the tick's frame"
        r = self.stream.frame(as_logged(frame))
        if r is not None and self.on_refresh is not None:
            self.on_refresh(r)

    def on_state(self, sim: object, spec_id: str, state: str) -> None:
        rec = self.recorder
        assert rec.last_instances is not None, "the recorder wrote the new instance table"
        self.stream.instances(rec.last_time_ns, rec.last_instances)


@dataclass
class FrontierReport:
    goals: list[str] = field(default_factory=list)  # frontiers and doors gone to
    failed: list[str] = field(default_factory=list)
    opened: list[str] = field(default_factory=list)


@dataclass(frozen=True)
class FrontierOptions:
    forget: float = 0.5  # m: goal cells this near one gone to before are skipped
    max_goals: int = 500


def explore_frontiers(skills: LiveSkills, log: Callable[[SkillOutcome], None],
                      options: FrontierOptions | None = None,
                      report: FrontierReport | None = None) -> FrontierReport:
    """Explore with ``skills`` until no frontier or closed door is left (module doc);
    ``log`` writes each navigation's action record."""
    opts = options or FrontierOptions()
    rep = report if report is not None else FrontierReport()
    body = skills.body
    body.look_around()
    failed_at: list[tuple[float, float]] = []  # goal cells gone to or tried
    doors_tried: set[str] = set()
    for _ in range(opts.max_goals):
        ref = skills.current()
        if ref is None or ref.layers is None:
            break
        pick = next_frontier(skills, ref, failed_at, opts.forget)
        door: int | None = None
        if pick is None:
            found = _next_door(skills, ref, doors_tried)
            if found is None:
                break
            goal, door = found
            doors_tried.add(goal.label)
            place = (float(goal.points[0, 0]), float(goal.points[0, 1]))
        else:
            goal, place = pick
        t0, d0 = body.tick_index, body.travelled_m
        o, why, _ = skills.navigate(goal)
        log(SkillOutcome("navigate", goal.label, o, why, body.travelled_m - d0,
                         body.tick_index - t0))
        rep.goals.append(goal.label)
        failed_at.append(place)  # gone to (or tried): not a goal again
        if o != "success":
            rep.failed.append(goal.label)
            continue
        if door is not None and body.open(door).success:
            rep.opened.append(goal.label)
        body.look_around()
    return rep


def next_frontier(skills: LiveSkills, ref: Refresh, failed_at: list[tuple[float, float]],
                  forget: float) -> tuple[Goal, tuple[float, float]] | None:
    """The frontier cluster of ``ref`` whose nearest reachable cell is nearest along the
    floor on the robot's map, with that cell; clusters whose cell lies within ``forget`` of
    a cell of ``failed_at`` are skipped (None: no frontier left)."""
    layers = ref.layers
    assert layers is not None
    planned = skills.plan_map(ref)
    if planned is None or not layers.frontiers:
        return None
    occ, dist = planned
    best: tuple[float, Goal, tuple[float, float]] | None = None
    for fid in layers.frontier_ids:
        pts = frontier_points(layers, fid)
        if pts is None or not len(pts):
            continue
        goal = Goal(fid, "cells", pts)
        cell = skills.select(goal, occ, dist)
        if cell is None or any(math.dist(cell, p) <= forget for p in failed_at):
            continue
        r, c = occ.grid.cell_of(cell[0], cell[1])
        d = float(dist[int(r), int(c)])
        if best is None or d < best[0] - 1e-9:
            best = (d, goal, cell)
    return None if best is None else (best[1], best[2])


def _next_door(skills: LiveSkills, ref: Refresh, tried: set[str]
               ) -> tuple[Goal, int] | None:
    """The nearest (straight line) closed door of the graph not tried yet, with its
    instance id."""
    here = skills.body.base[:2]
    doors = [d for d in ref.graph.doors
             if d.state == "closed" and d.id not in tried and d.instance >= 0]
    if not doors:
        return None
    d = min(doors, key=lambda n: (math.dist(here, n.position), n.id))
    return Goal(d.id, "stand", np.array([d.position], dtype=np.float64)), int(d.instance)
