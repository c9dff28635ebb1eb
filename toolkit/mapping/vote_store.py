"""The voxel map's sorted (key, vote count) arrays, kept in two sorted levels.

Inserting a few thousand new keys into one sorted array of millions (``np.insert``) copies
the whole array every time: at 30 rooms that was most of a refresh's BEV stage. New keys
go into a small sorted **tail** instead; the tail is merged into the **main** array only
when it outgrows ``max(min_tail, sqrt(tail_factor * len(main)))`` entries, so a merge of
the big array happens every few dozen flushes and an insert copies only the tail.

Main and tail never share a key. :meth:`VoteStore.arrays` merges the tail first and gives
the one sorted array with its counts: exactly what a single array updated by
``searchsorted`` + ``insert`` at every flush would hold (tested against that).
"""

from __future__ import annotations

import math

import numpy as np

_EMPTY = np.zeros(0, dtype=np.int64)


def drain_keys(parts: list[np.ndarray]) -> np.ndarray:
    """The concatenated ``parts`` (int64 keys), the list emptied."""
    out = np.concatenate(parts) if parts else np.zeros(0, dtype=np.int64)
    parts.clear()
    return out


def _member(keys: np.ndarray, uk: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(insertion positions of ``uk`` in sorted ``keys``, which of ``uk`` are in it)."""
    pos = np.searchsorted(keys, uk)
    found = np.zeros(len(uk), dtype=bool)
    inb = pos < len(keys)
    found[inb] = keys[pos[inb]] == uk[inb]
    return pos, found


def spans(lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """The indices ``lo[0]..hi[0]-1, lo[1]..hi[1]-1, ...`` in one array (empty spans
    allowed)."""
    n = np.maximum(hi - lo, 0)
    total = int(n.sum())
    if total == 0:
        return np.zeros(0, dtype=np.int64)
    return np.repeat(lo - (np.cumsum(n) - n), n) + np.arange(total, dtype=np.int64)


def sorted_unique(a: np.ndarray) -> np.ndarray:
    """The distinct values of int64 ``a``, sorted (``np.unique`` without its overhead:
    one sort and one comparison)."""
    if len(a) < 2:
        return np.sort(a)
    s = np.sort(a)
    return s[np.concatenate([[True], s[1:] != s[:-1]])]


class VoteStore:
    """Distinct sorted int64 keys with int64 vote counts (module doc)."""

    def __init__(self, min_tail: int = 1 << 16, tail_factor: int = 1 << 13) -> None:
        self.min_tail = min_tail
        self.tail_factor = tail_factor
        self._keys, self._counts = _EMPTY, _EMPTY
        self._tail_keys, self._tail_counts = _EMPTY, _EMPTY

    def __len__(self) -> int:
        return len(self._keys) + len(self._tail_keys)

    def add(self, uk: np.ndarray, cnt: np.ndarray) -> np.ndarray:
        """Add ``cnt`` votes to the sorted distinct keys ``uk``; returns the keys that were
        not in the store (sorted)."""
        pos, found = _member(self._keys, uk)
        self._counts[pos[found]] += cnt[found]
        if found.all():
            return _EMPTY
        rest = ~found
        uk, cnt = uk[rest], cnt[rest]
        pos, found = _member(self._tail_keys, uk)
        self._tail_counts[pos[found]] += cnt[found]
        new = ~found
        nk = uk[new]
        if len(nk):
            self._tail_keys = np.insert(self._tail_keys, pos[new], nk)
            self._tail_counts = np.insert(self._tail_counts, pos[new], cnt[new])
            limit = max(self.min_tail, math.isqrt(self.tail_factor * len(self._keys)))
            if len(self._tail_keys) > limit:
                self._merge()
        return nk

    def arrays(self) -> tuple[np.ndarray, np.ndarray]:
        """(sorted keys, counts) of everything, the tail merged in."""
        self._merge()
        return self._keys, self._counts

    def within(self, lo: np.ndarray, hi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(sorted keys, counts) of the entries with ``lo[i] <= key < hi[i]`` for some i
        (sorted, disjoint ranges), read from both levels without merging the tail: the
        same entries :meth:`arrays` holds in those ranges."""
        parts = []
        for keys, counts in ((self._keys, self._counts),
                             (self._tail_keys, self._tail_counts)):
            if len(keys):
                idx = spans(np.searchsorted(keys, lo), np.searchsorted(keys, hi))
                parts.append((keys[idx], counts[idx]))
        if not parts:
            return _EMPTY, _EMPTY
        if len(parts) == 1:
            return parts[0]
        keys = np.concatenate([p[0] for p in parts])
        counts = np.concatenate([p[1] for p in parts])
        order = np.argsort(keys, kind="stable")  # main and tail never share a key
        return keys[order], counts[order]

    def replace(self, keys: np.ndarray, counts: np.ndarray) -> None:
        """Set the whole content (sorted distinct ``keys``), e.g. after a removal."""
        self._keys, self._counts = keys, counts
        self._tail_keys, self._tail_counts = _EMPTY, _EMPTY

    def _merge(self) -> None:
        if not len(self._tail_keys):
            return
        pos = np.searchsorted(self._keys, self._tail_keys)
        self._keys = np.insert(self._keys, pos, self._tail_keys)
        self._counts = np.insert(self._counts, pos, self._tail_counts)
        self._tail_keys, self._tail_counts = _EMPTY, _EMPTY
