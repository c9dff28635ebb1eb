"""Room categories from contents with the containment model (replaces frequency counting)."""

from __future__ import annotations

import pytest
from semantics_fixtures import encoder

from sgtool.semantics.priors import LearnedPriors
from sgtool.semantics.rooms import ContainmentRoomClassifier


@pytest.fixture(scope="module")
def clf() -> ContainmentRoomClassifier:
    return ContainmentRoomClassifier(LearnedPriors(encoder()))


@pytest.mark.parametrize(
    "objects,room",
    [
        (["toilet", "bathtub", "sink"], "bathroom"),
        (["bed", "nightstand", "wardrobe"], "bedroom"),
        (["stove", "electric_refrigerator", "dishwasher"], "kitchen"),
        (["sofa", "coffee_table", "television"], "living_room"),
        (["washing_machine", "clothes_dryer"], "utility_room"),
    ],
)
def test_typical_rooms(clf: ContainmentRoomClassifier, objects: list[str], room: str) -> None:
    ranked = clf.classify(objects)
    assert ranked[0][0] == room


def test_output_is_a_distribution_best_first(clf: ContainmentRoomClassifier) -> None:
    ranked = clf.classify(["sofa", "chair", "sofa"])
    probs = [p for _, p in ranked]
    assert probs == sorted(probs, reverse=True)
    assert sum(probs) == pytest.approx(1.0)
    assert {r for r, _ in ranked} == set(clf.room_types)  # household room types only
    assert "grocery_store" not in clf.room_types
    assert clf.classify([]) == []


def test_evidence_accumulates(clf: ContainmentRoomClassifier) -> None:
    one = dict(clf.classify(["toilet"]))["bathroom"]
    three = dict(clf.classify(["toilet", "bathtub", "sink"]))["bathroom"]
    assert three > one
