"""BEHAVIOR-1K knowledge: the loader's figures against independent counts of the package's
files, the BDDL parser on a hand-written problem, readable names, affordances."""

from __future__ import annotations

import csv
import json
import re
from collections import Counter

import pytest

from sgtool.datasets.activities import parse_activity
from sgtool.datasets.knowledge import load_knowledge, negated_relation_counts
from sgtool.datasets.synsets import bddl_root, readable_name


@pytest.fixture(scope="module")
def k():
    return load_knowledge()


def test_rooms_and_scenes_match_the_json(k):
    data = json.loads((bddl_root() / "generated_data" / "combined_room_object_list.json")
                      .read_text())
    scenes = data["scenes"]
    assert len(k.scenes) == len(scenes) == 51
    assert len(k.rooms) == sum(len(v) for v in scenes.values()) == 374
    types = Counter(re.sub(r"_\d+$", "", room) for s in scenes.values() for room in s)
    assert dict(k.room_type_counts) == dict(types)
    assert k.room_type_counts["kitchen"] == 18 and k.room_type_counts["bathroom"] == 57


def test_kitchen_fridge_frequency_matches_the_json(k):
    """Share of kitchens holding a refrigerator model, counted straight from the files."""
    root = bddl_root() / "generated_data"
    data = json.loads((root / "combined_room_object_list.json").read_text())
    with open(root / "category_mapping.csv", newline="") as fh:
        fridge_cats = {r["category"] for r in csv.DictReader(fh)
                       if r["synset"] == "electric_refrigerator.n.01"}
    kitchens = [objs for s in data["scenes"].values() for room, objs in s.items()
                if re.sub(r"_\d+$", "", room) == "kitchen"]
    with_fridge = sum(any(m.rsplit("-", 1)[0] in fridge_cats for m in objs) for objs in kitchens)
    row = {f.synset: f for f in k.room_furniture["kitchen"]}["electric_refrigerator.n.01"]
    assert row.frequency == pytest.approx(with_fridge / len(kitchens))
    assert row.name == "refrigerator"


def test_relation_counts_match_the_files(k):
    """Every '(inside ' / '(ontop ' / '(inroom ' in :init and :goal is a loader record or
    a negated atom the loader leaves out."""
    base = bddl_root() / "activity_definitions"
    dirs = sorted(p for p in base.iterdir() if p.is_dir())
    assert len(k.activities) == len(dirs) == 1016
    raw = Counter()
    for d in dirs:
        text = re.sub(r";[^\n]*", "", (d / "problem0.bddl").read_text())
        for rel in ("inside", "ontop", "inroom"):
            raw[rel] += len(re.findall(r"\(\s*" + rel + r"\s", text))
    counts = k.relation_counts()
    neg = negated_relation_counts()
    for rel in ("inside", "ontop", "inroom"):
        assert counts[rel] + neg.get(rel, 0) == raw[rel], rel
    # the "about 2,700 inside, 5,300 ontop and 3,200 inroom"
    assert counts == {"inside": 2608, "ontop": 5313, "inroom": 3207}
    assert neg == {"inside": 64, "ontop": 17}
    # the triple table sums to the relation records
    assert sum(t.count for t in k.triples.values()) == 2608 + 5313


def test_parser_on_a_hand_written_problem():
    text = """
    (define (problem demo-0) (:domain omnigibson)
      (:objects apple.n.01_1 apple.n.01_2 - apple.n.01 electric_refrigerator.n.01_1 - x
                bowl.n.01_1 - bowl.n.01 countertop.n.01_1 - countertop.n.01)
      (:init (inside apple.n.01_1 electric_refrigerator.n.01_1)   ; a comment (ontop x y)
             (ontop bowl.n.01_1 countertop.n.01_1)
             (inside apple.n.01_2 bowl.n.01_1)
             (inroom electric_refrigerator.n.01_1 kitchen)
             (inroom countertop.n.01_1 kitchen))
      (:goal (and (forall (?apple.n.01 - apple.n.01)
                          (ontop ?apple.n.01 ?countertop.n.01_1))
                  (not (inside ?bowl.n.01_1 ?electric_refrigerator.n.01_1))
                  (forn (2) (?apple.n.01 - apple.n.01) (inside ?apple.n.01 ?bowl.n.01_1)))))
    """
    rels, inroom, neg = parse_activity("demo", text)
    got = [(r.child, r.relation, r.parent, r.section, r.room_type) for r in rels]
    assert got == [
        ("apple.n.01", "inside", "electric_refrigerator.n.01", "init", "kitchen"),
        ("bowl.n.01", "ontop", "countertop.n.01", "init", "kitchen"),
        # the bowl is on the countertop, which is in the kitchen: the room propagates
        ("apple.n.01", "inside", "bowl.n.01", "init", "kitchen"),
        ("apple.n.01", "ontop", "countertop.n.01", "goal", "kitchen"),
        ("apple.n.01", "inside", "bowl.n.01", "goal", "kitchen"),
    ]
    assert [(i.synset, i.room_type) for i in inroom] == [
        ("electric_refrigerator.n.01", "kitchen"), ("countertop.n.01", "kitchen")]
    assert neg == Counter({"inside": 1})


def test_readable_names():
    assert readable_name("electric_refrigerator.n.01") == "refrigerator"
    assert readable_name("pack__of__ground_beef.n.01") == "pack of ground beef"
    assert readable_name("apple.n.01") == "apple"
    assert readable_name("cabinet.n.01") == "cabinet"
    assert readable_name("cabinet.n.03") == "locker"  # homonym: its OmniGibson category
    assert readable_name("not_in_the_package.n.01") == "not in the package"


def test_affordances_follow_the_flags_and_relations(k):
    # openable per synsets.csv
    with open(bddl_root() / "generated_data" / "synsets.csv", newline="") as fh:
        flags = {r["synset"]: r for r in csv.DictReader(fh)}
    for s in ("electric_refrigerator.n.01", "cabinet.n.01", "dishwasher.n.01", "oven.n.01"):
        assert flags[s]["openable"] == "1"
        assert {"openable", "container"} <= set(k.affordances[s])
    assert "openable" not in k.affordances.get("bookcase.n.01", ())
    assert "container" in k.affordances["bookcase.n.01"]  # things are inside bookcases
    assert "supporter" in k.affordances["breakfast_table.n.01"]
    assert k.kind("electric_refrigerator.n.01") == "furniture"
    assert k.kind("apple.n.01") == "object"
    assert k.kind("wall.n.01") == "structure"
    assert k.kind("water.n.06") == "substance"


def test_room_objects_and_load_is_cached(k):
    kitchen = dict(k.room_objects["kitchen"])
    assert kitchen.get("bowl.n.01", 0) > kitchen.get("pillow.n.01", 0)
    assert load_knowledge() is k
