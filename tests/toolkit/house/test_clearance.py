"""Pieces no camera sees (sgtool.house.clearance.hidden_pieces): a box under the floor, or
inside another piece's box; what they hold is found by the symbolic bench only, so
`scenes check` and the bench name them."""

from __future__ import annotations

import copy
import math

from support.datasets_fixtures import two_rooms

from sgtool.house.clearance import hidden_pieces, pieces_in_walls, walls_in_rooms
from sgtool.house.io import load_house


def test_a_sunk_or_enclosed_piece_is_hidden_and_a_standing_one_is_not() -> None:
    d = two_rooms()
    assert hidden_pieces(load_house(d)) == []
    sunk = copy.deepcopy(d)
    sunk["furniture"][1]["center"][2] = -0.5  # the table's top at -0.125
    for o in sunk["objects"]:
        if o["parent"] == "furn_1":
            o["position"][2] -= 0.875
    assert hidden_pieces(load_house(sunk)) == [
        (1, "its box lies under the floor (top at z = -0.125 m)")]
    walled = copy.deepcopy(d)
    walled["furniture"].append({
        "id": "furn_2", "category": "wardrobe", "synset": "wardrobe.n.01", "room": "room_1",
        "center": [6.0, 3.4, 1.0], "size": [1.6, 1.2, 2.0], "yaw": 0,
        "affordances": [], "state": None})
    assert hidden_pieces(load_house(walled)) == [
        (1, "its box lies inside furniture[2] (furn_2, wardrobe)")]
    # a piece on top of another, or beside it, is seen
    on_top = copy.deepcopy(walled)
    on_top["furniture"][2]["center"] = [6.0, 3.4, 1.75]  # from 0.75 up: above the table
    assert hidden_pieces(load_house(on_top)) == []


def test_scenes_check_names_a_hidden_piece(tmp_path) -> None:
    import json

    from click.testing import CliRunner

    from sgtool.cli import cli

    d = two_rooms()
    d["furniture"][1]["center"][2] = -0.5
    for o in d["objects"]:
        if o["parent"] == "furn_1":
            o["position"][2] -= 0.875
    f = tmp_path / "sunk.json"
    f.write_text(json.dumps(d))
    r = CliRunner().invoke(cli, ["scenes", "check", str(f)])
    assert r.exit_code == 0, r.output
    assert "furniture[1] (furn_1, table): its box lies under the floor" in r.output


def test_a_piece_through_a_wall_is_named_and_one_against_it_is_not(tmp_path) -> None:
    """The refrigerator (0.8 x 0.7 m) pushed through the 0.1 m wall at x = 0 (to x =
    -0.08, within the 0.1 m a piece may stand outside its room) has 0.03 x 0.7 = 0.021
    m^2 of its footprint past the wall's far face (x < -0.05); set against its face (x
    from 0.05) or into its body up to the room's border (x from 0) it has none."""
    import json

    from click.testing import CliRunner

    from sgtool.cli import cli

    d = two_rooms()
    assert pieces_in_walls(load_house(d)) == []
    against = copy.deepcopy(d)
    for x in (0.45, 0.4):
        against["furniture"][0]["center"][0] = x
        assert pieces_in_walls(load_house(against)) == []
    through = copy.deepcopy(d)
    through["furniture"][0]["center"][0] = 0.32
    for o in through["objects"]:
        if o["parent"] == "furn_0":
            o["position"][0] -= 0.18
    (k, wall, area, depth), = pieces_in_walls(load_house(through))
    assert (k, wall) == (0, "wall_2") and abs(area - 0.021) < 1e-9
    assert abs(depth - 0.03) < 1e-5  # yaw pi: corners within float noise
    f = tmp_path / "through.json"
    f.write_text(json.dumps(through))
    r = CliRunner().invoke(cli, ["scenes", "check", str(f)])
    assert r.exit_code == 0, r.output
    assert "furniture[0] (furn_0, refrigerator): 0.02 m² of its footprint lies past " \
        "wall_2's far face, up to 0.03 m" in r.output


def test_a_corner_turned_through_a_thin_wall_is_named() -> None:
    """The refrigerator turned 45 degrees (its half-extent along x (0.8 + 0.7) / 2 /
    sqrt(2) = 0.530 m) at x = 0.435 pokes one corner to x = -0.095 through a 2 cm wall at
    x = 0 (far face x = -0.01): 0.085 m deep but only 0.085^2 = 0.0072 m^2 past the face,
    under the area rule; the depth rule names it. Turned the other way round against the
    face (x = 0.54, corner at x = 0.01) it reaches nothing."""
    d = two_rooms()
    next(w for w in d["walls"] if w["id"] == "wall_2")["thickness"] = 0.02
    turned = copy.deepcopy(d)
    fridge = turned["furniture"][0]
    fridge["yaw"] = math.pi / 4
    fridge["center"][0] = 0.435
    for o in turned["objects"]:
        if o["parent"] == "furn_0":
            o["position"][0] = 0.435
            o["position"][1] = fridge["center"][1]
    (k, wall, area, depth), = pieces_in_walls(load_house(turned))
    assert (k, wall) == (0, "wall_2")
    assert abs(depth - 0.085) < 1e-3 and abs(area - 0.085 ** 2) < 1e-3 < 0.01
    fridge["center"][0] = 0.54
    for o in turned["objects"]:
        if o["parent"] == "furn_0":
            o["position"][0] = 0.54
    assert pieces_in_walls(load_house(turned)) == []


def test_a_wall_through_a_rooms_inside_is_named(tmp_path) -> None:
    """Walls run along rooms' borders; one from (5, 1) to (5, 3) stands 1 m inside room_1
    (x 4-8): 2.0 m of it farther than 0.15 m from the border."""
    import json

    from click.testing import CliRunner

    from sgtool.cli import cli

    d = two_rooms()
    assert walls_in_rooms(load_house(d)) == []
    d["walls"].append({"id": "wall_9", "a": [5.0, 1.0], "b": [5.0, 3.0], "thickness": 0.1,
                       "height": 2.5})
    (room, walls, inside), = walls_in_rooms(load_house(d))
    assert (room, walls) == ("room_1", (6,)) and abs(inside - 2.0) < 1e-9
    pieces = copy.deepcopy(d)  # the same wall drawn as eight 0.25 m pieces
    pieces["walls"][6:] = [{"id": f"wall_{9 + k}", "a": [5.0, 1.0 + 0.25 * k],
                            "b": [5.0, 1.25 + 0.25 * k], "thickness": 0.1, "height": 2.5}
                           for k in range(8)]
    (room, walls, inside), = walls_in_rooms(load_house(pieces))
    assert (room, walls) == ("room_1", tuple(range(6, 14))) and abs(inside - 2.0) < 1e-9
    f = tmp_path / "cut.json"
    f.write_text(json.dumps(d))
    r = CliRunner().invoke(cli, ["scenes", "check", str(f)])
    assert r.exit_code == 0, r.output
    assert "walls[6] (wall_9) run 2.0 m through room_1's inside" in r.output


def test_a_start_against_a_wall_is_moved_clear_in_its_own_room() -> None:
    """A start 0.02 m from the shared wall (x = 4, 0.05 m thick each side) moves straight
    away from it, to where the robot's 0.2 m disc touches nothing, staying in its room; a
    clear start stays where it is."""
    from sgtool.house.clearance import Covers, clear_start, cramped_starts

    spec = load_house(two_rooms())
    x, y = clear_start(spec, 3.93, 3.0, 0.2)  # the wall's face at x = 3.95
    assert (x, y) != (3.93, 3.0) and x < 4.0  # still in room_0
    assert Covers(spec).gap(x, y, 0.2) >= 0.2
    assert abs(y - 3.0) < 0.05 and 3.70 <= x <= 3.76  # the nearest place: 0.2 m off the face
    assert clear_start(spec, 2.0, 2.0, 0.2) == (2.0, 2.0)
    d = two_rooms()
    d["starts"] = [{"x": 3.93, "y": 3.0, "yaw": 0.0, "room": "room_0"}]
    assert [i for i, _ in cramped_starts(load_house(d), 0.2)] == [0]
