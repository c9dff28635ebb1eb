"""`sgtool run --frames-per-room N`: the frame budget is N x the house's room count; with
--frames too it is a one-line error and nothing is written."""

from __future__ import annotations

from click.testing import CliRunner

from sgtool.cli import cli
from sgtool.datasets.generator import generate_house
from sgtool.house.io import save_house
from sgtool.log import LogReader

BASE = ["run", "--planner", "greedy", "--resolution", "64x48", "--quiet"]


def test_frames_per_room_sets_the_budget(tmp_path) -> None:
    house = tmp_path / "small.json"
    spec = generate_house(6, rooms=(4, 4))
    save_house(spec, house)
    out = tmp_path / "ep.mcap"
    r = CliRunner().invoke(cli, [*BASE, "--house", str(house), "--frames-per-room", "10",
                                 "-o", str(out)])
    assert r.exit_code == 0, r.output
    with LogReader(out) as log:
        started = next(e for _, e in log.records("episode"))
        assert started["extra"]["frame_budget"] == 10 * len(spec.rooms) == 40
        assert log.frame_count() <= 40


def test_frames_and_frames_per_room_exclude_each_other(tmp_path) -> None:
    out = tmp_path / "ep.mcap"
    r = CliRunner().invoke(cli, [*BASE, "--seed", "6", "--rooms", "4-4", "--frames", "100",
                                 "--frames-per-room", "10", "-o", str(out)])
    assert r.exit_code == 2 and r.output.count("\n") == 1
    assert "either --frames or --frames-per-room" in r.output and "Traceback" not in r.output
    assert not out.exists() and not list(tmp_path.glob("*.partial"))
