"""(F1): the furniture-level prior from BEHAVIOR-1K, and the table the core ships."""

from __future__ import annotations

from collections import Counter

import pytest

from sgtool.datasets.furniture_level import (
    first_level_vocabulary,
    furniture_levels,
    levels_document,
)
from sgtool.datasets.split import training_knowledge
from sgtool.planning.furniture_prior import LEVELS_FILE, load_levels


@pytest.fixture(scope="module")
def levels() -> dict[str, float]:
    return furniture_levels(training_knowledge())


def test_shipped_table_is_the_training_knowledge_table() -> None:
    assert LEVELS_FILE.read_text(encoding="utf-8") == levels_document(training_knowledge())
    assert load_levels()["sofa"] == 1.0


def test_vocabulary_is_furniture_and_floor_holders() -> None:
    vocab = first_level_vocabulary()
    assert vocab["sofa"] == "furniture" and vocab["dishwasher"] == "furniture"
    assert vocab["trash can"] == "object"  # a floor-standing holder (ashcan.n.01)
    assert "apple" not in vocab and "bowl" not in vocab


def test_values_follow_f1(levels) -> None:
    assert set(levels) == set(first_level_vocabulary())
    assert all(0.0 < v <= 1.0 for v in levels.values())
    # a small object's name is not in the table: φ = 0
    assert "apple" not in levels
    # furniture is never placed on anything: φ ≈ 1; a sack is placed inside things more
    # often than it stands alone (24 / 35 in the training knowledge): φ < 1/2
    assert levels["sofa"] > 0.99 and levels["refrigerator"] > 0.9
    assert levels["sack"] < 0.5 < levels["trash can"]


def test_f1_by_hand(monkeypatch) -> None:
    """Two holders of kind object (n_F, n_O) = (3, 1) and (0, 0): m = 3 / 4, so
    φ = (3 + 2 · 0.75) / (4 + 2) = 0.75 and (0 + 1.5) / (0 + 2) = 0.75; a furniture name
    with (1, 1) alone in its kind: m = 1 / 2, φ = (1 + 1) / (2 + 2) = 0.5."""
    import sgtool.datasets.furniture_level as fl

    monkeypatch.setattr(fl, "first_level_vocabulary",
                        lambda: {"bin": "object", "box": "object", "desk": "furniture"})
    monkeypatch.setattr(fl, "first_level_counts",
                        lambda k: (Counter({"bin": 3, "desk": 1}), Counter({"bin": 1, "desk": 1})))
    assert fl.furniture_levels(None) == {"bin": 0.75, "box": 0.75, "desk": 0.5}
