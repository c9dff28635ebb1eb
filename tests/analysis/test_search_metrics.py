"""Metrics against values worked out by hand (SR, SPL, steps, AUC-E, seeds, Table IX)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from sgtool.analysis.search_metrics import (
    DISTANCE_COST,
    STEP_COST,
    Stat,
    auc_e,
    auc_e_of,
    cost_models,
    distance_cost,
    efficiency_curve,
    episode_spl,
    mean_decision_time,
    mean_steps,
    seen_unseen,
    spl,
    success_rate,
    summarize,
)
from sgtool.results import EpisodeResult


def ep(success: bool, steps: int = 10, travelled: float = 10.0, shortest: float | None = 5.0,
       planner: str = "p", seed: int = 0, n_open: int = 0, seen: bool | None = None,
       decision_s: float = 0.0, episode: int = 0) -> EpisodeResult:
    return EpisodeResult(planner=planner, seed=seed, house="h", episode=episode, query="cup",
                         success=success, steps=steps, travelled_m=travelled,
                         shortest_m=shortest, n_open=n_open, seen=seen,
                         wall={"decision_s": decision_s, "decisions": steps})


def test_episode_spl_cases():
    assert episode_spl(True, 5.0, 10.0) == 0.5
    assert episode_spl(True, 5.0, 4.0) == 1.0  # travelled below shortest: capped at 1
    assert episode_spl(False, 5.0, 5.0) == 0.0
    assert episode_spl(True, 0.0, 0.0) == 1.0  # target visible from the start
    assert math.isnan(episode_spl(True, None, 3.0))


def test_sr_spl_steps_over_a_set():
    rs = [ep(True, steps=4, travelled=10, shortest=5), ep(True, steps=6, travelled=8, shortest=8),
          ep(False, steps=50), ep(True, steps=2, travelled=3, shortest=None)]
    assert success_rate(rs) == 0.75
    # SPL over the three episodes with a known shortest path: (0.5 + 1 + 0) / 3
    assert spl(rs) == pytest.approx(0.5)
    assert mean_steps(rs) == pytest.approx(62 / 4)


def test_decision_time_is_per_decision():
    rs = [ep(True, steps=2, decision_s=0.2), ep(False, steps=8, decision_s=0.3)]
    assert mean_decision_time(rs) == pytest.approx(0.05)


def test_efficiency_curve_vertices_and_area():
    # N = 4: a point per episode (the failure at 30 too); 60 is over the budget 50
    xs, ys = efficiency_curve([10, 20, 30, 60], [True, True, False, True], 50)
    assert xs.tolist() == [0, 10, 20, 30, 50]
    assert ys.tolist() == [0, 0.25, 0.5, 0.5, 0.5]
    # trapezoids: 10 * 0.125 + 10 * 0.375 + 10 * 0.5 + 20 * 0.5 = 20; 20 / 50 = 0.4
    assert auc_e([10, 20, 30, 60], [True, True, False, True], 50) == pytest.approx(0.4)


def test_auc_e_bounds_and_ties():
    assert auc_e([0, 0, 0], [True, True, True], 50) == pytest.approx(1.0)
    assert auc_e([1, 2, 3], [False, False, False], 50) == 0.0
    assert auc_e([], [], 50) == 0.0
    assert auc_e([60, 70], [True, True], 50) == 0.0  # every cost over the budget
    # ties share the full count: two solved at 25 of 2 -> (25, 1) twice; area = 25 * 0.5
    # (the ramp from (0, 0)) + 25 * 1 = 37.5 (it was 31.25, the first tie at y = 0.5)
    assert auc_e([25, 25], [True, True], 50) == pytest.approx(37.5 / 50)


def momallm_auc(costs, successes, max_x):
    """MoMa-LLM's released code (run_agent.py, _plot then calc_area_under_curve), with
    numpy for pandas and sklearn: the reference the metric must agree with."""
    order = np.argsort(costs, kind="stable")
    x = np.asarray(costs, dtype=float)[order]
    won = np.asarray(successes, dtype=bool)
    y = np.array([np.logical_and(won, np.asarray(costs) <= m).mean() for m in x])
    if max(x) > max_x:
        x, y = x[x <= max_x], y[x <= max_x]
    if max(x) < max_x:
        x, y = np.concatenate([x, [max_x]]), np.concatenate([y, [y[-1]]])
    x, y = np.concatenate([[0], x]), np.concatenate([[0], y])
    return float(np.trapezoid(y, x)) / max_x


@pytest.mark.parametrize("costs, successes", [
    ([10, 40, 50], [True, False, True]),  # a failure between two successes: 0.333, was 0.433
    ([15, 49, 49] + [50] * 6, [True] * 3 + [False] * 6),  # ties: 0.174, was 0.137
    ([3, 7, 7, 12, 30, 44, 49], [False, True, True, False, True, True, False]),
    ([0, 5, 5, 5, 20], [True, False, True, True, False]),
])
def test_auc_e_is_momallms_computation(costs, successes):
    assert auc_e(costs, successes, 50) == pytest.approx(momallm_auc(costs, successes, 50))
    assert auc_e(costs, successes, 25) == pytest.approx(momallm_auc(costs, successes, 25))


def test_distance_cost_is_momallm_low_level():
    r = ep(True, travelled=12.3, n_open=2)
    assert distance_cost(r) == pytest.approx(123 + 60)
    assert DISTANCE_COST.max_cost == 5000 and STEP_COST.max_cost == 50
    # one episode solved with cost 183 of budget 5000: area = 183 * 0.5 + (5000-183) * 1
    assert auc_e_of([r], DISTANCE_COST) == pytest.approx((91.5 + 4817) / 5000)
    d, s = cost_models(distance_budget=1000, open_cost=10)
    assert d.cost(r) == pytest.approx(143) and d.max_cost == 1000 and "1000" in d.statement()
    assert s.cost(r) == 10


def test_summary_mean_std_over_seeds():
    rs = [ep(True, seed=0), ep(False, seed=0, episode=1),
          ep(True, seed=1), ep(True, seed=1, episode=1),
          ep(False, planner="q", seed=0)]
    sums = summarize(rs)
    assert [s.planner for s in sums] == ["p", "q"]
    sr = sums[0].stats["sr"]
    assert sr.per_seed == (0.5, 1.0)
    assert sr.mean == pytest.approx(0.75)
    assert sr.std == pytest.approx(math.sqrt(0.125))  # sample std of (0.5, 1.0)
    assert sums[0].episodes == 4 and sums[0].seeds == (0, 1)
    assert math.isnan(sums[1].stats["sr"].std)  # one seed: no spread measured
    assert set(sums[0].stats) >= {"sr", "spl", "steps", "decision_s", "auc_e_distance",
                                  "auc_e_steps"}
    assert Stat.of([math.nan, 1.0]).mean == 1.0


def test_seen_unseen_breakdown():
    rs = [ep(True, seen=True), ep(False, seen=True), ep(True, seen=False, travelled=5),
          ep(True, seen=None)]
    (row,) = seen_unseen(rs)
    assert (row.seen_n, row.unseen_n) == (2, 1)
    assert row.seen_sr == 0.5 and row.unseen_sr == 1.0
    assert row.seen_spl == pytest.approx(0.25) and row.unseen_spl == pytest.approx(1.0)


def test_an_episode_without_a_shortest_path_is_out_of_spl_either_way() -> None:
    """SPL leaves out an episode whose shortest path is unknown, failed or not (a failure
    kept as 0 beside successes left out pulled the mean towards 0)."""
    assert math.isnan(episode_spl(False, None, 3.0))
    assert math.isnan(episode_spl(True, math.nan, 3.0))
    assert episode_spl(False, 2.0, 3.0) == 0.0


def test_run_prints_the_spl_eval_scores() -> None:
    """`sgtool run`'s report and `sgtool eval` share one SPL: an episode that starts in
    the target's room (shortest path 0) and finds it without moving scores 1 in both."""
    from pathlib import Path

    from sgtool.recorders.sim.closed_loop_report import ClosedLoopReport
    from sgtool.results import episode_spl

    def report(success: bool, shortest: float | None, travelled: float) -> ClosedLoopReport:
        return ClosedLoopReport(Path("x.mcap"), "h", "scout", "mug", "ep_0", success,
                                "found" if success else "budget", 0, travelled, shortest,
                                1, 1, 0, (), 0.0)

    for success, shortest, travelled in ((True, 0.0, 0.0), (True, 2.0, 4.0),
                                         (False, 2.0, 1.0), (True, 0.0, 3.0)):
        assert report(success, shortest, travelled).spl == \
            episode_spl(success, shortest, travelled)
    assert report(True, 0.0, 0.0).spl == 1.0
    assert report(True, None, 1.0).spl is None


def test_the_table_has_a_column_per_cost_model_it_is_given():
    """A user's cost model (opens) gets its AUC-E column; without models the table keeps
    the distance and step columns."""
    from sgtool.analysis.report import format_table
    from sgtool.analysis.search_metrics import CostModel

    opens = CostModel("opens", "containers and doors opened", 10.0, lambda r: float(r.n_open))
    runs = [ep(True, n_open=2, seed=0), ep(True, n_open=4, seed=1), ep(False, seed=2)]
    header = format_table(summarize(runs, [opens]), models=[opens]).splitlines()[0]
    assert "AUC-E opens" in header and "AUC-E dist" not in header
    both = [*cost_models(5000.0, 50.0), opens]
    header = format_table(summarize(runs, both), models=both).splitlines()[0]
    assert [h.strip() for h in header.split("|") if "AUC-E" in h] == \
        ["AUC-E dist ↑", "AUC-E steps ↑", "AUC-E opens ↑"]
    plain = format_table(summarize(runs)).splitlines()[0]
    assert [h.strip() for h in plain.split("|") if "AUC-E" in h] == \
        ["AUC-E dist ↑", "AUC-E steps ↑"]
    lines = format_table(summarize(runs, [opens]), models=[opens]).splitlines()
    col = [h.strip() for h in lines[0].split("|")].index("AUC-E opens ↑")
    assert lines[2].split("|")[col].strip() not in ("", "-")  # the column holds a figure
