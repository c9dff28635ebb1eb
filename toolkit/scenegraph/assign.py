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
    # (source node, search limit) -> distances
    rows: dict[tuple[int, float], np.ndarray] = field(default_factory=dict)
    sight: dict[tuple[float, float], tuple[bytes, np.ndarray]] = field(default_factory=dict)
    hits: int = 0
    misses: int = 0


def _graph_key(graph: csr_matrix) -> bytes:
    g = graph.tocsr()
    h = hashlib.blake2b(digest_size=16)
    h.update(repr(g.shape).encode())
    for a in (g.indptr, g.indices, g.data):
        h.update(np.ascontiguousarray(a).tobytes())
    return h.digest()


def _sight_key(occ: OccupancyGrid, blocked: np.ndarray, v: tuple[float, float],
               targets: np.ndarray) -> bytes:
    """Everything the segments from ``v`` to ``targets`` read: grid origin, resolution
    and bounds of the window around them (2 cells of margin), the targets, and the
    ``blocked`` cells in that window."""
    xs = np.append(targets[:, 0], v[0])
    ys = np.append(targets[:, 1], v[1])
    r, c = occ.cell_of(np.asarray([xs.min(), xs.max()]), np.asarray([ys.min(), ys.max()]))
    r0, r1, c0, c1 = int(r[0]) - 2, int(r[1]) + 3, int(c[0]) - 2, int(c[1]) + 3
    h, w = blocked.shape
    cr0, cr1, cc0, cc1 = max(r0, 0), min(r1, h), max(c0, 0), min(c1, w)
    d = hashlib.blake2b(digest_size=16)
    d.update(repr((occ.origin, occ.resolution, (r0, r1, c0, c1), (cr0, cr1, cc0, cc1),
                   v)).encode())
    d.update(np.ascontiguousarray(targets, dtype=np.float64).tobytes())
    if cr0 < cr1 and cc0 < cc1:
        d.update(np.packbits(blocked[cr0:cr1, cc0:cc1], axis=1).tobytes())  # bits: 8x fewer bytes
    return d.digest()


def _visible_nodes(positions: np.ndarray, near_of: dict[tuple[float, float], np.ndarray],
                   occ: OccupancyGrid, blocked: np.ndarray, cache: AssignCache | None
                   ) -> dict[tuple[float, float], np.ndarray]:
    """Per viewpoint: visibility of each of its near nodes (one batched line-of-sight
    test for the viewpoints the cache cannot answer)."""
    out: dict[tuple[float, float], np.ndarray] = {}
    keys: dict[tuple[float, float], bytes] = {}
    todo = []
    for v, nodes in near_of.items():
        if len(nodes) == 0:
            out[v] = np.zeros(0, dtype=bool)
            continue
        if cache is not None:
            keys[v] = _sight_key(occ, blocked, v, positions[nodes])
            got = cache.sight.get(v)
            if got is not None and got[0] == keys[v]:
                out[v] = got[1]
                cache.hits += 1
                continue
            cache.misses += 1
        todo.append(v)
    if todo:
        seg_vp = np.concatenate([np.repeat(np.asarray([v]), len(near_of[v]), axis=0)
                                 for v in todo])
        seg_n = np.concatenate([near_of[v] for v in todo])
        vis = line_of_sight(blocked, occ, seg_vp, positions[seg_n])
        at = 0
        for v in todo:
            m = len(near_of[v])
            out[v] = vis[at:at + m]
            at += m
    if cache is not None:
        cache.sight = {v: (keys[v], out[v]) for v in keys}  # only the viewpoints in use
    return out


def _distance_rows(graph: csr_matrix, sources: np.ndarray, n: int,
                   cache: AssignCache | None, limit: float = np.inf) -> np.ndarray:
    """Dijkstra distances (len(sources), n) from each source (inf beyond ``limit``: the
    search stops there; the distances within it are the unlimited ones, bit for bit),
    rows reused from the cache while the graph is unchanged."""
    if cache is None:
        return dijkstra(graph, directed=False, indices=sources,
                        limit=limit).reshape(len(sources), n)
    key = _graph_key(graph)
    if key != cache.graph_key:
        cache.graph_key, cache.rows = key, {}
    missing = [int(s) for s in sources.tolist() if (int(s), limit) not in cache.rows]
    if missing:
        got = dijkstra(graph, directed=False, indices=np.asarray(missing, dtype=np.int64),
                       limit=limit)
        for s, row in zip(missing, got.reshape(len(missing), n), strict=True):
            cache.rows[(s, limit)] = row
    return np.stack([cache.rows[(int(s), limit)] for s in sources.tolist()])


def _path_terms(graph: csr_matrix, positions: np.ndarray,
                near_of: dict[tuple[float, float], np.ndarray],
                viewpoints: list[tuple[float, float]], n: int, u: float,
                cache: AssignCache | None, limit: float
                ) -> dict[tuple[float, float], np.ndarray]:
    """Per viewpoint vp: min over its nodes v of (d_graph(v, node) + |vp - v|) / u for every
    node (inf where every d_graph is beyond ``limit``)."""
    out: dict[tuple[float, float], np.ndarray] = {}
    if not viewpoints:
        return out
    sources = np.unique(np.concatenate([near_of[v] for v in viewpoints]))
    row_of = np.full(n, -1, dtype=np.int64)
    row_of[sources] = np.arange(len(sources))
    dist = _distance_rows(graph, sources, n, cache, limit)
    for v in viewpoints:
        vs = near_of[v]
        start = np.hypot(positions[vs, 0] - v[0], positions[vs, 1] - v[1])
        out[v] = np.min(dist[row_of[vs]] + start[:, None], axis=0) / u
    return out


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
    for v in distinct:
        near_of[v] = np.asarray(sorted(tree_all.query_ball_point(v, cfg.viewpoint_radius)),
                                dtype=np.int64)
    if cfg.line_of_sight and occ is not None and blocked is not None and distinct:
        vis = _visible_nodes(positions, near_of, occ, blocked, cache)
        for v in distinct:
            if vis[v].any():
                near_of[v] = near_of[v][vis[v]]
    for v in distinct:
        if len(near_of[v]) == 0:
            near_of[v] = np.asarray([int(tree_all.query(v)[1])], dtype=np.int64)
    n = len(positions)
    # path term per distinct viewpoint, first from searches stopped at the limit
    limit = cfg.search_limit
    path_of = _path_terms(graph, positions, near_of, distinct, n, u, cache, limit)
    full_path: dict[tuple[float, float], np.ndarray] = {}
    # candidates: labelled nodes within the radius (a k-d tree proposes, the distance
    # formula of the cost decides), else the nearest labelled node (ties: the lowest id)
    lab_tree = cKDTree(positions[labelled])
    proposals = lab_tree.query_ball_point(objects, cfg.candidate_radius + 1e-6)
    for i in range(k):
        ox, oy = objects[i, 0], objects[i, 1]
        cand = labelled[np.asarray(sorted(proposals[i]), dtype=np.int64)]
        d = np.hypot(ox - positions[cand, 0], oy - positions[cand, 1])
        inside = d <= cfg.candidate_radius
        if inside.any():
            cand, d = cand[inside], d[inside]
        else:
            d_lab = np.hypot(ox - positions[labelled, 0], oy - positions[labelled, 1])
            j = int(np.argmin(d_lab))
            cand, d = labelled[j:j + 1], d_lab[j:j + 1]
        euc = (d / u) ** cfg.exponent
        vp = vp_key[i]
        c = euc + path_of[vp][cand] if vp is not None else euc
        if vp is not None and not c.min() < limit / u:
            # the best may lie beyond the limit: this viewpoint's full search
            if vp not in full_path:
                full_path.update(_path_terms(graph, positions, near_of, [vp], n, u, cache,
                                             np.inf))
            c = euc + full_path[vp][cand]
        j = int(np.argmin(c))  # ties: the lowest node id (cand is sorted)
        if np.isfinite(c[j]):
            node[i], cost[i] = int(cand[j]), float(c[j])
        else:  # no path from the viewpoint: fall back on the nearest candidate
            j = int(np.argmin(euc))
            node[i], cost[i] = int(cand[j]), float(euc[j])
    return Assignment(node, cost)
