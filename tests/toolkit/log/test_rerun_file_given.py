"""A Rerun recording (what `sgtool view -o` writes) given where a log is read is one line
saying what it is: its header happened to look like an MCAP file whose opening magic was
damaged, and the advice to recover it with doctor wrote an empty log. (`sgtool info`
summarises it: tests/analysis/test_rerun_view.py.)"""

from __future__ import annotations

import pytest
from click.testing import CliRunner

from sgtool.cli import cli


@pytest.fixture
def rrd(tmp_path):
    rr = pytest.importorskip("rerun")
    path = tmp_path / "view.rrd"
    rec = rr.RecordingStream("test")
    rec.save(str(path))
    rec.log("world/p", rr.Points3D([[0.0, 0.0, 0.0]]))
    rec.disconnect()
    assert path.read_bytes()[:3] == b"RRF"
    return path


@pytest.mark.parametrize("command", [["replay"], ["doctor"], ["export", "bag"]])
def test_a_rerun_recording_is_named_as_one(rrd, tmp_path, command):
    args = [*command, str(rrd)] + (["-o", str(tmp_path / "out")] if command[0] == "export"
                                   else [])
    r = CliRunner().invoke(cli, args)
    assert r.exit_code == 2, r.output
    assert "is a Rerun recording (.rrd), not an sgtool log" in r.output
    assert "--recover" not in r.output and "Traceback" not in r.output
    assert not (tmp_path / "out").exists()
