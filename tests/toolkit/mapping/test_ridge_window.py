"""Shortcuts of the Voronoi ridge stage equal the plain computation bit for bit: the
distance field from scipy's feature transform alone, and the ridge computed from scratch on
the free cells' bounding box (plus one cell, :func:`sgtool.mapping.ridge_window.ridge_fields`)
instead of the whole grid (``support.ridge_reference``)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import ndimage
from support.ridge_reference import whole_grid_ridge

from sgtool.mapping.esdf import distance_field
from sgtool.mapping.ridge_window import ridge_fields
from sgtool.mapping.voronoi import VoronoiConfig

RES = 0.05


def random_free(seed: int) -> np.ndarray:
    """Rooms and corridors (free rectangles) with furniture (obstacle blocks) in a grid
    with an unknown margin; odd seeds let the free space touch the grid's border."""
    rng = np.random.default_rng(seed)
    h, w = (int(v) for v in rng.integers(40, 120, 2))
    free = np.zeros((h, w), dtype=bool)
    lo = 0 if seed % 2 else 5
    for _ in range(int(rng.integers(2, 7))):
        r0, c0 = rng.integers(lo, h - 10), rng.integers(lo, w - 10)
        free[r0:r0 + rng.integers(6, 40), c0:c0 + rng.integers(6, 40)] = True
    if not seed % 2:
        free[:5], free[-5:], free[:, :5], free[:, -5:] = False, False, False, False
    for _ in range(int(rng.integers(0, 10))):
        r0, c0 = rng.integers(0, h - 3), rng.integers(0, w - 3)
        free[r0:r0 + rng.integers(1, 4), c0:c0 + rng.integers(1, 4)] = False
    return free


@pytest.mark.parametrize("seed", range(16))
def test_distance_field_equals_scipy(seed: int) -> None:
    obstacle = ~random_free(seed)
    dist, feat = distance_field(obstacle, RES, with_features=True)
    padded = np.pad(~obstacle, 1, constant_values=False)
    ref_d, ref_f = ndimage.distance_transform_edt(padded, return_indices=True)
    assert np.array_equal(dist, ref_d[1:-1, 1:-1] * RES)
    assert np.array_equal(feat, ref_f[:, 1:-1, 1:-1] - 1)


@pytest.mark.parametrize("seed", range(16))
def test_ridge_on_the_free_box_equals_the_whole_grid(seed: int) -> None:
    free = random_free(seed)
    cfg = VoronoiConfig()
    fields = ridge_fields(free, RES, cfg)
    ref_ridge, ref_dist = whole_grid_ridge(free, RES, cfg)
    assert np.array_equal(fields.ridge0, ref_ridge) and np.array_equal(fields.dist_m, ref_dist)
    assert fields.ridge0.any()  # rooms wide enough to have a centre line


def test_no_free_cell_no_ridge() -> None:
    fields = ridge_fields(np.zeros((5, 7), dtype=bool), RES, VoronoiConfig())
    ridge, dist = fields.ridge0, fields.dist_m
    assert ridge.shape == dist.shape == (5, 7) and not ridge.any() and not dist.any()
