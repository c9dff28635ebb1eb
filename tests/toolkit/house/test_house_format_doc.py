"""docs/house-format.md is the house format field by field: its example loads as a house
and writes back the same content, and its tables list exactly the keys a house is written
with (read from the doc, so the two cannot drift apart)."""

from __future__ import annotations

import json
import re

from support.paths import REPO

from sgtool.datasets.generator import generate_house
from sgtool.house.io import load_house, load_house_text

DOC = REPO / "docs" / "house-format.md"
SECTIONS = {"Top level": "top", "rooms[]": "rooms", "walls[]": "walls", "doors[]": "doors",
            "passages[]": "passages", "furniture[]": "furniture", "objects[]": "objects",
            "starts[]": "starts"}
# keys a house is written with only when it has them (the generated houses may not)
WHEN_GIVEN = {("top", "id"), ("furniture", "levels"), ("objects", "affordances"),
              ("objects", "state")}


def doc_keys() -> set[tuple[str, str]]:
    out, section = set(), None
    for line in DOC.read_text(encoding="utf-8").splitlines():
        if line.startswith("## "):
            section = SECTIONS.get(line[3:].strip())
        elif section and (m := re.match(r"\| `([a-z_]+)` \|", line)):
            out.add((section, m[1]))
    return out


def written_keys(d: dict) -> set[tuple[str, str]]:
    out = {("top", k) for k in d}
    for section in SECTIONS.values():
        if section != "top":
            out |= {(section, k) for item in d.get(section, []) for k in item}
    return out


def test_the_example_loads_and_writes_back_its_content() -> None:
    text = re.search(r"```json\n(.*?)```", DOC.read_text(encoding="utf-8"), re.DOTALL)
    assert text is not None
    house = load_house_text(text[1])
    again = json.loads(house.to_json())
    assert [o["id"] for o in again["objects"]] == ["obj_0", "obj_1"]
    assert load_house_text(house.to_json()) == house


def test_the_tables_list_every_key_a_house_is_written_with() -> None:
    written: set[tuple[str, str]] = set()
    houses = [generate_house(s, rooms=(4, 8)) for s in range(3)]
    houses += [load_house(p) for p in sorted((REPO / "datasets" / "data" / "handmade")
                                              .glob("*.json"))]
    for h in houses:
        written |= written_keys(h.to_dict())
    documented = doc_keys()
    assert written - documented == set(), "written but not documented"
    assert documented - written <= WHEN_GIVEN, "documented but never written"
