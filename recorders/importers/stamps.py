"""Pairing by time: the stamp of one stream nearest to another's, within a tolerance (a
bag's colour and id images to its depth images, a TUM folder's colour images to its depth
images)."""

from __future__ import annotations

import bisect


def nearest_within(stamps: list[int], order: list[int], t: int, max_dt: int) -> int | None:
    """Index (into ``stamps``) of the stamp nearest ``t`` within ``max_dt``; ``order`` is
    the argsort of ``stamps``."""
    if not stamps:
        return None
    sorted_t = [stamps[i] for i in order]
    j = bisect.bisect_left(sorted_t, t)
    best = None
    for jj in (j - 1, j):
        if 0 <= jj < len(sorted_t):
            d = abs(sorted_t[jj] - t)
            if d <= max_dt and (best is None or d < best[0]):
                best = (d, order[jj])
    return None if best is None else best[1]


