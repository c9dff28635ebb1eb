"""Room categories from the objects a room contains.

SCOUT infers room categories "from the objects they contain" (sec. IV-A); MoMa-LLM asks an
LLM with the room's object list (paper Fig. 3; 27.6% room category accuracy in
simulation). Any object with ``classify(object_categories) -> [(room type, probability),
...]`` best first (empty for an empty room) is a :class:`RoomClassifier`; the learned
:class:`sgtool.semantics.room_classification.ContainmentRoomClassifier` is one.

:class:`FrequencyRoomClassifier` is the transparent one: multinomial naive Bayes over a
table ``room type -> {object category: count}``,

    log P(r | o_1..o_k) = log P(r) + sum_i log (c(r, o_i) + alpha) / (N_r + alpha |V|) + const

with Laplace smoothing ``alpha``, vocabulary V (categories in the table), N_r the total
count of room type r, and a uniform prior by default (houses need not follow the table's
room-type frequencies). Categories outside V carry no evidence and are skipped.
Categories are compared after :func:`sgtool.semantics.text.category_text` ("Bottom_cabinet"
= "bottom cabinet"). ``sgtool.datasets.room_evidence.frequency_room_classifier`` builds the
table from the training part of the BEHAVIOR-1K knowledge only (never the evaluation part
that furnishes benchmark houses). A room none of whose categories is in V gets the
``fallback`` classifier's answer (none: unknown).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Protocol, runtime_checkable

from sgtool.semantics.text import category_text


@runtime_checkable
class RoomClassifier(Protocol):
    def classify(self, object_categories: list[str]) -> list[tuple[str, float]]:
        """[(room type, probability)] best first; [] when nothing can be said."""
        ...


class FrequencyRoomClassifier:
    """Naive Bayes over a room-type x category count table (module doc)."""

    name = "frequency"

    def __init__(self, table: Mapping[str, Mapping[str, float]], alpha: float = 1.0,
                 prior: Mapping[str, float] | None = None,
                 fallback: RoomClassifier | None = None) -> None:
        if not table:
            raise ValueError("the room-type table is empty")
        if alpha <= 0:
            raise ValueError("alpha must be > 0")
        self.fallback = fallback
        counts: dict[str, dict[str, float]] = {}
        for room, row in table.items():
            acc: dict[str, float] = {}
            for cat, c in row.items():
                if c < 0:
                    raise ValueError(f"negative count for {room!r}/{cat!r}")
                key = category_text(cat)
                acc[key] = acc.get(key, 0.0) + float(c)
            counts[room] = acc
        self.room_types = tuple(sorted(counts))
        self.vocabulary = frozenset(c for row in counts.values() for c in row)
        v = len(self.vocabulary)
        self._log_p: dict[str, dict[str, float]] = {}
        self._log_unseen: dict[str, float] = {}
        for room in self.room_types:
            row = counts[room]
            denom = sum(row.values()) + alpha * v
            self._log_p[room] = {c: math.log((n + alpha) / denom) for c, n in row.items()}
            self._log_unseen[room] = math.log(alpha / denom)
        if prior is None:
            self._log_prior = {r: 0.0 for r in self.room_types}
        else:
            tot = sum(max(prior.get(r, 0.0), 0.0) for r in self.room_types)
            if tot <= 0:
                raise ValueError("prior has no mass on the table's room types")
            self._log_prior = {r: math.log(max(prior.get(r, 0.0), 1e-12) / tot)
                               for r in self.room_types}

    def classify(self, object_categories: list[str]) -> list[tuple[str, float]]:
        cats = [c for c in (category_text(x) for x in object_categories) if c in self.vocabulary]
        if not cats:
            return self.fallback.classify(object_categories) if self.fallback else []
        score = {}
        for r in self.room_types:
            lp, lu = self._log_p[r], self._log_unseen[r]
            score[r] = self._log_prior[r] + sum(lp.get(c, lu) for c in cats)
        top = max(score.values())
        z = sum(math.exp(s - top) for s in score.values())
        ranked = sorted(((r, math.exp(s - top) / z) for r, s in score.items()),
                        key=lambda rp: (-rp[1], rp[0]))
        return ranked
