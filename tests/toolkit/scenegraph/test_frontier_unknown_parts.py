"""Frontiers from the hole filling's unknown labelling equal frontiers labelled afresh."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import ndimage

from sgtool.mapping.bev import fill_holes, fill_holes_parts
from sgtool.mapping.grid import FREE, OCCUPIED, UNKNOWN, OccupancyGrid
from sgtool.scenegraph.frontiers import FrontierConfig, find_frontiers


def _random_grid(rng: np.random.Generator) -> np.ndarray:
    """Free rooms with walls, unknown blobs of all sizes (holes, pockets, outside)."""
    h, w = int(rng.integers(20, 70)), int(rng.integers(20, 70))
    grid = np.full((h, w), UNKNOWN, dtype=np.int8)
    for _ in range(int(rng.integers(2, 7))):  # free rectangles
        r, c = int(rng.integers(0, h - 5)), int(rng.integers(0, w - 5))
        grid[r:r + int(rng.integers(4, 30)), c:c + int(rng.integers(4, 30))] = FREE
    grid[rng.random((h, w)) < 0.04] = OCCUPIED
    grid[rng.random((h, w)) < 0.03] = UNKNOWN  # one-cell holes
    for _ in range(int(rng.integers(0, 6))):  # bigger unknown patches
        r, c = int(rng.integers(0, h - 2)), int(rng.integers(0, w - 2))
        grid[r:r + int(rng.integers(1, 5)), c:c + int(rng.integers(1, 5))] = UNKNOWN
    return grid


def _same_partition(a: np.ndarray, b: np.ndarray) -> bool:
    """Same cells labelled 0 and the same grouping of the others (numbering aside)."""
    if not np.array_equal(a == 0, b == 0):
        return False
    pairs = np.unique(np.stack([a[a > 0], b[b > 0]], axis=1), axis=0)
    return len(np.unique(pairs[:, 0])) == len(pairs) == len(np.unique(pairs[:, 1]))


@pytest.mark.parametrize("seed", range(40))
def test_parts_of_the_filling_give_the_same_frontiers(seed: int) -> None:
    rng = np.random.default_rng(seed)
    grid = _random_grid(rng)
    max_cells = int(rng.integers(1, 12))
    plain = grid.copy()
    filled = fill_holes(plain, max_cells)
    got, parts = fill_holes_parts(grid, max_cells)
    assert got == filled and np.array_equal(grid, plain)
    assert parts is not None
    lab, n = parts
    fresh, _ = ndimage.label(grid == UNKNOWN, structure=ndimage.generate_binary_structure(2, 1))
    assert _same_partition(lab, fresh)
    assert lab.max(initial=0) <= n
    occ = OccupancyGrid(grid, (0.0, 0.0), 0.1)
    free = np.argwhere(grid == FREE)
    start = None if len(free) == 0 or seed % 5 == 0 else tuple(
        (free[int(rng.integers(len(free)))][::-1] + 0.5) * 0.1)
    cfg = FrontierConfig(min_pocket=float(rng.choice([0.0, 0.03, 0.08])), min_size=0.1,
                         max_size=float(rng.choice([0.5, 2.5])))
    want = find_frontiers(occ, start, cfg)
    have = find_frontiers(occ, start, cfg, parts)
    assert [(f.medoid_cell, f.size, f.leading_out) for f in have] == \
        [(f.medoid_cell, f.size, f.leading_out) for f in want]
    for f, g in zip(have, want, strict=True):
        np.testing.assert_array_equal(f.cells, g.cells)


def test_every_hole_filled_leaves_no_labels() -> None:
    grid = np.full((5, 5), FREE, dtype=np.int8)
    grid[2, 2] = UNKNOWN
    filled, (lab, n) = fill_holes_parts(grid, 4)
    assert filled == 1 and grid[2, 2] == FREE and n == 1 and not lab.any()
    assert fill_holes_parts(grid, 0) == (0, None)
