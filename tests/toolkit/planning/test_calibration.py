"""Calibrated priors and the novelty blend of learned and cosine scores."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import pytest
from support.semantics_fixtures import TableScorer

from sgtool.planning.calibration import BlendedPriors, BlendParams, calibrate, novelty_weight


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
