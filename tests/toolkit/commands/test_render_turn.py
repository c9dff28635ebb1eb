"""`sgtool run --render-turn DEG`: a tick that turns the robot on the spot is a frame only
once the camera turned DEG degrees since the last frame; the setting is logged, and a
value out of range is a one-line usage error with nothing written."""

from __future__ import annotations

from click.testing import CliRunner

from sgtool.cli import cli
from sgtool.log import LogReader

BASE = ["run", "--planner", "greedy", "--resolution", "64x48", "--quiet", "--seed", "6",
        "--rooms", "4-4", "--max-steps", "1"]


def test_a_larger_render_angle_logs_fewer_frames(tmp_path) -> None:
    frames = {}
    for deg in ("20", "40"):
        out = tmp_path / f"ep{deg}.mcap"
        r = CliRunner().invoke(cli, [*BASE, "--render-turn", deg, "-o", str(out)])
        assert r.exit_code == 0, r.output
        with LogReader(out) as log:
            started = next(e for _, e in log.records("episode"))
            assert started["extra"]["turn_render_deg"] == float(deg)
            frames[deg] = log.frame_count()
    # the opening look-around turns a full circle on the spot: 18 frames at 20 degrees,
    # half as many at 40 (driving frames, if any, are the same rule's)
    assert 0 < frames["40"] < frames["20"]


def test_a_render_angle_out_of_range_is_a_usage_error(tmp_path) -> None:
    out = tmp_path / "ep.mcap"
    r = CliRunner().invoke(cli, [*BASE, "--render-turn", "120", "-o", str(out)])
    assert r.exit_code == 2 and "--render-turn" in r.output and "Traceback" not in r.output
    assert not out.exists()
