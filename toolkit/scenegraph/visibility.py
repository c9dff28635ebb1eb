"""Voronoi nodes seen from points: the nodes within a radius with a clear line of sight
(else the nearest node), used for the robot's entry nodes and a frontier's node."""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

from sgtool.mapping.bev import line_of_sight
from sgtool.mapping.grid import OccupancyGrid
from sgtool.mapping.voronoi import VoronoiGraph


def visible_near(vg: VoronoiGraph, cand: np.ndarray, points: list[tuple[float, float]],
                 occ: OccupancyGrid, blocked: np.ndarray, radius: float) -> list[np.ndarray]:
    """Per point: the candidate nodes within ``radius`` visible from it, else the nearest
    candidate (one batched line-of-sight test for all points)."""
    pos = vg.positions
    if len(cand) == 0 or not points:
        return [np.zeros(0, dtype=np.int64) for _ in points]
    tree = cKDTree(pos[cand])
    near = [cand[np.asarray(sorted(tree.query_ball_point(p, radius)), dtype=np.int64)]
            for p in points]
    a = np.concatenate([np.repeat(np.asarray([p]), len(n), axis=0)
                        for p, n in zip(points, near, strict=True)] or [np.zeros((0, 2))])
    idx = np.concatenate(near) if near else np.zeros(0, dtype=np.int64)
    vis = line_of_sight(blocked, occ, a, pos[idx]) if len(idx) else np.zeros(0, bool)
    out = []
    at = 0
    for p, n in zip(points, near, strict=True):
        sel = vis[at:at + len(n)]
        at += len(n)
        if sel.any():
            out.append(n[sel])
        else:
            out.append(np.asarray([int(cand[int(tree.query(p)[1])])], dtype=np.int64))
    return out


def entry_nodes(vg: VoronoiGraph, xy: tuple[float, float], occ: OccupancyGrid,
                blocked: np.ndarray, radius: float) -> np.ndarray:
    """Visible nodes within ``radius`` of ``xy`` (else the nearest node)."""
    return visible_near(vg, np.arange(len(vg.positions)), [xy], occ, blocked, radius)[0]


def nearest_visible(vg: VoronoiGraph, cand: np.ndarray, points: list[tuple[float, float]],
                    occ: OccupancyGrid, blocked: np.ndarray, radius: float) -> list[int]:
    """Per point: the nearest visible candidate node (see :func:`visible_near`), -1
    without candidates."""
    out = []
    for p, e in zip(points, visible_near(vg, cand, points, occ, blocked, radius), strict=True):
        if len(e) == 0:
            out.append(-1)
            continue
        d = np.hypot(vg.positions[e, 0] - p[0], vg.positions[e, 1] - p[1])
        out.append(int(e[int(np.lexsort((e, d))[0])]))
    return out
