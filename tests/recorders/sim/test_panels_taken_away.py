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
    assert rep.taken_away == ("door_0",)
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
