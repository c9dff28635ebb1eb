"""`sgtool demo` (the README's first command) end to end, shortened: every stage runs and
leaves its output."""

from __future__ import annotations

from click.testing import CliRunner

from sgtool.cli import cli
from sgtool.log import LogReader


def test_demo_runs_every_stage(tmp_path):
    out = tmp_path / "demo"
    r = CliRunner().invoke(cli, ["demo", "-o", str(out), "--frames", "40", "--houses", "1",
                                 "--episodes", "2", "--seeds", "1"])
    assert r.exit_code == 0, r.output
    for stage in ("sgtool record", "sgtool info", "sgtool replay", "sgtool bench"):
        assert f"== {stage}" in r.output
    assert "quality (merged)" in r.output and "| scout" in r.output
    with LogReader(out / "demo.mcap") as log:
        assert log.frame_count() == 40
    with LogReader(out / "derived.mcap") as log:
        assert log.message_count("/sgtool/scene_graph") >= 4  # every 10 frames, and actions
    assert (out / "view.rrd").stat().st_size > 0
    assert (out / "bench" / "summary.md").exists()


def test_demo_refuses_a_file_as_its_folder(tmp_path):
    f = tmp_path / "file"
    f.write_text("x")
    r = CliRunner().invoke(cli, ["demo", "-o", str(f)])
    assert r.exit_code == 2 and "is a file" in r.output and "Traceback" not in r.output
