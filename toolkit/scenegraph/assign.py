"""Objects to rooms by MoMa-LLM's weighted travel distance, so nothing is assigned through a
wall.

MoMa-LLM (paper sec. III-B, Eq. 2; exact form from NOTES): for an object o seen from its
closest viewpoint vp, the candidate nodes are the Voronoi nodes within 2.5 m of o, the
viewpoint nodes those within 5 m of vp, and

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

from sgtool.mapping.bev import OccupancyGrid, line_of_sight


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
    tree_lab = cKDTree(positions[labelled])
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
    vp_nodes = [near_of[v] if v is not None else np.zeros(0, dtype=np.int64) for v in vp_key]
    sources = np.unique(np.concatenate([v for v in vp_nodes if len(v)] or
                                       [np.zeros(0, np.int64)]))
    row_of = {int(s): j for j, s in enumerate(sources.tolist())}
    dist = dijkstra(graph, directed=False, indices=sources) if len(sources) else None
    for i in range(k):
        o = objects[i]
        cand = labelled[np.asarray(sorted(tree_lab.query_ball_point(o, cfg.candidate_radius)),
                                   dtype=np.int64)]
        if len(cand) == 0:
            cand = labelled[[int(tree_lab.query(o)[1])]]
        euc = (np.hypot(positions[cand, 0] - o[0], positions[cand, 1] - o[1]) / u) ** cfg.exponent
        vs = vp_nodes[i]
        if len(vs) and dist is not None:
            vp = viewpoints[i]
            start = np.hypot(positions[vs, 0] - vp[0], positions[vs, 1] - vp[1]) / u
            rows = dist[[row_of[int(v)] for v in vs]][:, cand] / u  # (|vs|, |cand|)
            path = np.min(rows + start[:, None], axis=0)
            c = path + euc
        else:
            c = euc
        j = int(np.argmin(c))  # ties: the lowest node id (cand is sorted)
        if np.isfinite(c[j]):
            node[i] = int(cand[j])
            cost[i] = float(c[j])
        else:  # no path from the viewpoint: fall back on the nearest candidate
            j = int(np.argmin(euc))
            node[i] = int(cand[j])
            cost[i] = float(euc[j])
    return Assignment(node, cost)
