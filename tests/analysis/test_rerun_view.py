"""`sgtool view` writes a Rerun recording that `rerun rrd verify` accepts."""

from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path

import pytest
import rerun as rr
from click.testing import CliRunner
from support.logfixtures import write_log
from support.paths import GOLDEN

from sgtool.cli import cli
from sgtool.colors import color_for


@pytest.fixture(autouse=True)
def strict_rerun():
    rr.set_strict_mode(True)  # bad input raises instead of being dropped with a warning
    yield
    rr.set_strict_mode(False)


def rrd_verify(path: Path) -> subprocess.CompletedProcess[str]:
    """`rerun rrd verify PATH` (the venv's rerun, else the one on PATH); must succeed."""
    exe = str(Path(sys.executable).parent / "rerun")
    if not Path(exe).exists():
        exe = shutil.which("rerun") or "rerun"
    res = subprocess.run([exe, "rrd", "verify", str(path)], capture_output=True, text=True,
                         timeout=120)
    assert res.returncode == 0, res.stderr
    return res


def test_view_writes_a_verified_rrd(tmp_path):
    log = write_log(tmp_path / "run.mcap")
    out = tmp_path / "view.rrd"
    r = CliRunner().invoke(cli, ["view", str(log), "-o", str(out), "--no-voxels"])
    assert r.exit_code == 0, r.output
    assert out.stat().st_size > 10_000 and not (tmp_path / "view.rrd.partial").exists()
    res = rrd_verify(out)
    assert "verified without error" in res.stderr + res.stdout


def test_view_refuses_to_overwrite_its_input(tmp_path):
    log = write_log(tmp_path / "run.mcap")
    r = CliRunner().invoke(cli, ["view", str(log), "-o", str(log)])
    assert r.exit_code == 2 and "must not be the input" in r.output


def test_colours_are_stable_and_distinct():
    assert color_for(3) == color_for(3)
    assert len({color_for(i) for i in range(50)}) == 50
    assert color_for("room:1") == color_for("room:1")


def test_view_of_a_replayed_log_with_voxels_and_derived_layers(tmp_path):
    """A golden log replayed (occupancy, Voronoi graph, rooms, scene graphs) and viewed with
    the voxel map, in strict mode: every logged archetype is valid, and the file verifies."""
    from sgtool.replayers.derived_log import ReplayOptions, replay

    golden = GOLDEN / "house10-start.mcap"
    derived = tmp_path / "derived.mcap"
    replay(golden, derived, ReplayOptions(max_frames=40))
    out = tmp_path / "view.rrd"
    r = CliRunner().invoke(cli, ["view", str(derived), "-o", str(out)])
    assert r.exit_code == 0, r.output
    rrd_verify(out)
