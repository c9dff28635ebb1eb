"""Widening the room knowledge: folding room types by content, adding targets, the table."""

from __future__ import annotations

import pytest

from sgtool.semantics.relational_set import table_to_set
from sgtool.semantics.room_knowledge import (
    add_room_targets,
    content_likeness,
    fold_room_types,
    fold_targets,
    room_table,
    set_to_table,
)

# kitchen and private office are the scored room types; shared office holds office things
# (a pen, a desk), the private office a desk; the kitchen an apple and a desk at 0.
TABLE = {
    ("kitchen", "apple"): 1.0, ("kitchen", "desk"): 0.0, ("kitchen", "pen"): 0.0,
    ("private_office", "desk"): 1.0, ("private_office", "pen"): 0.0,
    ("shared_office", "pen"): 1.0, ("shared_office", "desk"): 0.8,
}
SCORED = ("kitchen", "private_office")


def test_content_likeness_is_the_cosine_of_target_columns() -> None:
    nodes, like = content_likeness(table_to_set("containment", TABLE))
    i, j, k = nodes.index("shared_office"), nodes.index("private_office"), nodes.index("kitchen")
    # shared office (desk 0.8, pen 1) against private office (desk 1): 0.8 / |(0.8, 1)|
    assert like[i, j] == pytest.approx(0.8 / (0.8 ** 2 + 1) ** 0.5)
    assert like[i, k] == 0.0  # nothing in common with the kitchen
    assert like[j, j] == pytest.approx(1.0)


def test_fold_moves_a_room_type_into_the_scored_one_alike_in_contents() -> None:
    rs = table_to_set("containment", TABLE)
    assert fold_targets(rs, SCORED) == {"shared_office": "private_office"}
    folded = set_to_table(fold_room_types(rs, SCORED))
    assert folded[("private_office", "pen")] == 1.0  # was 0: the shared office's pen
    assert folded[("private_office", "desk")] == 1.0  # the larger of 1.0 and 0.8 stays
    assert folded[("shared_office", "pen")] == 1.0  # the folded type's pairs stay
    assert folded[("kitchen", "pen")] == 0.0
    # below the likeness asked for, nothing moves
    assert fold_targets(rs, SCORED, min_likeness=0.9) == {}
    assert set_to_table(fold_room_types(rs, SCORED, 0.9)) == pytest.approx(TABLE)


def test_add_room_targets_averages_a_known_name_and_brings_new_names_with_zeros() -> None:
    rs = table_to_set("containment", TABLE)
    out = set_to_table(add_room_targets(rs, {
        # apple is known (kitchen 1.0): the other source says kitchen 0.25, bedroom 1.0
        "Apple": {"kitchen": 0.25, "bedroom": 1.0},
        "soap bar": {"bathroom": 1.0, "kitchen": 0.0},
    }))
    assert out[("kitchen", "apple")] == pytest.approx((1.0 + 0.25) / 2)
    assert out[("bedroom", "apple")] == pytest.approx(0.5)  # never seen there: 0 and 1
    assert out[("bathroom", "soap bar")] == 1.0
    assert out[("kitchen", "soap bar")] == 0.0  # "never in a kitchen" is trained
    assert out[("private_office", "desk")] == 1.0  # pairs the source does not name stay
    assert len(out) == len(TABLE) + 3


def test_add_room_targets_max_rule_keeps_the_larger() -> None:
    rs = table_to_set("containment", TABLE)
    extra = {"Apple": {"kitchen": 0.25, "bedroom": 1.0}}
    out = set_to_table(add_room_targets(rs, extra, merge="max"))
    assert out[("kitchen", "apple")] == 1.0
    assert out[("bedroom", "apple")] == 1.0
    with pytest.raises(ValueError, match="merge"):
        add_room_targets(rs, extra, merge="min")


def test_room_table_lists_names_from_the_target_threshold() -> None:
    rs = table_to_set("containment", TABLE)
    assert room_table(rs, ["kitchen", "private_office", "bedroom"]) == {
        "kitchen": ["apple"], "private_office": ["desk"], "bedroom": []}
    assert room_table(rs, ["shared_office"], min_target=0.9) == {"shared_office": ["pen"]}
