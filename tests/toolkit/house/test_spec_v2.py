"""House spec 2: a hand-written house with nesting three objects deep, a lower shelf and
ids without digits loads, saves and round-trips; version-1 files migrate; bad files are
refused with the file and the field named; the limits refuse hostile input fast."""

from __future__ import annotations

import copy
import json

import pytest
from support.datasets_fixtures import two_rooms
from support.nested_house import nested_house

from sgtool.errors import SpecError
from sgtool.house.io import load_house, save_house
from sgtool.house.parse import parse_house
from sgtool.house.spec import LIMITS, SPEC_VERSION, SpecLimits, hidden_objects


def test_a_foreign_nested_house_loads_saves_and_round_trips(tmp_path):
    spec = load_house(nested_house())
    assert spec.version == SPEC_VERSION == "2.0"
    objs = spec.object_by_id()
    assert objs["obj_candy"].parent == "obj_tin" and objs["obj_tin"].parent == "obj_box"
    assert spec.root_furniture()["obj_candy"] == "furn_cabinet"
    assert objs["obj_box"].affordances == ("container", "openable")  # sorted
    assert objs["obj_box"].state == "closed"
    cabinet = spec.furniture_by_id()["furn_cabinet"]
    assert cabinet.levels == (0.45,) and cabinet.supports == (0.45, 1.0)
    p = save_house(spec, tmp_path / "house.json")
    text = p.read_text()
    assert load_house(p) == spec and load_house(text).to_json() == text
    d = json.loads(text)
    assert d["version"] == "2.0"
    assert d["furniture"][0]["levels"] == [0.45]
    assert "levels" not in d["furniture"][1]  # version-2 fields only where they are used
    assert d["objects"][3]["affordances"] == ["container", "openable"]
    assert "affordances" not in d["objects"][0] and "state" not in d["objects"][0]
    assert hidden_objects(spec) == {"obj_book", "obj_box", "obj_tin", "obj_candy"}


def test_a_version_1_file_loads_as_the_same_spec_in_version_2():
    v1 = two_rooms()
    assert v1["version"] == "1.0"
    spec = load_house(v1)
    v2 = dict(v1, version="2.0")
    assert spec == load_house(v2) and spec.version == "2.0"
    # the text is the version-1 text but for the version
    old = json.loads(spec.to_json())
    assert old.pop("version") == "2.0"
    assert all("levels" not in f for f in old["furniture"])
    assert all(set(o) == {"id", "category", "synset", "parent", "relation", "room",
                          "position", "size"} for o in old["objects"])
    # a "1.0" file may not use version-2 fields
    bad = copy.deepcopy(v1)
    bad["furniture"][1]["levels"] = [0.3]
    with pytest.raises(SpecError, match=r"^furniture\[1\].levels: a version-2.0 field"):
        load_house(bad)
    bad = copy.deepcopy(v1)
    bad["objects"][1]["parent"] = "obj_0"
    with pytest.raises(SpecError, match=r"^objects\[1\].parent: 'obj_0' is a small object"):
        load_house(bad)


def _mutated(mutate) -> dict:
    d = copy.deepcopy(nested_house())
    mutate(d)
    return d


def _obj(d: dict, oid: str) -> dict:
    return next(o for o in d["objects"] if o["id"] == oid)


@pytest.mark.parametrize("mutate, message", [
    (lambda d: _obj(d, "obj_candy").__setitem__("parent", "furn_99"),
     "objects[4].parent: 'furn_99' is not a furniture or object id"),
    (lambda d: _obj(d, "obj_box").__setitem__("parent", "obj_candy"),
     "objects[4].parent: 'obj_tin' makes a cycle"),
    (lambda d: _obj(d, "obj_book").__setitem__("position", [0.7, 0.35, 0.55]),
     "objects[1].position: obj_book bottom z=0.525 is on none of furn_cabinet's surfaces "
     "z=0.450, 1.000"),
    (lambda d: _obj(d, "obj_apple").__setitem__("parent", "obj_vase"),
     "objects[6].parent: obj_vase (vase) is not a container"),
    (lambda d: _obj(d, "obj_apple").__setitem__("room", "room_den"),
     "objects[6].room: 'room_den' differs from its furniture furn_counter's room"),
    (lambda d: _obj(d, "obj_candy").__setitem__("position", [1.0, 0.35, 0.3]),
     "objects[4].position: obj_candy sticks out of obj_tin vertically"),
    (lambda d: d["furniture"][0].__setitem__("levels", [0.6, 0.45]),
     "furniture[0].levels[1]: levels must be ascending"),
    (lambda d: d["furniture"][0].__setitem__("levels", [1.5]),
     "furniture[0].levels[0]: 1.5 is not within the piece's height"),
    (lambda d: _obj(d, "obj_vase").__setitem__("state", "open"),
     "objects[0].state: 'open' given but the piece is not openable"),
    (lambda d: d["rooms"][1].__setitem__("polygon", [[3, 0], [8, 0], [8, 4], [3, 4]]),
     "rooms[1].polygon: overlaps rooms[0] (room_kitchen) by 4.00 m^2"),
    (lambda d: d["doors"][0].__setitem__("center", [1000, 1.95]),
     "doors[0].center: (1000.0, 1.95) is 996.00 m from its room room_kitchen"),
    (lambda d: d["furniture"][1].__setitem__("center", [3.6, 3.6, 0.45]),
     "furniture[1].size: a corner (4.20, 3.30) is 0.20 m outside its room room_kitchen"),
    (lambda d: d["furniture"][1].__setitem__("size", [1000, 0.6, 0.9]),
     "furniture[1].size: [1000.0, 0.6, 0.9] has a side over the limit of 20 m (lengths are "
     "in metres"),
    (lambda d: d["walls"][0].__setitem__("b", [1e9, 0]),
     "walls[0].b[0]: 1000000000.0 is out of range"),
    (lambda d: d["doors"][0].__setitem__("width", 1e6),
     "doors[0].width: 1000000.0 is out of range"),
    (lambda d: d["doors"][0].__setitem__("width", 900),
     "doors[0].width: 900.0 is more than the limit of 5 m (lengths are in metres: a file "
     "written in centimetres? divide by 100)"),
    (lambda d: d["rooms"][0].__setitem__("id", "kitchen"),
     "rooms[0].id: 'kitchen' should start with 'room_' (every id starts with its section's "
     "prefix: room_, wall_, door_, pass_, furn_, obj_; e.g. 'room_kitchen')"),
    (lambda d: d["rooms"][1].__setitem__("polygon", [[4, 0], [800, 0], [800, 4], [4, 4]]),
     "rooms: the house spans 800 m x 4 m, more than the limit of 100 m"),
    (lambda d: d["furniture"][0].__setitem__("center", [10 ** 400, 0.35, 0.5]),
     "furniture[0].center[0]: an integer of 401 digits is out of range"),
    (lambda d: d["furniture"][0].__setitem__("center", [float("nan"), 0.35, 0.5]),
     "furniture[0].center[0]: expected a finite number, got nan"),
    (lambda d: d["furniture"][0].__setitem__("category", "x" * 100_000),
     "furniture[0].category: 100000 characters, more than the limit of 128"),
    (lambda d: d.__setitem__("objects", d["objects"] * 20_000),
     "objects: 160000 entries, more than the limit of 5000"),
    (lambda d: d["rooms"][0].__setitem__("polygon", [[0, 0]] * 65),
     "rooms[0].polygon: 65 points, more than the limit of 64"),
])
def test_bad_houses_are_refused_naming_the_field(mutate, message):
    d = _mutated(mutate)
    with pytest.raises(SpecError) as e:
        load_house(d)
    assert str(e.value).startswith(message), str(e.value)
    assert "\n" not in str(e.value)


def test_a_refusal_names_the_file_and_the_field(tmp_path):
    d = nested_house()
    d["objects"][4]["parent"] = "furn_99"
    p = tmp_path / "house.json"
    p.write_text(json.dumps(d))
    with pytest.raises(SpecError) as e:
        load_house(p)
    assert str(e.value) == f"{p}: objects[4].parent: 'furn_99' is not a furniture or object id"


def _chain(d: dict, n: int) -> dict:
    """``n`` boxes, each inside the previous one, the first inside the cabinet."""
    d["objects"] = [{"id": f"obj_{k}", "category": "box", "synset": "box.n.01",
                     "parent": "furn_cabinet" if k == 0 else f"obj_{k - 1}",
                     "relation": "inside", "room": "room_kitchen", "position": [1.0, 0.35, 0.5],
                     "size": [0.3, 0.3, 0.3], "affordances": ["container"]}
                    for k in range(n)]
    return d


def test_nesting_depth_is_bounded_and_deep_json_is_refused(tmp_path):
    assert len(load_house(_chain(nested_house(), LIMITS.depth)).objects) == LIMITS.depth
    with pytest.raises(SpecError, match=r"^objects\[8\].parent: nested more than 8 levels"):
        load_house(_chain(nested_house(), LIMITS.depth + 1))
    with pytest.raises(SpecError, match="^objects: 100000 entries, more than the limit"):
        parse_house(_chain(nested_house(), 100_000))
    with pytest.raises(SpecError, match="nested more than 8 levels"):  # limits lifted
        parse_house(_chain(nested_house(), 20_000), SpecLimits(objects=20_000))
    p = tmp_path / "deep.json"
    p.write_text('{"version": "2.0", "rooms": ' + "[" * 100_000 + "]" * 100_000 + "}")
    with pytest.raises(SpecError, match=r"deep.json: JSON nested too deeply to read"):
        load_house(p)
    p.write_text('{"version": "2.0", "seed": ' + "9" * 5000 + "}")
    with pytest.raises(SpecError, match=r"deep.json: not readable JSON"):
        load_house(p)
