"""The distance field and ridge cells (step 1 of :mod:`sgtool.mapping.voronoi`) computed over
the whole grid, with no window or bounding box: what the shortcuts of
:mod:`sgtool.mapping.ridge_window` are checked against, cell for cell."""

from __future__ import annotations

import numpy as np

from sgtool.mapping.esdf import distance_field
from sgtool.mapping.ridge_window import ridge_from_fields
from sgtool.mapping.voronoi import VoronoiConfig


def whole_grid_ridge(free: np.ndarray, resolution: float, config: VoronoiConfig
                     ) -> tuple[np.ndarray, np.ndarray]:
    """(ridge cells before thinning, clearance in m of every cell) of the bool grid
    ``free``, the field computed on the whole grid (cells beyond it are obstacles)."""
    dist_m, feat = distance_field(~free, resolution, with_features=True)
    assert feat is not None
    return ridge_from_fields(free, dist_m, feat, resolution, config), dist_m
