"""House files that `sgtool bench` / `run-bench` cannot use are refused when the files are
checked, before any episode and any output: an id that cannot name a log folder, a room
without free floor for the robot, a folder without house files among other --house
arguments; *.JSON counts in any case. Log paths never leave their output folder."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest
from click.testing import CliRunner
from support.datasets_fixtures import no_free_floor
from support.foreign_house import cottage, write_cottage

from sgtool.analysis.bench_houses import (
    HouseFilesError,
    load_house_files,
    output_path,
    symbolic_house_problem,
)
from sgtool.analysis.closed_loop_bench import log_path
from sgtool.cli import cli
from sgtool.errors import SgtoolError
from sgtool.house.io import load_house


def test_paths_stay_inside_their_folder(tmp_path: Path) -> None:
    assert output_path(tmp_path, "none", "greedy", "Villa Rosa", "ep-000.mcap") == \
        tmp_path / "none/greedy/Villa Rosa/ep-000.mcap"
    for bad in ("..", ".", "../../ESCAPED", "/tmp/ABSOLUTE", "a\\b", "line\nbreak", "",
                "字" * 90):  # 90 characters, 270 bytes: too long for a file name
        with pytest.raises(SgtoolError, match="cannot name a folder or file inside"):
            output_path(tmp_path, "none", bad)
        with pytest.raises(SgtoolError, match="cannot name a folder or file inside"):
            log_path(tmp_path, "none", "greedy", bad, 0)


def test_an_id_too_long_for_a_folder_name_is_refused_with_the_file(tmp_path: Path) -> None:
    long_id = write_cottage(tmp_path, "long.json", id="字" * 90)
    with pytest.raises(HouseFilesError) as e:
        load_house_files([long_id])
    assert str(e.value) == (f"{long_id}: id: the house id {'字' * 90!r} (its \"id\", else "
                            "the file name) cannot name a log folder: more than 255 bytes "
                            "as a file name")


@pytest.mark.parametrize("house_id", ["../../ESCAPED", "/tmp/ABSOLUTE"])
def test_run_bench_writes_nothing_for_an_id_that_leaves_the_folder(tmp_path: Path,
                                                                    house_id: str) -> None:
    f = write_cottage(tmp_path / "h", "x.json", id=house_id)
    out = tmp_path / "a" / "b" / "rb"
    res = CliRunner().invoke(cli, ["run-bench", "--houses", "0", "--house", str(f),
                                   "--planners", "greedy", "--episodes", "1", "--resolution",
                                   "64x48", "--frames", "10", "--no-progress", "-o", str(out)])
    assert res.exit_code == 2 and "Traceback" not in res.output
    assert len(res.output.strip().splitlines()) == 1 and str(f) in res.output
    assert "id" in res.output
    assert not (tmp_path / "a").exists() and not (tmp_path / "ESCAPED").exists()


def test_a_room_without_free_floor_is_refused_before_any_episode(tmp_path: Path) -> None:
    f = tmp_path / "tiny.json"
    f.write_text(json.dumps(no_free_floor()))
    line = (f"{f}: rooms: room room_0 has no free floor (no cell where the robot fits) and "
            "no door or passage to a room that has")
    assert symbolic_house_problem(load_house(f), f) == line
    assert symbolic_house_problem(load_house(cottage()), "cottage") is None
    with pytest.raises(HouseFilesError) as e:
        load_house_files([f])
    assert str(e.value) == line
    for cmd in (["bench", "--seeds", "1"], ["run-bench", "--resolution", "64x48"]):
        out = tmp_path / cmd[0]
        res = CliRunner().invoke(cli, [*cmd, "--houses", "0", "--house", str(f),
                                       "--planners", "random", "--episodes", "1",
                                       "--no-progress", "-o", str(out)])
        assert res.exit_code == 2 and res.output.strip() == f"sgtool: error: {line}"
        assert not out.exists()


def test_folders_empty_among_others_and_upper_case_suffixes(tmp_path: Path) -> None:
    good = write_cottage(tmp_path / "good")
    (tmp_path / "empty").mkdir()
    (tmp_path / "empty" / "notes.txt").write_text("no house")
    with pytest.raises(HouseFilesError) as e:
        load_house_files([tmp_path / "empty", good])
    assert str(e.value) == f"{tmp_path / 'empty'}: no *.json house files there"
    upper = write_cottage(tmp_path / "upper", "HOUSE.JSON")
    write_cottage(tmp_path / "upper", "b.Json", id="other")
    houses = load_house_files([tmp_path / "upper"])
    assert [(h.id, h.source) for h in houses] == [("HOUSE", str(upper)),
                                                  ("other", str(tmp_path / "upper/b.Json"))]


def test_a_container_facing_a_wall_and_a_cramped_start_are_noted(tmp_path: Path) -> None:
    """A fridge set with its front (local +y) to the wall, as a yaw of 0 does for a piece
    against a north wall, and a start 0.07 m from a wall: `scenes check` says both (the
    symbolic bench finds what is inside; the closed loop could not look in)."""
    from support.datasets_fixtures import two_rooms

    d = two_rooms()
    d["furniture"][0]["yaw"] = 0.0  # the fridge at the north wall, its front to the wall
    d["starts"][0].update(x=0.12, y=1.0)  # the west wall's face is at x = 0.05
    f = tmp_path / "h.json"
    f.write_text(json.dumps(d))
    r = CliRunner().invoke(cli, ["scenes", "check", str(f)])
    assert r.exit_code == 0, r.output
    assert ("furniture[0] (furn_0, refrigerator): the room's border is within 0.3 m of its "
            "front (its local +y face, where it opens); the closed loop cannot look into it "
            "(turn it to face the room: yaw + pi)") in r.output
    assert "starts[0] (0.12, 1): 0.07 m from a wall or a piece, less than the robot's radius "\
        "(0.2 m)" in r.output
    d["furniture"][0]["yaw"] = 3.14159  # facing the room: nothing to say
    d["starts"][0].update(x=1.0)
    f.write_text(json.dumps(d))
    r = CliRunner().invoke(cli, ["scenes", "check", str(f)])
    assert r.exit_code == 0 and "note:" not in r.output, r.output
    d["furniture"][0]["yaw"] = 180  # degrees by mistake
    f.write_text(json.dumps(d))
    r = CliRunner().invoke(cli, ["scenes", "check", str(f)])
    assert "yaw beyond 2 pi: furniture[0] (180); yaws are radians" in r.output


def test_a_closed_box_holding_things_is_noted(tmp_path: Path) -> None:
    """A closed lidded box with a tin inside: the symbolic bench opens it, the closed loop
    (which opens furniture only) cannot, and `scenes check` says so."""
    from support.nested_house import nested_house

    f = tmp_path / "nested.json"
    f.write_text(json.dumps(nested_house()))
    r = CliRunner().invoke(cli, ["scenes", "check", str(f)])
    assert r.exit_code == 0, r.output
    assert "obj_box (" in r.output and "the closed loop cannot (it opens furniture only)" \
        in r.output


def test_a_door_with_no_wall_beside_it_at_a_corner_gets_a_note() -> None:
    """A door whose opening ends at a room's corner (its panel swung along the side wall):
    the replay merged the two rooms, with no word at check time. A door 0.1 m from the
    corner has no note."""
    import dataclasses

    from support.datasets_fixtures import two_rooms

    from sgtool.analysis.bench_houses import house_notes, symbolic_house
    from sgtool.house.io import load_house

    spec = load_house(two_rooms())
    d = spec.doors[0]
    ys = [p[1] for r in d.rooms for p in spec.room(r).polygon]
    at = dataclasses.replace(d, center=(d.center[0], min(ys) + d.width / 2))
    for door, noted in ((at, True), (dataclasses.replace(
            at, center=(d.center[0], min(ys) + d.width / 2 + 0.1)), False)):
        house, bad = symbolic_house(dataclasses.replace(spec, doors=(door,)), "h.json")
        assert bad is None
        said = [n for n in house_notes(house) if "from a corner of" in n]
        assert bool(said) == noted, said


def test_a_front_blocked_by_a_piece_of_a_corner_says_to_move_that_piece() -> None:
    """A fridge backed against the north wall whose front a counter along the west wall
    blocks (as the generator's kitchens had it before it kept fronts clear): turning it
    (yaw + pi) would face the wall; the note says to move the counter instead. A basket
    standing on the bedroom's table, its front over the table top, is not blocked by the
    table under it."""
    from support.datasets_fixtures import two_rooms

    from sgtool.analysis.bench_houses import house_notes, symbolic_house
    from sgtool.house.io import load_house

    d = two_rooms()
    d["furniture"] += [
        {"id": "furn_2", "category": "countertop", "synset": "countertop.n.01",
         "room": "room_0", "center": [0.35, 2.5, 0.45], "size": [1.2, 0.6, 0.9],
         "yaw": -math.pi / 2, "affordances": ["supporter"], "state": None},
        {"id": "furn_3", "category": "wicker basket", "synset": "wicker_basket.n.01",
         "room": "room_1", "center": [6.0, 3.2, 0.9], "size": [0.3, 0.3, 0.3], "yaw": 0.0,
         "affordances": ["container"], "state": None}]
    house, bad = symbolic_house(load_house(d), "h.json")
    fronts = [n for n in house_notes(house) if "cannot look into it" in n]
    assert bad is None
    assert fronts == ["furniture[0] (furn_0, refrigerator): furn_2 is within 0.3 m of its front "
                      "(its local +y face, where it opens); the closed loop cannot look into "
                      "it (move furn_2 away from it)"], fronts


def test_a_hole_in_the_wall_beside_a_closed_door_is_noted(tmp_path: Path) -> None:
    """The cottage's closed bedroom door with the wall north of it left out (a 1.55 m hole
    from y 2.45 to 4, centre 3.225): the robot walks past the closed door; `scenes check`
    says where. The cottage as written (walls up to both door jambs) has no such note, and room
    categories the replay's classifier never names are noted too."""
    doc = cottage()
    doc["walls"] = [w for w in doc["walls"] if w["a"] != [6, 2.45]]
    doc["rooms"][0]["category"] = "Lounge"
    f = write_cottage(tmp_path, "holed.json", walls=doc["walls"], rooms=doc["rooms"])
    r = CliRunner().invoke(cli, ["scenes", "check", str(f), str(write_cottage(tmp_path))])
    assert r.exit_code == 0, r.output
    holed, whole = r.output.split("ok ")[1:]
    assert "the walls between room_bed and room_hall have a 1.55 m gap at (6.00, 3.22) " \
        "beside their door(s)" in holed
    assert "room categories 'Lounge': not a room type the replay's room classifier names" \
        in holed and "living room" in holed
    assert "gap" not in whole and "room categories" not in whole
