"""ProcTHOR's room annotations as containment targets: reading, levels, targets, shipped table."""

from __future__ import annotations

import json
import zipfile

import pytest

from sgtool.datasets.room_annotations import (
    MEMBER,
    SHIPPED,
    SOMETIMES,
    annotation_levels,
    load_levels,
    main,
    read_annotations,
    room_targets,
)
from sgtool.errors import SgtoolError

DATA = {
    "inKitchens": {"SoapBar": 0, "AlarmClock": 0, "Window": None, "Statue": 0},
    "inLivingRooms": {"SoapBar": 0, "AlarmClock": 1, "Window": None, "Statue": 0},
    "inBedrooms": {"SoapBar": 0, "AlarmClock": 2, "Window": None, "Statue": 0},
    "inBathrooms": {"SoapBar": 2, "AlarmClock": 0, "Window": None, "Statue": 0},
}


def test_levels_keep_types_placed_somewhere_and_annotated_everywhere() -> None:
    assert annotation_levels(DATA) == {
        "alarm clock": {"bathroom": 0, "bedroom": 2, "kitchen": 0, "living_room": 1},
        "soap bar": {"bathroom": 2, "bedroom": 0, "kitchen": 0, "living_room": 0},
    }  # the window (null) and the statue (placed nowhere) are left out


def test_targets_of_the_levels() -> None:
    t = room_targets(annotation_levels(DATA))
    assert t["alarm clock"] == {"bathroom": 0.0, "bedroom": 1.0, "kitchen": 0.0,
                                "living_room": SOMETIMES}


def test_read_from_a_file_or_a_wheel_and_fail_in_one_line(tmp_path) -> None:
    f = tmp_path / "placement-annotations.json"
    f.write_text(json.dumps(DATA))
    assert read_annotations(f) == DATA
    whl = tmp_path / "procthor-0.0.1.dev2-py3-none-any.whl"
    with zipfile.ZipFile(whl, "w") as z:
        z.writestr(MEMBER, json.dumps(DATA))
    assert read_annotations(whl) == DATA
    f.write_text(json.dumps({"inKitchens": {}}))
    with pytest.raises(SgtoolError, match="lack one of"):
        read_annotations(f)
    with pytest.raises(SgtoolError, match="cannot read"):
        read_annotations(tmp_path / "missing.json")


def test_cli_writes_the_table_it_reads_back(tmp_path, capsys) -> None:
    src, out = tmp_path / "a.json", tmp_path / "t.json"
    src.write_text(json.dumps(DATA))
    assert main(["--source", str(src), "--out", str(out)]) == 0
    assert load_levels(out) == annotation_levels(DATA)
    assert main(["--source", str(tmp_path / "none.json"), "--out", str(out)]) == 2
    assert "cannot read" in capsys.readouterr().err


def test_the_shipped_table() -> None:
    levels = load_levels(SHIPPED)
    assert len(levels) == 103
    assert levels["soap bar"]["bathroom"] == 2 and levels["teddy bear"]["bedroom"] == 1
    assert all(set(r) == {"kitchen", "living_room", "bedroom", "bathroom"}
               for r in levels.values())
