"""The windowed update of the ridge stage (:mod:`sgtool.mapping.ridge_window`) equals the
computation over the whole grid, cell for cell: distances, nearest obstacles (scipy's
choice among ties included) and ridge cells, along random sequences of local changes of
the free space (rooms being explored: free cells appear, furniture and walls are seen,
a door opens), and the ridge graph built from the previous one equals a fresh one."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import ndimage
from support.ridge_reference import whole_grid_ridge

from sgtool.mapping.grid import FREE, OCCUPIED, UNKNOWN, OccupancyGrid
from sgtool.mapping.ridge_window import ridge_fields, update_fields
from sgtool.mapping.voronoi import VoronoiConfig, ridge_graph

RES = 0.05
CFG = VoronoiConfig()


def rooms(rng: np.random.Generator, h: int, w: int) -> np.ndarray:
    """Free rectangles (rooms, corridors) with obstacles inside, in unknown space."""
    free = np.zeros((h, w), dtype=bool)
    for _ in range(int(rng.integers(2, 6))):
        r0, c0 = int(rng.integers(0, h - 8)), int(rng.integers(0, w - 8))
        free[r0:r0 + int(rng.integers(6, 40)), c0:c0 + int(rng.integers(6, 40))] = True
    return free


def local_change(free: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """A change where the camera looked: a free patch appears, an obstacle is seen, or
    a wall line (with a gap) crosses a small area."""
    out = free.copy()
    h, w = free.shape
    r0, c0 = int(rng.integers(0, h - 4)), int(rng.integers(0, w - 4))
    dh, dw = int(rng.integers(2, 25)), int(rng.integers(2, 25))
    kind = rng.random()
    if kind < 0.5:
        out[r0:r0 + dh, c0:c0 + dw] = True
    elif kind < 0.8:
        out[r0:r0 + min(dh, 6), c0:c0 + min(dw, 6)] = False
    else:
        out[r0, c0:c0 + dw] = False
        out[r0, c0 + dw // 2:c0 + dw // 2 + 3] = True
    return out


def assert_whole_grid(fields, free: np.ndarray) -> None:  # noqa: ANN001
    padded = np.pad(free, 1, constant_values=False)
    ref_feat = ndimage.distance_transform_edt(padded, return_distances=False,
                                              return_indices=True)[:, 1:-1, 1:-1] - 1
    ref_ridge, ref_dist = whole_grid_ridge(free, RES, CFG)
    assert np.array_equal(fields.free, free)
    assert np.array_equal(fields.feat, ref_feat)
    assert np.array_equal(fields.dist_m, ref_dist)
    assert np.array_equal(fields.ridge0, ref_ridge)


@pytest.mark.parametrize("seed", range(12))
def test_windowed_fields_equal_the_whole_grid(seed: int) -> None:
    rng = np.random.default_rng(seed)
    h, w = int(rng.integers(50, 110)), int(rng.integers(50, 140))
    free = rooms(rng, h, w)
    fields = ridge_fields(free, RES, CFG)
    assert_whole_grid(fields, free)
    windowed = 0
    for _ in range(10):
        free = local_change(free, rng)
        got = update_fields(fields, free, RES, CFG)
        if got is None:  # the window would be the whole grid
            got = ridge_fields(free, RES, CFG)
        else:
            windowed += 1
        assert_whole_grid(got, free)
        fields = got
    assert windowed >= 3 and fields.ridge0.any()


def test_unchanged_free_cells_reuse_the_fields_and_other_shapes_start_over() -> None:
    free = rooms(np.random.default_rng(5), 60, 80)
    fields = ridge_fields(free, RES, CFG)
    assert update_fields(fields, free.copy(), RES, CFG) is fields
    assert update_fields(fields, np.pad(free, ((0, 20), (0, 0))), RES, CFG) is None
    assert update_fields(fields, free, 2 * RES, CFG) is None


@pytest.mark.parametrize("seed", range(4))
def test_ridge_graph_from_the_previous_equals_a_fresh_one(seed: int) -> None:
    rng = np.random.default_rng(100 + seed)
    free = rooms(rng, 90, 120)
    grid = np.where(free, FREE, UNKNOWN).astype(np.int8)
    prev = None
    for _ in range(6):
        occ = OccupancyGrid(grid.copy(), (0.0, 0.0), RES)
        got = ridge_graph(occ, CFG, previous=prev)
        fresh = ridge_graph(occ, CFG)
        assert np.array_equal(got.ridge, fresh.ridge)
        assert np.array_equal(got.clearance, fresh.clearance)
        assert np.array_equal(got.flat, fresh.flat)
        assert np.array_equal(got.component, fresh.component)
        for part in ("indptr", "indices", "data"):
            assert np.array_equal(getattr(got.adj, part), getattr(fresh.adj, part))
        prev = got
        free = local_change(free, rng)
        grid = np.where(free, FREE, np.where(rng.random(free.shape) < 0.5, OCCUPIED, UNKNOWN)
                        ).astype(np.int8)
    assert len(prev.flat) > 0  # type: ignore[union-attr]
