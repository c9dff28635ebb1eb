"""How much of a house's floor a robot's map holds (the report of ``sgtool record
--explore frontier``; ground truth, used for scoring only, never by the robot).

The floor is the set of cells of :func:`sgtool.mapping.occupancy.house_occupancy` (robot
radius 0) that are inside a room and under no wall, closed door or piece of furniture;
a floor cell is *seen* when the cell of the robot's bird's-eye grid holding its centre is
known (free or occupied).
"""

from __future__ import annotations

import numpy as np

from sgtool.house.spec import HouseSpec
from sgtool.mapping.grid import UNKNOWN, OccupancyGrid
from sgtool.mapping.occupancy import house_occupancy


def floor_points(spec: HouseSpec, resolution: float = 0.1) -> np.ndarray:
    """World (x, y) of the centres of the house's floor cells, (n, 2)."""
    occ = house_occupancy(spec, resolution, robot_radius=0.0, closed_doors_free=True)
    rows, cols = np.nonzero(~occ.occupied)
    x, y = occ.grid.center_of(rows, cols)
    return np.stack([x, y], axis=1)


def coverage(grid: OccupancyGrid, floor: np.ndarray) -> float:
    """Share (0..1) of the ``floor`` points whose cell of ``grid`` is known."""
    if len(floor) == 0:
        return 0.0
    r, c = grid.cell_of(floor[:, 0], floor[:, 1])
    inside = grid.inside(r, c)
    known = np.zeros(len(floor), bool)
    known[inside] = grid.grid[r[inside], c[inside]] != UNKNOWN
    return float(known.mean())
