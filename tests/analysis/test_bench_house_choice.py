"""Which houses ``sgtool bench --house`` benches, and the messages about house files: the
generated houses are opt-in next to the user's own, a stray JSON file in a house folder
says that the folder is read as houses, a furniture message names the piece's id."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from click.testing import CliRunner
from support.foreign_house import cottage, write_cottage

from sgtool.analysis.bench_houses import HouseFilesError, generated_count, load_house_files
from sgtool.cli import cli
from sgtool.errors import SpecError
from sgtool.house.io import load_house

TINY = ["bench", "--episodes", "1", "--seeds", "1", "--planners", "random", "--rooms", "4-5",
        "--preset", "default", "--no-progress"]


def test_generated_houses_are_opt_in_next_to_house_files() -> None:
    assert generated_count(None, (), 10) == 10
    assert generated_count(None, ("h.json",), 10) == 0
    assert generated_count(2, ("h.json",), 10) == 2
    assert generated_count(0, (), 10) == 0  # refused later: no house at all


def _houses(out: Path) -> list[str]:
    return [h["id"] for h in json.loads((out / "summary.json").read_text())["houses"]]


def test_bench_of_a_house_folder_benches_those_houses_only(tmp_path: Path) -> None:
    folder = tmp_path / "houses"
    write_cottage(folder)
    r = CliRunner().invoke(cli, [*TINY, "--house", str(folder), "-o", str(tmp_path / "a")])
    assert r.exit_code == 0, r.output
    assert _houses(tmp_path / "a") == ["cottage"]  # was: 10 generated houses + cottage
    assert "generated" not in r.output.splitlines()[0]
    # generated houses join when asked for
    r = CliRunner().invoke(cli, [*TINY, "--house", str(folder), "--houses", "1",
                                 "-o", str(tmp_path / "b")])
    assert r.exit_code == 0, r.output
    assert _houses(tmp_path / "b") == ["house-0", "cottage"]


def test_a_stray_json_file_in_a_house_folder_says_how_folders_are_read(tmp_path: Path) -> None:
    folder = tmp_path / "houses"
    write_cottage(folder)
    stray = folder / "manifest.json"
    stray.write_text(json.dumps({"files": ["cottage.json"]}))
    with pytest.raises(HouseFilesError) as e:
        load_house_files([folder])
    (line,) = str(e.value).splitlines()
    assert line.startswith(f"{stray}: version: missing")
    assert f"every *.json in {folder} is one" in line and "--house FILE" in line
    # through the command: one line, nothing run
    r = CliRunner().invoke(cli, [*TINY, "--house", str(folder), "-o", str(tmp_path / "o")])
    assert r.exit_code == 2 and len(r.output.strip().splitlines()) == 1
    assert "every *.json in" in r.output and not (tmp_path / "o").exists()
    # a house file given by name has no such note, nor has a broken house in a folder
    with pytest.raises(HouseFilesError) as e:
        load_house_files([stray])
    assert "every *.json" not in str(e.value)
    stray.unlink()
    broken = write_cottage(folder, "broken.json", version="9.0")
    with pytest.raises(HouseFilesError) as e:
        load_house_files([folder])
    assert str(e.value).startswith(f"{broken}: version:") and "every *.json" not in str(e.value)


def test_a_furniture_message_names_the_pieces_id() -> None:
    d = cottage()
    d["furniture"][1]["size"] = [1.6, 0, 0.9]
    with pytest.raises(SpecError) as e:
        load_house(d)
    assert str(e.value).startswith("furniture[1].size: every side must be > 0")
    assert str(e.value).endswith("(furniture[1] is 'furn_counter')")
    d = cottage()
    d["furniture"][3]["center"] = [20.0, 2.0, 0.3]  # outside its room (and every room)
    with pytest.raises(SpecError) as e:
        load_house(d)
    assert str(e.value).startswith("furniture[3].center:")
    assert "(furniture[3] is 'furn_bed')" in str(e.value)
    d = cottage()
    d["furniture"][4]["center"] = [9.9, 3.5, 1.0]  # a corner 0.2 m through the wall
    with pytest.raises(SpecError) as e:
        load_house(d)
    assert str(e.value).startswith("furniture[4].size: a corner")
    assert str(e.value).endswith("(furniture[4] is 'furn_wardrobe')")
    d = cottage()
    d["furniture"][2]["id"] = "furn/bench"  # a message about the id itself: no note
    with pytest.raises(SpecError) as e:
        load_house(d)
    assert str(e.value).startswith("furniture[2].id:") and " is '" not in str(e.value)
