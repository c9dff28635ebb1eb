"""`sgtool record` on a house file without start poses: it gets one per reachable room, as
`sgtool bench` gives it (sgtool.datasets.start_poses.with_start_poses); a house where none
can be made is refused in one line naming the file and saying what to add."""

from __future__ import annotations

import json
from pathlib import Path

from click.testing import CliRunner
from support.foreign_house import write_cottage

from sgtool.cli import cli
from sgtool.datasets.start_poses import with_start_poses
from sgtool.house.io import load_house
from sgtool.log.reader import LogReader

ARGS = ["record", "--resolution", "64x48", "--frames", "5", "--quiet"]


def test_a_house_without_starts_is_recorded_from_the_bench_start(tmp_path: Path) -> None:
    house = write_cottage(tmp_path)  # "starts": []
    out = tmp_path / "c.mcap"
    res = CliRunner().invoke(cli, [*ARGS, "--house", str(house), "--start", "2", "-o",
                                   str(out)])
    assert res.exit_code == 0, res.output
    spec = load_house(house)
    with LogReader(out) as r:
        logged = load_house(json.loads(r.house_json() or "{}"))
    assert logged.starts == with_start_poses(spec, spec.seed).starts and len(logged.starts) == 3


def test_a_house_where_no_start_can_be_made_is_refused(tmp_path: Path) -> None:
    tiny = tmp_path / "tiny.json"
    tiny.write_text(json.dumps({
        "version": "2.0", "rooms": [{"id": "room_0", "category": "kitchen",
                                     "polygon": [[0, 0], [0.6, 0], [0.6, 0.6], [0, 0.6]]}],
        "furniture": [{"id": "furn_0", "category": "cabinet", "synset": "cabinet.n.01",
                       "room": "room_0", "center": [0.3, 0.3, 0.45], "size": [0.5, 0.5, 0.9],
                       "affordances": ["supporter"]}],
        "objects": [], "walls": [], "doors": [], "starts": []}))
    out = tmp_path / "t.mcap"
    res = CliRunner().invoke(cli, [*ARGS, "--house", str(tiny), "-o", str(out)])
    assert res.exit_code == 2 and not out.exists()
    assert res.output.strip() == (
        f"sgtool: error: {tiny}: starts: none given, and none can be made (no free floor "
        "reachable from the first room); add a \"starts\" entry")


def test_run_on_a_house_without_starts_starts_where_bench_would(tmp_path: Path) -> None:
    """`sgtool run` gives a house file without starts the same start poses as record."""
    house = write_cottage(tmp_path)  # "starts": []
    out = tmp_path / "run.mcap"
    res = CliRunner().invoke(cli, ["run", "--planner", "random", "--house", str(house),
                                   "--episode", "0", "--frames", "30", "--resolution", "64x48",
                                   "--quiet", "-o", str(out)])
    assert res.exit_code == 0, res.output
    spec = load_house(house)
    with LogReader(out) as r:
        logged = load_house(json.loads(r.house_json() or "{}"))
    assert logged.starts == with_start_poses(spec, spec.seed).starts


def test_a_start_against_a_wall_is_recorded_from_clear_of_it(tmp_path: Path) -> None:
    """A start pose 0.02 m from a wall would put the camera's near plane past the wall: the
    robot starts at the nearest place clear of it, and the log says where."""
    from support.datasets_fixtures import two_rooms

    from sgtool.house.clearance import Covers

    d = two_rooms()
    d["starts"] = [{"x": 3.93, "y": 3.0, "yaw": 0.0, "room": "room_0"}]
    house = tmp_path / "h.json"
    house.write_text(json.dumps(d))
    out = tmp_path / "h.mcap"
    res = CliRunner().invoke(cli, [*ARGS, "--house", str(house), "-o", str(out)])
    assert res.exit_code == 0, res.output
    with LogReader(out) as r:
        x, y, _ = next(iter(r.records("episode")))[1]["extra"]["start_pose"]
    assert x < 3.93 and Covers(load_house(d)).gap(x, y, 0.2) >= 0.2
