"""RoboTHOR apartments -> house specs (sgtool.datasets.robothor_houses): a small scene built
here in AI2-THOR's metadata format, with every value worked out by hand, and the converted
houses shipped in datasets/data/robothor checked by the house validator."""

from __future__ import annotations

import json
import zipfile
from pathlib import Path
from typing import Any

import pytest

from sgtool.datasets import robothor_houses as rh
from sgtool.errors import SgtoolError
from sgtool.house.io import load_house
from sgtool.house.spec import hidden_objects

DATA = Path(__file__).resolve().parents[2] / "datasets" / "data" / "robothor"


def obj(kind: str, n: int, center: tuple[float, float, float], size: tuple[float, float, float],
        parents: tuple[str, ...] = (), *, fixed: bool = False, openable: bool = False,
        ) -> dict[str, Any]:
    """One AI2-THOR metadata object; ``center``/``size`` in AI2-THOR axes (x, y up, z)."""
    cx, cy, cz = center
    sx, sy, sz = size
    return {"objectId": f"{kind}|{n}", "objectType": kind,
            "axisAlignedBoundingBox": {"center": {"x": cx, "y": cy, "z": cz},
                                       "size": {"x": sx, "y": sy, "z": sz}},
            "parentReceptacles": list(parents) or None, "openable": openable,
            "isOpen": False, "pickupable": not fixed, "moveable": False}


def scene() -> list[dict[str, Any]]:
    """A 9 m strip: bed | dresser (two closed drawers) | tv stand with a shelf | dining
    table with an apple and a closed box holding a phone | a bat on the floor, a desk
    (listed "on" its chair) and the chair; a painting on the wall."""
    return [
        obj("Bed", 1, (1.0, 0.25, 1.0), (2.0, 0.5, 1.4), fixed=True),            # x 0-2
        obj("Dresser", 1, (3.0, 0.4, 0.3), (1.0, 0.8, 0.5), fixed=True),         # x 2.5-3.5
        obj("Drawer", 1, (2.8, 0.6, 0.3), (0.35, 0.2, 0.4), fixed=True, openable=True),
        obj("Drawer", 2, (3.2, 0.6, 0.3), (0.35, 0.2, 0.4), fixed=True, openable=True),
        obj("TVStand", 1, (4.5, 0.4, 1.7), (0.8, 0.8, 0.4), fixed=True),         # x 4.1-4.9
        obj("Shelf", 1, (4.5, 0.2, 1.7), (0.7, 0.02, 0.35), fixed=True),
        obj("Book", 1, (4.5, 0.25, 1.7), (0.2, 0.08, 0.25), ("Shelf|1",)),       # bottom 0.21
        obj("DiningTable", 1, (6.0, 0.375, 1.0), (1.2, 0.75, 0.8), fixed=True),  # x 5.4-6.6
        obj("Apple", 1, (6.1, 0.81, 1.0), (0.1, 0.1, 0.1), ("DiningTable|1",)),  # 1 cm high
        obj("Box", 1, (5.8, 0.85, 1.1), (0.3, 0.2, 0.3), ("DiningTable|1",), openable=True),
        obj("CellPhone", 1, (5.8, 0.80, 1.1), (0.08, 0.02, 0.15),
            ("DiningTable|1", "Box|1")),
        obj("BaseballBat", 1, (7.5, 0.04, 0.5), (0.9, 0.08, 0.1)),               # on the floor
        obj("Desk", 1, (7.5, 0.375, 1.6), (1.0, 0.75, 0.6), ("Chair|1",), fixed=True),
        obj("Chair", 1, (7.5, 0.45, 1.2), (0.5, 0.9, 0.5), fixed=True),
        obj("Painting", 1, (4.0, 1.5, 0.01), (0.8, 0.6, 0.02), fixed=True),
    ]


def by_category(items: Any) -> dict[str, Any]:
    return {x.category: x for x in items}


def test_type_words_split_camel_case_and_acronyms() -> None:
    assert rh.type_words("AlarmClock") == "alarm clock"
    assert rh.type_words("TVStand") == "tv stand"
    assert rh.type_words("CD") == "cd"
    assert rh.type_words("Apple") == "apple"
    assert rh.synset_of("alarm clock") == "alarm_clock.n.01"


def test_cut_points_cut_in_the_free_gap_nearest_the_midpoint() -> None:
    intervals = [(0, 2), (2.5, 3.5), (4.1, 4.9), (5.4, 6.6), (7.0, 8.0)]
    anchors = [(1.0, "bedroom"), (6.0, "dining_room"), (7.5, "private_office")]
    # gaps at 2.25, 3.8, 5.15, 6.8; bed|table midpoint 3.5 -> 3.8; table|desk 6.75 -> 6.8
    cuts, cats = rh.cut_points(intervals, anchors)
    assert cuts == pytest.approx([3.8, 6.8])
    assert cats == ["bedroom", "dining_room", "private_office"]


def test_cut_points_merge_without_a_gap_and_same_names() -> None:
    # no free gap between the bed and the desk: one room, named by the bed
    assert rh.cut_points([(0, 2), (1.5, 4)], [(1, "bedroom"), (3, "private_office")]) == \
        ([], ["bedroom"])
    # living | office | living, office merged into the second living room -> one room
    assert rh.cut_points([(0, 1), (2, 3), (3, 4)],
                         [(0.5, "living_room"), (2.5, "private_office"),
                          (3.5, "living_room")]) == ([], ["living_room"])
    assert rh.cut_points([(0, 1)], []) == ([], ["living_room"])


def test_convert_scene_rooms_furniture_objects() -> None:
    spec = rh.convert_scene(scene(), seed=3)
    assert [r.category for r in spec.rooms] == ["bedroom", "dining_room", "private_office"]
    # strip x from 0 - 0.6 to 8 + 0.6, cut at 3.8 and 6.8; y (AI2-THOR z) 0.05..1.9 +- 0.6
    assert spec.rooms[0].bounds == pytest.approx((-0.6, -0.55, 3.8, 2.5))
    assert spec.rooms[2].bounds == pytest.approx((6.8, -0.55, 8.6, 2.5))
    assert [p.rooms for p in spec.passages] == [("room_0", "room_1"), ("room_1", "room_2")]
    assert spec.passages[0].width == pytest.approx(3.05 - 0.2)
    assert len(spec.walls) == 4 and spec.doors == ()
    assert len(spec.starts) == 3  # one per room
    # painting dropped; drawers and shelf join their pieces; bat and desk are furniture
    furn = by_category(spec.furniture)
    assert sorted(furn) == ["baseball bat", "bed", "chair", "desk", "dining table",
                            "dresser", "tv stand"]
    assert furn["dresser"].affordances == ("container", "openable")
    assert furn["dresser"].state == "closed"
    assert furn["tv stand"].levels == pytest.approx((0.21,))
    assert furn["tv stand"].room == "room_1" and furn["desk"].room == "room_2"
    assert furn["dining table"].affordances == ("supporter",)
    objs = by_category(spec.objects)
    assert sorted(objs) == ["apple", "book", "box", "cell phone"]
    assert objs["apple"].parent == furn["dining table"].id
    assert objs["apple"].relation == "ontop"
    assert objs["apple"].position[2] == pytest.approx(0.75 + 0.05)  # moved 1 cm down
    assert objs["book"].parent == furn["tv stand"].id
    assert objs["book"].position[2] == pytest.approx(0.25)  # on its level, unchanged
    assert objs["box"].affordances == ("container", "openable")
    assert objs["cell phone"].parent == objs["box"].id
    assert objs["cell phone"].relation == "inside"
    assert objs["cell phone"].room == "room_1"
    assert hidden_objects(spec) == {objs["cell phone"].id}


def test_convert_scene_without_furniture_is_one_line() -> None:
    with pytest.raises(SgtoolError, match="no furniture"):
        rh.convert_scene([obj("Painting", 1, (0, 1.5, 0), (1, 1, 0.02), fixed=True)])


def test_read_scenes_from_wheel_and_json_and_refusals(tmp_path: Path) -> None:
    doc = json.dumps({"robothor": [scene()], "kitchens": []})
    wheel = tmp_path / "procthor-0.0.1.dev2-py3-none-any.whl"
    with zipfile.ZipFile(wheel, "w") as z:
        z.writestr(rh.METADATA_MEMBER, doc)
    plain = tmp_path / "meta.json"
    plain.write_text(doc)
    assert rh.read_scenes(wheel) == rh.read_scenes(plain) == [scene()]
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps({"kitchens": []}))
    with pytest.raises(SgtoolError, match="no list of scenes under 'robothor'"):
        rh.read_scenes(bad)
    with pytest.raises(SgtoolError, match="cannot read the RoboTHOR metadata"):
        rh.read_scenes(tmp_path / "missing.json")


def test_cli_writes_valid_houses(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    meta = tmp_path / "meta.json"
    meta.write_text(json.dumps({"robothor": [scene(), scene()]}))
    out = tmp_path / "houses"
    assert rh.main([str(out), "--metadata", str(meta), "--scenes", "1"]) == 0
    assert sorted(p.name for p in out.iterdir()) == ["robothor_01.json"]
    assert len(load_house(out / "robothor_01.json").objects) == 4
    assert "robothor_01: 3 rooms (bedroom, dining_room, private_office)" in \
        capsys.readouterr().out
    assert rh.main([str(out), "--metadata", str(meta), "--scenes", "2"]) == 2
    assert "--scenes: 2 is outside 0-1" in capsys.readouterr().err


def test_shipped_houses_pass_the_validator() -> None:
    files = sorted(DATA.glob("robothor_*.json"))
    assert len(files) == 75
    specs = [load_house(p) for p in files]
    assert all(1 <= len(s.rooms) <= 4 for s in specs)
    assert sum(len(s.objects) for s in specs) == 1451
    assert sum(len(s.furniture) for s in specs) == 1171
