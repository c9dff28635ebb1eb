"""Pairing by time: the stamp of one stream nearest to another's, within a tolerance (a
bag's colour and id images to its depth images, a TUM folder's colour images to its depth
images)."""

from __future__ import annotations

import bisect
from collections.abc import Sequence


class NearestStamp:
    """``near(t, max_dt)``: the index (into ``stamps``) of the stamp nearest ``t`` within
    ``max_dt``, else None; the stamps are sorted once, for one query per frame."""

    def __init__(self, stamps: Sequence[int]) -> None:
        self.order = sorted(range(len(stamps)), key=lambda i: stamps[i])
        self.sorted = [stamps[i] for i in self.order]

    def __call__(self, t: int, max_dt: int) -> int | None:
        j = bisect.bisect_left(self.sorted, t)
        best = None
        for jj in (j - 1, j):
            if 0 <= jj < len(self.sorted):
                d = abs(self.sorted[jj] - t)
                if d <= max_dt and (best is None or d < best[0]):
                    best = (d, self.order[jj])
        return None if best is None else best[1]
