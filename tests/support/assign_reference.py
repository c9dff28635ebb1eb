"""The plain form of object assignment (:mod:`sgtool.scenegraph.assign`), one object at a
time, as it was written before the vectorised and cached paths: what the tests compare
those against, bit for bit."""

from __future__ import annotations

import numpy as np
from scipy.sparse import csr_matrix
from scipy.sparse.csgraph import dijkstra
from scipy.spatial import cKDTree

from sgtool.mapping.bev import line_of_sight
from sgtool.mapping.grid import OccupancyGrid
from sgtool.scenegraph.assign import AssignConfig


def reference_assignment(positions: np.ndarray, node_room: np.ndarray, graph: csr_matrix,
                         objects: np.ndarray, viewpoints: np.ndarray,
                         occ: OccupancyGrid | None = None, blocked: np.ndarray | None = None,
                         config: AssignConfig | None = None) -> tuple[np.ndarray, np.ndarray]:
    """(node, cost) per object: the module doc's cost, unlimited searches, a loop."""
    cfg = config or AssignConfig()
    k = len(objects)
    node = np.full(k, -1, dtype=np.int64)
    cost = np.full(k, np.inf)
    labelled = np.flatnonzero(node_room >= 0)
    if k == 0 or len(labelled) == 0:
        return node, cost
    u = cfg.unit
    tree = cKDTree(positions)
    n = len(positions)
    for i in range(k):
        ox, oy = objects[i, 0], objects[i, 1]
        d_lab = np.hypot(ox - positions[labelled, 0], oy - positions[labelled, 1])
        inside = d_lab <= cfg.candidate_radius
        if inside.any():
            cand, d = labelled[inside], d_lab[inside]
        else:
            j = int(np.argmin(d_lab))
            cand, d = labelled[j:j + 1], d_lab[j:j + 1]
        euc = (d / u) ** cfg.exponent
        c = euc
        if np.all(np.isfinite(viewpoints[i])):
            v = (float(viewpoints[i][0]), float(viewpoints[i][1]))
            near = np.asarray(sorted(tree.query_ball_point(v, cfg.viewpoint_radius)),
                              dtype=np.int64)
            if cfg.line_of_sight and occ is not None and blocked is not None and len(near):
                vis = line_of_sight(blocked, occ, np.repeat(np.asarray([v]), len(near), axis=0),
                                    positions[near])
                if vis.any():
                    near = near[vis]
            if len(near) == 0:
                near = np.asarray([int(tree.query(v)[1])], dtype=np.int64)
            dist = dijkstra(graph, directed=False, indices=near).reshape(len(near), n)
            start = np.hypot(positions[near, 0] - v[0], positions[near, 1] - v[1])
            path = np.min(dist + start[:, None], axis=0) / u
            c = euc + path[cand]
        j = int(np.argmin(c))
        if np.isfinite(c[j]):
            node[i], cost[i] = int(cand[j]), float(c[j])
        else:
            j = int(np.argmin(euc))
            node[i], cost[i] = int(cand[j]), float(euc[j])
    return node, cost
