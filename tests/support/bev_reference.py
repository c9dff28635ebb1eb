"""The bird's-eye view of a set of voxel keys built from scratch in one go: what the
incremental :class:`~sgtool.mapping.bev.ColumnGrid` is checked against, and a short way
for tests to turn hand-placed voxels into an occupancy grid."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from sgtool.mapping.bev import BevConfig, ColumnGrid, classify_keys, floor_level
from sgtool.mapping.grid import OccupancyGrid
from sgtool.mapping.voxels import unpack


def occupancy_from_keys(keys: np.ndarray, resolution: float, config: BevConfig,
                        trajectory: Sequence[tuple[float, float]] = (),
                        level: int | None = None) -> OccupancyGrid:
    """The BEV of packed voxel ``keys`` (sorted or not) and the robot's ``trajectory``
    (world x, y in m), all added at once; ``level``: the floor's voxel level, estimated
    from the keys' height histogram (:func:`~sgtool.mapping.bev.floor_level`) when None."""
    if level is None:
        lo, hist = 0, np.zeros(0, np.int64)
        if keys.size:
            iz = unpack(keys)[2]
            lo = int(iz.min())
            hist = np.bincount(iz - lo)
        level = floor_level(config, resolution, lo, hist)
    presorted = bool(keys.size < 2 or np.all(keys[1:] >= keys[:-1]))
    grid = ColumnGrid(resolution, config)
    grid.add(classify_keys(keys, level, resolution, config, presorted), trajectory)
    return grid.occupancy(trajectory, level)
