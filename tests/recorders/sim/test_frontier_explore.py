"""`sgtool record --explore frontier`: frontier exploration on the robot's own map, on the
4-room house of test_closed_loop at 64x48 with a 200-frame budget; and the coverage
figure on a hand-built grid."""

from __future__ import annotations

import dataclasses

import numpy as np
from click.testing import CliRunner

from sgtool.cli import cli
from sgtool.log import LogReader
from sgtool.mapping.grid import FREE, OCCUPIED, UNKNOWN, OccupancyGrid
from sgtool.recorders.sim.coverage import coverage
from sgtool.recorders.sim.recording import coverage_at


def test_coverage_counts_known_floor_cells() -> None:
    g = np.full((4, 4), UNKNOWN, np.int8)
    g[:, :2] = FREE
    g[0, 2] = OCCUPIED
    grid = OccupancyGrid(g, (0.0, 0.0), 1.0)
    floor = np.array([[0.5, 0.5], [1.5, 3.5], [2.5, 0.5], [3.5, 3.5], [9.0, 9.0]])
    assert coverage(grid, floor) == 3 / 5  # two free, one occupied; one unknown, one outside
    assert coverage(grid, np.zeros((0, 2))) == 0.0
    samples = [(0.0, 0.1), (30.0, 0.4), (75.0, 0.7)]
    assert [coverage_at(samples, t) for t in (-1, 0, 60, 120)] == [0.0, 0.1, 0.4, 0.7]


def test_a_report_without_goals_visited_says_none_without_an_empty_list(tmp_path) -> None:
    from sgtool.recorders.sim.recording import RecordReport

    out = tmp_path / "x.mcap"
    out.write_bytes(b"")
    report = RecordReport(out, "house-0", 10, 0, 0.0, (), {}, (), False, 1.0,
                          coverage=((1.0, 0.2),))
    assert "goals visited: 0" in report.lines() and not any("()" in line
                                                            for line in report.lines())
    assert "rooms visited: 2 (kitchen, bath)" in dataclasses.replace(
        report, coverage=(), rooms_visited=("kitchen", "bath")).lines()


def test_record_explore_frontier(tmp_path) -> None:
    out = tmp_path / "frontier.mcap"
    res = CliRunner().invoke(cli, ["record", "--seed", "6", "--rooms", "4-4", "--explore",
                                   "frontier", "--resolution", "64x48", "--frames", "200",
                                   "-o", str(out)])
    assert res.exit_code == 0, res.output
    assert "floor seen: end (20 s)" in res.output and "goals visited" in res.output
    seen = float(res.output.split("floor seen: end (20 s) ")[1].split(" %")[0])
    assert 10.0 < seen <= 100.0
    with LogReader(out) as r:
        acts = [a for _, a in r.records("action")]
        started = next(r.records("episode"))[1]
    assert started["extra"]["explore"] == "frontier"
    assert acts[0]["skill"] == "look_around"
    navs = [a for a in acts if a["skill"] == "navigate"]
    assert navs and all(a["target"].startswith(("frontier:", "door:")) for a in navs)
    assert any(a["travelled_m"] > 0.5 for a in navs)
    # the budget stops the exploration midway: the goals it went to are still reported
    # (they read "goals visited: 0" when the budget cut it short)
    visited = int(res.output.split("goals visited: ")[1].split()[0])
    assert visited == len(navs), (visited, len(navs))
