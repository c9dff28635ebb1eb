"""Pieces no camera sees (sgtool.house.clearance.hidden_pieces): a box under the floor, or
inside another piece's box; what they hold is found by the symbolic bench only, so
`scenes check` and the bench name them."""

from __future__ import annotations

import copy

from support.datasets_fixtures import two_rooms

from sgtool.house.clearance import hidden_pieces
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
