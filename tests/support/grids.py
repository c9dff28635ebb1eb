"""Small hand-built occupancy grids for the mapping and scene-graph parameter tests."""

from __future__ import annotations

import numpy as np

from sgtool.mapping.grid import FREE, OCCUPIED, UNKNOWN


def walled(rows: int, cols: int) -> np.ndarray:
    """``rows`` x ``cols`` free cells inside a 2-cell wall, 2 cells of unknown around it;
    free cell (i, j) is grid cell (4 + i, 4 + j)."""
    g = np.full((rows + 8, cols + 8), UNKNOWN, dtype=np.int8)
    g[2:-2, 2:-2] = OCCUPIED
    g[4:-4, 4:-4] = FREE
    return g
