"""The near depth of a depth image written plainly (a padded sliding-window minimum): what
:meth:`sgtool.mapping.free_space.View.of` (repeated 3 x 3 minima) is checked against."""

from __future__ import annotations

import numpy as np
from numpy.lib.stride_tricks import sliding_window_view


def near_depth(depth: np.ndarray, min_range: float, radius: int) -> np.ndarray:
    """The smallest depth of each pixel's (2 ``radius`` + 1)^2 neighbourhood (float32), 0
    where any of them has no valid depth (below ``min_range``, not finite); beyond the
    image border the border's pixels repeat."""
    d = np.asarray(depth, dtype=np.float32)
    valid = np.where(np.isfinite(d) & (d >= min_range), d, np.float32(0.0))
    padded = np.pad(valid, radius, mode="edge")
    size = 2 * radius + 1
    return sliding_window_view(padded, (size, size)).min(axis=(2, 3))
