"""Regions of a room: places on the Voronoi graph that group nearby objects.

SCOUT's third layer holds regions and frontiers; SymSearch (sec. V-B) clusters a room's
object positions with a Gaussian mixture whose component count is chosen by BIC. A room
being explored may hold no object yet, and every region must be a place the robot can go,
so we cluster the room's Voronoi nodes instead: k-means (:mod:`sgtool.scenegraph.kmeans`)
on node positions with ``k = clamp(round(graph length / region_length), 1, max_regions)``,
initialised deterministically (the room centre node, then farthest-point), with the
region's position the node closest to its cluster mean (a real, reachable node). An
object's region is the region of the node it was assigned to
(:mod:`sgtool.scenegraph.assign`), so regions and objects agree.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from sgtool.scenegraph.kmeans import kmeans, planar_distances


@dataclass(frozen=True)
class RegionConfig:
    region_length: float = 4.0  # m of Voronoi edges per region
    max_regions: int = 4
    iterations: int = 20


@dataclass(frozen=True, eq=False)
class Regions:
    labels: np.ndarray  # (k,) region index of each of the room's nodes
    centres: np.ndarray  # (r,) index (into the room's nodes) of each region's centre node


def cluster_room(positions: np.ndarray, length: float, centre: int,
                 config: RegionConfig | None = None) -> Regions:
    """Regions of one room: ``positions`` (k, 2) of its nodes, ``length`` (m) of its
    edges, ``centre`` the index of its centre node among them."""
    cfg = config or RegionConfig()
    k = len(positions)
    if k == 0:
        return Regions(np.zeros(0, np.int64), np.zeros(0, np.int64))
    r = int(min(max(1, round(length / cfg.region_length)), cfg.max_regions, k))
    labels, means = kmeans(positions, r, centre, metric=planar_distances,
                           iterations=cfg.iterations)
    centres = np.zeros(r, dtype=np.int64)
    keep = []
    for c in range(r):
        members = np.flatnonzero(labels == c)
        if len(members) == 0:
            continue
        dm = np.hypot(*(positions[members] - means[c]).T)
        centres[c] = int(members[int(np.argmin(dm))])
        keep.append(c)
    # renumber non-empty clusters in order of their centre node (stable naming)
    keep.sort(key=lambda c: int(centres[c]))
    remap = np.full(r, -1, dtype=np.int64)
    for i, c in enumerate(keep):
        remap[c] = i
    return Regions(remap[labels], centres[keep])
