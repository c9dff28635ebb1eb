"""The train/eval split: disjoint, complete, rule as documented, no evaluation record in
the training tables, unseen queries absent from training."""

from __future__ import annotations

import hashlib

from sgtool.datasets.knowledge import load_knowledge
from sgtool.datasets.split import (
    SALT,
    evaluation_knowledge,
    evaluation_scenes,
    is_household_scene,
    placeable_objects,
    scene_family,
    training_knowledge,
    unseen_queries,
)
from sgtool.datasets.synsets import readable_name


def test_parts_are_disjoint_and_complete():
    full, tr, ev = load_knowledge(), training_knowledge(), evaluation_knowledge()
    assert not set(tr.scenes) & set(ev.scenes)
    assert not set(tr.activities) & set(ev.activities)
    assert set(tr.scenes) | set(ev.scenes) == set(full.scenes)
    assert set(tr.activities) | set(ev.activities) == set(full.activities)
    assert len(tr.rooms) + len(ev.rooms) == len(full.rooms)
    assert len(tr.relations) + len(ev.relations) == len(full.relations)
    assert len(tr.inroom) + len(ev.inroom) == len(full.inroom)
    # records stay with their source
    assert {r.scene for r in ev.rooms} <= set(ev.scenes)
    assert {r.activity for r in ev.relations} <= set(ev.activities)
    assert {r.activity for r in tr.relations} <= set(tr.activities)
    # about one in three to evaluation
    assert 330 <= len(ev.activities) <= 345
    assert ev.relation_counts()["inside"] + tr.relation_counts()["inside"] == 2608


def test_rule_as_documented():
    """Families never straddle; household and other families each send every third one
    (by SHA-256 order) to evaluation."""
    full = load_knowledge()
    ev = evaluation_scenes()
    fams = {}
    for s in full.scenes:
        fams.setdefault(scene_family(s), set()).add(s in ev)
    assert all(len(v) == 1 for v in fams.values())  # a family is all eval or all train
    def order(names):
        return sorted(names, key=lambda n: hashlib.sha256((SALT + n).encode()).hexdigest())
    house = [f for f in fams if f in ("Beechwood", "Benevolence", "Ihlen", "Merom", "Pomaria",
                                      "Rs", "Wainscott", "house", "gates", "hotel")]
    expect = {f for i, f in enumerate(order(house)) if i % 3 == 2}
    got = {f for f in house if True in fams[f]}
    assert got == expect
    # evaluation has homes with the core room types
    ev_types = {r.room_type for r in evaluation_knowledge().rooms if is_household_scene(r.scene)}
    assert {"kitchen", "living_room", "bathroom", "bedroom", "corridor"} <= ev_types


def test_training_tables_hold_no_evaluation_record():
    tr, ev = training_knowledge(), evaluation_knowledge()
    ev_acts = set(ev.activities)
    # every training triple is supported by training activities only
    train_keys = {(r.child, r.relation, r.parent) for r in tr.relations}
    assert set(tr.triples) == train_keys
    assert not {r.activity for r in tr.relations} & ev_acts
    # furniture frequencies come from training rooms only: recount one table
    kitchens = [r for r in tr.rooms if r.room_type == "kitchen"]
    have = sum(any(s == "electric_refrigerator.n.01" for s, _ in r.items) for r in kitchens)
    row = {f.synset: f for f in tr.room_furniture["kitchen"]}["electric_refrigerator.n.01"]
    assert row.frequency == have / len(kitchens)


def test_unseen_queries_never_occur_in_training():
    tr, ev = training_knowledge(), evaluation_knowledge()
    unseen = unseen_queries()
    assert unseen == sorted(unseen) and len(unseen) == len(set(unseen))
    assert 40 <= len(unseen) <= 150  # SCOUT's SymSearch: 61 of 142 queries unseen
    train_names = {readable_name(s) for s in tr.vocabulary()}
    assert not set(unseen) & train_names
    eval_names = {readable_name(s) for s in placeable_objects(ev)}
    assert set(unseen) <= eval_names
    assert unseen_queries() == unseen  # deterministic
