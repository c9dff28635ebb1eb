"""Relational training sets: exact values on a tiny hand-made knowledge, and the real split."""

from __future__ import annotations

import math

import numpy as np
import pytest
from support.tiny_knowledge import tiny

from sgtool.datasets.relational import (
    containment_set,
    cooccurrence_labels,
    cooccurrence_set,
    knowledge_fingerprint,
    training_sets,
)
from sgtool.semantics.relational_set import holdout_queries


def test_containment_targets_by_hand() -> None:
    cs = containment_set(tiny(), seed=0)
    # plate: activity placements cook/kitchen, wash/kitchen, party/dining room -> shares
    # 2/3 and 1/3, never in a scanned room: y = sqrt(e / max e)
    assert cs.target("kitchen", "plate") == pytest.approx(1.0)
    assert cs.target("dining room", "plate") == pytest.approx(math.sqrt(0.5))
    # refrigerator: 2 of 2 kitchens (+3 pseudo rooms) = 0.4, plus all its placements (1.0)
    assert cs.target("kitchen", "refrigerator") == pytest.approx(1.0)
    # sink: kitchens 1/5 + activity 1.0 = 1.2; bathroom 1/4 = 0.25
    assert cs.target("bathroom", "sink") == pytest.approx(math.sqrt(0.25 / 1.2))
    # toilet: only the bathroom; the other room types are negatives with target 0
    assert cs.target("bathroom", "toilet") == pytest.approx(1.0)
    assert cs.target("kitchen", "toilet") == 0.0
    assert set(cs.nodes) == {"bathroom", "dining room", "kitchen"}
    assert np.all((cs.targets >= 0) & (cs.targets <= 1))


def test_cooccurrence_labels_by_hand() -> None:
    pos, related = cooccurrence_labels(tiny())
    # plate in/on the cabinet in 3 activities: positive both ways
    assert ("cabinet", "plate") in pos and ("plate", "cabinet") in pos
    # apple in the fridge once, and the apple has a single place: the one fact counts
    assert ("refrigerator", "apple") in pos
    # fridge and cabinet share 3 places (both scanned kitchens, the "cook" kitchen): all 3
    # of the fridge's places and 3 of the cabinet's 6 (>= 0.2): positive both ways
    assert ("cabinet", "refrigerator") in pos and ("refrigerator", "cabinet") in pos
    # toilet and fridge never share a place
    assert ("toilet", "refrigerator") not in related
    cs = cooccurrence_set(tiny(), seed=0)
    for q in cs.queries:
        qi = cs.queries.index(q)
        t = cs.targets[cs.pairs[:, 1] == qi]
        assert (t == 1).sum() >= (t == 0).sum()  # at most one negative per positive


def test_training_sets_are_deterministic_and_from_training_only() -> None:
    from sgtool.datasets.split import training_knowledge, unseen_queries

    a = training_sets(seed=0)
    training_sets.cache_clear()
    b = training_sets(seed=0)
    assert a.containment.fingerprint() == b.containment.fingerprint()
    assert a.cooccurrence.fingerprint() == b.cooccurrence.fingerprint()
    assert a.split_fingerprint == knowledge_fingerprint(training_knowledge())
    # categories that only the evaluation part knows never appear in training data
    unseen = set(unseen_queries())
    assert unseen
    for rs in (a.containment, a.cooccurrence):
        assert not unseen & set(rs.queries)
        assert not unseen & set(rs.nodes)
    # sizes of the order of SCOUT's (92K / 7.5K from an LLM): thousands of pairs each
    assert len(a.containment) > 3000 and len(a.cooccurrence) > 3000
    assert 0.05 < a.containment.positives / len(a.containment) < 0.3  # 8 zeros per positive
    assert a.cooccurrence.positives * 2 == len(a.cooccurrence)  # balanced
    assert {"kitchen", "bathroom", "bedroom", "living_room"} <= set(a.room_types)


def test_holdout_is_stable_and_about_the_fraction() -> None:
    qs = [f"object {i}" for i in range(2000)]
    held = holdout_queries(qs, 0.15, seed=0)
    assert 0.12 < len(held) / len(qs) < 0.18
    assert holdout_queries(qs[:500], 0.15, seed=0) == {q for q in held if q in qs[:500]}
    assert holdout_queries(qs, 0.15, seed=1) != held
