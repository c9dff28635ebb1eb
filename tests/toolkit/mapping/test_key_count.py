"""Counting a frame's voxel keys: exactly ``np.unique(keys, return_counts=True)``."""

from __future__ import annotations

import numpy as np
import pytest

from sgtool.mapping.key_count import count_keys, count_sorted, runs


def _reference(keys: np.ndarray, drop: int | None = None) -> tuple[np.ndarray, np.ndarray]:
    if drop is not None:
        keys = keys[keys != drop]
    return np.unique(keys, return_counts=True)


def _frame_like(rng: np.random.Generator, n: int, span: int, base: int) -> np.ndarray:
    """Keys in runs of random length (neighbouring pixels in one voxel), from a range."""
    values = base + rng.integers(0, span, size=n // 3 + 1, dtype=np.int64)
    reps = rng.integers(1, 6, size=values.size)
    return np.repeat(values, reps)[:n]


@pytest.mark.parametrize("seed", range(20))
def test_counts_equal_unique_on_runs_of_keys(seed: int) -> None:
    rng = np.random.default_rng(seed)
    keys = _frame_like(rng, int(rng.integers(1, 5000)), int(rng.integers(1, 1 << 40)),
                       int(rng.integers(0, 1 << 60)))
    got, cnt = count_keys(keys)
    ref, rcnt = _reference(keys)
    np.testing.assert_array_equal(got, ref)
    np.testing.assert_array_equal(cnt, rcnt)
    assert got.dtype == np.int64 and cnt.dtype == np.int64
    assert int(cnt.sum()) == keys.size


def test_wide_range_falls_back_to_a_full_sort() -> None:
    # keys spanning almost all of int64: no bits are left for the run lengths
    keys = np.array([5, 5, 5, (1 << 62) + 3, 0, (1 << 62) + 3, 5, -(1 << 62), 0],
                    dtype=np.int64)
    got, cnt = count_keys(keys)
    assert got.tolist() == [-(1 << 62), 0, 5, (1 << 62) + 3]
    assert cnt.tolist() == [1, 2, 4, 2]
    got2, cnt2 = count_keys(keys, drop=5)
    assert got2.tolist() == [-(1 << 62), 0, (1 << 62) + 3]
    assert cnt2.tolist() == [1, 2, 2]


def test_one_long_run_and_its_length_bits() -> None:
    keys = np.full(70_000, 123_456_789, dtype=np.int64)
    keys[-1] = 7
    got, cnt = count_keys(keys)
    assert got.tolist() == [7, 123_456_789]
    assert cnt.tolist() == [1, 69_999]


@pytest.mark.parametrize("seed", range(10))
def test_dropped_value_is_left_out(seed: int) -> None:
    rng = np.random.default_rng(100 + seed)
    drop = (1 << 63) - 1
    keys = _frame_like(rng, 3000, 1 << 20, 1 << 50)
    bad = rng.random(keys.size) < 0.1
    keys[bad] = drop
    got, cnt = count_keys(keys, drop=drop)
    ref, rcnt = _reference(keys, drop)
    np.testing.assert_array_equal(got, ref)
    np.testing.assert_array_equal(cnt, rcnt)
    assert int(cnt.sum()) == int((~bad).sum())


def test_empty_and_all_dropped() -> None:
    empty = np.zeros(0, dtype=np.int64)
    got, cnt = count_keys(empty)
    assert got.size == 0 and cnt.size == 0
    got, cnt = count_keys(np.full(4, 9, dtype=np.int64), drop=9)
    assert got.size == 0 and cnt.size == 0
    got, cnt = count_sorted(empty)
    assert got.size == 0 and cnt.size == 0


def test_runs_of_neighbours() -> None:
    first, length = runs(np.array([3, 3, 1, 1, 1, 3], dtype=np.int64))
    assert first.tolist() == [0, 2, 5]
    assert length.tolist() == [2, 3, 1]
