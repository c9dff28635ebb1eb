"""Column flags updated after a removal equal a column grid rebuilt from scratch."""

from __future__ import annotations

import numpy as np
import pytest

from sgtool.mapping.bev import BevConfig, ColumnGrid, classify_keys
from sgtool.mapping.column_update import column_runs, fresh_extent, reclassify_columns
from sgtool.mapping.voxels import COLUMN_SHIFT, LABEL_MASK, pack

RES = 0.05
LEVEL = 0


def _keys(rng: np.random.Generator, n: int, span: int, labels: int) -> np.ndarray:
    ix = rng.integers(-span, span, n)
    iy = rng.integers(-span, span, n)
    iz = rng.integers(-2, 40, n)  # floor (<= 2), band (3..32), above the band
    return pack(ix, iy, iz, rng.integers(0, labels, n))


def _built(keys: np.ndarray, trajectory: list[tuple[float, float]],
           carve: ColumnGrid, cfg: BevConfig) -> ColumnGrid:
    """The builder's rebuild: a fresh grid of every key, the carved grid merged in."""
    cg = ColumnGrid(RES, cfg)
    cg.add(classify_keys(keys, LEVEL, RES, cfg, presorted=True), trajectory)
    cg.merge(carve)
    return cg


@pytest.mark.parametrize("seed", range(30))
def test_reclassified_columns_equal_a_rebuild(seed: int) -> None:
    rng = np.random.default_rng(seed)
    cfg = BevConfig(margin=int(rng.integers(0, 4)), snap=int(rng.integers(1, 6)))
    span = int(rng.integers(4, 30))
    labels = int(rng.integers(2, 6))
    carve = ColumnGrid(RES, cfg)
    fans = np.array([[0.0, 0.0, rng.uniform(-0.5, 0.5), rng.uniform(-0.5, 0.5), 0.0]])
    carve.carve(fans, LEVEL)
    trajectory = [(0.0, 0.0)]
    keys = np.unique(_keys(rng, int(rng.integers(5, 400)), span, labels))
    cg = _built(keys, trajectory, carve, cfg)
    for _ in range(4):  # new keys, then one label's keys dropped (a door that opened)
        new = np.setdiff1d(np.unique(_keys(rng, int(rng.integers(0, 80)), span, labels)),
                           keys)
        trajectory = trajectory + [(float(rng.uniform(-0.3, 0.3)), 0.1)]
        keys = np.union1d(keys, new)
        gone_label = int(rng.integers(1, labels))
        gone = keys[(keys & LABEL_MASK) == gone_label]
        keys = keys[(keys & LABEL_MASK) != gone_label]
        cg.add(classify_keys(new, LEVEL, RES, cfg), trajectory)
        ok = reclassify_columns(cg, keys, np.unique(gone >> COLUMN_SHIFT), LEVEL)
        cg.merge(carve)
        want = _built(keys, trajectory, carve, cfg)
        if ok and fresh_extent(cg, trajectory, carve) == cg.extent:
            assert cg.extent == want.extent
            np.testing.assert_array_equal(cg.flags, want.flags)
        else:
            assert cg.extent != want.extent  # the only reason to rebuild
            cg = want


def test_fresh_extent_sees_a_shrunk_grid() -> None:
    cfg = BevConfig(margin=0, snap=1)
    far = pack(np.array([0, 50]), np.array([0, 0]), np.array([5, 5]), np.array([1, 2]))
    cg = ColumnGrid(RES, cfg)
    cg.add(classify_keys(far, LEVEL, RES, cfg, presorted=True), [(0.0, 0.0)])
    assert cg.extent == (0, 0, 50, 0)
    assert reclassify_columns(cg, far[:1], np.unique(far[1:] >> COLUMN_SHIFT), LEVEL)
    assert cg.flags[0, 50] == 0 and cg.flags[0, 0] == ColumnGrid.OCC
    assert fresh_extent(cg, [(0.0, 0.0)], None) == (0, 0, 0, 0)


def test_column_runs_gathers_whole_columns_in_key_order() -> None:
    keys = np.sort(pack(np.array([0, 0, 1, 2, 2]), np.zeros(5, np.int64),
                        np.array([1, 3, 1, 1, 9]), 0))
    cols = np.unique(keys >> COLUMN_SHIFT)
    assert list(column_runs(keys, cols[[0, 2]])) == [0, 1, 3, 4]
    assert list(column_runs(keys, cols[[1]])) == [2]
    assert len(column_runs(keys, np.zeros(0, np.int64))) == 0
