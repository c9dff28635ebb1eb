"""Lengths of paths, for tests that check distances on an occupancy map."""

from __future__ import annotations

import math
from collections.abc import Sequence

from sgtool.mapping.occupancy import OccupancyMap, geodesic_distances, nearest_free_cell


def shortest_path_length(occ: OccupancyMap, a: Sequence[float], b: Sequence[float],
                         max_snap: float = 0.5) -> float:
    """Geodesic distance (m) between world points ``a`` and ``b`` on ``occ`` (each moved to
    its nearest free cell within ``max_snap`` m), ``inf`` when they are not connected."""
    cb = nearest_free_cell(occ, b[0], b[1], max_snap)
    if cb is None:
        return math.inf
    return float(geodesic_distances(occ, a, max_snap)[cb])


def path_length(path: Sequence[Sequence[float]]) -> float:
    """Summed Euclidean length of a polyline (its points' units)."""
    return float(sum(math.dist(path[i], path[i + 1]) for i in range(len(path) - 1)))
