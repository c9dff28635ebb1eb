"""A house file without walls: the simulator stands walls along its outer outline
(sgtool.house.outline), outside the rooms, none between rooms that meet; the closed
loop then searches it as a walled house (it drove at the void
before: frontiers the robot could never reach)."""

from __future__ import annotations

import json
import math

import pytest
from click.testing import CliRunner
from support.datasets_fixtures import two_rooms

from sgtool.cli import cli
from sgtool.house.io import load_house
from sgtool.house.outline import outline_walls


def _ends(walls):
    return sorted((tuple(round(v, 3) for v in w.a), tuple(round(v, 3) for v in w.b))
                  for w in walls)


def test_two_rooms_get_six_walls_outside_and_none_between() -> None:
    d = two_rooms()
    d["walls"], d["doors"] = [], []
    walls = outline_walls(load_house(d))
    # each room's three outer sides, their inner faces on the border (no floor covered)
    assert len(walls) == 6 and all(w.thickness == 0.1 for w in walls)
    assert not any(abs(w.a[0] - 4) < 0.2 and abs(w.b[0] - 4) < 0.2 for w in walls)
    assert sum(math.dist(w.a, w.b) for w in walls) == pytest.approx(3 * 4 * 2, abs=1e-6)
    assert ((0.0, -0.05), (4.0, -0.05)) in _ends(walls)


def test_an_l_shaped_room_gets_no_wall_on_its_floor() -> None:
    """A room with a reflex corner, either winding: every wall lies outside the floor."""
    from sgtool.house.spec import HouseSpec, Room

    ell = ((0.0, 0.0), (4.0, 0.0), (4.0, 2.0), (2.0, 2.0), (2.0, 4.0), (0.0, 4.0))
    for poly in (ell, ell[::-1]):
        spec = HouseSpec(seed=0, rooms=(Room("room_0", "kitchen", poly),), walls=(),
                         doors=(), furniture=(), objects=(), starts=())
        walls = outline_walls(spec)
        assert len(walls) == 6
        for w in walls:
            mid = ((w.a[0] + w.b[0]) / 2, (w.a[1] + w.b[1]) / 2)
            assert not spec.rooms[0].contains(*mid)


ONE_ROOM = {  # a kitchen without walls, a bowl in a closed cabinet (a review's house)
    "version": "2.0", "seed": 1,
    "rooms": [{"id": "room_0", "category": "kitchen",
               "polygon": [[0, 0], [4, 0], [4, 4], [0, 4]]}],
    "walls": [], "doors": [],
    "furniture": [
        {"id": "furn_0", "category": "table", "synset": "table.n.01", "room": "room_0",
         "center": [2, 2, 0.45], "size": [0.8, 0.6, 0.9], "yaw": 0.0,
         "affordances": ["supporter"], "state": None},
        {"id": "furn_1", "category": "cabinet", "synset": "cabinet.n.01", "room": "room_0",
         "center": [3.5, 0.4, 0.45], "size": [0.8, 0.6, 0.9], "yaw": 0.0,
         "affordances": ["container", "openable"], "state": "closed"}],
    "objects": [
        {"id": "obj_0", "category": "mug", "synset": "mug.n.01", "parent": "furn_0",
         "relation": "ontop", "room": "room_0", "position": [2, 2, 0.95],
         "size": [0.1, 0.1, 0.1]},
        {"id": "obj_1", "category": "bowl", "synset": "bowl.n.01", "parent": "furn_1",
         "relation": "inside", "room": "room_0", "position": [3.5, 0.4, 0.45],
         "size": [0.1, 0.1, 0.1]}],
    "starts": [{"x": 1, "y": 1, "yaw": 0, "room": "room_0"}],
}


def test_the_closed_loop_searches_a_house_without_walls(tmp_path) -> None:
    """Without walls the robot spent its steps driving at frontiers into the void and
    never opened the cabinet (15 m driven, not found); with the outline's walls it opens
    it."""
    house = tmp_path / "open.json"
    house.write_text(json.dumps(ONE_ROOM))
    r = CliRunner().invoke(cli, ["scenes", "check", str(house)])
    assert "no walls: the closed loop stands 4 along the house's outer outline" in r.output
    out = tmp_path / "run.mcap"
    r = CliRunner().invoke(cli, ["run", "--house", str(house), "--planner", "scout",
                                 "--query", "bowl", "--max-steps", "12", "-o", str(out)])
    assert r.exit_code == 0, r.output
    assert "found after" in r.output and "1 opened" in r.output, r.output
