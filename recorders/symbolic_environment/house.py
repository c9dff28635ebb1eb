"""A house prepared for SymSearch roll-outs: regions, places and travel distances.

**Scene graph of a house** (SCOUT V.B, Fig. 5). Rooms are the spec's rooms. Regions: per
room, the (x, y) positions of its furniture are clustered by k-means (deterministic
farthest-point initialisation) with the number of clusters chosen by the Bayesian
Information Criterion of the matching spherical Gaussian mixture (X-means), k in
``[1, min(4, n - 1)]``; a room without furniture is one empty region. Furniture are the
first-level objects of their region; small objects are nested in their parent (a piece of
furniture or, house spec 2, another small object: a bowl in a cabinet holds an apple;
relation "inside"/"ontop"). Rooms are joined by doors (open/closed) and open-plan passages.

**Travel** (SCOUT Fig. 5 f). Every node the agent can go to has a *place*: the walkable cell
of its own room nearest to it (walkable: free on the occupancy grid dilated by the robot
radius, in the room's largest free component), i.e. the closest unoccupied point to the
goal within the same room; in a room too small for the robot (a niche, a closet), the
nearest walkable cell of the rooms its doors and passages join (it is searched from its
doorway). Distances are geodesics on the occupancy grid of
:mod:`sgtool.mapping.occupancy`. To let doors open and close during an episode without
re-rasterising, they are computed once on the grid with every door closed (each room, or
open-plan group, its own component) between all places, plus one place each side of every
door; an open door joins its two side places with an edge of their straight-line length.
Travel distance is then the shortest path on that place graph for the current door states.
A door whose doorway furniture blocks (:mod:`~sgtool.recorders.symbolic_environment.doorways`)
joins nothing: it is read as a wall, and not offered.
A nested object's place is its furniture's (the piece at the bottom of its chain of
parents); a room's is its nearest region's; a door's is its nearer side.
"""

from __future__ import annotations

import dataclasses
import functools
import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TypeVar

import numpy as np
from scipy import ndimage
from scipy.sparse import csr_matrix
from scipy.sparse.csgraph import connected_components, dijkstra

from sgtool.arg_checks import of_type
from sgtool.house.spec import HouseSpec, enclosed
from sgtool.mapping.occupancy import (
    OccupancyMap,
    cell_to_world,
    free_cell_graph,
    house_occupancy,
    nearest_free_cell,
    world_to_cell,
)
from sgtool.recorders.symbolic_environment.doorways import blocked_doors
from sgtool.recorders.symbolic_environment.furniture_regions import cluster_regions
from sgtool.scenegraph.examined import EXAMINE, examinable
from sgtool.scenegraph.graph import ObjectNode
from sgtool.semantics.text import category_text
from sgtool.vocabulary import OPEN_STATES, RELATIONS, OpenState, Relation

_V = TypeVar("_V", bound=str)
# geodesics between places are searched in batches of starts whose result arrays hold
# at most this many cells together (bounded memory on a large open floor)
_GEODESIC_BATCH_CELLS = 8_000_000


def _member(value: str, allowed: tuple[_V, ...]) -> _V:
    """``value`` as the member of ``allowed`` it equals; ValueError for any other."""
    for a in allowed:
        if a == value:
            return a
    raise ValueError(f"{value!r} is not one of {', '.join(allowed)}")


def spec_state(state: str | None) -> OpenState | None:
    """A house spec's ``state`` (the parser admits "open", "closed" or none) as typed."""
    return None if state is None else _member(state, OPEN_STATES)


def spec_relation(relation: str) -> Relation:
    """A house spec's ``relation`` (the parser admits "inside" or "ontop") as typed."""
    return _member(relation, RELATIONS)


@dataclass(frozen=True)
class Region:
    id: str  # "region:<room>.<k>"
    room: int  # index into spec.rooms
    center: tuple[float, float]
    furniture: tuple[int, ...]  # indices into spec.furniture
    place: int


class SymbolicHouse:
    """A house prepared for SymSearch roll-outs: regions, places and their distances.

    Build once per house (``SymbolicHouse(spec)``, the costly step) and run any number of
    episodes on it; it is never modified by an episode.
    """

    def __init__(self, spec: HouseSpec, resolution: float = 0.05, robot_radius: float = 0.2):
        of_type("spec", spec, HouseSpec, "a HouseSpec (sgtool.load_house(path) reads a file)")
        self.spec = spec
        self.resolution = resolution
        self.robot_radius = robot_radius
        closed = dataclasses.replace(
            spec, doors=tuple(dataclasses.replace(d, state="closed") for d in spec.doors))
        self.occ: OccupancyMap = house_occupancy(closed, resolution=resolution,
                                                 robot_radius=robot_radius)
        self.room_index = {r.id: i for i, r in enumerate(spec.rooms)}
        self.room_ids = tuple(f"room:{i}" for i in range(len(spec.rooms)))
        self.room_names = tuple(category_text(r.category) for r in spec.rooms)
        self.furn_cat = tuple(category_text(f.category) for f in spec.furniture)
        self.obj_cat = tuple(category_text(o.category) for o in spec.objects)
        self._furn_nodes: dict[tuple[int, OpenState | None, bool], ObjectNode] = {}
        self._obj_nodes: dict[tuple[int, OpenState | None, bool], ObjectNode] = {}
        # one position tuple per item, shared by the nodes of its states (so a planner's
        # per-episode object table sees a state change as the same row)
        self._positions: dict[tuple[str, int], tuple[float, float, float]] = {}
        self._walkable_rooms()  # sets self.blocked_doors too
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
            if di in self.blocked_doors:  # furniture in the doorway: a wall
                continue
            a, b = (self.room_index[r] for r in d.rooms)
            self.links[a].append((b, di))
            self.links[b].append((a, di))
        for p in spec.passages:
            a, b = (self.room_index[r] for r in p.rooms)
            self.links[a].append((b, None))
            self.links[b].append((a, None))
        # rooms whose free floor meets where the file has no wall, door or passage: open
        # plan, joined as by a passage (the robot drives across; so does the planner)
        self.open_floor = open_floor_pairs(self._raster, self.occ.blocked, self.links)
        for a, b in self.open_floor:
            self.links[a].append((b, None))
            self.links[b].append((a, None))
        # small objects: children of each piece and of each object, the piece at the root
        # of each object's chain, whether a closed parent hides it (spec.enclosed)
        self.obj_index = {o.id: j for j, o in enumerate(spec.objects)}
        self.nested: list[list[int]] = [[] for _ in spec.furniture]
        self.obj_children: list[list[int]] = [[] for _ in spec.objects]
        holders = spec.holder_by_id()
        self.enclosed = tuple(enclosed(o, holders[o.parent]) for o in spec.objects)
        for j, o in enumerate(spec.objects):
            if o.parent in self.furn_index:
                self.nested[self.furn_index[o.parent]].append(j)
            else:
                self.obj_children[self.obj_index[o.parent]].append(j)
        # pieces one can look into / onto (whatever they hold)
        self.explorable = tuple(bool(set(f.affordances) & {"container", "supporter"}) or
                                bool(self.nested[i]) for i, f in enumerate(spec.furniture))
        roots = spec.root_furniture()
        self.obj_furn = tuple(self.furn_index[roots[o.id]] for o in spec.objects)
        self._graphs: dict[frozenset[int], csr_matrix] = {}
        self._rows: dict[tuple[frozenset[int], int], np.ndarray] = {}
        self._lookups()

    def _lookups(self) -> None:
        """Per-house tables the episodes read at every step (computed once here)."""
        spec = self.spec
        self.room_centroids = tuple((float(r.centroid[0]), float(r.centroid[1]))
                                    for r in spec.rooms)
        self.region_index = {r.id: i for i, r in enumerate(self.regions)}
        self.place_region: dict[int, str] = {}
        for r in self.regions:
            self.place_region.setdefault(r.place, r.id)
        # a room's candidate places (its regions'), ascending, so the first nearest wins
        self.room_places = tuple(tuple(sorted(self.regions[k].place for k in regs))
                                 for regs in self.room_regions)
        self.furn_ids = tuple(self.furn_node_id(f) for f in range(len(spec.furniture)))
        self.obj_ids = tuple(self.obj_node_id(j) for j in range(len(spec.objects)))
        self.obj_place = tuple(self.furn_place[f] for f in self.obj_furn)
        self.obj_has_affordances = tuple(bool(o.affordances) for o in spec.objects)
        self.door_rooms = tuple(tuple(self.room_ids[self.room_index[r]] for r in d.rooms)
                                for d in spec.doors)

    # ----- ids ------------------------------------------------------------------------
    def furn_node_id(self, i: int) -> str:
        return f"obj:{i + 1}"

    def obj_node_id(self, j: int) -> str:
        return f"obj:{len(self.spec.furniture) + 1 + j}"

    # ----- geometry -------------------------------------------------------------------
    def _walkable_rooms(self) -> None:
        from sgtool.datasets.episodes import room_raster

        raster = self._raster = room_raster(self.spec, self.occ)
        free = ~self.occ.blocked
        walks: list[np.ndarray | None] = []
        for ri in range(len(self.spec.rooms)):
            # 4-connected: paths may not cut corners, so cells touching only diagonally
            # are not connected for the robot
            lab, n = ndimage.label(free & (raster == ri))
            walks.append(lab == (1 + int(np.argmax(np.bincount(lab.ravel())[1:])))
                         if n else None)
        open_occ = house_occupancy(self.spec, resolution=self.resolution,
                                   robot_radius=self.robot_radius, closed_doors_free=True)
        self.blocked_doors = frozenset(blocked_doors(self.spec, open_occ, raster, walks))
        self._snap: list[tuple[tuple[slice, slice], np.ndarray, np.ndarray] | None] = []
        # rooms without free floor for the robot (searched from the rooms next to them)
        self.niches = tuple(ri for ri, walk in enumerate(walks) if walk is None)
        for ri, walk in enumerate(walks):
            if walk is None:  # a niche the robot does not fit in: seen from the next room
                near = [w for j in self._neighbours(ri) if (w := walks[j]) is not None]
                walk = np.logical_or.reduce(near) if near else None
            self._snap.append(None if walk is None else self._snap_table(walk))

    def _neighbours(self, ri: int) -> list[int]:
        """Rooms joined to room ``ri`` by a door or passage, ascending."""
        rid = self.spec.rooms[ri].id
        links = [d.rooms for di, d in enumerate(self.spec.doors)
                 if di not in self.blocked_doors] + [p.rooms for p in self.spec.passages]
        return sorted({self.room_index[r] for pair in links if rid in pair
                       for r in pair if r != rid})

    @staticmethod
    def _snap_table(walk: np.ndarray) -> tuple[tuple[slice, slice], np.ndarray, np.ndarray]:
        """(window, row and column of the nearest walkable cell) over ``walk``'s extent."""
        rr, cc = np.nonzero(walk)
        win = (slice(max(rr.min() - 2, 0), rr.max() + 3),
               slice(max(cc.min() - 2, 0), cc.max() + 3))
        _, (ir, ic) = ndimage.distance_transform_edt(~walk[win], return_indices=True)
        return win, ir, ic

    def snap(self, x: float, y: float, room: int) -> tuple[int, int]:
        """The walkable cell of ``room`` nearest to (x, y)."""
        s = self._snap[room]
        if s is None:
            raise ValueError(f"room {self.spec.rooms[room].id} has no free floor (no cell "
                             "where the robot fits) and no door or passage to a room that has")
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

    @functools.cached_property
    def _base(self) -> np.ndarray:
        """Geodesics between all places with every door closed (inf across doors): the
        costly part of a house, computed at its first travel question (a check of the house
        file asks none). The same distances as :func:`~sgtool.mapping.occupancy.
        geodesic_distances` from each place to the others' cells, searched only within the
        free space each place can reach (a room, or rooms joined by passages), so a house
        of many rooms costs its rooms, not its rooms times its whole grid."""
        n = len(self.places)
        out = np.full((n, n), np.inf)
        g, index, _ = free_cell_graph(self.occ)
        if g.shape[0] == 0:
            return out
        _, part = connected_components(g, directed=False)
        targets = np.array([index[world_to_cell(self.occ, x, y)] for x, y in self.places])
        sources = np.array([-1 if c is None else index[c] for c in
                            (nearest_free_cell(self.occ, x, y, 0.0) for x, y in self.places)])
        for label in sorted({int(part[s]) for s in sources if s >= 0}):
            nodes = np.flatnonzero(part == label)  # ascending: the whole graph's order
            local = np.full(g.shape[0], -1, np.int64)
            local[nodes] = np.arange(nodes.size)
            sub = g[nodes][:, nodes]
            rows = [i for i in range(n) if sources[i] >= 0 and part[sources[i]] == label]
            cols = [j for j in range(n) if targets[j] >= 0 and part[targets[j]] == label]
            starts = sorted({int(local[sources[i]]) for i in rows})
            # bounded memory: each batch of starts returns a (batch, cells) array
            batch = max(1, _GEODESIC_BATCH_CELLS // nodes.size)
            found: dict[int, np.ndarray] = {}
            for k in range(0, len(starts), batch):
                chunk = starts[k:k + batch]
                d = dijkstra(sub, directed=True, indices=chunk)
                for s, row in zip(chunk, np.atleast_2d(d), strict=True):
                    found[s] = row[local[targets[cols]]]
            for i in rows:
                out[i, cols] = found[int(local[sources[i]])]
        return np.minimum(out, out.T)  # exact symmetry despite float summation order

    def prepare(self) -> None:
        """Compute the geodesics between places now (the first travel question does it
        otherwise): a caller that times episodes calls it first, so the house's cost is
        not counted in its first episode."""
        self._base  # noqa: B018 (the cached property is the work)

    def _graph(self, open_doors: frozenset[int]) -> csr_matrix:
        g = self._graphs.get(open_doors)
        if g is None:
            w = self._base.copy()
            np.fill_diagonal(w, np.inf)
            for di in sorted(open_doors - self.blocked_doors):
                a, b = self.door_sides[di]
                d = math.dist(self.places[a], self.places[b])
                w[a, b] = w[b, a] = min(w[a, b], max(d, 1e-6))
            src, dst = np.nonzero(np.isfinite(w))
            g = csr_matrix((w[src, dst], (src, dst)), shape=w.shape)
            self._graphs[open_doors] = g
        return g

    @functools.cached_property
    def place_component(self) -> np.ndarray:
        """Per place, the label of the places it can reach with every door open (places of
        rooms no door or passage joins to the rest get labels of their own), labels in the
        order of each part's first place. Without geodesics: the free cells' 4-connected
        parts (the 8-connected moves that cut no corner join no more) joined through the
        doors that are not blocked, which is what the place graph with every door open
        joins."""
        parts, n = ndimage.label(~self.occ.blocked)
        raw = [int(parts[world_to_cell(self.occ, x, y)]) for x, y in self.places]
        doors = [(raw[a], raw[b]) for di, (a, b) in enumerate(self.door_sides)
                 if di not in self.blocked_doors]
        links = csr_matrix((np.ones(len(doors)), ([a for a, _ in doors], [b for _, b in doors])),
                           shape=(n + 1, n + 1))
        _, joined = connected_components(links, directed=False)
        first: dict[int, int] = {}
        return np.asarray([first.setdefault(int(joined[r]), len(first)) for r in raw])

    def isolated_rooms(self) -> tuple[str, ...]:
        """Ids of the rooms none of whose places the largest part of the house reaches with
        every door open (walled off: no door or passage leads in), in spec order."""
        labels = self.place_component
        main = int(np.argmax(np.bincount(labels)))
        return tuple(self.spec.rooms[ri].id for ri, regs in enumerate(self.room_regions)
                     if all(labels[self.regions[k].place] != main for k in regs))

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

    def furniture_node(self, f: int, state: OpenState | None, explored: bool) -> ObjectNode:
        """The node of furniture ``f`` in a given state (memoised: nodes are frozen)."""
        key = (f, state, explored)
        node = self._furn_nodes.get(key)
        if node is None:
            fu = self.spec.furniture[f]
            affs = set(fu.affordances)
            if examinable(affs):
                affs.add(EXAMINE)
            node = ObjectNode(
                id=self.furn_node_id(f), category=self.furn_cat[f],
                parent=self.regions[self.region_of_furn[f]].id,
                room=self.room_ids[self.room_index[fu.room]],
                position=self._position("furn", f, fu.center),
                instance=f + 1, state=state,
                affordances=tuple(sorted(affs)), explored=explored,
            )
            self._furn_nodes[key] = node
        return node

    def _position(self, kind: str, k: int, xyz: tuple[float, float, float]
                  ) -> tuple[float, float, float]:
        key = (kind, k)
        pos = self._positions.get(key)
        if pos is None:
            x, y, z = xyz
            pos = self._positions[key] = (float(x), float(y), float(z))
        return pos

    def parent_node_id(self, j: int) -> str:
        """Node id of small object ``j``'s parent (a piece of furniture or an object)."""
        parent = self.spec.objects[j].parent
        f = self.furn_index.get(parent)
        return self.furn_node_id(f) if f is not None else self.obj_node_id(self.obj_index[parent])

    def object_node(self, j: int, state: OpenState | None = None,
                    explored: bool = False) -> ObjectNode:
        """The node of small object ``j`` (nested in its parent) in ``state`` (an openable
        object's; None for others). An object without affordances has the node of house
        spec 1; a container or openable one lists them (with "examine" for a container)."""
        key = (j, state, explored)
        node = self._obj_nodes.get(key)
        if node is None:
            o = self.spec.objects[j]
            affs = set(o.affordances)
            if examinable(affs, small_object=True):
                affs.add(EXAMINE)
            node = ObjectNode(
                id=self.obj_node_id(j), category=self.obj_cat[j],
                parent=self.parent_node_id(j),
                room=self.room_ids[self.room_index[o.room]],
                position=self._position("obj", j, o.position),
                instance=len(self.spec.furniture) + 1 + j, relation=spec_relation(o.relation),
                state=state, affordances=tuple(sorted(affs)),
                explored=explored,
            )
            self._obj_nodes[key] = node
        return node

    def all_doors(self) -> frozenset[int]:
        return frozenset(range(len(self.spec.doors)))

    def initially_open(self) -> frozenset[int]:
        return frozenset(i for i, d in enumerate(self.spec.doors) if d.state == "open")


def open_floor_pairs(raster: np.ndarray, blocked: np.ndarray,
                     links: Sequence[Sequence[tuple[int, int | None]]]
                     ) -> list[tuple[int, int]]:
    """Pairs (a, b), a < b, of rooms (``raster``: a room index per cell, -1 outside) whose
    free cells (not ``blocked``: walls, closed doors, the robot's margin) touch side by
    side, that ``links`` (per room, (other room, door or None)) does not join yet."""
    lab = np.where(blocked, -1, raster)
    found: set[tuple[int, int]] = set()
    for a, b in ((lab[:, :-1], lab[:, 1:]), (lab[:-1, :], lab[1:, :])):
        meet = (a >= 0) & (b >= 0) & (a != b)
        found.update(zip(np.minimum(a, b)[meet].tolist(), np.maximum(a, b)[meet].tolist(),
                         strict=True))
    joined = {(min(a, o), max(a, o)) for a, ls in enumerate(links) for o, _ in ls}
    return sorted(found - joined)
