"""Calibrated priors and the novelty blend of learned and cosine scores."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import pytest
from support.semantics_fixtures import TableScorer

from sgtool.planning.calibration import (
    BlendedPriors,
    BlendParams,
    blended_relations,
    calibrate,
    novelty_weight,
)


def test_calibrate_floor_and_sharpness() -> None:
    assert calibrate(np.array([0.0, 1.0, 0.25]), 0.1).tolist() == pytest.approx(
        [0.1, 1.0, 0.1 + 0.9 * 0.25])
    assert calibrate(0.25, 0.0, sharpness=2.0) == pytest.approx(0.0625)
    assert calibrate(1.7, 0.0) == pytest.approx(1.0)  # clipped


def test_novelty_weight() -> None:
    assert novelty_weight(0.9, 0.5, 0.8) == 1.0
    assert novelty_weight(0.65, 0.5, 0.8) == pytest.approx(0.5)
    assert novelty_weight(0.2, 0.5, 0.8) == 0.0


class AxisEncoder:
    """Texts to unit vectors: "apple" and "pear" share an axis, "tractor" is orthogonal."""

    def __init__(self) -> None:
        self.calls = 0

    def encode(self, texts: Sequence[str]) -> np.ndarray:
        self.calls += 1
        axes = {"apple": [1.0, 0.0], "pear": [0.8, 0.6], "tractor": [0.0, 1.0]}
        return np.array([axes[t] for t in texts])


def test_blend_keeps_learned_scores_for_training_queries() -> None:
    learned = TableScorer({"kitchen": 0.9}, {"fridge": 0.7})
    cosine = TableScorer({"kitchen": 0.35}, {"fridge": 0.6})
    enc = AxisEncoder()
    b = BlendedPriors(learned, cosine, ["apple"], enc, BlendParams(lo=0.5, hi=0.9,
                                                                   cos_lo=0.1, cos_hi=0.6))
    assert b.rooms(["kitchen"], "apple").tolist() == [0.9]
    assert enc.calls == 0  # a training query needs no encoding
    # "pear": best training match cos 0.8 -> lambda = (0.8 - 0.5) / 0.4 = 0.75
    # cosine 0.35 -> (0.35 - 0.1) / 0.5 = 0.5; blend 0.75 * 0.9 + 0.25 * 0.5
    assert b.learned_weight("pear") == pytest.approx(0.75)
    assert b.rooms(["kitchen"], "pear")[0] == pytest.approx(0.75 * 0.9 + 0.25 * 0.5)
    # "tractor": nothing like it in training -> cosine only ((0.6 - 0.1) / 0.5 = 1)
    assert b.objects(["fridge"], "tractor")[0] == pytest.approx(1.0)


def test_blend_without_training_queries_is_the_learned_scorer() -> None:
    learned = TableScorer({"kitchen": 0.9}, {})
    b = BlendedPriors(learned, TableScorer({}, {}), None, AxisEncoder())
    assert b.rooms(["kitchen"], "tractor").tolist() == [0.9]


def _report(learned_auc: float, cos_auc: float) -> dict:
    rel = {"learned": {"auc": learned_auc}, "cosine": {"auc": cos_auc}}
    return {"unseen": {"containment": rel, "cooccurrence": {
        "learned": {"auc": 0.7}, "cosine": {"auc": 0.6}}}}


def test_gate_blends_only_the_relations_where_cosine_measured_better() -> None:
    # containment: cosine 0.8 > learned 0.6 -> blended; co-occurrence: learned better -> not
    assert blended_relations(_report(0.6, 0.8)) == {"containment"}
    assert blended_relations(_report(0.9, 0.7)) == set()
    assert blended_relations(None) == {"containment", "cooccurrence"}  # nothing measured
    assert blended_relations({"unseen": {"containment": {}}}) == {"containment",
                                                                   "cooccurrence"}


def test_gated_blend_keeps_learned_scores_where_learned_measured_better() -> None:
    learned = TableScorer({"kitchen": 0.9}, {"fridge": 0.7})
    learned.metadata = {"report": _report(0.6, 0.8)}  # type: ignore[attr-defined]
    cosine = TableScorer({"kitchen": 0.35}, {"fridge": 0.6})
    params = BlendParams(lo=0.5, hi=0.9, cos_lo=0.1, cos_hi=0.6)
    b = BlendedPriors(learned, cosine, ["apple"], AxisEncoder(), params)
    # rooms (containment) blended as in (C3): lambda("pear") = 0.75
    assert b.rooms(["kitchen"], "pear")[0] == pytest.approx(0.75 * 0.9 + 0.25 * 0.5)
    # objects (co-occurrence): the learned model measured better -> unchanged, even for a
    # query with nothing like it in training
    assert b.objects(["fridge"], "tractor").tolist() == [0.7]
    # gate off: the distance blend on both relations
    ungated = BlendedPriors(learned, cosine, ["apple"], AxisEncoder(),
                            BlendParams(lo=0.5, hi=0.9, cos_lo=0.1, cos_hi=0.6, gate=False))
    assert ungated.objects(["fridge"], "tractor")[0] == pytest.approx(1.0)
