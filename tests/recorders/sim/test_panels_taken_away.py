"""An open door with no room to swing (two 1.2 m corridors side by side: its 0.9 m leaf
would cut either one) is taken out of the simulation; the record report says so, since
the replay then sees an empty doorway."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

pytest.importorskip("pybullet")

W = {"thickness": 0.1, "height": 2.5}


def _two_corridors() -> dict:
    return {
        "version": "1.0", "seed": 7,
        "rooms": [
            {"id": "room_0", "category": "corridor",
             "polygon": [[0, 0], [1.2, 0], [1.2, 6], [0, 6]]},
            {"id": "room_1", "category": "corridor",
             "polygon": [[1.2, 0], [2.4, 0], [2.4, 6], [1.2, 6]]}],
        "walls": [dict(id="wall_0", a=[0, 0], b=[2.4, 0], **W),
                  dict(id="wall_1", a=[0, 6], b=[2.4, 6], **W),
                  dict(id="wall_2", a=[0, 0], b=[0, 6], **W),
                  dict(id="wall_3", a=[2.4, 0], b=[2.4, 6], **W),
                  dict(id="wall_4", a=[1.2, 0], b=[1.2, 2.55], **W),
                  dict(id="wall_5", a=[1.2, 3.45], b=[1.2, 6], **W)],
        "doors": [{"id": "door_0", "center": [1.2, 3.0], "width": 0.9, "yaw": math.pi / 2,
                   "state": "open", "rooms": ["room_0", "room_1"]}],
        "furniture": [{"id": "furn_0", "category": "table", "synset": "table.n.02",
                       "room": "room_0", "center": [0.6, 5.5, 0.375], "size": [0.6, 0.6, 0.75],
                       "yaw": 0, "affordances": ["supporter"], "state": None}],
        "objects": [{"id": "obj_0", "category": "cup", "synset": "cup.n.01", "parent": "furn_0",
                     "relation": "ontop", "room": "room_0", "position": [0.6, 5.5, 0.8],
                     "size": [0.08, 0.08, 0.1]}],
        "starts": [{"x": 0.6, "y": 1.0, "yaw": 0, "room": "room_0"}],
    }


def test_a_door_without_room_to_swing_is_named_in_the_report(tmp_path: Path) -> None:
    import sgtool

    rep = sgtool.record_house(sgtool.load_house(_two_corridors()), tmp_path / "c.mcap",
                              sgtool.RecordOptions(frames=3, camera=sgtool.CameraConfig(
                                  width=32, height=24)))
    assert rep.taken_away == rep.doors_taken_away == ("door_0",)
    (line,) = [x for x in rep.lines() if x.startswith("open without room to swing")]
    assert "taken out of the simulation: door_0 (the log shows an empty doorway" in line


def test_a_door_with_room_to_swing_is_not(tmp_path: Path) -> None:
    import sgtool

    house = _two_corridors()
    house["rooms"][1]["polygon"] = [[1.2, 0], [4.2, 0], [4.2, 6], [1.2, 6]]  # 3 m wide
    for w in house["walls"]:
        for end in ("a", "b"):
            if w[end][0] == 2.4:
                w[end][0] = 4.2
    rep = sgtool.record_house(sgtool.load_house(house), tmp_path / "c.mcap",
                              sgtool.RecordOptions(frames=3, camera=sgtool.CameraConfig(
                                  width=32, height=24)))
    assert rep.taken_away == ()
    assert not [x for x in rep.lines() if "without room to swing" in x]


def test_a_container_whose_door_cannot_swing_is_worded_as_a_piece(tmp_path: Path) -> None:
    """A cabinet whose door would hit the table in front of it: its door is taken away when
    the tour opens it; the report called that an empty doorway."""
    import sgtool

    house = _two_corridors()
    house["rooms"][1]["polygon"] = [[1.2, 0], [4.2, 0], [4.2, 6], [1.2, 6]]
    for w in house["walls"]:
        for end in ("a", "b"):
            if w[end][0] == 2.4:
                w[end][0] = 4.2
    house["furniture"] += [
        {"id": "furn_1", "category": "cabinet", "synset": "cabinet.n.01", "room": "room_1",
         "center": [3.0, 5.7, 0.45], "size": [0.8, 0.5, 0.9], "yaw": math.pi,
         "affordances": ["openable", "container"], "state": "closed"},
        {"id": "furn_2", "category": "table", "synset": "table.n.02", "room": "room_1",
         "center": [3.0, 5.05, 0.375], "size": [1.6, 0.5, 0.75], "yaw": 0,
         "affordances": ["supporter"], "state": None}]
    house["objects"].append({"id": "obj_1", "category": "apple", "synset": "apple.n.01",
                             "parent": "furn_1", "relation": "inside", "room": "room_1",
                             "position": [3.0, 5.7, 0.3], "size": [0.08, 0.08, 0.08]})
    rep = sgtool.record_house(sgtool.load_house(house), tmp_path / "c.mcap",
                              sgtool.RecordOptions(camera=sgtool.CameraConfig(
                                  width=32, height=24)))
    assert rep.taken_away == ("furn_1",) and rep.doors_taken_away == ()
    (line,) = [x for x in rep.lines() if "to swing" in x]
    assert line.startswith("opened without room for their doors to swing") and \
        "furn_1 (seen open, no door leaf)" in line and "doorway" not in line
