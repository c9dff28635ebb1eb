"""`sgtool record`: the demo house by default, a house file, a generated house, options
reaching the log, and user errors that leave no file behind."""

from __future__ import annotations

import json
import sys
from pathlib import Path

import pytest
from click.testing import CliRunner
from support.small_house import small_house, small_house_dict

from sgtool.cli import cli
from sgtool.log import LogReader


def _run(*args: str):  # type: ignore[no-untyped-def]
    return CliRunner().invoke(cli, ["record", *args])


def test_records_the_demo_house_by_default_and_info_reads_it(tmp_path: Path) -> None:
    out = tmp_path / "demo.mcap"
    r = _run("-o", str(out), "--frames", "4", "--resolution", "64x48")
    assert r.exit_code == 0, r.output
    assert "house demo: 4 frames" in r.output
    info = CliRunner().invoke(cli, ["info", str(out)])
    assert info.exit_code == 0, info.output
    assert "frames 4" in info.output and "camera 64x48" in info.output
    from sgtool.datasets import demo_house

    with LogReader(out) as log:
        assert log.house_json() == demo_house().to_json()


def test_options_reach_the_log(tmp_path: Path) -> None:
    house = tmp_path / "small.json"
    house.write_text(small_house().to_json())
    out = tmp_path / "run.mcap"
    r = _run("--house", str(house), "-o", str(out), "--frames", "12", "--fps", "5",
             "--resolution", "64x48", "--fov", "60", "--depth-range", "0.2,4",
             "--noise", "mild,holes=0.2", "--noise-seed", "7", "--start", "1", "--quiet")
    assert r.exit_code == 0, r.output
    assert r.output == ""
    with LogReader(out) as log:
        assert log.frame_times() == [i * 200_000_000 for i in range(12)]
        assert log.seed == 7
        start = next(rec for _, rec in log.records("episode"))
        extra = start["extra"]
        assert start["house_id"] == "small" and extra["fps"] == 5.0
        assert extra["camera"]["vfov_deg"] == 60.0 and extra["camera"]["depth_max"] == 4.0
        assert extra["noise"]["holes"] == 0.2 and extra["noise"]["name"] == "mild,holes=0.2"
        f = next(log.frames())
        assert f.depth.shape == (48, 64) and f.depth.max() <= 4.0
        assert 0.15 < (f.depth == 0).mean()  # the holes
        assert f.base_pose[0, 3] > 4.0  # start 1 is in the kitchen


def test_generated_house_from_a_seed(tmp_path: Path) -> None:
    out = tmp_path / "gen.mcap"
    r = _run("--seed", "4", "--rooms", "4,5", "-o", str(out), "--frames", "2",
             "--resolution", "32x24")
    assert r.exit_code == 0, r.output
    assert "house house-4" in r.output


@pytest.mark.parametrize("problem", ["bad_spec", "not_json", "missing"])
def test_bad_house_spec_is_a_clear_error_and_no_file(tmp_path: Path, problem: str) -> None:
    house = tmp_path / "house.json"
    if problem == "bad_spec":
        d = small_house_dict()
        d["furniture"][1]["size"] = [1.0, -0.6, 0.75]
        house.write_text(json.dumps(d))
    elif problem == "not_json":
        house.write_text("{rooms: ")
    out = tmp_path / "run.mcap"
    r = _run("--house", str(house), "-o", str(out))
    assert r.exit_code == 2
    assert r.output.startswith("sgtool: error: ") and str(house) in r.output
    if problem == "bad_spec":
        assert "furniture[1].size" in r.output
    assert not out.exists() and not Path(str(out) + ".partial").exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ([] if problem == "missing"
                                                          else ["house.json"])


def test_option_errors(tmp_path: Path) -> None:
    out = tmp_path / "x.mcap"
    cases = [
        (["-o", str(tmp_path / "x.bag")], "name it *.mcap"),
        (["-o", str(out), "--seed", "1", "--house", "h.json"], "either --house or --seed"),
        (["-o", str(out), "--start", "9"], "start 9"),
        (["-o", str(out), "--frames", "0"], "--frames 0"),
        (["-o", str(out), "--resolution", "big"], "WIDTHxHEIGHT"),
        (["-o", str(out), "--noise", "loud"], "unknown profile"),
        (["-o", str(out), "--depth-range", "3"], "MIN,MAX"),
        (["-o", str(out), "--fov", "200"], "field of view"),
        (["-o", str(tmp_path / "no" / "x.mcap")], "does not exist"),
    ]
    for args, msg in cases:
        r = _run(*args)
        assert r.exit_code == 2, (args, r.output)
        assert msg in r.output, (args, r.output)
    assert list(tmp_path.iterdir()) == []
    out.write_bytes(b"keep")
    r = _run("-o", str(out), "--frames", "1")
    assert r.exit_code == 2 and "--force" in r.output and out.read_bytes() == b"keep"


def test_same_bytes_in_a_fresh_process(tmp_path: Path) -> None:
    """A separate interpreter (other hash seed, fresh PyBullet) writes the same log.

    The BLAS kernel choice (``OPENBLAS_*``, set on some machines) is passed through: another
    kernel changes the last bits of the noise model's matrix products, as any numpy
    program's."""
    import hashlib
    import os
    import subprocess
    import sys

    args = ["record", "--seed", "2", "--rooms", "4,5", "--frames", "30", "--resolution",
            "48x36", "--noise", "strong", "--quiet"]
    a, b = tmp_path / "a.mcap", tmp_path / "b.mcap"
    r = CliRunner().invoke(cli, [*args, "-o", str(a)])
    assert r.exit_code == 0, r.output
    code = f"from sgtool.cli import main; main({[*args, '-o', str(b)]!r})"
    subprocess.run([sys.executable, "-c", code], check=True, capture_output=True,
                   env={"PYTHONHASHSEED": "77", "PATH": "/usr/bin:/bin",
                        **{k: v for k, v in os.environ.items() if k.startswith("OPENBLAS_")}})
    assert hashlib.sha256(a.read_bytes()).digest() == hashlib.sha256(b.read_bytes()).digest()


def test_a_mistake_is_one_line_in_a_fresh_process(tmp_path: Path) -> None:
    """PyBullet prints its build time on the C-level stderr when imported; the import that
    checks it is installed silences that too, so a refusal stays one line."""
    import subprocess

    r = subprocess.run([sys.executable, "-c", "from sgtool.cli import main; main()",
                        "record", "--seed", "3", "--rooms", "4-4", "--start", "999", "-o",
                        str(tmp_path / "x.mcap")],
                       capture_output=True, text=True, timeout=120)
    assert r.returncode == 2
    assert r.stderr == "sgtool: error: start 999: the house has 4 start poses (0..3)\n"
    assert r.stdout == ""
