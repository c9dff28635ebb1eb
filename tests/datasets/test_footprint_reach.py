"""The windowed reach mask of a piece is the whole-grid formula, cell for cell: rotated
boxes, boxes on the grid's edge and off it, cells exactly ``reach`` from a face."""

from __future__ import annotations

import math

import numpy as np
import pytest

from sgtool.datasets.footprint_reach import full_mask, near_footprint
from sgtool.house.spec import Furniture
from sgtool.mapping.raster import cell_centers


class _Grid:
    """A bare grid: 8 m x 6 m at 5 cm, origin (-1, -2)."""

    origin = (-1.0, -2.0)
    resolution = 0.05
    shape = (120, 160)


def whole_grid(X: np.ndarray, Y: np.ndarray, f: Furniture, reach: float) -> np.ndarray:
    """The formula on every cell (what the episode code computed before the window)."""
    c, s = math.cos(f.yaw), math.sin(f.yaw)
    dx, dy = X - f.center[0], Y - f.center[1]
    lx, ly = c * dx + s * dy, -s * dx + c * dy
    ex = np.maximum(np.abs(lx) - f.size[0] / 2, 0.0)
    ey = np.maximum(np.abs(ly) - f.size[1] / 2, 0.0)
    return ex ** 2 + ey ** 2 <= reach ** 2


def piece(x: float, y: float, yaw: float, sx: float = 0.8, sy: float = 0.5) -> Furniture:
    return Furniture(id="f", category="table", synset="table.n.02", room="r",
                     center=(x, y, 0.4), size=(sx, sy, 0.8), yaw=yaw)


@pytest.mark.parametrize("reach", [1.0, 0.8, 0.05])
def test_window_mask_is_the_whole_grid_formula(reach: float) -> None:
    grid = _Grid()
    X, Y = cell_centers(grid)
    rng = np.random.default_rng(7)
    pieces = [piece(float(rng.uniform(-2, 8)), float(rng.uniform(-3, 5)),
                    float(rng.uniform(-math.pi, math.pi)), float(rng.uniform(0.1, 2.0)),
                    float(rng.uniform(0.1, 2.0))) for _ in range(60)]
    # axis-aligned, with faces on cell centres: cells exactly `reach` away
    pieces += [piece(1.025, 0.975, 0.0, 0.5, 0.3), piece(-0.975, -1.975, 0.0),
               piece(6.975, 3.975, math.pi / 2), piece(20.0, 20.0, 0.3)]
    inside = 0
    for f in pieces:
        want = whole_grid(X, Y, f, reach)
        near = near_footprint(grid, X, Y, f, reach)
        assert np.array_equal(full_mask(grid.shape, near), want)
        inside += int(want.sum())
        if near is not None:  # the window is small: the point of it
            assert near[1].size < X.size
    assert inside > 1000


def test_off_the_grid_is_none() -> None:
    grid = _Grid()
    X, Y = cell_centers(grid)
    assert near_footprint(grid, X, Y, piece(40.0, 40.0, 0.0), 1.0) is None
    assert not full_mask(grid.shape, None).any()
