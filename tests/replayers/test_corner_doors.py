"""A door at a room's corner, recorded and replayed: its doorway ends at the wall across
it, with no wall continuing past the opening, and the two rooms it joins stay two."""

from __future__ import annotations

from pathlib import Path

import pytest
from click.testing import CliRunner

pytest.importorskip("pybullet")


def _corner_house(low: float) -> dict:
    """The two 4 m rooms of ``two_rooms`` with their 0.9 m door from ``low`` m up the
    shared wall (0.05: the opening ends at the inner face of the outer wall)."""
    from support.datasets_fixtures import two_rooms

    house = two_rooms()
    walls = [w for w in house["walls"] if w["id"] not in ("wall_4", "wall_5")]
    if low > 0.05:
        walls.append({"id": "wall_4", "a": [4, 0], "b": [4, low], "thickness": 0.1,
                      "height": 2.5})
    walls.append({"id": "wall_5", "a": [4, low + 0.9], "b": [4, 4], "thickness": 0.1,
                  "height": 2.5})
    house["walls"] = walls
    house["doors"][0]["center"] = [4, low + 0.45]
    return house


@pytest.mark.parametrize("low", [0.05, 1.5])
def test_a_door_at_a_rooms_corner_keeps_its_two_rooms(tmp_path: Path, low: float) -> None:
    import sgtool
    from sgtool.cli import cli

    log = tmp_path / "corner.mcap"
    sgtool.record_house(sgtool.load_house(_corner_house(low)), log, sgtool.RecordOptions(
        camera=sgtool.CameraConfig(width=128, height=96)))
    r = CliRunner().invoke(cli, ["replay", str(log), "--score"])
    assert r.exit_code == 0, r.output
    strict = next(line for line in r.output.splitlines() if line.startswith("quality (strict)"))
    assert "rooms 2 vs 2 seen of 2" in strict and "ARI 1.000" in strict, strict
