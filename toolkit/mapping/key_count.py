"""Distinct int64 keys with their occurrences: ``np.unique(keys, return_counts=True)``
without its overhead (pure functions; the result is exactly ``np.unique``'s).

A frame's voxel keys come in pixel order, where neighbouring pixels mostly fall into the
same voxel: runs of equal keys are collapsed first, and only the runs are sorted. The
run lengths travel with their keys inside the sort: a frame's keys span a small range
(a few metres of voxels), so ``key - min`` leaves the low bits of a uint64 free for the
run length, and one plain value sort (much cheaper than an ``argsort`` and a gather)
orders both. A frame whose keys or runs do not fit sorts all its keys instead.
"""

from __future__ import annotations

import numpy as np


def run_starts(keys: np.ndarray) -> np.ndarray:
    """First index of each run of equal neighbours in ``keys`` (non-empty)."""
    change = np.empty(keys.size, dtype=bool)
    change[0] = True
    np.not_equal(keys[1:], keys[:-1], out=change[1:])
    return np.flatnonzero(change)


def runs(keys: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(first index, length) of each run of equal neighbours in ``keys`` (non-empty)."""
    first = run_starts(keys)
    length = np.empty_like(first)
    np.subtract(first[1:], first[:-1], out=length[:-1])
    length[-1] = keys.size - first[-1]
    return first, length


def count_sorted(keys: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(sorted distinct keys, occurrences) by sorting all of ``keys``."""
    if keys.size == 0:
        return keys, np.zeros(0, dtype=np.int64)
    keys = np.sort(keys)
    first, length = runs(keys)
    return keys[first], length


def count_keys(keys: np.ndarray, drop: int | None = None) -> tuple[np.ndarray, np.ndarray]:
    """(sorted distinct keys, occurrences) of int64 ``keys`` (module doc), leaving out the
    value ``drop`` when given (it marks points the caller discards)."""
    if keys.size == 0:
        return keys, np.zeros(0, dtype=np.int64)
    first, length = runs(keys)
    rk = keys[first]
    if drop is not None:
        keep = rk != drop
        if not keep.all():
            rk, length = rk[keep], length[keep]
            if rk.size == 0:
                return rk, length
    lo = int(rk.min())
    bits = int(length.max()).bit_length()
    if int(rk.max()) - lo >= 1 << (64 - bits):  # the run lengths do not fit beside the keys
        return count_sorted(keys if drop is None else keys[keys != drop])
    shift = np.uint64(bits)
    packed = np.subtract(rk, lo).view(np.uint64)  # exact: 0 <= key - lo < 2**(64 - bits)
    np.left_shift(packed, shift, out=packed)
    np.bitwise_or(packed, length.view(np.uint64), out=packed)
    packed.sort()
    rel = packed >> shift
    starts = run_starts(rel)
    np.bitwise_and(packed, np.uint64((1 << bits) - 1), out=packed)
    counts = np.add.reduceat(packed.view(np.int64), starts)
    out = rel[starts].view(np.int64)
    np.add(out, lo, out=out)
    return out, counts
