"""Stable frontier ids across refreshes: a frontier keeps the id of the previous one whose
medoid is nearest within a radius (greedy, nearest pair first); the others take new ids."""

from __future__ import annotations

import math
from dataclasses import dataclass, field


@dataclass
class FrontierTracker:
    next_id: int = 0
    known: list[tuple[int, tuple[float, float]]] = field(default_factory=list)

    def assign(self, medoids: list[tuple[float, float]], radius: float) -> list[int]:
        pairs = []
        for i, (x, y) in enumerate(medoids):
            for fid, (ox, oy) in self.known:
                d = math.hypot(x - ox, y - oy)
                if d <= radius:
                    pairs.append((d, fid, i))
        pairs.sort()
        out: list[int | None] = [None] * len(medoids)
        used: set[int] = set()
        for _d, fid, i in pairs:
            if out[i] is None and fid not in used:
                out[i] = fid
                used.add(fid)
        result = []
        for i in range(len(medoids)):
            r = out[i]
            if r is None:
                r = self.next_id
                self.next_id += 1
            result.append(r)
        self.known = list(zip(result, medoids, strict=True))
        return result
