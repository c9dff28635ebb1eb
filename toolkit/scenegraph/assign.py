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
graph (hundreds of nodes), not an all-pairs table.
"""

from __future__ import annotations

from dataclasses import dataclass

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


@dataclass(frozen=True)
class Assignment:
    node: np.ndarray  # (k,) chosen node per object, -1 when there is no labelled node
    cost: np.ndarray  # (k,)


def assign_objects(positions: np.ndarray, node_room: np.ndarray, graph: csr_matrix,
                   objects: np.ndarray, viewpoints: np.ndarray,
                   occ: OccupancyGrid | None = None, blocked: np.ndarray | None = None,
                   config: AssignConfig | None = None) -> Assignment:
    """Node (hence room) of every object. ``positions`` (n, 2) node positions,
    ``node_room`` (n,) room index or -1, ``graph`` the sparse graph (m), ``objects`` (k, 2)
    object positions, ``viewpoints`` (k, 2) closest viewpoints (NaN: unknown);
    ``occ``/``blocked`` give line of sight (occupied cells) when given."""
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
    # those visible from it when any is (one batched line-of-sight test)
    vp_key = [None if not np.all(np.isfinite(viewpoints[i])) else
              (float(viewpoints[i][0]), float(viewpoints[i][1])) for i in range(k)]
    distinct = sorted({v for v in vp_key if v is not None})
    near_of: dict[tuple[float, float], np.ndarray] = {}
    for v in distinct:
        near_of[v] = np.asarray(sorted(tree_all.query_ball_point(v, cfg.viewpoint_radius)),
                                dtype=np.int64)
    if cfg.line_of_sight and occ is not None and blocked is not None and distinct:
        seg_vp = np.concatenate([np.repeat(np.asarray([v]), len(near_of[v]), axis=0)
                                 for v in distinct] or [np.zeros((0, 2))])
        seg_n = np.concatenate([near_of[v] for v in distinct])
        vis = line_of_sight(blocked, occ, seg_vp, positions[seg_n]) if len(seg_n) else \
            np.zeros(0, bool)
        at = 0
        for v in distinct:
            m = len(near_of[v])
            sel = vis[at:at + m]
            if sel.any():
                near_of[v] = near_of[v][sel]
            at += m
    for v in distinct:
        if len(near_of[v]) == 0:
            near_of[v] = np.asarray([int(tree_all.query(v)[1])], dtype=np.int64)
    n = len(positions)
    # path term per distinct viewpoint: min over its nodes v of d_graph(v, n) + |vp - v|
    path_of: dict[tuple[float, float], np.ndarray] = {}
    if distinct:
        sources = np.unique(np.concatenate([near_of[v] for v in distinct]))
        row_of = np.full(n, -1, dtype=np.int64)
        row_of[sources] = np.arange(len(sources))
        dist = dijkstra(graph, directed=False, indices=sources).reshape(len(sources), n)
        for v in distinct:
            vs = near_of[v]
            start = np.hypot(positions[vs, 0] - v[0], positions[vs, 1] - v[1])
            path_of[v] = np.min(dist[row_of[vs]] + start[:, None], axis=0) / u
    # Euclidean term and candidates for all objects at once (objects x nodes)
    d_on = np.hypot(objects[:, None, 0] - positions[None, :, 0],
                    objects[:, None, 1] - positions[None, :, 1])
    is_lab = node_room >= 0
    euc_all = (d_on / u) ** cfg.exponent
    for i in range(k):
        cand_mask = is_lab & (d_on[i] <= cfg.candidate_radius)
        if not cand_mask.any():  # nearest labelled node (ties: the lowest id)
            cand_mask = np.zeros(n, dtype=bool)
            cand_mask[labelled[int(np.argmin(d_on[i, labelled]))]] = True
        cand = np.flatnonzero(cand_mask)
        euc = euc_all[i, cand]
        c = euc + path_of[vp_key[i]][cand] if vp_key[i] is not None else euc
        j = int(np.argmin(c))  # ties: the lowest node id (cand is sorted)
        if np.isfinite(c[j]):
            node[i], cost[i] = int(cand[j]), float(c[j])
        else:  # no path from the viewpoint: fall back on the nearest candidate
            j = int(np.argmin(euc))
            node[i], cost[i] = int(cand[j]), float(euc[j])
    return Assignment(node, cost)
