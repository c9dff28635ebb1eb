"""Objects to rooms by MoMa-LLM's weighted travel distance, so nothing is assigned through a
wall.

MoMa-LLM (paper sec. III-B, Eq. 2; the exact form is that of MoMa-LLM's released code, as
summarised in the project's reference notes): for an object o seen from its closest
viewpoint vp, the candidate nodes are the Voronoi nodes within 2.5 m of o, the viewpoint
nodes those within 5 m of vp, and

    cost(n) = min_v  d_graph(v, n) / u  +  (|o - n| / u) ** 1.3  +  |vp - v| / u

with u their voxel size; o goes to the room of the cheapest candidate. Path length from
where the robot stood dominates, so a node behind a wall (close in Euclidean terms, far
along the graph) loses. We keep u = 0.075 m whatever our voxel size, so the balance
between the three terms (the exponent makes it scale-dependent) is MoMa-LLM's, and we
also require the viewpoint nodes to be *visible* from the viewpoint (no occupied cell on
the segment; all within 5 m if none is): a viewpoint node behind a wall would otherwise
start the path in the wrong room. Without a viewpoint the cost is the Euclidean term
alone. Candidates are nodes that have a room; with none within 2.5 m the nearest
labelled node is the only candidate.

Graph distances come from one Dijkstra per distinct viewpoint node over the sparsified
graph (hundreds of nodes), not an all-pairs table, stopped at ``search_limit`` metres
(nodes farther are inf; nodes within are reached by the same relaxations, so their
distances are the unlimited ones bit for bit). An object whose cheapest candidate costs
less than ``search_limit / u`` has the assignment of an unlimited search (a candidate
beyond the limit costs at least that much); any other object gets its viewpoint's full
search. In a large house most searches stop after a few rooms.

Between refreshes most of this repeats: the objects keep their closest viewpoints, the
map around old viewpoints stops changing, and the graph often stays the same. An
:class:`AssignCache` (the builder keeps one) reuses exactly what cannot have changed, so
results equal a run without it bit for bit: the Dijkstra row of a source node while the
graph (its sparse adjacency) is unchanged, and the visibility of a viewpoint's nodes
while the grid origin and resolution, those nodes' positions and every ``blocked`` cell
in the window the segments can touch are unchanged. Candidates come from a k-d tree
query (filtered by the same distance formula), not an objects x nodes matrix.
"""

from __future__ import annotations

import hashlib
from dataclasses import dataclass, field
from itertools import chain

import numpy as np
from scipy.sparse import csr_matrix
from scipy.sparse.csgraph import dijkstra
from scipy.spatial import cKDTree

from sgtool.mapping.bev import line_of_sight
from sgtool.mapping.grid import OccupancyGrid


@dataclass(frozen=True)
class AssignConfig:
    candidate_radius: float = 2.5  # m around the object
    viewpoint_radius: float = 5.0  # m around the viewpoint
    unit: float = 0.075  # m: MoMa-LLM's voxel size, the unit of the cost
    exponent: float = 1.3
    line_of_sight: bool = True
    search_limit: float = 10.0  # m: graph distances searched this far first (module doc)


@dataclass(frozen=True)
class Assignment:
    node: np.ndarray  # (k,) chosen node per object, -1 when there is no labelled node
    cost: np.ndarray  # (k,)


@dataclass
class AssignCache:
    """What :func:`assign_objects` reuses between calls (module doc); mutable, one per
    builder. ``hits``/``misses`` count reused and computed viewpoint visibilities."""

    graph_key: bytes = b""
    # search limit -> (Dijkstra rows of the sources searched so far, row of each node or -1)
    rows: dict[float, tuple[np.ndarray, np.ndarray]] = field(default_factory=dict)
    # viewpoint -> (its window, its targets' bytes, visibility of each target)
    sight: dict[tuple[float, float], tuple[tuple, bytes, np.ndarray]] = field(
        default_factory=dict)
    blocked: np.ndarray | None = None  # the blocked cells of the last call
    hits: int = 0
    misses: int = 0


def _graph_key(graph: csr_matrix) -> bytes:
    g = graph.tocsr()
    h = hashlib.blake2b(digest_size=16)
    h.update(repr(g.shape).encode())
    for a in (g.indptr, g.indices, g.data):
        h.update(np.ascontiguousarray(a).tobytes())
    return h.digest()


def _sight_windows(occ: OccupancyGrid, shape: tuple[int, int],
                   views: list[tuple[float, float]], targets: list[np.ndarray]) -> list[tuple]:
    """Per viewpoint, everything its segments read but the cells: grid origin, resolution,
    the window around the viewpoint and its targets (2 cells of margin) and that window
    clipped to the grid (``shape``), all viewpoints at once."""
    sizes = np.fromiter((len(t) for t in targets), dtype=np.int64, count=len(targets))
    starts = np.concatenate([[0], np.cumsum(sizes)[:-1]])
    pts = np.concatenate(targets)
    vxy = np.asarray(views, dtype=np.float64).reshape(-1, 2)
    lo = np.minimum(np.minimum.reduceat(pts, starts, axis=0), vxy)
    hi = np.maximum(np.maximum.reduceat(pts, starts, axis=0), vxy)
    rlo, clo = occ.cell_of(lo[:, 0], lo[:, 1])
    rhi, chi = occ.cell_of(hi[:, 0], hi[:, 1])
    h, w = shape
    out = []
    for v, a, b, c, d in zip(views, rlo.tolist(), rhi.tolist(), clo.tolist(), chi.tolist(),
                             strict=True):
        r0, r1, c0, c1 = a - 2, b + 3, c - 2, d + 3
        out.append((occ.origin, occ.resolution, (r0, r1, c0, c1),
                    (max(r0, 0), min(r1, h), max(c0, 0), min(c1, w)), v))
    return out


class _Changes:
    """Where ``blocked`` differs from the blocked cells of the cache's last call (on the
    cells both grids hold: a window clipped alike to both lies within them)."""

    def __init__(self, prev: np.ndarray | None, blocked: np.ndarray) -> None:
        self.box: tuple[int, int, int, int] | None = None
        self.diff: np.ndarray | None = None
        self.sat: np.ndarray | None = None
        if prev is None:
            return
        h, w = min(prev.shape[0], blocked.shape[0]), min(prev.shape[1], blocked.shape[1])
        self.diff = prev[:h, :w] != blocked[:h, :w]
        rows = np.flatnonzero(self.diff.any(axis=1))
        if rows.size:
            cols = np.flatnonzero(self.diff.any(axis=0))
            self.box = (int(rows[0]), int(rows[-1]) + 1, int(cols[0]), int(cols[-1]) + 1)

    def none_in(self, win: tuple[int, int, int, int]) -> bool:
        """True when no cell of the (clipped) window changed."""
        if self.diff is None:
            return False
        if self.box is None:
            return True
        r0, r1, c0, c1 = win
        b0, b1, d0, d1 = self.box
        if r1 <= b0 or b1 <= r0 or c1 <= d0 or d1 <= c0:
            return True
        return not self.diff[r0:r1, c0:c1].any()

    def any_in(self, r0: np.ndarray, r1: np.ndarray, c0: np.ndarray, c1: np.ndarray
               ) -> np.ndarray:
        """Per box (rows r0:r1, cols c0:c1, within a window :meth:`none_in` was asked
        about): whether a cell in it changed (counted on a summed-area table of the
        changed cells' bounding box)."""
        if self.box is None or self.diff is None:
            return np.zeros(len(r0), dtype=bool)
        b0, b1, d0, d1 = self.box
        if self.sat is None:
            sat = np.zeros((b1 - b0 + 1, d1 - d0 + 1), dtype=np.int64)
            sat[1:, 1:] = self.diff[b0:b1, d0:d1].cumsum(axis=0).cumsum(axis=1)
            self.sat = sat
        sat = self.sat
        y0, y1 = np.clip(r0 - b0, 0, b1 - b0), np.clip(r1 - b0, 0, b1 - b0)
        x0, x1 = np.clip(c0 - d0, 0, d1 - d0), np.clip(c1 - d0, 0, d1 - d0)
        return sat[y1, x1] - sat[y0, x1] - sat[y1, x0] + sat[y0, x0] > 0


def _visible_nodes(positions: np.ndarray, near_of: dict[tuple[float, float], np.ndarray],
                   occ: OccupancyGrid, blocked: np.ndarray, cache: AssignCache | None
                   ) -> dict[tuple[float, float], np.ndarray]:
    """Per viewpoint: visibility of each of its near nodes (one batched line-of-sight
    test for the segments the cache cannot answer). A cached answer stands while the
    viewpoint's window (:func:`_sight_windows`) and targets are the same and no blocked
    cell in the window changed since the last call (every answer kept was checked then);
    when some did, only the segments with a changed cell in their bounding box (grown by
    a cell: every cell the segment's samples fall in lies inside) are tested again."""
    out: dict[tuple[float, float], np.ndarray] = {}
    views = [v for v, nodes in near_of.items() if len(nodes)]
    for v, nodes in near_of.items():
        if len(nodes) == 0:
            out[v] = np.zeros(0, dtype=bool)
    # (viewpoint, the segments to test; None: all)
    todo: list[tuple[tuple[float, float], np.ndarray | None]] = [(v, None) for v in views]
    kept: dict[tuple[float, float], tuple[tuple, bytes]] = {}
    if cache is not None and views:
        targets = [positions[near_of[v]] for v in views]
        wins = _sight_windows(occ, blocked.shape, views, targets)
        changes = _Changes(cache.blocked, blocked)
        todo = []
        for v, t, win in zip(views, targets, wins, strict=True):
            tb = t.tobytes()
            kept[v] = (win, tb)
            got = cache.sight.get(v)
            if got is None or got[0] != win or got[1] != tb or changes.diff is None:
                todo.append((v, None))
                cache.misses += 1
                continue
            out[v] = got[2]
            if changes.none_in(win[3]):
                cache.hits += 1
                continue
            stale = np.flatnonzero(_stale_segments(occ, changes, v, t))
            if len(stale):
                todo.append((v, stale))
                cache.misses += 1
            else:
                cache.hits += 1
    if todo:
        picks = [near_of[v] if sel is None else near_of[v][sel] for v, sel in todo]
        seg_vp = np.concatenate([np.repeat(np.asarray([v]), len(p), axis=0)
                                 for (v, _), p in zip(todo, picks, strict=True)])
        vis = line_of_sight(blocked, occ, seg_vp, positions[np.concatenate(picks)])
        at = 0
        for (v, sel), p in zip(todo, picks, strict=True):
            m = len(p)
            if sel is None:
                out[v] = vis[at:at + m]
            else:
                out[v] = out[v].copy()
                out[v][sel] = vis[at:at + m]
            at += m
    if cache is not None:  # only the viewpoints in use
        cache.sight = {v: (win, tb, out[v]) for v, (win, tb) in kept.items()}
        cache.blocked = blocked.copy()
    return out


def _stale_segments(occ: OccupancyGrid, changes: _Changes, v: tuple[float, float],
                    targets: np.ndarray) -> np.ndarray:
    """Per segment from ``v`` to a target: whether a changed cell lies in the bounding
    box of its two end cells grown by one cell."""
    rv, cv = occ.cell_of(np.asarray([v[0]]), np.asarray([v[1]]))
    rt, ct = occ.cell_of(targets[:, 0], targets[:, 1])
    return changes.any_in(np.minimum(rt, rv) - 1, np.maximum(rt, rv) + 2,
                          np.minimum(ct, cv) - 1, np.maximum(ct, cv) + 2)


def _distance_table(graph: csr_matrix, sources: np.ndarray, n: int,
                    cache: AssignCache | None, limit: float) -> tuple[np.ndarray, np.ndarray]:
    """(table, row of every node in it or -1): Dijkstra distances (rows, n) from each
    source (inf beyond ``limit``: the search stops there; the distances within it are
    the unlimited ones, bit for bit), rows reused from the cache while the graph is
    unchanged (a source's row does not depend on the other sources searched with it)."""
    if cache is None:
        row_of = np.full(n, -1, dtype=np.int64)
        row_of[sources] = np.arange(len(sources))
        return dijkstra(graph, directed=False, indices=sources,
                        limit=limit).reshape(len(sources), n), row_of
    key = _graph_key(graph)
    if key != cache.graph_key:
        cache.graph_key, cache.rows = key, {}
    table, row_of = cache.rows.get(limit, (np.zeros((0, n)), np.full(n, -1, dtype=np.int64)))
    missing = sources[row_of[sources] < 0]
    if len(missing):
        got = dijkstra(graph, directed=False, indices=missing, limit=limit).reshape(
            len(missing), n)
        row_of = row_of.copy()
        row_of[missing] = len(table) + np.arange(len(missing))
        table = np.concatenate([table, got]) if len(table) else got
        cache.rows[limit] = (table, row_of)
    return table, row_of


def _path_terms(graph: csr_matrix, positions: np.ndarray,
                near_of: dict[tuple[float, float], np.ndarray],
                cols_of: dict[tuple[float, float], np.ndarray], u: float,
                cache: AssignCache | None, limit: float
                ) -> dict[tuple[float, float], np.ndarray]:
    """Per viewpoint vp (the keys of ``cols_of``): min over its nodes v of
    (d_graph(v, node) + |vp - v|) / u for the nodes ``cols_of[vp]`` (inf where every
    d_graph is beyond ``limit``)."""
    out: dict[tuple[float, float], np.ndarray] = {}
    if not cols_of:
        return out
    sources = np.unique(np.concatenate([near_of[v] for v in cols_of]))
    table, row_of = _distance_table(graph, sources, len(positions), cache, limit)
    for v, cols in cols_of.items():
        vs = near_of[v]
        start = np.hypot(positions[vs, 0] - v[0], positions[vs, 1] - v[1])
        out[v] = np.min(table[row_of[vs][:, None], cols[None, :]] + start[:, None],
                        axis=0) / u
    return out


def _candidates(positions: np.ndarray, labelled: np.ndarray, objects: np.ndarray,
                radius: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(object, candidate node, distance) entries, grouped by object and sorted by node
    within it: the labelled nodes within ``radius`` (a k-d tree proposes, the distance
    formula of the cost decides), else the nearest labelled node (ties: the lowest id)."""
    k = len(objects)
    proposals = cKDTree(positions[labelled]).query_ball_point(objects, radius + 1e-6,
                                                              return_sorted=True)
    sizes = np.fromiter((len(p) for p in proposals), dtype=np.int64, count=k)
    flat = np.fromiter(chain.from_iterable(proposals), dtype=np.int64, count=int(sizes.sum()))
    obj = np.repeat(np.arange(k, dtype=np.int64), sizes)
    cand = labelled[flat]
    d = np.hypot(objects[obj, 0] - positions[cand, 0], objects[obj, 1] - positions[cand, 1])
    inside = d <= radius
    obj, cand, d = obj[inside], cand[inside], d[inside]
    alone = np.ones(k, dtype=bool)
    alone[obj] = False
    if alone.any():
        lone = np.flatnonzero(alone)
        d_lab = np.hypot(objects[lone, 0][:, None] - positions[labelled, 0][None, :],
                         objects[lone, 1][:, None] - positions[labelled, 1][None, :])
        j = np.argmin(d_lab, axis=1)
        order = np.argsort(np.concatenate([obj, lone]), kind="stable")
        obj = np.concatenate([obj, lone])[order]
        cand = np.concatenate([cand, labelled[j]])[order]
        d = np.concatenate([d, d_lab[np.arange(len(lone)), j]])[order]
    return obj, cand, d


def assign_objects(positions: np.ndarray, node_room: np.ndarray, graph: csr_matrix,
                   objects: np.ndarray, viewpoints: np.ndarray,
                   occ: OccupancyGrid | None = None, blocked: np.ndarray | None = None,
                   config: AssignConfig | None = None,
                   cache: AssignCache | None = None) -> Assignment:
    """Node (hence room) of every object. ``positions`` (n, 2) node positions,
    ``node_room`` (n,) room index or -1, ``graph`` the sparse graph (m), ``objects`` (k, 2)
    object positions, ``viewpoints`` (k, 2) closest viewpoints (NaN: unknown);
    ``occ``/``blocked`` give line of sight (occupied cells) when given; ``cache`` reuses
    work of earlier calls (module doc; the result is the same without it)."""
    cfg = config or AssignConfig()
    k = len(objects)
    node = np.full(k, -1, dtype=np.int64)
    cost = np.full(k, np.inf)
    labelled = np.flatnonzero(node_room >= 0)
    if k == 0 or len(labelled) == 0:
        return Assignment(node, cost)
    u = cfg.unit
    tree_all = cKDTree(positions)
    # viewpoint nodes per object: the nodes within reach of each distinct viewpoint,
    # those visible from it when any is
    vp_key = [None if not np.all(np.isfinite(viewpoints[i])) else
              (float(viewpoints[i][0]), float(viewpoints[i][1])) for i in range(k)]
    distinct = sorted({v for v in vp_key if v is not None})
    near_of: dict[tuple[float, float], np.ndarray] = {}
    if distinct:
        near = tree_all.query_ball_point(np.asarray(distinct, dtype=np.float64),
                                         cfg.viewpoint_radius, return_sorted=True)
        for v, nodes in zip(distinct, near, strict=True):
            near_of[v] = np.asarray(nodes, dtype=np.int64)
    if cfg.line_of_sight and occ is not None and blocked is not None and distinct:
        vis = _visible_nodes(positions, near_of, occ, blocked, cache)
        for v in distinct:
            if vis[v].any():
                near_of[v] = near_of[v][vis[v]]
    for v in distinct:
        if len(near_of[v]) == 0:
            near_of[v] = np.asarray([int(tree_all.query(v)[1])], dtype=np.int64)
    obj, cand, d = _candidates(positions, labelled, objects, cfg.candidate_radius)
    euc = (d / u) ** cfg.exponent
    # the entries of each distinct viewpoint's objects, and their candidate nodes
    vp_row = {v: i for i, v in enumerate(distinct)}
    vpi = np.asarray([-1 if v is None else vp_row[v] for v in vp_key], dtype=np.int64)
    ent_vp = vpi[obj]
    by_vp = np.flatnonzero(ent_vp >= 0)
    by_vp = by_vp[np.argsort(ent_vp[by_vp], kind="stable")]
    bounds = np.searchsorted(ent_vp[by_vp], np.arange(len(distinct) + 1)).tolist()
    cols_of: dict[tuple[float, float], np.ndarray] = {}
    entries: dict[tuple[float, float], tuple[np.ndarray, np.ndarray]] = {}
    for j, v in enumerate(distinct):  # every viewpoint is some object's: entries
        e = by_vp[bounds[j]:bounds[j + 1]]
        cols_of[v], at = np.unique(cand[e], return_inverse=True)
        entries[v] = (e, at)
    # path terms, first from searches stopped at the limit
    limit = cfg.search_limit
    path_of = _path_terms(graph, positions, near_of, cols_of, u, cache, limit)
    c = euc.copy()
    for v, (e, at) in entries.items():
        c[e] = euc[e] + path_of[v][at]
    starts = np.searchsorted(obj, np.arange(k))
    stops = np.append(starts[1:], len(obj))
    full_path: dict[tuple[float, float], np.ndarray] = {}
    for i in np.flatnonzero((vpi >= 0) & ~(np.minimum.reduceat(c, starts) < limit / u)).tolist():
        # the best may lie beyond the limit: this viewpoint's full search
        vp = vp_key[i]
        assert vp is not None
        if vp not in full_path:
            full_path.update(_path_terms(graph, positions, near_of, {vp: cols_of[vp]}, u,
                                         cache, np.inf))
        a, b = int(starts[i]), int(stops[i])
        c[a:b] = euc[a:b] + full_path[vp][np.searchsorted(cols_of[vp], cand[a:b])]
    best = np.minimum.reduceat(c, starts)
    hit = np.flatnonzero(c == best[obj])  # the first hit: the lowest node id (cand sorted)
    _, first = np.unique(obj[hit], return_index=True)
    found = np.isfinite(best)
    node[found] = cand[hit[first]][found[obj[hit[first]]]]
    cost[found] = c[hit[first]][found[obj[hit[first]]]]
    for i in np.flatnonzero(~found).tolist():
        # no path from the viewpoint: fall back on the nearest candidate
        a, b = int(starts[i]), int(stops[i])
        j = a + int(np.argmin(euc[a:b]))
        node[i], cost[i] = int(cand[j]), float(euc[j])
    return Assignment(node, cost)
