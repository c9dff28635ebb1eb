"""Shortcuts of the BEV stage equal the plain computation exactly, on randomised inputs:
the trajectory's cell bounds kept from call to call (vs converting every point), the cell
values in one table look-up (vs one masked write per class)."""

from __future__ import annotations

import numpy as np
import pytest

from sgtool.mapping.bev import (
    BevConfig,
    ColumnGrid,
    TrackBox,
    appended,
    cell_values,
    grid_extent,
    track_box,
)
from sgtool.mapping.grid import FREE, OCCUPIED, UNKNOWN

RES = 0.05


def test_appended_points() -> None:
    assert appended([], []) == []
    assert appended([(0.0, 1.0)], [(0.0, 1.0), (2.0, 3.0)]) == [(2.0, 3.0)]
    assert appended([(0.0, 1.0)], [(0.0, 1.0)]) == []
    assert appended([(0.0, 1.0)], [(0.5, 1.0), (2.0, 3.0)]) is None  # another start
    assert appended([(0.0, 1.0), (2.0, 3.0)], [(0.0, 1.0)]) is None  # shorter


@pytest.mark.parametrize("seed", range(10))
def test_track_box_kept_equals_all_points(seed: int) -> None:
    rng = np.random.default_rng(seed)
    kept = TrackBox(RES)
    traj: list[tuple[float, float]] = []
    assert kept.of(traj) is None and track_box(traj, RES) is None
    for step in range(30):
        if step % 11 == 10:  # a new trajectory (not an extension): starts afresh
            traj = traj[:int(rng.integers(0, len(traj) + 1))]
            if traj:
                traj[0] = (traj[0][0] + 1.0, traj[0][1])
        for _ in range(int(rng.integers(0, 5))):
            x, y = traj[-1] if traj else (0.0, 0.0)
            traj.append((x + float(rng.normal(0, 0.3)), y + float(rng.normal(0, 0.3))))
        want = track_box(traj, RES)
        assert kept.of(traj) == want
        if traj:
            t = np.floor(np.asarray(traj) / RES)
            assert want == (int(t[:, 0].min()), int(t[:, 1].min()), int(t[:, 0].max()),
                            int(t[:, 1].max()))


@pytest.mark.parametrize("seed", range(6))
def test_grid_extent_with_kept_bounds_equals_plain(seed: int) -> None:
    rng = np.random.default_rng(seed)
    cfg = BevConfig(margin=int(rng.integers(0, 12)), snap=int(rng.integers(1, 25)))
    cg = ColumnGrid(RES, cfg)
    traj: list[tuple[float, float]] = []
    for _ in range(10):
        traj += [tuple(rng.normal(0, 3, 2).tolist()) for _ in range(int(rng.integers(0, 4)))]
        cols = rng.integers(-300, 300, (int(rng.integers(0, 4)), 2))
        assert cg.fitted_extent([cols], traj) == grid_extent([cols], RES, cfg, traj)


@pytest.mark.parametrize("seed", range(6))
def test_cell_values_equal_masked_writes(seed: int) -> None:
    rng = np.random.default_rng(seed)
    shape = (int(rng.integers(1, 40)), int(rng.integers(1, 40)))
    flags = rng.integers(0, 8, shape).astype(np.uint8)
    stamped = rng.random(shape) < 0.3
    plain = np.full(shape, UNKNOWN, dtype=np.int8)
    plain[(flags & (ColumnGrid.FLOOR | ColumnGrid.CARVED)) != 0] = FREE
    plain[stamped] = FREE
    plain[(flags & ColumnGrid.OCC) != 0] = OCCUPIED
    got = cell_values(flags, stamped)
    assert got.dtype == np.int8 and np.array_equal(got, plain)
