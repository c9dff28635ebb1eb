"""Euclidean distance fields of the occupancy grid and obstacle inflation.

MoMa-LLM (paper sec. III-B, "Voronoi graph") inflates the obstacles of the BEV map with a
Euclidean signed distance field before computing the generalized Voronoi diagram, and
filters Voronoi nodes "in the immediate vicinity of obstacles". Both come from
``scipy.ndimage.distance_transform_edt``: the distance from every cell centre to the
nearest obstacle cell centre, and (``return_indices``) which obstacle cell that is (the
*feature transform*, used by :mod:`sgtool.mapping.voronoi` to find the cells equidistant
from two obstacles). Cells outside the grid count as obstacles, so nothing leaks out.
"""

from __future__ import annotations

import numpy as np
from scipy import ndimage

from sgtool.mapping.bev import FREE, OCCUPIED, OccupancyGrid, disk


def obstacles(occ: OccupancyGrid, unknown_is_obstacle: bool = True) -> np.ndarray:
    """Boolean obstacle mask: occupied cells (and unknown ones, by default: the Voronoi
    graph lives in *explored* free space)."""
    return occ.grid != FREE if unknown_is_obstacle else occ.grid == OCCUPIED


def distance_field(obstacle: np.ndarray, resolution: float, with_features: bool = False
                   ) -> tuple[np.ndarray, np.ndarray | None]:
    """Distance (m) from each cell to the nearest obstacle cell (0 on obstacles), and with
    ``with_features`` the (2, H, W) row/col indices of that obstacle cell (-1 .. H/W for the
    virtual obstacle border around the grid)."""
    padded = np.pad(~obstacle, 1, constant_values=False)
    if with_features:
        dist, feat = ndimage.distance_transform_edt(padded, return_indices=True)
        return dist[1:-1, 1:-1] * resolution, feat[:, 1:-1, 1:-1] - 1
    dist = ndimage.distance_transform_edt(padded)
    return dist[1:-1, 1:-1] * resolution, None


def signed_distance(obstacle: np.ndarray, resolution: float) -> np.ndarray:
    """ESDF (m): positive in free space (distance to the nearest obstacle), negative inside
    obstacles (minus the distance to the nearest free cell)."""
    outside, _ = distance_field(obstacle, resolution)
    if obstacle.all():
        return -np.full(obstacle.shape, np.inf)
    inside = ndimage.distance_transform_edt(obstacle) * resolution
    return np.where(obstacle, -inside, outside)


def inflate(obstacle: np.ndarray, radius: float, resolution: float) -> np.ndarray:
    """Obstacles grown by ``radius`` m: a cell is blocked when its centre is within
    ``radius`` of an obstacle cell centre."""
    r = int(np.floor(radius / resolution + 1e-9))
    if r <= 0:
        return obstacle.copy()
    return ndimage.binary_dilation(obstacle, structure=disk(r))
