"""Door-based room segmentation of the Voronoi graph, room centres, neighbours, stable ids.

MoMa-LLM (paper sec. III-B, "Room clustering (door-based separation)"): a Gaussian kernel
density over observed door positions, ``rho(x) = 1/N_D sum_i K_H(x - x_i)``; Voronoi edges
and nodes in high-density door regions are removed, which cuts the graph into disjoint
components, the rooms. Neighbouring rooms: "if a path traverses exactly two components,
they are marked as neighbors". MoMa-LLM's released code (as summarised in the project's
reference notes): bandwidth 0.15 m evaluated on the grid, an edge is cut when its summed
density exceeds 0.001, isolated nodes and tiny components are dropped, the room's position
is the graph centre.

What we do, and why it differs:

- **Door evidence** is the doorway itself, not one point per door (the centroid of a
  swung panel misses the opening by half a door width): the grid cells of an open (or
  state-unknown) door instance that are passable (its lintel above the free opening),
  or, for a door seen only as its swung panel, the panel's closed position
  (:func:`sgtool.scenegraph.door_panel.opening_from_panel`), or else all its cells; and
  the cells under a lintel seen over a gap in a wall, where no door leaf was seen
  (:mod:`sgtool.scenegraph.lintels`). Closed doors are walls already
  (the graph never crosses them) and would only cut corridors running past them.
- **Density without the 1/N_D factor**: ``gaussian_filter(door_cells, sigma=0.15 m)`` is
  ``sum_i K_H(x - x_i) * cell_area``, the kernel mass of door cells near x. With the 1/N_D
  normalisation a fixed threshold cuts less and less as more doors are observed (the same
  doorway stops cutting once ten other doors are seen); without it the cut depends only
  on the door itself. Next to a one-cell-thick line of door cells the value is
  ``cell / (sqrt(2 pi) sigma)`` = 0.13 at 5 cm, and the default threshold 0.03 cuts within
  about 0.3 m of the door cells, which covers a doorway's Voronoi edge whatever the
  resolution (the filter is defined in metres).
- **Cut on the maximum** density along an edge's ridge cells (not the sum, which grows
  with edge length and node spacing).
- **Tiny components**: fewer than ``min_room_length`` metres of edges (isolated nodes
  have none), unless on floor of their own (below). Dropped nodes keep no room label.
- **Slits**: a component long enough none of whose nodes has ``ROBOT_RADIUS`` of
  clearance is no room: nowhere in it would the robot fit (a strip of floor that a
  cabinet door opened beside a doorway leaves between itself and the wall, whose only
  mouth lies in the doorway's cut zone). Its nodes keep no room label.
- **A door separates its two sides, nothing more**: given the grid, components
  whose nodes lie in one connected part of the free space outside the cut zone (cells
  below the threshold, 4-connected) are one room. The cut zone is a disc-like region
  around the door cells, so it also cuts a corridor whose graph runs close past a
  doorway (a door panel swung into the corridor leaves the ridge only the gap beside
  the doorway); the floor on that side still joins up past the zone. Pieces of one room
  that the graph does not join (free space it does not cover, a phantom obstacle on
  the ridge) join the same way. Joining floor keeps ``JOIN_SEAL`` (0.3 m) from door
  evidence (the cut zone reaches about 0.1 m past the end of a line of door cells, so a
  doorway whose cells cover part of it would leak) and from the floor near a door whose
  doorway was not found (a door standing partly open, whose cells need not span its
  opening), and needs passages ``JOIN_WIDTH`` wide (a slit beside a closed leaf, a gap
  at a wall's end join nothing): the floor is eroded k cells, which keeps passages of
  2k + 1 cells, k the fewest steps that make those at least ``JOIN_WIDTH`` (3 cells at
  5 cm). The robot's own path joins too: a stretch of it that stays outside the cut zone
  and ``WALK_SEAL`` joins the parts of open floor it crosses, whatever the grid shows
  between them now (a phantom obstacle on its way, a swung door leaf and a cabinet door
  opened after it passed, leaving a pocket of the room closed off; a path through a
  doorway enters its cut zone, so it joins nothing there). A door's leaf swung into a
  room is open floor to this join where it stands out of its doorway's wall
  (:func:`sgtool.scenegraph.door_evidence.doorways` gives its cells): a leaf whose end
  meets a cabinet walls off no pocket of the room. A merged room's centre is
  taken on its largest piece.
  A component shorter than ``min_room_length`` is a room when it stands on open floor of
  its own (no longer component's nodes on it) of at least ``OWN_FLOOR`` times
  ``min_room_length`` squared (0.5 m^2): a room glimpsed through a doorway, or a closet or
  WC of 1.5 m (0.9 m^2 of open floor outside its door's cut zone), has little graph but
  floor that belongs to no other room. Its floor must not join a longer component's
  beside the door evidence either (a cell off the evidence, ``JOIN_SEAL`` off unsure floor
  that is not evidence, passages ``JOIN_WIDTH`` wide): a pocket of floor at a corridor's
  end, behind furniture, whose mouth runs past a doorway is cut off from the corridor by
  that doorway's seal only, and is the corridor's, not a room.

Room ids stay stable across refreshes (:class:`RoomTracker`): new rooms take the id of the
previous room whose nodes they overlap most (greedy, largest overlap first), so a planner's
history keeps meaning; a room seen only through a closed door (an unexplored room node)
passes its id to the explored room found beyond that door later.
"""

from __future__ import annotations

import hashlib
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np
from scipy import ndimage
from scipy.sparse import csr_matrix
from scipy.sparse.csgraph import connected_components, dijkstra
from scipy.spatial import cKDTree

from sgtool.mapping.bev import BevConfig
from sgtool.mapping.grid import OccupancyGrid
from sgtool.mapping.occupancy import within_cells
from sgtool.mapping.voronoi import VoronoiGraph, submatrix

JOIN_WIDTH = 0.15  # m: passages of open floor narrower than this join no rooms (module doc)
JOIN_SEAL = 0.3  # m around door evidence (and unsure floor) where floor joins nothing
# m around door evidence (and unsure floor) where the robot's path joins nothing: a door
# leaf's width (door_evidence.UNSURE_REACH), within which a doorway lies of its evidence
# (drift spreads passes through one doorway over its jambs)
WALK_SEAL = 0.9
OWN_FLOOR = 0.5  # of min_room_length squared: the open floor of its own a short room needs
ROBOT_RADIUS = BevConfig.robot_radius  # m: the robot's footprint, as the map clears it


@dataclass(frozen=True)
class RoomConfig:
    door_bandwidth: float = 0.15  # m (MoMa-LLM)
    door_threshold: float = 0.03  # kernel mass of door cells (module doc)
    min_room_length: float = 1.0  # m of edges; smaller components are no room
    match_radius: float = 0.6  # m: a node overlaps an old room's node this close


def door_density(door_cells: np.ndarray, resolution: float, bandwidth: float) -> np.ndarray:
    """Kernel mass of door cells around every cell (module doc)."""
    if not door_cells.any():
        return np.zeros(door_cells.shape, dtype=np.float64)
    return ndimage.gaussian_filter(door_cells.astype(np.float64), sigma=bandwidth / resolution,
                                   mode="constant", truncate=4.0)


@dataclass(frozen=True, eq=False)
class RoomSegmentation:
    """Rooms as components of the cut graph. ``labels[n]`` is the room index of node n
    (-1: cut away or in a dropped component); rooms are numbered by their lowest node."""

    labels: np.ndarray
    cut_edges: np.ndarray  # bool per edge of the Voronoi graph
    cut_nodes: np.ndarray  # bool per node
    rooms: tuple[np.ndarray, ...]  # node ids per room, sorted
    centres: tuple[int, ...]  # graph-centre node per room

    @property
    def count(self) -> int:
        return len(self.rooms)


def segment_rooms(vg: VoronoiGraph, density: np.ndarray | None,
                  config: RoomConfig | None = None,
                  centre_memo: dict[bytes, int] | None = None,
                  occ: OccupancyGrid | None = None,
                  unsure: np.ndarray | None = None,
                  trajectory: np.ndarray | Sequence[tuple[float, float]] | None = None,
                  leaves: np.ndarray | None = None,
                  doors: np.ndarray | None = None) -> RoomSegmentation:
    """Cut ``vg`` where the door density reaches the threshold; components are rooms.
    ``centre_memo`` keeps each room's centre across calls, keyed by its sub-graph (a room
    whose sub-graph is unchanged has the same centre: the same arrays, the same Dijkstra).
    ``occ``: the grid of ``vg``; with it, components sharing free space outside the cut
    zone are one room, and a short one on floor of its own is a room (module doc);
    ``unsure``: the door evidence and the cells near a door whose doorway is not known
    (bool, ``vg.shape``): floor within ``JOIN_SEAL`` of them joins nothing;
    ``trajectory``: (k, 2) world x, y of the robot's path: a stretch of it that stays out
    of the cut zone and that floor joins the parts it crosses (module doc);
    ``leaves``: the cells of door leaves swung into rooms (bool, ``vg.shape``), floor to
    join by (module doc); ``doors``: the door evidence alone (bool, ``vg.shape``): a short
    component whose floor joins a room's beside it is no room of its own."""
    cfg = config or RoomConfig()
    n, m = len(vg.positions), len(vg.edges)
    cut_e = np.zeros(m, dtype=bool)
    cut_n = np.zeros(n, dtype=bool)
    if density is not None and density.any() and n:
        flat = density.ravel()
        h, w = vg.shape
        cut_n = flat[vg.cells[:, 0] * w + vg.cells[:, 1]] >= cfg.door_threshold
        if m:  # the maximum density along every edge's cells, all edges in one pass
            cells, starts = vg.edge_cells_flat()
            cut_e = np.maximum.reduceat(flat[cells], starts) >= cfg.door_threshold
    keep = ~cut_e
    if m:
        keep &= ~cut_n[vg.edges[:, 0]] & ~cut_n[vg.edges[:, 1]]
    labels = np.full(n, -1, dtype=np.int64)
    if n == 0:
        return RoomSegmentation(labels, cut_e, cut_n, (), ())
    graph = vg.csgraph(keep)
    ncomp, comp = connected_components(graph, directed=False)
    comp_len = np.zeros(ncomp)
    if m:
        np.add.at(comp_len, comp[vg.edges[keep, 0]], vg.lengths[keep])
    rooms: list[np.ndarray] = []
    by_comp = np.argsort(comp, kind="stable")  # nodes grouped by component, ascending
    bounds = np.searchsorted(comp[by_comp], np.arange(ncomp + 1))
    short: list[np.ndarray] = []
    for c in range(ncomp):  # components are numbered by their lowest node already
        if comp_len[c] < cfg.min_room_length and occ is None:
            continue
        nodes = by_comp[bounds[c]:bounds[c + 1]]
        nodes = nodes[~cut_n[nodes]]
        if not len(nodes):
            continue
        if comp_len[c] < cfg.min_room_length:
            short.append(nodes)
        elif vg.clearance[nodes].max() >= ROBOT_RADIUS:  # somewhere the robot fits
            rooms.append(nodes)
    if occ is not None:
        rooms = _rooms_by_floor(vg, rooms, short, occ, density, cfg, unsure, trajectory,
                                leaves, doors)
    for i, nodes in enumerate(rooms):
        labels[nodes] = i
    where = np.full(n, -1, dtype=np.int64)
    keys = _room_keys(vg, keep, labels, rooms) if centre_memo is not None else None
    centres = tuple(_graph_centre(graph, nodes, where, centre_memo,
                                  None if keys is None else keys[i])
                    for i, nodes in enumerate(rooms))
    return RoomSegmentation(labels, cut_e, cut_n, tuple(rooms), centres)


def _rooms_by_floor(vg: VoronoiGraph, rooms: list[np.ndarray], short: list[np.ndarray],
                    occ: OccupancyGrid, density: np.ndarray | None,
                    cfg: RoomConfig, unsure: np.ndarray | None = None,
                    trajectory: np.ndarray | Sequence[tuple[float, float]] | None = None,
                    leaves: np.ndarray | None = None,
                    doors: np.ndarray | None = None) -> list[np.ndarray]:
    """``rooms`` (components long enough) joined where their nodes share a 4-connected part
    of the open floor (free or a door's ``leaves``, outside the cut zone and ``unsure``)
    that passages at least
    ``JOIN_WIDTH`` wide hold together, plus the ``short`` components whose parts of the
    open floor no such room touches and hold at least ``OWN_FLOOR`` times
    ``min_room_length`` squared, and (with ``doors``) whose floor beside the door evidence
    (:func:`_beside_doors`) no such room stands on either;
    numbered by their lowest node."""
    away = np.ones(occ.shape, dtype=bool) if density is None else density < cfg.door_threshold
    if unsure is not None:  # and what lies within JOIN_SEAL of it
        away &= ~within_cells(unsure, JOIN_SEAL / occ.resolution)
    open_floor = occ.free & away if leaves is None else (occ.free | leaves) & away
    if short:
        part, count = ndimage.label(open_floor)
        area = np.bincount(part.ravel(), minlength=count + 1) * occ.resolution ** 2
        taken = {p for nodes in rooms for p in _parts(vg, part, nodes)}
        beside = _beside_doors(occ, doors, unsure, leaves)
        by_side = set() if beside is None else \
            {p for nodes in rooms for p in _parts(vg, beside, nodes)}
        rooms = rooms + [nodes for nodes in short if (mine := _parts(vg, part, nodes))
                         and not taken.intersection(mine)
                         and area[mine].sum() >= OWN_FLOOR * cfg.min_room_length ** 2
                         and (beside is None
                              or not by_side.intersection(_parts(vg, beside, nodes)))]
        rooms.sort(key=lambda nodes: int(nodes[0]))
    # a passage narrower than JOIN_WIDTH (a gap at a wall's end, beside a closed leaf)
    # joins nothing: k erosion steps keep passages of 2k + 1 cells and more
    steps = max(0, math.ceil((JOIN_WIDTH / occ.resolution - 1) / 2 - 1e-9))
    if steps > 0:  # (the grid's edge is no wall)
        open_floor = ndimage.binary_erosion(open_floor, iterations=steps, border_value=1)
    part, count = ndimage.label(open_floor)
    # rooms and parts of floor as one graph: a room linked to each part it stands on
    links = [(i, len(rooms) + p) for i, nodes in enumerate(rooms) for p in _parts(vg, part, nodes)]
    size = len(rooms) + count + 1
    walked = _walked(occ, part, away, unsure, trajectory)
    links += [(size + run, len(rooms) + p) for run, p in walked]  # linked to its parts
    size += max((run + 1 for run, _ in walked), default=0)
    a, b = np.array(links, dtype=np.int64).reshape(-1, 2).T
    _, joined = connected_components(csr_matrix((np.ones(len(a)), (a, b)), shape=(size, size)),
                                     directed=False)
    groups: dict[int, list[np.ndarray]] = {}
    for i, nodes in enumerate(rooms):  # rooms come by lowest node: so do the groups
        groups.setdefault(int(joined[i]), []).append(nodes)
    return [np.sort(np.concatenate(g)) if len(g) > 1 else g[0] for g in groups.values()]


def _beside_doors(occ: OccupancyGrid, doors: np.ndarray | None, unsure: np.ndarray | None,
                  leaves: np.ndarray | None) -> np.ndarray | None:
    """Labelled parts of the floor (free or ``leaves``) off the door evidence ``doors``
    (a cell's margin) and ``JOIN_SEAL`` off the unsure floor that is not door evidence,
    passages ``JOIN_WIDTH`` wide: floor a short component shares with a room there is the
    room's, reached beside a doorway through its cut zone, not through it (a pocket of a
    corridor's end behind furniture next to a doorway). None without ``doors``."""
    if doors is None:
        return None
    floor = occ.free if leaves is None else occ.free | leaves
    floor = floor & ~ndimage.binary_dilation(doors, structure=np.ones((3, 3), dtype=bool))
    if unsure is not None:
        floor &= ~within_cells(unsure & ~doors, JOIN_SEAL / occ.resolution)
    steps = max(0, math.ceil((JOIN_WIDTH / occ.resolution - 1) / 2 - 1e-9))
    if steps > 0:
        floor = ndimage.binary_erosion(floor, iterations=steps, border_value=1)
    return ndimage.label(floor)[0]


def _walked(occ: OccupancyGrid, part: np.ndarray, away: np.ndarray,
            unsure: np.ndarray | None,
            trajectory: np.ndarray | Sequence[tuple[float, float]] | None
            ) -> list[tuple[int, int]]:
    """(stretch, part) for the labelled parts of floor each stretch of the ``trajectory``
    crosses, a stretch being a piece of the path (sampled every cell) that stays on
    ``away`` cells of the grid farther than ``WALK_SEAL`` from ``unsure`` (the door
    evidence and unsure floor): the robot passed from one part to the other without
    passing a door, whatever the grid shows between them now (a phantom obstacle on its
    way). No path (a hand-held camera): nothing, and no distance transform."""
    if trajectory is None or len(trajectory) < 2:
        return []
    if unsure is not None:
        away = away & ~within_cells(unsure, WALK_SEAL / occ.resolution)
    pts = np.asarray(trajectory, dtype=np.float64).reshape(-1, 2)
    step = np.diff(pts, axis=0)
    n = np.maximum(1, np.ceil(np.hypot(step[:, 0], step[:, 1]) / occ.resolution)).astype(np.int64)
    seg = np.repeat(np.arange(len(step)), n)
    t = (np.arange(len(seg)) - np.repeat(np.cumsum(n) - n, n)) / np.repeat(n, n)
    xy = np.vstack([pts[seg] + step[seg] * t[:, None], pts[-1:]])
    r, c = occ.cell_of(xy[:, 0], xy[:, 1])
    ok = occ.inside(r, c)
    ok[ok] = away[r[ok], c[ok]]
    run = np.cumsum(~ok)  # a new stretch after every sample off the away cells
    p = np.zeros(len(ok), dtype=np.int64)
    p[ok] = part[r[ok], c[ok]]
    keep = ok & (p > 0)
    pairs = np.unique(np.stack([run[keep], p[keep]], axis=1), axis=0)
    _, stretch = np.unique(pairs[:, 0], return_inverse=True)  # numbered from 0
    return list(zip(stretch.ravel().tolist(), pairs[:, 1].tolist(), strict=True))


def _parts(vg: VoronoiGraph, part: np.ndarray, nodes: np.ndarray) -> list[int]:
    """The labelled parts of floor the ``nodes`` stand on (a node on none joins nothing)."""
    p = np.unique(part[vg.cells[nodes, 0], vg.cells[nodes, 1]])
    return p[p > 0].tolist()


def _room_keys(vg: VoronoiGraph, keep: np.ndarray, labels: np.ndarray,
               rooms: list[np.ndarray]) -> list[bytes]:
    """Per room, a digest of its sub-graph: its node count and its kept edges (both ends
    in the room, as every kept edge at a room node is) in edge order, as (local u, local
    v, length); the sub-graph's arrays (:func:`sgtool.mapping.voronoi.submatrix`) are a
    function of these alone (nodes and edges are sorted)."""
    local = np.full(len(labels), -1, dtype=np.int64)
    for nodes in rooms:
        local[nodes] = np.arange(len(nodes))
    e = vg.edges[keep]
    w = np.ascontiguousarray(vg.lengths[keep], dtype=np.float64)
    lab = labels[e[:, 0]] if len(e) else np.zeros(0, dtype=np.int64)
    order = np.argsort(lab, kind="stable")
    bounds = np.searchsorted(lab[order], np.arange(len(rooms) + 1))
    lu, lv, lw = local[e[order, 0]], local[e[order, 1]], w[order]
    keys = []
    for i, nodes in enumerate(rooms):
        a, b = int(bounds[i]), int(bounds[i + 1])
        h = hashlib.blake2b(repr(len(nodes)).encode(), digest_size=16)
        for arr in (lu[a:b], lv[a:b], lw[a:b]):
            h.update(arr.tobytes())
        keys.append(h.digest())
    return keys


def _graph_centre(graph: csr_matrix, nodes: np.ndarray, where: np.ndarray,
                  memo: dict[bytes, int] | None = None, key: bytes | None = None) -> int:
    """The node of minimum eccentricity within its room (ties: the lowest id); ``where``
    is scratch space (-1 everywhere, as it is left); ``memo``: see :func:`segment_rooms`,
    ``key`` the room's digest there (:func:`_room_keys`)."""
    if len(nodes) == 1:
        return int(nodes[0])
    if memo is not None and key is not None and key in memo:
        return int(nodes[memo[key]])
    d = dijkstra(submatrix(graph, nodes, where), directed=False)
    reach = np.isfinite(d)
    count = reach.sum(axis=1)
    # a room of pieces (joined by free space): the centre of its largest piece
    ecc = np.where(count == count.max(), np.where(reach, d, 0.0).max(axis=1), np.inf)
    best = int(np.argmin(ecc))
    if memo is not None and key is not None:
        if len(memo) > 1024:
            memo.clear()
        memo[key] = best
    return int(nodes[best])


def room_neighbours(vg: VoronoiGraph, seg: RoomSegmentation) -> list[tuple[int, int]]:
    """Pairs (a, b), a < b, of rooms whose shortest path between centres on the *unsplit*
    graph passes through no third room (MoMa-LLM: "traverses exactly two components")."""
    out: list[tuple[int, int]] = []
    if seg.count < 2:
        return out
    g = vg.csgraph()
    centres = np.asarray(seg.centres, dtype=np.int64)
    dist, pred = dijkstra(g, directed=False, indices=centres, return_predecessors=True)
    labels = seg.labels.tolist()
    for a in range(seg.count):
        other = _other_rooms(pred[a].tolist(), labels, a)
        for b in range(a + 1, seg.count):
            t = int(centres[b])
            if np.isfinite(dist[a, t]) and other(t) == b:
                out.append((a, b))
    return out


def _other_rooms(pred: list[int], labels: list[int], a: int) -> Callable[[int], int]:
    """For the shortest-path tree ``pred`` from room ``a``'s centre: a function of a node
    t giving the room other than ``a`` on the path to t (-1: none, -2: more than one).
    Each tree node is climbed once; the values along a climbed path are kept."""
    memo: dict[int, int] = {}

    def with_label(v: int, node: int) -> int:
        lab = labels[node]
        if lab < 0 or lab == a or v == -2 or v == lab:
            return v
        return lab if v == -1 else -2

    def other(t: int) -> int:
        path = []
        node = t
        while node >= 0 and node not in memo:
            path.append(node)
            node = pred[node]
        v = memo[node] if node >= 0 else -1
        for n in reversed(path):
            v = with_label(v, n)
            memo[n] = v
        return v

    return other


def room_overlaps(known: dict[int, np.ndarray], room_positions: Sequence[np.ndarray],
                  radius: float) -> list[tuple[int, int, int]]:
    """(-count, new room, old room) for every pair of a new room and an old room (node
    positions ``known``) with ``count`` of the new room's nodes nearest (within
    ``radius``) to a node of the old room; all nodes in one k-d tree query."""
    old_ids = sorted(known)
    if not old_ids or not room_positions:
        return []
    old_pos = np.concatenate([known[o] for o in old_ids])
    old_lab = np.concatenate([np.full(len(known[o]), o) for o in old_ids])
    if not len(old_pos):
        return []
    new = [np.asarray(p, dtype=np.float64).reshape(-1, 2) for p in room_positions]
    owner = np.repeat(np.arange(len(new), dtype=np.int64), [len(p) for p in new])
    d, j = cKDTree(old_pos).query(np.concatenate(new), k=1, distance_upper_bound=radius)
    hit = np.isfinite(d)
    span = int(old_lab.max()) + 1
    pairs, counts = np.unique(owner[hit] * span + old_lab[j[hit]], return_counts=True)
    rooms, labs = np.divmod(pairs, span)
    return [(-c, i, lab) for i, lab, c in zip(rooms.tolist(), labs.tolist(), counts.tolist(),
                                              strict=True)]


@dataclass
class _Known:
    positions: np.ndarray  # (k, 2) node positions of the room at the last refresh


@dataclass
class RoomTracker:
    """Stable room ids across refreshes (module doc). Ids are ``room:<n>``, n from 0."""

    next_id: int = 0
    known: dict[int, _Known] = field(default_factory=dict)
    unexplored: dict[int, tuple[int, tuple[float, float]]] = field(default_factory=dict)
    # door instance -> (room number, position) of the unexplored room behind it

    def assign(self, room_positions: Sequence[np.ndarray], radius: float) -> list[int]:
        """Room numbers for this refresh's rooms (node positions of each)."""
        n_new = len(room_positions)
        overlap = room_overlaps({o: k.positions for o, k in self.known.items()},
                                room_positions, radius)  # (-count, new, old)
        overlap.sort()
        result: list[int | None] = [None] * n_new
        used: set[int] = set()
        for _negc, i, old in overlap:
            if result[i] is None and old not in used:
                result[i] = old
                used.add(old)
        # rooms found behind a door that had an unexplored room: inherit its number
        for door in sorted(self.unexplored):
            num, (x, y) = self.unexplored[door]
            if num in used:
                continue
            best = None
            for i, pos in enumerate(room_positions):
                if result[i] is not None or len(pos) == 0:
                    continue
                d = float(np.min(np.hypot(pos[:, 0] - x, pos[:, 1] - y)))
                if d <= 1.5 and (best is None or d < best[0]):
                    best = (d, i)
            if best is not None:
                result[best[1]] = num
                used.add(num)
        out: list[int] = []
        for i in range(n_new):
            r = result[i]
            if r is None:
                r = self._new()
            out.append(r)
        self.known = {r: _Known(np.asarray(room_positions[i]).reshape(-1, 2))
                      for i, r in enumerate(out)}
        for door in [d for d, (num, _) in self.unexplored.items() if num in used]:
            del self.unexplored[door]
        return out

    def unexplored_room(self, door: int, position: tuple[float, float]) -> int:
        """Number of the unexplored room behind closed door ``door`` (created once)."""
        got = self.unexplored.get(door)
        if got is None:
            got = (self._new(), position)
        else:
            got = (got[0], position)
        self.unexplored[door] = got
        return got[0]

    def _new(self) -> int:
        r = self.next_id
        self.next_id += 1
        return r
