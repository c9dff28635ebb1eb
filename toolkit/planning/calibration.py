"""Prior scores as probabilities, and open-vocabulary blending by distance to the training data.

**Calibration.** The distilled scores (SCOUT Eqs. 10-11) are trained as binary relations with
a cross-entropy loss, so they are read as P(relation | names), but two corrections make them
usable as the likelihoods of a search distribution:

    p = floor + (1 - floor) * s ** sharpness                                         (C1)

- ``floor`` > 0: a place the model rules out is not impossible (the models err on unseen
  queries: their AUC is in the weights' ``report``); without a floor a Bayes posterior
  never recovers from a prior of 0;
- ``sharpness`` (1 = as trained) tempers (< 1) or sharpens (> 1) an over- or
  under-confident model.

**Blending by novelty.** For a query far from the training vocabulary the learned models
extrapolate; the sentence-encoder cosine (Eqs. 14-15) may degrade more gracefully. With
``sim(q) = max_t cos(E(q), E(t))`` over the training queries t (the weights' metadata
``training_queries``),

    lambda(q) = clip((sim(q) - lo) / (hi - lo), 0, 1)                                (C2)
    s(n, q)   = lambda(q) * s_learned(n, q) + (1 - lambda(q)) * s_cos'(n, q)          (C3)

where ``s_cos' = clip((cos - cos_lo) / (cos_hi - cos_lo), 0, 1)`` maps the cosine (whose
useful range for name pairs is about 0.1-0.6) onto [0, 1]. A query in the training set has
sim = 1 and keeps the learned scores unchanged. Without ``training_queries`` in the
metadata there is no training-like set to measure against (the room types are rooms, not
queries), so lambda = 1: no blending rather than a wrong one.

**Blend only where the cosine is the better judge** (``gate``, default on). Whether the
cosine extrapolates better than the learned model is a measurable fact of each set of
weights: ``sgtool distill`` reports, per relation, the ROC-AUC of both on query categories
never seen in training (the weights' ``report.unseen``). Relation x is blended by (C3) only
when

    AUC_cos(x) > AUC_learned(x)                                                      (C4)

and is the learned model unchanged otherwise (weights without a report keep (C3)). The
measurements behind the gate (AUC per similarity bin, the search with and without the
blend) are in docs/experiments/moved-from-docstrings.md; the everyday-object check set
(:mod:`sgtool.semantics.everyday_rooms`, names outside BEHAVIOR-1K) is checked by
``benchmarks/priors_check.py``.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from sgtool.semantics.encoder import SentenceEncoder
from sgtool.semantics.priors import RelationScorer, can_score_room
from sgtool.semantics.text import category_text


def calibrate(scores: np.ndarray | float, floor: float, sharpness: float = 1.0
              ) -> np.ndarray:
    """(C1): ``floor + (1 - floor) * clip(s, 0, 1) ** sharpness``."""
    s = np.clip(np.asarray(scores, dtype=np.float64), 0.0, 1.0)
    return floor + (1.0 - floor) * s ** sharpness


def novelty_weight(similarity: float, lo: float, hi: float) -> float:
    """(C2): weight of the learned scores for a query whose best training match is
    ``similarity``."""
    if hi <= lo:
        return 1.0 if similarity >= hi else 0.0
    return float(np.clip((similarity - lo) / (hi - lo), 0.0, 1.0))


RELATIONS = ("containment", "cooccurrence")


def blended_relations(report: object) -> frozenset[str]:
    """The relations (C3) applies to under the gate (C4): those whose held-out ROC-AUC in
    ``report["unseen"]`` (the weights' quality report) is higher for the cosine than for
    the learned model; every relation when there is no such report."""
    unseen = report.get("unseen") if isinstance(report, dict) else None
    if not isinstance(unseen, dict):
        return frozenset(RELATIONS)
    out = set()
    for rel in RELATIONS:
        try:
            learned = float(unseen[rel]["learned"]["auc"])
            cos = float(unseen[rel]["cosine"]["auc"])
        except (KeyError, TypeError, ValueError):
            out.add(rel)  # nothing measured: keep the distance blend
            continue
        if cos > learned:
            out.add(rel)
    return frozenset(out)


@dataclass(frozen=True)
class BlendParams:
    lo: float = 0.55  # at or below this best-match cosine: cosine scores only
    hi: float = 0.85  # at or above: learned scores only
    cos_lo: float = 0.1
    cos_hi: float = 0.6
    gate: bool = True  # (C4): blend a relation only where the held-out AUC favours cosine


class BlendedPriors:
    """A :class:`~sgtool.semantics.priors.RelationScorer` that blends learned and cosine
    scores by the query's distance to the training queries, (C2)-(C3)."""

    def __init__(self, learned: RelationScorer, cosine: RelationScorer,
                 training_queries: Sequence[str] | None, encoder: SentenceEncoder | None,
                 params: BlendParams = BlendParams()) -> None:
        self.name = f"blend({learned.name},{cosine.name})"
        self.learned = learned
        self.cosine = cosine
        self.params = params
        self._training = [category_text(q) for q in training_queries or ()]
        self._encoder = encoder
        self._train_vecs: np.ndarray | None = None
        self._weights: dict[str, float] = {}
        report = getattr(learned, "metadata", {}).get("report") if params.gate else None
        self.blended_relations = blended_relations(report)

    def blends(self, relation: str) -> bool:
        """Whether ``relation`` (containment or cooccurrence) is blended at all, (C4)."""
        return relation in self.blended_relations

    def can_score_room(self, name: str) -> bool:
        return can_score_room(self.learned, name)

    @property
    def room_types(self) -> tuple[str, ...]:
        return tuple(getattr(self.learned, "room_types", ()))

    def learned_weight(self, query: str) -> float:
        """lambda(q) of (C2), memoised per query."""
        q = category_text(query)
        if q not in self._weights:
            if not self._training or self._encoder is None:
                self._weights[q] = 1.0
            elif q in set(self._training):
                self._weights[q] = 1.0
            else:
                if self._train_vecs is None:
                    self._train_vecs = self._encoder.encode(self._training)
                v = self._encoder.encode([q])[0]
                sim = float(np.max(self._train_vecs @ v))
                self._weights[q] = novelty_weight(sim, self.params.lo, self.params.hi)
        return self._weights[q]

    def _blend(self, relation: str, learned: np.ndarray,
               cosine_fn: Callable[[Sequence[str], str], np.ndarray], names: Sequence[str],
               query: str) -> np.ndarray:
        if not self.blends(relation):
            return learned
        lam = self.learned_weight(query)
        if lam >= 1.0:
            return learned
        p = self.params
        cos = np.clip((cosine_fn(names, query) - p.cos_lo) / (p.cos_hi - p.cos_lo), 0.0, 1.0)
        return lam * learned + (1.0 - lam) * cos

    def rooms(self, names: Sequence[str], query: str) -> np.ndarray:
        return self._blend("containment", self.learned.rooms(names, query), self.cosine.rooms,
                           names, query)

    def objects(self, names: Sequence[str], query: str) -> np.ndarray:
        return self._blend("cooccurrence", self.learned.objects(names, query),
                           self.cosine.objects, names, query)
