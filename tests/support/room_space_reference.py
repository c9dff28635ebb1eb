"""The definition that :class:`sgtool.datasets.room_space.RoomSpace` keeps incrementally."""

from __future__ import annotations

import numpy as np
from scipy import ndimage

from sgtool.datasets.robot_clearance import ROBOT_RADIUS


def free_mask_edt(occ: np.ndarray, cell: float) -> np.ndarray:
    """The free cells of an in-room occupancy grid (``cell`` metres per cell): those whose
    centre is at least ROBOT_RADIUS + half a cell from every occupied cell and from the walls
    around the grid, by the Euclidean distance transform of the padded grid."""
    padded = np.pad(occ, 1, constant_values=True)  # the walls
    dist = ndimage.distance_transform_edt(~padded, sampling=cell)[1:-1, 1:-1]
    return dist >= ROBOT_RADIUS + cell / 2 - 1e-9
