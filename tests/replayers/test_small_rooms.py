"""A 1.3 m closet off a room, recorded and replayed: its open floor outside its door's cut
zone is under 1 m^2 (0.56), and the closet merged into the room (its shelf and hat put there, the
room then named after them). A short room needs 0.5 m^2 of floor of its own."""

from __future__ import annotations

from pathlib import Path

import pytest
from click.testing import CliRunner

pytest.importorskip("pybullet")

W = {"thickness": 0.1, "height": 2.5}


def _room_and_closet() -> dict:
    return {
        "version": "1.0", "seed": 5,
        "rooms": [
            {"id": "room_0", "category": "living_room",
             "polygon": [[0, 0], [4, 0], [4, 4], [0, 4]]},
            {"id": "room_1", "category": "closet",
             "polygon": [[4, 0], [5.3, 0], [5.3, 1.3], [4, 1.3]]}],
        "walls": [dict(id="wall_0", a=[0, 0], b=[5.3, 0], **W),
                  dict(id="wall_1", a=[4, 0], b=[4, 0.35], **W),
                  dict(id="wall_2", a=[4, 1.15], b=[4, 4], **W),
                  dict(id="wall_3", a=[4, 4], b=[0, 4], **W),
                  dict(id="wall_4", a=[0, 4], b=[0, 0], **W),
                  dict(id="wall_5", a=[5.3, 0], b=[5.3, 1.3], **W),
                  dict(id="wall_6", a=[5.3, 1.3], b=[4, 1.3], **W)],
        "doors": [{"id": "door_0", "center": [4, 0.75], "width": 0.8, "yaw": 1.570796,
                   "state": "open", "rooms": ["room_0", "room_1"]}],
        "furniture": [
            {"id": "furn_0", "category": "coffee table", "synset": "coffee_table.n.01",
             "room": "room_0", "center": [2.0, 2.5, 0.225], "size": [1.1, 0.6, 0.45],
             "yaw": 0.0, "affordances": ["supporter"], "state": None},
            {"id": "furn_1", "category": "shelf", "synset": "shelf.n.01", "room": "room_1",
             "center": [5.1, 0.75, 0.75], "size": [0.6, 0.3, 1.5], "yaw": 1.570796,
             "affordances": ["supporter"], "state": None}],
        "objects": [
            {"id": "obj_0", "category": "candle", "synset": "candle.n.01", "parent": "furn_0",
             "relation": "ontop", "room": "room_0", "position": [2.0, 2.5, 0.51],
             "size": [0.08, 0.08, 0.12]},
            {"id": "obj_1", "category": "hat", "synset": "hat.n.01", "parent": "furn_1",
             "relation": "ontop", "room": "room_1", "position": [5.1, 0.75, 1.56],
             "size": [0.3, 0.25, 0.12]}],
        "starts": [{"x": 1.0, "y": 1.0, "yaw": 0.0, "room": "room_0"}],
    }


def test_a_closet_of_one_point_three_metres_stays_a_room(tmp_path: Path) -> None:
    import sgtool
    from sgtool.cli import cli

    log = tmp_path / "closet.mcap"
    sgtool.record_house(sgtool.load_house(_room_and_closet()), log, sgtool.RecordOptions(
        camera=sgtool.CameraConfig(width=128, height=96)))
    r = CliRunner().invoke(cli, ["replay", str(log), "--score"])
    assert r.exit_code == 0, r.output
    strict = next(line for line in r.output.splitlines() if line.startswith("quality (strict)"))
    assert "rooms 2 vs 2 seen of 2" in strict and "objects in the right room 100.0%" in strict, \
        strict
