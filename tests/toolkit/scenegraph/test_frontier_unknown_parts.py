"""Frontiers from the hole filling's unknown labelling equal frontiers labelled afresh, and
both equal the plain whole-grid search (``support.frontier_reference``)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import ndimage
from support.frontier_reference import (
    plain_fill_holes,
    plain_frontier_cells,
    plain_frontiers,
    plain_outside,
)

from sgtool.mapping.grid import FREE, OCCUPIED, UNKNOWN, OccupancyGrid
from sgtool.mapping.holes import fill_holes_parts, near, near_at, unknown_parts
from sgtool.scenegraph.frontiers import (
    FrontierConfig,
    eight_components,
    find_frontiers,
)


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


def _summary(frontiers: list) -> list:  # type: ignore[type-arg]
    return [(f.medoid_cell, f.medoid, f.size, f.leading_out, f.cells.tolist())
            for f in frontiers]


@pytest.mark.parametrize("seed", range(60))
def test_parts_of_the_filling_give_the_same_frontiers(seed: int) -> None:
    rng = np.random.default_rng(seed)
    grid = _random_grid(rng)
    max_cells = int(rng.integers(1, 12))
    plain = grid.copy()
    filled = plain_fill_holes(plain, max_cells)
    got, parts = fill_holes_parts(grid, max_cells)
    assert got == filled and np.array_equal(grid, plain)
    assert parts is not None
    assert int(parts.sizes[parts.filled].sum()) == filled
    left = np.where(parts.filled[parts.labels], 0, parts.labels)  # the components left
    fresh, _ = ndimage.label(grid == UNKNOWN, structure=ndimage.generate_binary_structure(2, 1))
    assert _same_partition(left, fresh)
    assert parts.labels.max(initial=0) <= parts.count
    assert np.array_equal(parts.near_occupied, near(grid == OCCUPIED))
    occ = OccupancyGrid(grid, (0.0, 0.0), 0.1)
    free = np.argwhere(grid == FREE)
    start = None if len(free) == 0 or seed % 5 == 0 else tuple(
        (free[int(rng.integers(len(free)))][::-1] + 0.5) * 0.1)
    cfg = FrontierConfig(min_pocket=float(rng.choice([0.0, 0.03, 0.08])), min_size=0.1,
                         max_size=float(rng.choice([0.3, 0.5, 2.5])))
    want = plain_frontiers(occ, start, cfg)
    assert _summary(find_frontiers(occ, start, cfg)) == _summary(want)
    assert _summary(find_frontiers(occ, start, cfg, parts)) == _summary(want)
    # one cell is a frontier's minimum here (min_size = resolution): every frontier cell is
    # in a frontier, and a frontier leads out where a cell touches unknown open to outside
    got_cells = np.zeros(grid.shape, dtype=bool)
    for f in find_frontiers(occ, start, cfg, parts):
        got_cells[f.cells[:, 0], f.cells[:, 1]] = True
        assert f.leading_out == bool(near(plain_outside(occ))[f.cells[:, 0], f.cells[:, 1]].any())
    assert np.array_equal(got_cells, plain_frontier_cells(occ, start, cfg.snap, cfg.min_pocket))


@pytest.mark.parametrize("seed", range(10))
def test_near_at_equals_the_dilation(seed: int) -> None:
    rng = np.random.default_rng(seed)
    mask = rng.random((int(rng.integers(1, 30)), int(rng.integers(1, 30)))) < 0.1
    rows, cols = np.nonzero(rng.random(mask.shape) < 0.5)
    assert np.array_equal(near_at(mask, rows, cols), near(mask)[rows, cols])


def test_every_hole_filled() -> None:
    grid = np.full((5, 5), FREE, dtype=np.int8)
    grid[2, 2] = UNKNOWN
    filled, parts = fill_holes_parts(grid, 4)
    assert parts is not None
    assert filled == 1 and grid[2, 2] == FREE and parts.count == 1
    assert parts.filled.tolist() == [False, True] and parts.sizes[1] == 1
    assert fill_holes_parts(grid, 0) == (0, None)
    assert unknown_parts(grid).count == 0


def test_parts_name_border_components_and_sizes() -> None:
    grid = np.full((6, 8), FREE, dtype=np.int8)
    grid[0, 2:5] = UNKNOWN  # 3 cells on the border
    grid[3:5, 3:5] = UNKNOWN  # 4 enclosed cells
    grid[4, 6] = OCCUPIED
    parts = unknown_parts(grid)
    assert parts.count == 2 and parts.sizes[1:].tolist() == [3, 4]
    assert parts.border.tolist() == [False, True, False]
    assert not parts.filled.any()
    assert parts.near_occupied[3, 5] and not parts.near_occupied[2, 2]


@pytest.mark.parametrize("seed", range(20))
def test_eight_components_equal_the_grid_labelling(seed: int) -> None:
    rng = np.random.default_rng(seed)
    h, w = int(rng.integers(1, 40)), int(rng.integers(1, 40))
    mask = rng.random((h, w)) < float(rng.choice([0.05, 0.2, 0.5]))
    rows, cols = np.nonzero(mask)
    n, of = eight_components(rows, cols, w)
    lab, m = ndimage.label(mask, structure=np.ones((3, 3), dtype=bool))
    assert n == m and of.min(initial=0) >= 0 and of.max(initial=-1) < n
    grid = np.zeros((h, w), dtype=np.int64)
    grid[rows, cols] = of + 1
    assert _same_partition(grid, lab)


@pytest.mark.parametrize("shape", [(0, 0), (0, 5), (5, 0)])
def test_an_empty_grid_has_no_holes_and_no_frontiers(shape: tuple[int, int]) -> None:
    g = np.full(shape, UNKNOWN, np.int8)
    assert fill_holes_parts(g.copy(), 10)[0] == 0 == plain_fill_holes(g.copy(), 10)
    assert unknown_parts(g).count == 0
    assert find_frontiers(OccupancyGrid(g, (0.0, 0.0), 0.05), (0.0, 0.0)) == []
