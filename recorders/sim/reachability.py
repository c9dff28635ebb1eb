"""Reachability on the robot's own map, as part of the scene graph the planner sees.

The scene graph's ``distances`` are the builder's (paths on the Voronoi graph of the
refresh); the robot drives on :func:`sgtool.mapping.live_paths.traversable` of the same
occupancy (obstacles grown by its radius, unknown blocked but for a short margin). A node
the first calls reachable may be one the second cannot reach, and a planner offered it
spends a step on a skill that fails at once ("unreachable on the robot's map"). So, in
live navigation, the closed loop shows the planner a **view** of the graph in force
(:func:`reachable_view`) in which every actionable node
(:func:`~sgtool.planning.candidates.actionable`) has been tried the way the skill would
try it: the goal of the node (:func:`~sgtool.recorders.sim.live_goals.goal_of_node`) and
the cell the robot would drive to (:meth:`LiveSkills.select`'s rule, on a window around
the goal) on the robot's map, from where the robot stands:

- reachable: its ``distances`` entry is the geodesic distance along the robot's map to
  that cell (metres), the cost the skill will pay;
- not reachable: the node has no ``distances`` entry, so it is not actionable (the
  candidates rule: a node missing from ``distances`` is unreachable), and the reason is
  kept (:attr:`View.withheld`, counted per episode into the closing Episode record's
  ``extra.withheld``);
- failed before (:class:`FailedGoals`): a node whose skill failed is withheld while the
  cell the robot would drive to for it is within ``same`` metres of the one of the
  failure (the same attempt would be made again); it is offered again once the map moves
  that cell (a door opened, a bump marked, more floor seen), and once more when nothing
  else is left to do (:meth:`FailedGoals.release`: a door whose opening a passing contact
  stopped must not wall the robot in for the rest of the episode);
- looked from there before: a frontier, room or region node (a goal the skill goes to and
  looks around at) whose cell is within ``same`` metres of a place where the robot has
  already looked around toward all the unknown it could (``LiveSkills.looked``): going
  there to look again shows nothing new (the frontier stayed because it cannot be seen
  from there); the counterpart of the symbolic environment dropping an explored frontier.

Nothing else of the graph changes (nodes, ids, the other distances); the logged scene
graphs are the stream's, untouched, so replay still rebuilds them byte for byte. When the
view offers nothing actionable, the closed loop's fallback explores the robot's grid
frontiers (:mod:`sgtool.recorders.sim.fallback_explore`), which is "explore toward it"
for every withheld goal at once. Pure but for the robot's pose read through ``skills``.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Collection, Iterable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np
from scipy import ndimage

from sgtool.canonical import canonical_float
from sgtool.mapping.occupancy import OccupancyMap
from sgtool.planning.candidates import actionable
from sgtool.recorders.sim.live_goals import Goal, goal_of_node, room_cells
from sgtool.recorders.sim.live_skills import LiveSkills
from sgtool.scenegraph.examined import EXAMINE
from sgtool.scenegraph.graph import SceneGraph
from sgtool.scenegraph.stream import Refresh

if TYPE_CHECKING:
    from sgtool.scenegraph.builder import MapLayers

UNREACHABLE = "unreachable on the robot's map"
FAILED_BEFORE = "failed before from the same place"
NO_MAP = "the robot has no map yet"
LOOKED = "looked around from there before"


@dataclass(frozen=True)
class View:
    """The graph the planner sees (module doc) and, per withheld node id, why."""

    graph: SceneGraph
    withheld: dict[str, str] = field(default_factory=dict)


@dataclass
class FailedGoals:
    """Nodes whose skill failed, with the cell the robot was driving to (None: not
    known yet; set at the next view). ``same``: metres within which a cell is the
    same attempt."""

    same: float = 0.5
    cells: dict[str, tuple[float, float] | None] = field(default_factory=dict)
    retries: int = 1  # times a withheld node is released when nothing else is left
    released: dict[str, int] = field(default_factory=dict)

    def failed(self, node_id: str) -> None:
        self.cells[node_id] = None

    def release(self, node_ids: Iterable[str]) -> list[str]:
        """Offer these withheld nodes again (nothing else is actionable), each at most
        ``retries`` times in an episode; the ones released, in id order."""
        out = []
        for n in sorted(set(node_ids)):
            if n in self.cells and self.released.get(n, 0) < self.retries:
                del self.cells[n]
                self.released[n] = self.released.get(n, 0) + 1
                out.append(n)
        return out

    def blocks(self, node_id: str, cell: tuple[float, float]) -> bool:
        """Whether going to ``cell`` for ``node_id`` repeats a failed attempt (module
        doc); the first look after a failure records its cell."""
        if node_id not in self.cells:
            return False
        before = self.cells[node_id]
        if before is None:
            self.cells[node_id] = cell
            return True
        if math.dist(before, cell) <= self.same:
            return True
        del self.cells[node_id]  # the map moved the goal: a new attempt
        return False


def _window(occ: OccupancyMap, points: np.ndarray, radius: float
            ) -> tuple[slice, slice] | None:
    """Rows and columns of ``occ`` within ``radius`` m (plus a cell) of ``points``'s
    bounding box; None when that misses the grid."""
    res = occ.resolution
    lo_x = float(points[:, 0].min()) - radius - res
    hi_x = float(points[:, 0].max()) + radius + res
    lo_y = float(points[:, 1].min()) - radius - res
    hi_y = float(points[:, 1].max()) + radius + res
    h, w = occ.shape
    c0 = max(int(math.floor((lo_x - occ.origin[0]) / res)), 0)
    c1 = min(int(math.floor((hi_x - occ.origin[0]) / res)) + 1, w)
    r0 = max(int(math.floor((lo_y - occ.origin[1]) / res)), 0)
    r1 = min(int(math.floor((hi_y - occ.origin[1]) / res)) + 1, h)
    if c0 >= c1 or r0 >= r1:
        return None
    return slice(r0, r1), slice(c0, c1)


def _centres(occ: OccupancyMap, win: tuple[slice, slice]) -> tuple[np.ndarray, np.ndarray]:
    res = occ.resolution
    x = occ.origin[0] + (np.arange(win[1].start, win[1].stop) + 0.5) * res
    y = occ.origin[1] + (np.arange(win[0].start, win[0].stop) + 0.5) * res
    return np.meshgrid(x, y)


def _pick(occ: OccupancyMap, win: tuple[slice, slice], score: np.ndarray
          ) -> tuple[float, float] | None:
    """Centre of the window cell of least ``score`` (ties: lowest row, then column, as
    over the whole grid); None when no score is finite."""
    if score.size == 0 or not np.isfinite(score).any():
        return None
    r, c = divmod(int(np.argmin(score)), score.shape[1])
    res = occ.resolution
    return (occ.origin[0] + (win[1].start + c + 0.5) * res,
            occ.origin[1] + (win[0].start + r + 0.5) * res)


def goal_cell(skills: LiveSkills, goal: Goal, occ: OccupancyMap, dist: np.ndarray,
              layers: MapLayers | None = None) -> tuple[float, float] | None:
    """The cell :meth:`LiveSkills.select` drives to for ``goal`` (the same rule: stand
    within reach, point within ``snap``, nearest of a frontier's cells or within
    ``frontier_snap`` of them; a stand among the cells of the goal's ``room`` on
    ``layers``' map first), computed on a window around the goal; None: unreachable.
    A ``front`` goal is taken as ``stand``: it is reachable exactly when that is (the
    skill falls back to it), and its cell in front of the opening is chosen on the way."""
    cfg = skills.config
    pts = np.asarray(goal.points, dtype=np.float64).reshape(-1, 2)
    if len(pts) == 0:
        return None
    if goal.kind == "cells":
        radius = cfg.frontier_snap
    elif goal.kind in ("stand", "front"):
        radius = skills.body.config.reach - 0.05
    else:
        radius = cfg.snap
    win = _window(occ, pts, max(radius, 0.0))
    if win is None:
        return None
    d = dist[win]
    if goal.kind == "cells":
        rows, cols = occ.grid.cell_of(pts[:, 0], pts[:, 1])
        rows, cols = rows - win[0].start, cols - win[1].start
        inside = (rows >= 0) & (rows < d.shape[0]) & (cols >= 0) & (cols < d.shape[1])
        mask = np.zeros(d.shape, bool)
        mask[rows[inside], cols[inside]] = True
        hit = _pick(occ, win, np.where(mask, d, np.inf))
        if hit is not None or radius <= 0 or not mask.any():
            return hit
        near = ndimage.distance_transform_edt(~mask, sampling=occ.resolution) <= radius + 1e-9
        return _pick(occ, win, np.where(near, d, np.inf))
    X, Y = _centres(occ, win)
    off = np.hypot(X - pts[0, 0], Y - pts[0, 1])
    ok = np.isfinite(d) & (off <= radius + 1e-9)
    if goal.kind in ("stand", "front"):
        inside = None if goal.room is None else room_cells(occ, layers, goal.room)
        if inside is not None and (ok & inside[win]).any():  # in its room first, as select
            ok = ok & inside[win]
        if not ok.any():
            return None
        best = float(off[ok].min())
        return _pick(occ, win, np.where(ok & (off <= best + cfg.slack + 1e-9), d, np.inf))
    return _pick(occ, win, np.where(ok, off, np.inf))


def reachable_view(refresh: Refresh, skills: LiveSkills,
                   failed: FailedGoals | None = None) -> View:
    """The graph of ``refresh`` as the planner should see it (module doc)."""
    graph = refresh.graph
    cands = actionable(graph)
    if not cands:
        return View(graph)
    planned = skills.plan_map(refresh)
    if planned is None:
        return View(without_nodes(graph, {c.node_id for c in cands}),
                    {c.node_id: NO_MAP for c in cands})
    occ, dist = planned
    same = FailedGoals.same if failed is None else failed.same
    withheld: dict[str, str] = {}
    live: dict[str, float] = {}
    for c in cands:
        node = graph.node(c.node_id)
        assert node is not None
        cell = goal_cell(skills, goal_of_node(node, refresh.layers), occ, dist,
                         refresh.layers)
        if cell is None:
            withheld[c.node_id] = UNREACHABLE
            continue
        if failed is not None and failed.blocks(c.node_id, cell):
            withheld[c.node_id] = FAILED_BEFORE
            continue
        if c.skill == "explore" and _looked_near(skills.looked, cell, same):
            withheld[c.node_id] = LOOKED
            continue
        r, col = occ.grid.cell_of(cell[0], cell[1])
        # rounded as the log writes it, so a replay from the log shows the same numbers
        live[c.node_id] = canonical_float(dist[int(r), int(col)])
    return View(without_nodes(graph, set(withheld), live), withheld)


def _looked_near(looked: list[tuple[float, float]], cell: tuple[float, float],
                 same: float) -> bool:
    """Whether the robot looked around within ``same`` metres of ``cell``."""
    return any(math.dist(p, cell) <= same for p in looked)


def without_nodes(graph: SceneGraph, drop: Iterable[str],
                  live: dict[str, float] | None = None) -> SceneGraph:
    """``graph`` with the nodes ``drop`` taken out of its distances (so not actionable)
    and the distances ``live`` put in; an empty result keeps ``{"robot": 0.0}`` (an empty
    dict would mean "straight lines to every node")."""
    gone = set(drop)
    dists = {k: v for k, v in graph.distances.items() if k not in gone}
    dists.update(live or {})
    if not dists and graph.distances == {} and not gone:
        return graph
    if not dists:  # an empty dict means "no distances: straight lines" to the candidates
        dists = {"robot": 0.0}
    return dataclasses.replace(graph, distances=dists)


def not_seen_into(refresh: Refresh | None, target: str | None) -> bool:
    """Whether ``target`` is an examinable object of the refresh's graph that is not
    ``explored`` (:mod:`sgtool.scenegraph.examined`: its inside was not seen): a
    ``navigate`` to it that ends so is held back as a failed goal."""
    if refresh is None or target is None:
        return False
    node = next((n for n in refresh.graph.objects if n.id == target), None)
    return node is not None and EXAMINE in node.affordances and not node.explored


def give_up_handed_over(offered: Iterable[str], failed: Collection[str]) -> bool:
    """Whether a planner's give-up goes to the robot's own exploration (the closed loop's
    module doc): every goal on offer when it gave up (``offered``) had failed before in
    the episode (``failed``), so the give-up is the map's, not the planner's choice;
    otherwise done() ends the episode."""
    return all(n in failed for n in offered)
