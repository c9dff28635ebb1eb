"""The two-level vote store equals one sorted array updated by searchsorted + insert."""

from __future__ import annotations

import numpy as np
import pytest

from sgtool.mapping.vote_store import VoteStore, sorted_unique


def _reference_add(keys: np.ndarray, counts: np.ndarray, uk: np.ndarray, cnt: np.ndarray
                   ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The single sorted array the store replaces (the voxel map's old flush)."""
    pos = np.searchsorted(keys, uk)
    found = np.zeros(len(uk), dtype=bool)
    inb = pos < len(keys)
    found[inb] = keys[pos[inb]] == uk[inb]
    counts = counts.copy()
    counts[pos[found]] += cnt[found]
    new = ~found
    return (np.insert(keys, pos[new], uk[new]), np.insert(counts, pos[new], cnt[new]),
            uk[new])


@pytest.mark.parametrize("seed", range(12))
def test_store_matches_single_sorted_array(seed: int) -> None:
    rng = np.random.default_rng(seed)
    # tiny tail limits so the tail is merged often, at different fill levels
    store = VoteStore(min_tail=int(rng.integers(1, 40)), tail_factor=int(rng.integers(1, 64)))
    keys = np.zeros(0, np.int64)
    counts = np.zeros(0, np.int64)
    span = int(rng.integers(50, 3000))
    merges = 0
    for step in range(60):
        uk = np.unique(rng.integers(-span, span, size=int(rng.integers(0, 80))))
        cnt = rng.integers(1, 9, size=len(uk))
        keys, counts, want_new = _reference_add(keys, counts, uk, cnt)
        tail_before = len(store._tail_keys)
        got_new = store.add(uk.astype(np.int64), cnt.astype(np.int64))
        merges += len(store._tail_keys) < tail_before + len(got_new)
        np.testing.assert_array_equal(got_new, want_new)
        assert len(store) == len(keys)
        if step % 7 == 3:  # reading the whole merges the tail; later adds go on from it
            k, c = store.arrays()
            np.testing.assert_array_equal(k, keys)
            np.testing.assert_array_equal(c, counts)
        if step == 30:  # a removal replaces the content
            keep = (keys % 5) != 0
            keys, counts = keys[keep], counts[keep]
            store.replace(keys.copy(), counts.copy())
    k, c = store.arrays()
    np.testing.assert_array_equal(k, keys)
    np.testing.assert_array_equal(c, counts)
    assert merges > 0  # the merge path ran, not only reads


def test_keys_found_in_main_or_tail_get_votes_and_are_not_new() -> None:
    store = VoteStore(min_tail=2, tail_factor=1)
    assert list(store.add(np.array([1, 5, 9]), np.array([1, 1, 1]))) == [1, 5, 9]  # merged
    assert len(store._tail_keys) == 0 and list(store._keys) == [1, 5, 9]
    assert list(store.add(np.array([5, 7]), np.array([2, 3]))) == [7]  # 7 stays in the tail
    assert list(store._tail_keys) == [7]
    assert list(store.add(np.array([1, 7]), np.array([4, 4]))) == []
    k, c = store.arrays()
    assert list(k) == [1, 5, 7, 9] and list(c) == [5, 3, 7, 1]


@pytest.mark.parametrize("seed", range(10))
def test_within_ranges_equals_the_merged_arrays_sliced(seed: int) -> None:
    rng = np.random.default_rng(seed)
    store = VoteStore(min_tail=int(rng.integers(1, 200)), tail_factor=int(rng.integers(1, 64)))
    for _ in range(int(rng.integers(1, 30))):
        uk = np.unique(rng.integers(0, 2000, size=int(rng.integers(1, 60))))
        store.add(uk.astype(np.int64), rng.integers(1, 9, size=len(uk)).astype(np.int64))
    edges = np.unique(rng.integers(0, 2100, size=2 * int(rng.integers(1, 12))))
    if len(edges) % 2:
        edges = edges[:-1]
    lo, hi = edges[0::2].astype(np.int64), edges[1::2].astype(np.int64)
    tail = len(store._tail_keys)
    got_k, got_c = store.within(lo, hi)
    assert len(store._tail_keys) == tail  # read without merging the tail
    keys, counts = store.arrays()
    inside = np.zeros(len(keys), dtype=bool)
    for a, b in zip(lo.tolist(), hi.tolist(), strict=True):
        inside |= (keys >= a) & (keys < b)
    np.testing.assert_array_equal(got_k, keys[inside])
    np.testing.assert_array_equal(got_c, counts[inside])


@pytest.mark.parametrize("n", [0, 1, 2, 50, 3000])
def test_sorted_unique_equals_numpy_unique(n: int) -> None:
    a = np.random.default_rng(n).integers(-(1 << 40), 1 << 40, n) // 1000  # repeats
    a = np.concatenate([a, a[: n // 3]])
    np.testing.assert_array_equal(sorted_unique(a), np.unique(a))
