"""The robot explores on its own when the scene graph gives the planner nothing to act on.

In a cluttered start room the free floor after the first look-around can be many small
pieces: the Voronoi graph is a couple of nodes, no room is segmented, so the scene graph
has no room, region or frontier node and the planner gives up at once, although the
robot's occupancy grid has frontier cells it can reach. Later in an episode the planner
may have ruled out every node it is offered (failed twice, explored) while the grid still
has reachable frontiers. In both cases the closed loop hands over to this module
(:class:`Fallback`), which explores the grid's frontiers on the robot's own map (the
frontier choice of ``record --explore frontier``,
:func:`~sgtool.recorders.sim.frontier_explore.next_frontier`: the nearest reachable
cluster along the floor, go there, look around) until the graph offers an actionable node
(:func:`~sgtool.planning.candidates.actionable`) that was not on offer before, then hands
back to the planner.

Every goal is one ``sgtool.Action`` record, skill ``explore`` of the grid frontier's id,
reason ``fallback: <why>`` (``fallback: <why>; <the failure>`` when it fails), decided on
no graph (``graph_time_ns: null``, planner null, like the opening look-around): its frames
and metres count in the episode (frame budget, path length of SPL) but it is no planner
step. The robot side only: goals come from the live map (:class:`LiveSkills`), never from
the house. The choice is deterministic (nearest along the floor, id order on ties), and a
goal cell within ``forget`` of one gone to before in the episode is not a goal again, so
repeated hand-overs end.

When the graph's layers have no frontier the robot can reach, the fallback goes to an
**open edge** instead (:func:`open_edges`): the frontier rule of the scene graph
(MoMa-LLM's: free cells next to unknown, *not next to occupied*) finds nothing in a
cluttered room whose unknown floor is fringed with glimpses of furniture (a bed top seen
edgewise leaves a speckle of occupied cells along every boundary), and the planner used to
give up with unseen floor in reach. An open edge is a cluster of cells the robot's map can
reach (finite geodesic distance) that touch an unknown cell, near obstacles or not, of at
least ``min_edge`` metres; the nearest along the floor whose cell is not within ``forget``
of a goal gone to, nor within ``forget`` of a place the robot looked around from
(``LiveSkills.looked``), is gone to and looked around at, logged as ``explore`` of
``edge:ROW-COL`` (its cell on the robot's grid).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np
from scipy import ndimage

from sgtool.mapping.holes import near
from sgtool.mapping.occupancy import OccupancyMap
from sgtool.planning.candidates import Candidate, actionable
from sgtool.planning.memory import SAME_PLACE_M
from sgtool.recorders.sim.events import SkillOutcome, StopSimulation
from sgtool.recorders.sim.frontier_explore import next_frontier
from sgtool.recorders.sim.live_goals import Goal
from sgtool.recorders.sim.live_skills import LiveSkills
from sgtool.scenegraph.graph import SceneGraph
from sgtool.scenegraph.stream import Refresh

NO_ACTIONABLE = "no actionable node"
GAVE_UP = "the planner gave up while the robot's map has reachable frontiers"
MARKED = "the planner gave up while bump marks withheld goals: the marks are dropped"
PREFIX = "fallback: "


def is_fallback(reason: str | None) -> bool:
    """``reason`` is that of an action of the fallback (module doc)."""
    return bool(reason) and str(reason).startswith(PREFIX)


@dataclass(frozen=True)
class FallbackOptions:
    max_goals: int = 12  # grid frontiers per hand-over
    forget: float = 0.5  # m: goal cells this near one gone to before are not goals again
    min_edge: float = 0.3  # m: the least open edge (cells x resolution) worth a visit


@dataclass(frozen=True)
class FallbackRun:
    """What one hand-over did: frontiers gone to, whether the frame budget cut it and
    whether ``log`` asked to stop (the target came into view)."""

    goals: int
    cut: bool = False
    stopped: bool = False


def new_candidates(graph: SceneGraph, known: Sequence[Candidate], frontiers: bool = True
                   ) -> list[Candidate]:
    """The actionable nodes of ``graph`` not in ``known`` (same id within
    :data:`~sgtool.planning.memory.SAME_PLACE_M`, as the planners' memory keys nodes);
    frontier nodes only when ``frontiers``."""
    return [c for c in actionable(graph)
            if (frontiers or c.kind != "frontier") and
            not any(k.node_id == c.node_id and
                    math.dist(k.position, c.position) <= SAME_PLACE_M for k in known)]


@dataclass
class Fallback:
    """The hand-over of one episode (module doc): ``skills`` on the live map; ``log``
    writes an action record and returns True to stop (the target is in view); ``view``
    is the graph the planner would see of a refresh (its own graph when None; the closed
    loop's withholds goals the robot cannot reach, :mod:`.reachability`)."""

    skills: LiveSkills
    log: Callable[[SkillOutcome], bool]
    options: FallbackOptions = field(default_factory=FallbackOptions)
    view: Callable[[Refresh], SceneGraph] | None = None
    gone_to: list[tuple[float, float]] = field(default_factory=list)  # goal cells so far

    def can_explore(self) -> bool:
        """The robot's map has a reachable grid frontier (or open edge) not gone to
        before."""
        ref = self.skills.current()
        return ref is not None and ref.layers is not None and self._next(ref) is not None

    def _next(self, ref: Refresh) -> tuple[Goal, tuple[float, float]] | None:
        """A frontier of the graph's layers, else an open edge (module doc)."""
        pick = next_frontier(self.skills, ref, self.gone_to, self.options.forget)
        if pick is not None:
            return pick
        planned = self.skills.plan_map(ref)
        if planned is None:
            return None
        avoid = self.gone_to + list(self.skills.looked)
        return next_edge(*planned, avoid, self.options.forget, self.options.min_edge)

    def explore(self, why: str, known: Sequence[Candidate] = ()) -> FallbackRun:
        """Go to grid frontiers until the graph offers a node not in ``known`` (or none is
        left, or ``max_goals``, or the frame budget, or ``log`` says stop)."""
        skills, body = self.skills, self.skills.body
        n = 0
        for _ in range(self.options.max_goals):
            ref = skills.current()
            if ref is None or ref.layers is None:
                break
            if new_candidates(ref.graph if self.view is None else self.view(ref), known):
                break
            pick = self._next(ref)
            if pick is None:
                break
            goal, cell = pick
            self.gone_to.append(cell)
            t0, d0 = body.tick_index, body.travelled_m
            cut = False
            try:
                o, fail, _ = skills.explore(goal)
            except StopSimulation as e:
                o, fail, cut = "failure", f"stopped: {e}", True
            reason = PREFIX + why + (f"; {fail}" if o != "success" else "")
            n += 1
            stop = self.log(SkillOutcome("explore", goal.label, o, reason,
                                         body.travelled_m - d0, body.tick_index - t0))
            if cut or stop:
                return FallbackRun(n, cut=cut, stopped=stop)
        return FallbackRun(n)


def open_edges(occ: OccupancyMap, dist: np.ndarray, min_cells: int) -> list[np.ndarray]:
    """The open edges of the robot's map (module doc): 8-connected clusters of cells with
    a finite ``dist`` 8-adjacent to an unknown cell of ``occ.grid``, of at least
    ``min_cells`` cells; each as (k, 2) rows and columns in raster order, the clusters in
    raster order of their first cell."""
    reach = np.isfinite(dist)
    unknown = occ.grid.unknown
    edge = reach & near(unknown)
    lab, n = ndimage.label(edge, structure=np.ones((3, 3), bool))
    rows, cols = np.nonzero(lab)  # raster order
    of = lab[rows, cols]
    order = np.argsort(of, kind="stable")  # by cluster, raster order within one
    ends = np.cumsum(np.bincount(of, minlength=n + 1)[1:])
    out = [np.stack([rows[m], cols[m]], axis=1) for m in np.split(order, ends[:-1])
           if len(m) >= min_cells]
    out.sort(key=lambda c: (int(c[0, 0]), int(c[0, 1])))
    return out


def next_edge(occ: OccupancyMap, dist: np.ndarray, avoid: Sequence[tuple[float, float]],
              forget: float, min_edge: float) -> tuple[Goal, tuple[float, float]] | None:
    """The open edge whose nearest cell (along the floor; raster order on ties) is nearest,
    skipping edges whose nearest cell lies within ``forget`` of a point of ``avoid``: the
    goal (``edge:ROW-COL``, its cells) and that cell; None when none is left."""
    best: tuple[float, Goal, tuple[float, float]] | None = None
    min_cells = max(1, int(round(min_edge / occ.resolution)))
    for cells in open_edges(occ, dist, min_cells):
        d = dist[cells[:, 0], cells[:, 1]]
        i = int(np.argmin(d))
        r, c = int(cells[i, 0]), int(cells[i, 1])
        x, y = occ.grid.center_of(r, c)
        cell = (float(x), float(y))
        if any(math.dist(cell, p) <= forget for p in avoid):
            continue
        if best is None or float(d[i]) < best[0] - 1e-9:
            xs, ys = occ.grid.center_of(cells[:, 0], cells[:, 1])
            goal = Goal(f"edge:{r}-{c}", "cells", np.stack([xs, ys], axis=1))
            best = (float(d[i]), goal, cell)
    return None if best is None else (best[1], best[2])
