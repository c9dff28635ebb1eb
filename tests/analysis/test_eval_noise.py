"""`sgtool eval` keeps episodes of different sensor noise profiles apart."""

from __future__ import annotations

from sgtool.analysis.eval_run import per_noise
from sgtool.results import EpisodeResult


def _row(planner: str, noise: str = "", source: str = "") -> EpisodeResult:
    return EpisodeResult(planner=planner, seed=0, house="house-0", episode=0, query="cup",
                         success=True, steps=3, travelled_m=2.0, shortest_m=1.0,
                         noise=noise, source=source)


def test_rows_of_several_profiles_are_scored_apart():
    rows, profiles = per_noise([_row("scout", "none"), _row("scout", "strong")])
    assert profiles == ["none", "strong"]
    assert [r.planner for r in rows] == ["scout [none]", "scout [strong]"]
    one, none_said = per_noise([_row("scout", "none"), _row("random", "none")])
    assert none_said == [] and [r.planner for r in one] == ["scout", "random"]


def test_older_rows_name_their_profile_by_their_log_folder():
    """Rows written before they named their profile: a run-bench log's path says it."""
    rows, profiles = per_noise([
        _row("scout", source="/x/rb/logs/strong/scout/house-0/ep-000.mcap"),
        _row("scout", source="/x/rb/logs/none/scout/house-0/ep-000.mcap"),
        _row("scout", source="/elsewhere/run.mcap")])
    assert profiles == ["strong", "none", "unknown"]
    assert rows[2].planner == "scout [unknown]"


def test_a_symbolic_benchs_rows_are_named_symbolic_beside_a_closed_loop():
    """A symbolic bench (no sensor) beside closed-loop logs: its rows are `[symbolic]`,
    not `[unknown]`."""
    rows, profiles = per_noise([_row("scout", source="symbolic"),
                                _row("scout", "none", "logs/none/scout/house-0/ep-000.mcap")])
    assert profiles == ["symbolic", "none"]
    assert [r.planner for r in rows] == ["scout [symbolic]", "scout [none]"]
    # the bench's own logs (--log-dir) are symbolic too: one profile with its table rows
    log = "/x/b/logs/scout/house-0/ep-000-s0.mcap"
    rows, profiles = per_noise([_row("scout", source="symbolic"), _row("scout", source=log)],
                               symbolic_logs={log})
    assert profiles == [] and [r.planner for r in rows] == ["scout", "scout"]
