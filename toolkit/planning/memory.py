"""What a planner remembers within an episode: targets it has finished with or failed on.

A well-built scene graph marks an opened container ``explored`` and drops an explored
frontier, so a planner would not pick them again. Graphs built from real logs lag behind
(the container is opened but nothing new is in view yet) and executors fail (an unreachable
handle). Without memory a utility planner then selects the same best node forever. The
memory keys a node by its id *and* position, because frontier ids are re-issued when the
map is rebuilt: a new frontier that reuses an old id somewhere else is a new node.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from sgtool.planning.base import Feedback
from sgtool.planning.candidates import Candidate, CandidateColumns

SAME_PLACE_M = 0.5  # a node within this distance of a remembered one with the same id is it


@dataclass
class EpisodeMemory:
    """Targets finished (success) or failed (failure/invalid) in the current episode."""

    max_failures: int = 2
    finished: dict[str, tuple[float, float]] = field(default_factory=dict)
    failures: dict[str, list[tuple[float, float]]] = field(default_factory=dict)
    _last_position: dict[str, tuple[float, float]] = field(default_factory=dict)

    def reset(self) -> None:
        self.finished.clear()
        self.failures.clear()
        self._last_position.clear()

    def offered(self, candidates: list[Candidate]) -> None:
        """Remember where the candidates of this decision were (to key the feedback)."""
        for c in candidates:
            self._last_position[c.node_id] = c.position

    def record(self, fb: Feedback) -> None:
        target = fb.action.target
        if target is None or fb.action.skill == "done":
            return
        pos = self._last_position.get(target, (math.nan, math.nan))
        if fb.outcome == "success":
            if fb.action.skill in ("open", "explore", "navigate"):
                self.finished[target] = pos
        else:
            self.failures.setdefault(target, []).append(pos)

    def excluded(self, c: Candidate) -> bool:
        return self._excluded(c.node_id, c.position)

    def _excluded(self, node_id: str, position: tuple[float, float]) -> bool:
        def near(p: tuple[float, float]) -> bool:
            if math.isnan(p[0]):
                return True  # position unknown: trust the id
            return math.hypot(p[0] - position[0], p[1] - position[1]) <= SAME_PLACE_M

        if node_id in self.finished and near(self.finished[node_id]):
            return True
        fails = [p for p in self.failures.get(node_id, []) if near(p)]
        return len(fails) >= self.max_failures

    def filter(self, candidates: list[Candidate]) -> list[Candidate]:
        finished, failures = self.finished, self.failures
        if not finished and not failures:
            return list(candidates)
        return [c for c in candidates
                if not ((c.node_id in finished or c.node_id in failures) and self.excluded(c))]

    def filter_columns(self, cols: CandidateColumns) -> CandidateColumns:
        """:meth:`filter` of columns (the same object when nothing is left out)."""
        finished, failures = self.finished, self.failures
        if not finished and not failures:
            return cols
        pos = cols.positions
        keep = [k for k, i in enumerate(cols.ids)
                if not ((i in finished or i in failures) and self._excluded(i, pos[k]))]
        return cols if len(keep) == len(cols.ids) else cols.take(keep)

    def offered_columns(self, cols: CandidateColumns) -> None:
        """:meth:`offered` of columns."""
        self._last_position.update(zip(cols.ids, cols.positions, strict=True))
