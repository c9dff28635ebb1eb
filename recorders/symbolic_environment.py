"""The symbolic object-search benchmark: SCOUT's SymSearch roll-out over generated houses.

SCOUT (sec. V) evaluates high-level search decisions on scene graphs without a simulator.
This module turns a :class:`~sgtool.house.spec.HouseSpec` into that environment:

**Scene graph of a house** (SCOUT V.B, Fig. 5). Rooms are the spec's rooms. Regions: per
room, the (x, y) positions of its furniture are clustered by k-means (deterministic
farthest-point initialisation) with the number of clusters chosen by the Bayesian
Information Criterion of the matching spherical Gaussian mixture (X-means), k in
``[1, min(4, n - 1)]``; a room without furniture is one empty region. Furniture are the
first-level objects of their region; small objects are nested in their parent furniture
(relation "inside"/"ontop"). Rooms are joined by doors (open/closed) and open-plan passages.

**Travel** (SCOUT Fig. 5 f). Every node the agent can go to has a *place*: the walkable cell
of its own room nearest to it (walkable: free on the occupancy grid dilated by the robot
radius, in the room's largest free component), i.e. the closest unoccupied point to the
goal within the same room. Distances are geodesics on the occupancy grid of
:mod:`sgtool.mapping.occupancy`. To let doors open and close during an episode without
re-rasterising, they are computed once on the grid with every door closed (each room, or
open-plan group, its own component) between all places, plus one place each side of every
door; an open door joins its two side places with an edge of their straight-line length.
Travel distance is then the shortest path on that place graph for the current door states.
A nested object's place is its parent's; a room's is its nearest region's; a door's is its
nearer side.

**Roll-out** (SCOUT V.C, Fig. 4), :class:`SymbolicEnv`:

- start: a random region of a random room (rooms holding a target are avoided when others
  exist), drawn from the episode seed; the start room is explored: the agent sees the
  start region with its furniture, the room's other regions as frontiers ("unexplored
  area"), its doors, and the rooms behind its open doors and passages as unexplored rooms
  (``RoomNode(explored=False, category="unknown")``);
- ``explore`` (or ``navigate``) an unexplored room: the agent walks to the room's region
  nearest to it, which is revealed with its furniture; the room's other regions become
  frontiers; its doors and the rooms behind open doors/passages appear;
- ``explore`` (or ``navigate``) a frontier: the agent walks there; the region's furniture
  is revealed;
- ``open`` a closed openable object: walk there, open it, reveal its nested objects;
  ``navigate`` to (or ``explore``) an unexplored container/supporter that is not closed:
  look into / onto it, revealing its nested objects (SymSearch: every nested object needs
  its parent explored, "on top" included);
- ``open`` a closed door: walk to it and open it; the room beyond appears as an unexplored
  room. ``close`` closes an open object or door; ``navigate`` to anything else just walks;
- ``done``: ends the episode.

An action whose target is not a node of the observed graph (or is None, for anything but
``done``), or whose skill does not apply to that kind of node (open a room), is
**invalid**: a step is spent, nothing happens, feedback outcome "invalid". An action that
applies but has no effect (open an open fridge, a target that cannot be reached) is a
**failure**, also a spent step.

**End and success** (SCOUT V.C): the episode ends as soon as an object of the query
category is visible (success, even without ``done``: SymSearch terminates "when the target
object becomes visible"), on ``done`` (failure, since the target was not visible), or
after ``max_steps`` actions (failure; SymSearch's N_max = 50). Success therefore never
depends on a planner calling ``done``; MoMa-LLM's stricter rule (success only on an
explicit ``done()``) belongs to the closed loop.

Everything is deterministic: the start comes from ``numpy.random.default_rng`` seeded with
(seed, house seed, episode index); iteration is in id order.
"""

from __future__ import annotations

import dataclasses
import math
import time
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy import ndimage
from scipy.sparse import csr_matrix
from scipy.sparse.csgraph import dijkstra

from sgtool.house.spec import HouseSpec
from sgtool.mapping.occupancy import (
    OccupancyMap,
    cell_to_world,
    geodesic_distances,
    house_occupancy,
    world_to_cell,
)
from sgtool.planning.base import Action, Feedback, Planner
from sgtool.results import EpisodeResult, Step
from sgtool.scenegraph.graph import (
    DoorNode,
    ObjectNode,
    RegionNode,
    RobotState,
    RoomNode,
    SceneGraph,
)
from sgtool.semantics.text import category_text

N_MAX = 50  # SymSearch's maximum episode length (SCOUT sec. VI / appendix C)
MAX_REGIONS = 4
MIN_REGION_STD = 0.5  # m: the spread below which furniture counts as one place
_EXAMINE = "examine"


# ----------------------------------------------------------------------------------------
# regions: k-means with BIC (X-means)
# ----------------------------------------------------------------------------------------
def _kmeans(points: np.ndarray, k: int, iters: int = 50) -> tuple[np.ndarray, np.ndarray]:
    """Lloyd's k-means from a farthest-point initialisation (first centre: the point
    nearest the mean), so the result depends on the points only."""
    n = points.shape[0]
    first = int(np.argmin(((points - points.mean(0)) ** 2).sum(1)))
    centres = [points[first]]
    for _ in range(1, k):
        d2 = np.min([((points - c) ** 2).sum(1) for c in centres], axis=0)
        centres.append(points[int(np.argmax(d2))])
    c = np.array(centres, float)
    labels = np.zeros(n, int)
    for _ in range(iters):
        d2 = ((points[:, None, :] - c[None, :, :]) ** 2).sum(2)
        new = np.argmin(d2, axis=1)
        for j in range(k):
            if np.any(new == j):
                c[j] = points[new == j].mean(0)
        if np.array_equal(new, labels):
            break
        labels = new
    return labels, c


def _bic(points: np.ndarray, labels: np.ndarray, k: int, min_var: float) -> float:
    """BIC of a spherical Gaussian mixture with shared variance (Pelleg & Moore's X-means);
    lower is better. The variance is floored at ``min_var``."""
    n, d = points.shape
    counts = np.bincount(labels, minlength=k).astype(float)
    centres = np.array([points[labels == j].mean(0) if counts[j] else np.zeros(d)
                        for j in range(k)])
    sse = float(((points - centres[labels]) ** 2).sum())
    var = max(sse / max(d * (n - k), 1), min_var)
    nz = counts[counts > 0]
    loglik = (float(np.sum(nz * np.log(nz / n))) - n * d / 2.0 * math.log(2 * math.pi * var)
              - sse / (2.0 * var))
    params = (k - 1) + k * d + 1
    return -2.0 * loglik + params * math.log(n)


def cluster_regions(points: Sequence[Sequence[float]], max_k: int = MAX_REGIONS,
                    min_std: float = MIN_REGION_STD) -> np.ndarray:
    """Region label of each (x, y) point: k-means, k chosen by BIC in [1, min(max_k, n-1)].

    Labels are renumbered in order of first appearance, so they do not depend on k-means'
    internal order.
    """
    pts = np.asarray(points, float).reshape(-1, 2)
    n = pts.shape[0]
    if n <= 2:
        return np.zeros(n, int)
    best_labels, best_bic = np.zeros(n, int), _bic(pts, np.zeros(n, int), 1, min_std ** 2)
    for k in range(2, min(max_k, n - 1) + 1):
        labels, _ = _kmeans(pts, k)
        if len(set(labels.tolist())) < k:
            continue
        b = _bic(pts, labels, k, min_std ** 2)
        if b < best_bic - 1e-9:
            best_labels, best_bic = labels, b
    remap: dict[int, int] = {}
    return np.array([remap.setdefault(int(v), len(remap)) for v in best_labels], int)


# ----------------------------------------------------------------------------------------
# the static house
# ----------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Region:
    id: str  # "region:<room>.<k>"
    room: int  # index into spec.rooms
    center: tuple[float, float]
    furniture: tuple[int, ...]  # indices into spec.furniture
    place: int


class SymbolicHouse:
    """A house prepared for SymSearch roll-outs: regions, places and their distances.

    Build once per house (``SymbolicHouse(spec)``, ~0.1-0.5 s) and run any number of
    episodes on it; it is never modified by an episode.
    """

    def __init__(self, spec: HouseSpec, resolution: float = 0.05, robot_radius: float = 0.2):
        self.spec = spec
        self.resolution = resolution
        closed = dataclasses.replace(
            spec, doors=tuple(dataclasses.replace(d, state="closed") for d in spec.doors))
        self.occ: OccupancyMap = house_occupancy(closed, resolution=resolution,
                                                 robot_radius=robot_radius)
        self.room_index = {r.id: i for i, r in enumerate(spec.rooms)}
        self.room_ids = tuple(f"room:{i}" for i in range(len(spec.rooms)))
        self.room_names = tuple(category_text(r.category) for r in spec.rooms)
        self.furn_cat = tuple(category_text(f.category) for f in spec.furniture)
        self.obj_cat = tuple(category_text(o.category) for o in spec.objects)
        self._furn_nodes: dict[tuple[int, str | None, bool], ObjectNode] = {}
        self._obj_nodes: dict[int, ObjectNode] = {}
        self._walkable_rooms()
        self.places: list[tuple[float, float]] = []
        self.place_room: list[int] = []
        # furniture
        self.furn_index = {f.id: i for i, f in enumerate(spec.furniture)}
        self.furn_place = [self._add_place(f.center[0], f.center[1], self.room_index[f.room])
                           for f in spec.furniture]
        # regions per room
        self.regions: list[Region] = []
        self.room_regions: list[tuple[int, ...]] = []
        for ri, room in enumerate(spec.rooms):
            members = [i for i, f in enumerate(spec.furniture) if f.room == room.id]
            idx: list[int] = []
            if members:
                labels = cluster_regions([spec.furniture[i].center[:2] for i in members])
                for k in range(int(labels.max()) + 1):
                    fs = tuple(m for m, lab in zip(members, labels, strict=True) if lab == k)
                    cx = float(np.mean([spec.furniture[i].center[0] for i in fs]))
                    cy = float(np.mean([spec.furniture[i].center[1] for i in fs]))
                    idx.append(len(self.regions))
                    self.regions.append(Region(f"region:{ri}.{k}", ri, (cx, cy), fs,
                                               self._add_place(cx, cy, ri)))
            else:
                cx, cy = self._room_centre(ri)
                idx.append(len(self.regions))
                self.regions.append(Region(f"region:{ri}.0", ri, (cx, cy), (),
                                           self._add_place(cx, cy, ri)))
            self.room_regions.append(tuple(idx))
        self.region_of_furn = {f: ri for ri, reg in enumerate(self.regions) for f in reg.furniture}
        # doors: one place each side
        self.door_sides: list[tuple[int, int]] = []
        for d in spec.doors:
            a, b = (self.room_index[r] for r in d.rooms)
            self.door_sides.append((self._add_place(d.center[0], d.center[1], a),
                                    self._add_place(d.center[0], d.center[1], b)))
        # neighbours: (other room, door index or None for a passage)
        self.links: list[list[tuple[int, int | None]]] = [[] for _ in spec.rooms]
        for di, d in enumerate(spec.doors):
            a, b = (self.room_index[r] for r in d.rooms)
            self.links[a].append((b, di))
            self.links[b].append((a, di))
        for p in spec.passages:
            a, b = (self.room_index[r] for r in p.rooms)
            self.links[a].append((b, None))
            self.links[b].append((a, None))
        # small objects
        self.obj_index = {o.id: j for j, o in enumerate(spec.objects)}
        self.nested: list[list[int]] = [[] for _ in spec.furniture]
        for j, o in enumerate(spec.objects):
            self.nested[self.furn_index[o.parent]].append(j)
        self._base = self._base_distances()
        self._graphs: dict[frozenset[int], csr_matrix] = {}
        self._rows: dict[tuple[frozenset[int], int], np.ndarray] = {}

    # ----- ids ------------------------------------------------------------------------
    def furn_node_id(self, i: int) -> str:
        return f"obj:{i + 1}"

    def obj_node_id(self, j: int) -> str:
        return f"obj:{len(self.spec.furniture) + 1 + j}"

    # ----- geometry -------------------------------------------------------------------
    def _walkable_rooms(self) -> None:
        from sgtool.datasets.episodes import room_raster

        raster = room_raster(self.spec, self.occ)
        free = ~self.occ.blocked
        self._snap: list[tuple[tuple[slice, slice], np.ndarray, np.ndarray] | None] = []
        for ri in range(len(self.spec.rooms)):
            mask = free & (raster == ri)
            # 4-connected: paths may not cut corners, so cells touching only diagonally
            # are not connected for the robot
            lab, n = ndimage.label(mask)
            if n == 0:
                self._snap.append(None)
                continue
            sizes = np.bincount(lab.ravel())[1:]
            walk = lab == (1 + int(np.argmax(sizes)))
            rr, cc = np.nonzero(walk)
            win = (slice(max(rr.min() - 2, 0), rr.max() + 3),
                   slice(max(cc.min() - 2, 0), cc.max() + 3))
            sub = walk[win]
            _, (ir, ic) = ndimage.distance_transform_edt(~sub, return_indices=True)
            self._snap.append((win, ir, ic))

    def snap(self, x: float, y: float, room: int) -> tuple[int, int]:
        """The walkable cell of ``room`` nearest to (x, y)."""
        s = self._snap[room]
        if s is None:
            raise ValueError(f"room {self.spec.rooms[room].id} has no free floor")
        (rs, cs), ir, ic = s
        r, c = world_to_cell(self.occ, x, y)
        lr = min(max(r - rs.start, 0), ir.shape[0] - 1)
        lc = min(max(c - cs.start, 0), ir.shape[1] - 1)
        return int(ir[lr, lc]) + rs.start, int(ic[lr, lc]) + cs.start

    def _room_centre(self, ri: int) -> tuple[float, float]:
        cx, cy = self.spec.rooms[ri].centroid
        px, py = cell_to_world(self.occ, *self.snap(cx, cy, ri))
        return float(px), float(py)

    def _add_place(self, x: float, y: float, room: int) -> int:
        px, py = cell_to_world(self.occ, *self.snap(x, y, room))
        self.places.append((round(float(px), 6), round(float(py), 6)))
        self.place_room.append(room)
        return len(self.places) - 1

    def _base_distances(self) -> np.ndarray:
        """Geodesics between all places with every door closed (inf across doors)."""
        n = len(self.places)
        cells = [world_to_cell(self.occ, x, y) for x, y in self.places]
        rows = np.array([c[0] for c in cells])
        cols = np.array([c[1] for c in cells])
        out = np.full((n, n), np.inf)
        done: dict[tuple[int, int], np.ndarray] = {}
        for i, cell in enumerate(cells):
            if cell not in done:
                grid = geodesic_distances(self.occ, self.places[i], max_snap=0.0)
                done[cell] = grid[rows, cols]
            out[i] = done[cell]
        return np.minimum(out, out.T)  # exact symmetry despite float summation order

    def _graph(self, open_doors: frozenset[int]) -> csr_matrix:
        g = self._graphs.get(open_doors)
        if g is None:
            w = self._base.copy()
            np.fill_diagonal(w, np.inf)
            for di in sorted(open_doors):
                a, b = self.door_sides[di]
                d = math.dist(self.places[a], self.places[b])
                w[a, b] = w[b, a] = min(w[a, b], max(d, 1e-6))
            src, dst = np.nonzero(np.isfinite(w))
            g = csr_matrix((w[src, dst], (src, dst)), shape=w.shape)
            self._graphs[open_doors] = g
        return g

    def distances_from(self, place: int, open_doors: frozenset[int]) -> np.ndarray:
        """Travel distance (m) from ``place`` to every place with these doors open."""
        key = (open_doors, place)
        row = self._rows.get(key)
        if row is None:
            row = dijkstra(self._graph(open_doors), directed=False, indices=place)
            if len(self._rows) > 20000:
                self._rows.clear()
            self._rows[key] = row
        return row

    def furniture_node(self, f: int, state: str | None, explored: bool) -> ObjectNode:
        """The node of furniture ``f`` in a given state (memoised: nodes are frozen)."""
        key = (f, state, explored)
        node = self._furn_nodes.get(key)
        if node is None:
            fu = self.spec.furniture[f]
            affs = set(fu.affordances)
            if affs & {"container", "supporter"}:
                affs.add(_EXAMINE)
            node = ObjectNode(
                id=self.furn_node_id(f), category=self.furn_cat[f],
                parent=self.regions[self.region_of_furn[f]].id,
                room=self.room_ids[self.room_index[fu.room]],
                position=tuple(float(v) for v in fu.center),  # type: ignore[arg-type]
                instance=f + 1, state=state,  # type: ignore[arg-type]
                affordances=tuple(sorted(affs)), explored=explored,
            )
            self._furn_nodes[key] = node
        return node

    def object_node(self, j: int) -> ObjectNode:
        """The node of small object ``j`` (nested in its parent furniture)."""
        node = self._obj_nodes.get(j)
        if node is None:
            o = self.spec.objects[j]
            node = ObjectNode(
                id=self.obj_node_id(j), category=self.obj_cat[j],
                parent=self.furn_node_id(self.furn_index[o.parent]),
                room=self.room_ids[self.room_index[o.room]],
                position=tuple(float(v) for v in o.position),  # type: ignore[arg-type]
                instance=len(self.spec.furniture) + 1 + j, relation=o.relation,  # type: ignore[arg-type]
            )
            self._obj_nodes[j] = node
        return node

    def all_doors(self) -> frozenset[int]:
        return frozenset(range(len(self.spec.doors)))

    def initially_open(self) -> frozenset[int]:
        return frozenset(i for i, d in enumerate(self.spec.doors) if d.state == "open")


# ----------------------------------------------------------------------------------------
# the episode
# ----------------------------------------------------------------------------------------
@dataclass(frozen=True)
class StepOutcome:
    """What one action did (besides the feedback the planner gets)."""

    feedback: Feedback
    opened: bool = False  # a successful open interaction (MoMa-LLM's open cost)


class SymbolicEnv:
    """One SymSearch episode in a :class:`SymbolicHouse` (rules in the module doc)."""

    def __init__(self, house: SymbolicHouse, query: str, seed: int = 0, episode_index: int = 0,
                 avoid_rooms: Sequence[str] = (), max_steps: int = N_MAX,
                 start_region: str | None = None):
        self.house = house
        self.spec = house.spec
        self.query = query
        self._query_text = category_text(query)
        self._target_furn = {i for i, c in enumerate(house.furn_cat) if c == self._query_text}
        self._target_obj = {j for j, c in enumerate(house.obj_cat) if c == self._query_text}
        self.max_steps = int(max_steps)
        self.steps = 0
        self.travelled = 0.0
        self.n_open = 0
        self.n_invalid = 0
        self.n_failure = 0
        self.ended = False
        self.success = False
        self.end_reason = ""
        # dynamic state
        self.open_doors: set[int] = set(house.initially_open())
        self.furn_state: list[str | None] = [f.state for f in self.spec.furniture]
        self.furn_explored: set[int] = set()
        self.revealed_regions: set[int] = set()
        self.explored_rooms: set[int] = set()
        self.known_rooms: set[int] = set()
        self.visible_doors: set[int] = set()
        # start: a random region of a random room (SCOUT V.C)
        if start_region is not None:
            reg = next(i for i, r in enumerate(house.regions) if r.id == start_region)
        else:
            rng = np.random.default_rng([int(seed), int(self.spec.seed), int(episode_index)])
            avoid = {house.room_index[r] for r in avoid_rooms if r in house.room_index}
            rooms = [ri for ri in range(len(self.spec.rooms)) if ri not in avoid] or \
                list(range(len(self.spec.rooms)))
            ri = rooms[int(rng.integers(len(rooms)))]
            regs = house.room_regions[ri]
            reg = regs[int(rng.integers(len(regs)))]
        self.start_region = house.regions[reg].id
        self.place = house.regions[reg].place
        self.start_place = self.place
        self._enter_room(house.regions[reg].room, reg)
        self._check_found()
        if self.success:
            self.end_reason = "found"

    # ----- visibility -----------------------------------------------------------------
    def _enter_room(self, ri: int, region: int) -> None:
        self.explored_rooms.add(ri)
        self.known_rooms.add(ri)
        self.revealed_regions.add(region)
        for other, door in self.house.links[ri]:
            if door is not None:
                self.visible_doors.add(door)
                if door in self.open_doors:
                    self.known_rooms.add(other)
            else:
                self.known_rooms.add(other)

    def visible_furniture(self) -> list[int]:
        out = []
        for reg in sorted(self.revealed_regions):
            out.extend(self.house.regions[reg].furniture)
        return sorted(out)

    def visible_objects(self) -> list[int]:
        out = []
        for f in sorted(self.furn_explored):
            out.extend(self.house.nested[f])
        return sorted(out)

    def _check_found(self) -> None:
        if any(f in self._target_furn for f in self.visible_furniture()) or \
           any(j in self._target_obj for j in self.visible_objects()):
            self.success = True
            self.ended = True

    # ----- observation ----------------------------------------------------------------
    def _distances(self) -> np.ndarray:
        return self.house.distances_from(self.place, frozenset(self.open_doors))

    def _room_place(self, ri: int, dist: np.ndarray) -> int:
        regs = self.house.room_regions[ri]
        return min((self.house.regions[r].place for r in regs), key=lambda p: (dist[p], p))

    def _door_place(self, di: int, dist: np.ndarray) -> int:
        a, b = self.house.door_sides[di]
        return a if (dist[a], a) <= (dist[b], b) else b

    def observe(self) -> SceneGraph:
        """The observed subgraph with travel distances from the agent (finite ones only)."""
        h, spec = self.house, self.spec
        dist = self._distances()
        distances: dict[str, float] = {}

        def put(node_id: str, place: int) -> None:
            d = float(dist[place])
            if math.isfinite(d):
                distances[node_id] = d

        rooms = []
        for ri in sorted(self.known_rooms):
            rid = h.room_ids[ri]
            explored = ri in self.explored_rooms
            cx, cy = spec.rooms[ri].centroid
            neighbours = tuple(sorted({h.room_ids[o] for o, door in h.links[ri]
                                       if o in self.known_rooms})) if explored else ()
            rooms.append(RoomNode(
                id=rid, category=h.room_names[ri] if explored else "unknown",
                position=(float(cx), float(cy)), explored=explored,
                category_scores=((h.room_names[ri], 1.0),) if explored else (),
                neighbours=neighbours,
            ))
            put(rid, self._room_place(ri, dist))
        regions = []
        for ri in sorted(self.explored_rooms):
            for reg in h.room_regions[ri]:
                r = h.regions[reg]
                revealed = reg in self.revealed_regions
                regions.append(RegionNode(
                    id=r.id, room=h.room_ids[ri], position=r.center,
                    kind="region" if revealed else "frontier",
                    frontier_type=None if revealed else "unexplored area",
                ))
                put(r.id, r.place)
        objects = []
        for f in self.visible_furniture():
            objects.append(h.furniture_node(f, self.furn_state[f], f in self.furn_explored))
            put(h.furn_node_id(f), h.furn_place[f])
        for j in self.visible_objects():
            objects.append(h.object_node(j))
            put(h.obj_node_id(j), h.furn_place[h.furn_index[spec.objects[j].parent]])
        doors = []
        for di in sorted(self.visible_doors):
            d = spec.doors[di]
            doors.append(DoorNode(
                id=f"door:{di}", position=(float(d.center[0]), float(d.center[1])),
                state="open" if di in self.open_doors else "closed",
                rooms=tuple(h.room_ids[h.room_index[r]] for r in d.rooms), instance=-1,
            ))
            put(f"door:{di}", self._door_place(di, dist))
        here = self.place
        region = next((r.id for r in h.regions if r.place == here), None)
        robot = RobotState(position=h.places[here], room=h.room_ids[h.place_room[here]],
                           region=region)
        return SceneGraph(robot=robot, rooms=tuple(rooms), regions=tuple(regions),
                          objects=tuple(objects), doors=tuple(doors), distances=distances)

    # ----- acting ---------------------------------------------------------------------
    def _lookup(self, node_id: str | None) -> tuple[str, int] | None:
        """(kind, index) of an observed node, None when it is not in the observed graph."""
        if not node_id:
            return None
        h = self.house
        prefix, _, rest = node_id.partition(":")
        try:
            if prefix == "room":
                ri = int(rest)
                return ("room", ri) if ri in self.known_rooms else None
            if prefix == "region":
                reg = next((i for i, r in enumerate(h.regions) if r.id == node_id), None)
                if reg is None or h.regions[reg].room not in self.explored_rooms:
                    return None
                return "region", reg
            if prefix == "door":
                di = int(rest)
                return ("door", di) if di in self.visible_doors else None
            if prefix == "obj":
                k = int(rest) - 1
                nf = len(self.spec.furniture)
                if 0 <= k < nf:
                    return ("furniture", k) if k in set(self.visible_furniture()) else None
                j = k - nf
                if 0 <= j < len(self.spec.objects):
                    return ("object", j) if j in set(self.visible_objects()) else None
        except ValueError:
            return None
        return None

    def _move(self, place: int, dist: np.ndarray) -> float:
        d = float(dist[place])
        self.travelled += d
        self.place = place
        return d

    def step(self, action: Action) -> StepOutcome:
        """Execute ``action``; a step is spent whatever the outcome."""
        if self.ended:
            raise RuntimeError("the episode has ended")
        self.steps += 1
        out = self._execute(action)
        if out.feedback.outcome == "invalid":
            self.n_invalid += 1
        elif out.feedback.outcome == "failure":
            self.n_failure += 1
        if out.opened:
            self.n_open += 1
        if not self.ended:
            self._check_found()
            if self.success:
                self.end_reason = "found"
            elif self.steps >= self.max_steps:
                self.ended = True
                self.end_reason = "max_steps"
        return out

    def _fb(self, action: Action, outcome: str, message: str, travelled: float = 0.0,
            opened: bool = False) -> StepOutcome:
        return StepOutcome(Feedback(action, outcome, message, travelled), opened)  # type: ignore[arg-type]

    def _execute(self, a: Action) -> StepOutcome:
        h = self.house
        if a.skill == "done":
            self.ended = True
            self.end_reason = "gave_up" if a.target is None else "wrong_done"
            return self._fb(a, "success", "episode ended by the planner")
        found = self._lookup(a.target)
        if found is None:
            return self._fb(a, "invalid", f"{a.target!r} is not a node of the observed graph")
        kind, i = found
        dist = self._distances()
        skill = a.skill
        if kind == "room":
            if skill in ("open", "close"):
                return self._fb(a, "invalid", f"cannot {skill} a room")
            place = self._room_place(i, dist)
            if not math.isfinite(dist[place]):
                return self._fb(a, "failure", f"{a.target} cannot be reached")
            if i in self.explored_rooms:
                if skill == "explore":
                    return self._fb(a, "failure", f"{a.target} is already explored")
                return self._fb(a, "success", f"at {a.target}", self._move(place, dist))
            reg = next(r for r in h.room_regions[i] if h.regions[r].place == place)
            d = self._move(place, dist)
            self._enter_room(i, reg)
            n = len(h.regions[reg].furniture)
            return self._fb(a, "success", f"entered {h.room_names[i]}: {n} objects in view", d)
        if kind == "region":
            reg = h.regions[i]
            if skill in ("open", "close"):
                return self._fb(a, "invalid", f"cannot {skill} a region")
            if not math.isfinite(dist[reg.place]):
                return self._fb(a, "failure", f"{a.target} cannot be reached")
            if i in self.revealed_regions:
                if skill == "explore":
                    return self._fb(a, "failure", f"{a.target} is already explored")
                return self._fb(a, "success", f"at {a.target}", self._move(reg.place, dist))
            d = self._move(reg.place, dist)
            self.revealed_regions.add(i)
            return self._fb(a, "success", f"{len(reg.furniture)} objects in view", d)
        if kind == "door":
            place = self._door_place(i, dist)
            if not math.isfinite(dist[place]):
                return self._fb(a, "failure", f"{a.target} cannot be reached")
            is_open = i in self.open_doors
            if skill == "explore":
                return self._fb(a, "invalid", "cannot explore a door; open it")
            if skill == "navigate":
                return self._fb(a, "success", f"at {a.target}", self._move(place, dist))
            if skill == "open":
                if is_open:
                    return self._fb(a, "failure", f"{a.target} is already open")
                d = self._move(place, dist)
                self.open_doors.add(i)
                for r in self.spec.doors[i].rooms:
                    self.known_rooms.add(h.room_index[r])
                return self._fb(a, "success", "door opened", d, opened=True)
            if not is_open:  # close
                return self._fb(a, "failure", f"{a.target} is already closed")
            d = self._move(place, dist)
            self.open_doors.discard(i)
            return self._fb(a, "success", "door closed", d)
        if kind == "object":  # nested objects: walk to the parent
            parent = h.furn_index[self.spec.objects[i].parent]
            place = h.furn_place[parent]
            if skill != "navigate":
                return self._fb(a, "invalid", f"cannot {skill} a {self.spec.objects[i].category}")
            if not math.isfinite(dist[place]):
                return self._fb(a, "failure", f"{a.target} cannot be reached")
            return self._fb(a, "success", f"at {a.target}", self._move(place, dist))
        # furniture
        fu = self.spec.furniture[i]
        place = h.furn_place[i]
        if not math.isfinite(dist[place]):
            return self._fb(a, "failure", f"{a.target} cannot be reached")
        state = self.furn_state[i]
        explorable = bool(set(fu.affordances) & {"container", "supporter"})
        if skill == "open" or (skill == "explore" and state == "closed"):
            if not fu.is_openable:
                return self._fb(a, "failure", f"a {fu.category} cannot be opened")
            if state == "open":
                return self._fb(a, "failure", f"the {fu.category} is already open")
            d = self._move(place, dist)
            self.furn_state[i] = "open"
            return self._fb(a, "success", self._reveal(i), d, opened=True)
        if skill == "close":
            if state != "open":
                return self._fb(a, "failure", f"the {fu.category} is not open")
            d = self._move(place, dist)
            self.furn_state[i] = "closed"
            return self._fb(a, "success", f"{fu.category} closed", d)
        # navigate / explore of a piece that is not closed: look into / onto it
        fresh = explorable and i not in self.furn_explored and state != "closed"
        if skill == "explore" and not fresh:
            return self._fb(a, "failure", f"nothing left to explore at the {fu.category}")
        d = self._move(place, dist)
        if fresh:
            return self._fb(a, "success", self._reveal(i), d)
        return self._fb(a, "success", f"at the {fu.category}", d)

    def _reveal(self, f: int) -> str:
        self.furn_explored.add(f)
        names = sorted(self.house.obj_cat[j] for j in self.house.nested[f])
        return f"found {', '.join(names)}" if names else "nothing inside or on top"

    # ----- figures --------------------------------------------------------------------
    def shortest_path(self, targets: Sequence[str]) -> float | None:
        """Geodesic from the start to the nearest place a target is seen from, every door
        passable (an optimal agent opens the doors on its way); None when unreachable."""
        h = self.house
        dist = h.distances_from(self.start_place, h.all_doors())
        best = math.inf
        for t in targets:
            if t in h.obj_index:
                parent = h.furn_index[self.spec.objects[h.obj_index[t]].parent]
                best = min(best, float(dist[h.furn_place[parent]]))
            elif t in h.furn_index:
                f = h.furn_index[t]
                best = min(best, float(dist[h.regions[h.region_of_furn[f]].place]),
                           float(dist[h.furn_place[f]]))
        return best if math.isfinite(best) else None


# ----------------------------------------------------------------------------------------
# one episode with a planner
# ----------------------------------------------------------------------------------------
def planner_seed(seed: int, house_seed: int, episode_index: int) -> int:
    """The planner's seed for an episode (a 32-bit draw from the three numbers)."""
    ss = np.random.SeedSequence([int(seed), int(house_seed), int(episode_index), 1])
    return int(ss.generate_state(1)[0])


def run_episode(house: SymbolicHouse, planner: Planner, query: str, targets: Sequence[str],
                seed: int = 0, episode_index: int = 0, avoid_rooms: Sequence[str] = (),
                max_steps: int = N_MAX, seen: bool | None = None, house_id: str = "",
                planner_name: str | None = None, log: Any = None) -> EpisodeResult:
    """Roll out one episode: observe, decide, act, feed back, until it ends.

    ``targets`` (spec ids of the query's instances) only serve the shortest path of SPL;
    success is decided by category (module doc). Decision time is the wall time of each
    ``decide`` call (kept in the record's ``wall`` figures only).

    With ``log`` (an open :class:`sgtool.log.writer.LogWriter`) the episode is also
    recorded the way the closed loop records one, so ``sgtool eval`` reads both alike: an
    ``sgtool.Episode`` record "started" at t = 0, then per step k (t = k s) the
    ``sgtool.SceneGraph`` the planner saw and the ``sgtool.Action`` it took, and the
    closing Episode record with the final figures (``extra``: seed, planner_seed, episode,
    seen, end, n_open, start_region).
    """
    name = planner_name or getattr(planner, "name", "planner")
    hid = house_id or f"house-{house.spec.seed}"
    env = SymbolicEnv(house, query, seed=seed, episode_index=episode_index,
                      avoid_rooms=avoid_rooms, max_steps=max_steps)
    t_start = time.perf_counter()
    pseed = planner_seed(seed, house.spec.seed, episode_index)
    planner.reset(query, seed=pseed)
    trace: list[Step] = []
    decision_s = 0.0
    decisions = 0
    base = {"kind": "search", "source": "symbolic", "house_id": hid, "query": query,
            "planner": name, "frames": 0}
    if log is not None:
        log.write_record("episode", 0, {**base, "status": "started", "steps": 0,
                                         "travelled_m": 0.0, "shortest_m": None, "extra": {}})
    while not env.ended:
        graph = env.observe()
        t0 = time.perf_counter()
        action = planner.decide(graph)
        dt = time.perf_counter() - t0
        decision_s += dt
        decisions += 1
        out = env.step(action)
        planner.feedback(out.feedback)
        fb = out.feedback
        trace.append(Step(action.skill, action.target, fb.outcome, fb.travelled_m))
        if log is not None:
            t_ns = len(trace) * 1_000_000_000
            log.write_json_bytes("scene_graph", t_ns, graph.to_json().encode())
            log.write_record("action", t_ns, {
                "skill": action.skill, "target": action.target, "outcome": fb.outcome,
                "reason": action.reason, "travelled_m": round(fb.travelled_m, 4),
                "decision_time_s": dt, "planner": name, "step": len(trace),
            })
    shortest = env.shortest_path(targets)
    result = EpisodeResult(
        planner=name, seed=int(seed), house=hid,
        episode=int(episode_index), query=query, success=env.success, steps=env.steps,
        travelled_m=env.travelled, shortest_m=shortest,
        n_open=env.n_open, n_invalid=env.n_invalid, n_failure=env.n_failure, seen=seen,
        end=env.end_reason, source="symbolic", trace=tuple(trace),
        wall={"decision_s": decision_s, "decisions": float(decisions),
              "episode_s": time.perf_counter() - t_start},
    )
    if log is not None:
        log.write_record("episode", (len(trace) + 1) * 1_000_000_000, {
            **base, "status": "success" if env.success else "failure", "steps": env.steps,
            "travelled_m": round(env.travelled, 4),
            "shortest_m": None if shortest is None else round(shortest, 4),
            "extra": {"seed": int(seed), "planner_seed": pseed, "episode": int(episode_index),
                      "seen": seen, "end": env.end_reason, "n_open": env.n_open,
                      "start_region": env.start_region},
        })
    return result
