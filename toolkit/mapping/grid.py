"""The occupancy grid: the one grid type of sgtool's maps.

An int8 array ``grid[row, col]`` with row = y and col = x; cell (0, 0) has its lower-left
corner at ``origin`` (world x, y) and cells are ``resolution`` metres wide, so the centre of
cell (r, c) is ``origin + ((c + 0.5) * resolution, (r + 0.5) * resolution)``. Values follow
ROS and Foxglove occupancy grids: 0 free, 100 occupied, -1 unknown. The bird's-eye map of a
voxel map (:mod:`sgtool.mapping.bev`) and the rasterised house a simulator or the symbolic
benchmark plans on (:mod:`sgtool.mapping.occupancy`) are both this type. :func:`grid_at`
reads a bool grid (a mask of one) at points given in cells.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

FREE = np.int8(0)
OCCUPIED = np.int8(100)
UNKNOWN = np.int8(-1)


@dataclass(frozen=True, eq=False)
class OccupancyGrid:
    """int8 ``grid[row=y, col=x]`` of FREE / OCCUPIED / UNKNOWN (module doc)."""

    grid: np.ndarray
    origin: tuple[float, float]
    resolution: float
    floor_z: float = 0.0

    @property
    def shape(self) -> tuple[int, int]:
        return int(self.grid.shape[0]), int(self.grid.shape[1])

    @property
    def free(self) -> np.ndarray:
        return self.grid == FREE

    @property
    def occupied(self) -> np.ndarray:
        return self.grid == OCCUPIED

    @property
    def unknown(self) -> np.ndarray:
        return self.grid == UNKNOWN

    def cell_of(self, x: np.ndarray | float, y: np.ndarray | float
                ) -> tuple[np.ndarray, np.ndarray]:
        """(row, col) of world points (may be out of bounds)."""
        c = np.floor((np.asarray(x, dtype=np.float64) - self.origin[0]) / self.resolution)
        r = np.floor((np.asarray(y, dtype=np.float64) - self.origin[1]) / self.resolution)
        return r.astype(np.int64), c.astype(np.int64)

    def center_of(self, rows: np.ndarray | int, cols: np.ndarray | int
                  ) -> tuple[np.ndarray, np.ndarray]:
        """World (x, y) of cell centres."""
        x = self.origin[0] + (np.asarray(cols, dtype=np.float64) + 0.5) * self.resolution
        y = self.origin[1] + (np.asarray(rows, dtype=np.float64) + 0.5) * self.resolution
        return x, y

    def inside(self, rows: np.ndarray, cols: np.ndarray) -> np.ndarray:
        h, w = self.shape
        return (rows >= 0) & (rows < h) & (cols >= 0) & (cols < w)

    def value_at(self, x: float, y: float) -> int:
        r, c = self.cell_of(x, y)
        if not self.inside(r, c):
            return int(UNKNOWN)
        return int(self.grid[r, c])


def grid_at(points: np.ndarray, grid: np.ndarray, origin: tuple[int, int] = (0, 0)
            ) -> np.ndarray:
    """Per (column, row) point (N, 2; rounded to its cell): the bool ``grid``'s cell
    (False off the grid), ``grid``'s cell (0, 0) being cell ``origin`` (row, col)."""
    c = np.round(points[:, 0]).astype(np.int64) - origin[1]
    r = np.round(points[:, 1]).astype(np.int64) - origin[0]
    h, w = grid.shape
    ok = (r >= 0) & (r < h) & (c >= 0) & (c < w)
    out = np.zeros(len(points), dtype=bool)
    out[ok] = grid[r[ok], c[ok]]
    return out
