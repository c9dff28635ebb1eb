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
  (:func:`opening_from_panel`), or else all its cells. Closed doors are walls already
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
  have none). Dropped nodes keep no room label.

Room ids stay stable across refreshes (:class:`RoomTracker`): new rooms take the id of the
previous room whose nodes they overlap most (greedy, largest overlap first), so a planner's
history keeps meaning; a room seen only through a closed door (an unexplored room node)
passes its id to the explored room found beyond that door later.
"""

from __future__ import annotations

import hashlib
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from scipy import ndimage
from scipy.sparse import csr_matrix
from scipy.sparse.csgraph import connected_components, dijkstra
from scipy.spatial import cKDTree

from sgtool.mapping.voronoi import VoronoiGraph, submatrix


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


def opening_from_panel(rows: np.ndarray, cols: np.ndarray, occupied: np.ndarray,
                       min_width: int = 8, memo: dict[bytes, Any] | None = None
                       ) -> tuple[np.ndarray, np.ndarray] | None:
    """The doorway of a door seen only as its swung-open panel: the panel's closed
    position, found by turning it by 90 degrees about its hinge.

    For each end of the panel (along its principal axis) and each side across it, score
    how much the surroundings look like a doorway seen from the hinge: wall running away
    on one side (share of occupied cells 0.1-0.45 panel widths along it), a clear opening
    on the other (share of occupied cells along the panel's closed position, which must be
    low) and the far jamb just beyond it; the score is wall + jamb - 2 opening. The best
    hinge and side must score well and clearly beat every alternative. When none does (a
    free end whose far-jamb ray hits furniture can come close to a hinge whose opening
    ray, for a panel smeared longer than its doorway, reaches the far wall), they are
    scored again by the wall line alone: the lesser of the wall and jamb shares minus the
    opening's (at least ``LINE_LEAST``, ``LINE_MARGIN`` ahead of every alternative).
    Otherwise None (the caller then uses the panel's own cells), as for cells that are not
    one panel at least ``min_width`` cells long."""
    if len(rows) < 2:
        return None
    # work in a window around the panel (everything looked at is within 1.3 widths)
    span = int(max(rows.max() - rows.min(), cols.max() - cols.min())) + 1
    pad = int(1.5 * span) + 6
    r0, c0 = max(int(rows.min()) - pad, 0), max(int(cols.min()) - pad, 0)
    r1 = min(int(rows.max()) + pad + 1, occupied.shape[0])
    c1 = min(int(cols.max()) + pad + 1, occupied.shape[1])
    window = occupied[r0:r1, c0:c1]
    key = None
    if memo is not None:  # the same panel cells in the same surroundings: the same answer
        h = hashlib.blake2b(digest_size=16)
        for a in (rows - r0, cols - c0, np.ascontiguousarray(window)):
            h.update(np.ascontiguousarray(a).tobytes())
        h.update(repr((window.shape, min_width, r0, c0, rows.dtype.str)).encode())
        key = h.digest()
        if key in memo:
            return memo[key]
    got = _opening(rows - r0, cols - c0, window, min_width)
    out = None if got is None else (got[0] + r0, got[1] + c0)
    if memo is not None and key is not None:
        if len(memo) > 256:
            memo.clear()
        memo[key] = out
    return out


def _opening(rows: np.ndarray, cols: np.ndarray, occupied: np.ndarray, min_width: int
             ) -> tuple[np.ndarray, np.ndarray] | None:
    pts = np.stack([cols, rows], axis=1).astype(np.float64)
    mean = pts.mean(axis=0)
    cen = pts - mean
    evals, evecs = np.linalg.eigh(cen.T @ cen)
    a = evecs[:, int(np.argmax(evals))]
    proj = cen @ a
    s0, s1 = float(proj.min()), float(proj.max())
    width = s1 - s0 + 1.0
    if width < min_width:
        return None
    t = np.array([-a[1], a[0]])
    h, w = occupied.shape
    grown = ndimage.binary_dilation(occupied, structure=np.ones((3, 3), dtype=bool))

    # every (end, side, offset) of the panel: the shares of occupied cells along the wall
    # side, the opening and the far jamb, sampled at once (:func:`ray_shares`)
    rays = []
    for s, out in ((s0, -a), (s1, a)):
        for sign in (1.0, -1.0):
            d = sign * t
            for off in range(4):  # the wall line may lie a few cells beyond the panel's end
                end = mean + a * s + out * off
                rays += [(end, -d, 0.1 * width, 0.45 * width, True),
                         (end, d, 0.15 * width, 0.85 * width, False),
                         (end, d, 1.05 * width, 1.3 * width, True)]
    shares = ray_shares(rays, occupied, grown)
    best = _clear_best(shares, s0, s1, a, _sum_score, 1.0, 0.5)
    if best is None:  # ambiguous: ask for the wall line on both sides of the opening
        best = _clear_best(shares, s0, s1, a, _line_score, LINE_LEAST, LINE_MARGIN)
    if best is None:
        return None
    _, s_end, sign, off, out = best
    end, d = mean + a * s_end + out * off, sign * t
    f = np.linspace(0.0, width, int(np.ceil(2 * width)) + 1)[:, None]
    p = end[None, :] + d[None, :] * f
    c = np.round(p[:, 0]).astype(np.int64)
    r = np.round(p[:, 1]).astype(np.int64)
    ok = (r >= 0) & (r < h) & (c >= 0) & (c < w)
    return r[ok], c[ok]


LINE_LEAST = 0.5  # the wall-line score a hinge needs (0 to 1: wall on both sides, clear)
LINE_MARGIN = 0.25  # and its lead over every other hinge and side


def _sum_score(wall: float, opening: float, jamb: float) -> float:
    """Wall on one side, far jamb on the other, a clear opening between."""
    return wall + jamb - 2.0 * opening


def _line_score(wall: float, opening: float, jamb: float) -> float:
    """The wall line on *both* sides of a clear opening: a panel's free end, whose far-jamb
    ray can hit any obstacle in the room, has no wall beside it."""
    return min(wall, jamb) - opening


def _clear_best(shares: list[float], s0: float, s1: float, a: np.ndarray,
                score: Callable[[float, float, float], float], least: float, margin: float
                ) -> tuple[float, float, float, int, np.ndarray] | None:
    """The (score, end, side sign, offset, outward axis) of the best hinge and side under
    ``score`` of the (wall, opening, jamb) shares, when it scores at least ``least`` and
    beats every other hinge and side by ``margin``; else None."""
    scored: list[tuple[float, float, float, int, np.ndarray]] = []
    at = 0
    for s, out in ((s0, -a), (s1, a)):
        for sign in (1.0, -1.0):
            side: tuple[float, int] | None = None  # (score, offset) of the best offset
            for off in range(4):
                cand = (score(*shares[at:at + 3]), off)
                at += 3
                if side is None or cand[0] > side[0]:
                    side = cand
            assert side is not None
            scored.append((side[0], s, sign, side[1], out))
    scored.sort(key=lambda x: -x[0])
    best, second = scored[0], scored[1]
    if best[0] < least or best[0] - second[0] < margin:
        return None
    return best


def ray_shares(rays: list[tuple[np.ndarray, np.ndarray, float, float, bool]],
               occupied: np.ndarray, grown: np.ndarray) -> list[float]:
    """Per ray (start, direction, from, to, on the grown grid; in (column, row) cells of
    ``occupied``, ``grown`` being that grid dilated): the share of occupied cells at the
    points sampled every half cell from ``start + from * direction`` to
    ``start + to * direction``, rounded to cells (points off the grid skipped; 0.0 with
    none on it). The points of every ray are computed as one ray at a time would, the
    shares counted for all at once."""
    fs = [np.linspace(lo, hi, max(2, int(np.ceil(2 * (hi - lo))))) for _, _, lo, hi, _ in rays]
    sizes = np.fromiter((len(f) for f in fs), dtype=np.int64, count=len(rays))
    ray = np.repeat(np.arange(len(rays)), sizes)
    p0 = np.stack([r[0] for r in rays])[ray]
    direction = np.stack([r[1] for r in rays])[ray]
    p = p0 + direction * np.concatenate(fs)[:, None]
    c, r = np.round(p[:, 0]).astype(np.int64), np.round(p[:, 1]).astype(np.int64)
    h, w = occupied.shape
    ok = (r >= 0) & (r < h) & (c >= 0) & (c < w)
    on_grown = np.fromiter((g for *_, g in rays), dtype=bool, count=len(rays))[ray[ok]]
    hit = np.where(on_grown, grown[r[ok], c[ok]], occupied[r[ok], c[ok]])
    count = np.bincount(ray[ok], minlength=len(rays))
    total = np.bincount(ray[ok], weights=hit.astype(np.float64), minlength=len(rays))
    return [float(x / n) if n else 0.0 for x, n in zip(total.tolist(), count.tolist(),
                                                        strict=True)]


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
                  centre_memo: dict[bytes, int] | None = None) -> RoomSegmentation:
    """Cut ``vg`` where the door density reaches the threshold; components are rooms.
    ``centre_memo`` keeps each room's centre across calls, keyed by its sub-graph (a room
    whose sub-graph is unchanged has the same centre: the same arrays, the same Dijkstra)."""
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
    for c in np.flatnonzero(comp_len >= cfg.min_room_length).tolist():
        # components are numbered by their lowest node already
        nodes = by_comp[bounds[c]:bounds[c + 1]]
        nodes = nodes[~cut_n[nodes]]
        if len(nodes) == 0:
            continue
        labels[nodes] = len(rooms)
        rooms.append(nodes)
    where = np.full(n, -1, dtype=np.int64)
    keys = _room_keys(vg, keep, labels, rooms) if centre_memo is not None else None
    centres = tuple(_graph_centre(graph, nodes, where, centre_memo,
                                  None if keys is None else keys[i])
                    for i, nodes in enumerate(rooms))
    return RoomSegmentation(labels, cut_e, cut_n, tuple(rooms), centres)


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
    ecc = d.max(axis=1)
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
