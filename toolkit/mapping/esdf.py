"""Euclidean distance fields of the occupancy grid.

MoMa-LLM (paper sec. III-B, "Voronoi graph") inflates the obstacles of the BEV map with a
Euclidean signed distance field before computing the generalized Voronoi diagram, and
filters Voronoi nodes "in the immediate vicinity of obstacles"; here the Voronoi stage
filters by the clearance this distance field gives (free space only, so the unsigned field
suffices). The robot footprint's inflation of a house map is
:func:`sgtool.mapping.occupancy.inflate`. Both come from
``scipy.ndimage.distance_transform_edt``: the distance from every cell centre to the
nearest obstacle cell centre, and (``return_indices``) which obstacle cell that is (the
*feature transform*, used by :mod:`sgtool.mapping.voronoi` to find the cells equidistant
from two obstacles). Cells outside the grid count as obstacles, so nothing leaks out.
"""

from __future__ import annotations

import numpy as np
from scipy import ndimage

from sgtool.mapping.grid import FREE, OCCUPIED, OccupancyGrid


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
        # scipy's distances from its own features, without its float64 temporaries: the
        # squared offsets are small integers, so the square roots are bit for bit scipy's
        feat = ndimage.distance_transform_edt(padded, return_distances=False,
                                              return_indices=True)
        h, w = padded.shape
        dr = feat[0] - np.arange(h, dtype=feat.dtype)[:, None]
        dc = feat[1] - np.arange(w, dtype=feat.dtype)[None, :]
        dist = np.sqrt((dr * dr + dc * dc).astype(np.float64))
        return dist[1:-1, 1:-1] * resolution, feat[:, 1:-1, 1:-1] - 1
    dist = ndimage.distance_transform_edt(padded)
    return dist[1:-1, 1:-1] * resolution, None
