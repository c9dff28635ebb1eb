"""The closed-loop benchmark's config and the Rerun writer as the Python API gives them: a
name alone is a list of one, a set is refused, and every mistake is one SgtoolError line."""

from __future__ import annotations

from pathlib import Path

import pytest

import sgtool

LOG = Path(__file__).resolve().parents[1] / "golden" / "house6-tour.mcap"


def test_a_closed_loop_bench_config_takes_a_name_or_a_list() -> None:
    cfg = sgtool.ClosedLoopBenchConfig("scout", noise="mild", house_files="a.json",
                                       rooms=[4, 6])
    assert (cfg.planners, cfg.noise, cfg.house_files, cfg.rooms) == \
        (("scout",), ("mild",), ("a.json",), (4, 6))
    with pytest.raises(sgtool.SgtoolError, match="a set has no order"):
        sgtool.ClosedLoopBenchConfig({"scout", "random"})
    with pytest.raises(sgtool.SgtoolError, match=r"rooms: give \(MIN, MAX\)"):
        sgtool.ClosedLoopBenchConfig("scout", rooms=4)


def test_write_rerun_refuses_in_one_line(tmp_path) -> None:
    log = LOG
    with pytest.raises(sgtool.SgtoolError, match="must not be the input log"):
        sgtool.write_rerun(log, log)
    out = tmp_path / "x.rrd"
    out.write_bytes(b"old")
    with pytest.raises(sgtool.SgtoolError, match=r"exists; .*\(use --force \(overwrite=\)\)"):
        sgtool.write_rerun(log, out)
    with pytest.raises(sgtool.SgtoolError, match="every=0"):
        sgtool.write_rerun(log, tmp_path / "y.rrd", every=0)
    text = tmp_path / "notes.txt"
    text.write_text("not a log")
    with pytest.raises(sgtool.SgtoolError):
        sgtool.write_rerun(text, tmp_path / "z.rrd")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["notes.txt", "x.rrd"]
    assert out.read_bytes() == b"old"
