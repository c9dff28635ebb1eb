"""sgtool.analysis.intervals on hand-made tables whose answers are known without a
computer: identical planners, a planner that wins every house, one house, 0/0 resamples."""

from __future__ import annotations

import math

import numpy as np
import pytest

from sgtool.analysis.intervals import (
    Bootstrap,
    Interval,
    by_episode,
    comparison_pairs,
    kendall_tau,
    kendall_tau_interval,
    paired_comparison,
    planner_intervals,
    ratio_interval,
    resample_indices,
)
from sgtool.results import EpisodeResult

SMALL = Bootstrap(resamples=2000)


def ep(planner: str, house: str, episode: int, success: bool, travelled: float = 10.0,
       shortest: float | None = 5.0, seed: int = 0) -> EpisodeResult:
    """An episode whose SPL is shortest / travelled when solved (5 / 10 = 0.5 by default)."""
    return EpisodeResult(planner=planner, seed=seed, house=house, episode=episode,
                         query="mug", success=success, steps=3, travelled_m=travelled,
                         shortest_m=shortest)


def test_ratio_interval_of_equal_clusters_has_zero_width() -> None:
    # every house 1 success in 2 episodes: every resample gives 0.5
    iv = ratio_interval([1, 1, 1, 1], [2, 2, 2, 2], SMALL)
    assert iv == Interval(0.5, 0.5, 0.5)


def test_ratio_interval_lies_within_the_cluster_extremes_and_holds_the_value() -> None:
    # houses with SR 0, 0.5, 1: a resample's SR is between 0 and 1, and the interval
    # of this spread is wide but not the whole range
    iv = ratio_interval([0, 1, 2], [2, 2, 2], SMALL)
    assert iv.value == 0.5
    assert 0.0 <= iv.low < 0.5 < iv.high <= 1.0
    # the same draws (same seed, same cluster count): the same bytes, also in another order
    assert ratio_interval([0, 1, 2], [2, 2, 2], SMALL) == iv


def test_one_cluster_has_no_interval_and_no_clusters_no_value() -> None:
    iv = ratio_interval([1], [2], SMALL)
    assert iv.value == 0.5 and math.isnan(iv.low) and math.isnan(iv.high)
    assert not iv.excludes(0.0)
    assert math.isnan(ratio_interval([], [], SMALL).value)


def test_zero_denominators() -> None:
    # 0/0 resamples are left out: clusters (0/0, 1/1): only resamples that draw the
    # second house count, and they all give 1
    assert ratio_interval([0, 1], [0, 1], SMALL) == Interval(1.0, 1.0, 1.0)
    # x/0 counts as +inf: the reference solved nothing in the first house
    iv = ratio_interval([1, 1], [0, 1], SMALL)
    assert iv.value == 2.0 and iv.high == math.inf and iv.low == 1.0


def test_resamples_are_seeded() -> None:
    a = resample_indices(5, Bootstrap(resamples=10, seed=3))
    assert a.shape == (10, 5) and a.min() >= 0 and a.max() <= 4
    assert np.array_equal(a, resample_indices(5, Bootstrap(resamples=10, seed=3)))
    assert not np.array_equal(a, resample_indices(5, Bootstrap(resamples=10, seed=4)))
    with pytest.raises(ValueError):
        Bootstrap(resamples=0)


def test_identical_planners_give_ratio_one_and_zero_differences() -> None:
    rows = []
    for h in range(4):
        for e in range(3):
            ok = (h + e) % 2 == 0
            rows += [ep("a", f"h{h}", e, ok, travelled=5.0 + h), ep("b", f"h{h}", e, ok,
                                                                    travelled=5.0 + h)]
    c = paired_comparison(rows, "a", "b", boot=SMALL)
    assert c.spl_ratio == Interval(1.0, 1.0, 1.0)
    assert c.sr_diff == Interval(0.0, 0.0, 0.0) and c.spl_diff == Interval(0.0, 0.0, 0.0)
    assert (c.wins, c.losses, c.ties) == (0, 0, 4) and c.episodes == 12 and c.clusters == 4


def test_a_planner_that_wins_every_house_has_an_interval_above_one() -> None:
    rows = []
    for h in range(5):
        for e in range(4):
            # a: solves everything on the shortest path (SPL 1); b: half, at SPL 0.5
            rows.append(ep("a", f"h{h}", e, True, travelled=5.0))
            rows.append(ep("b", f"h{h}", e, e % 2 == 0, travelled=10.0))
    c = paired_comparison(rows, "a", "b", boot=SMALL)
    # a's mean SPL 1, b's 0.25 in every house: ratio 4 in every resample
    assert c.spl_ratio == Interval(4.0, 4.0, 4.0) and c.spl_ratio.excludes(1.0)
    assert c.sr_diff == Interval(0.5, 0.5, 0.5)
    assert (c.wins, c.losses, c.ties) == (5, 0, 0)
    back = paired_comparison(rows, "b", "a", boot=SMALL)
    assert back.spl_ratio.value == 0.25 and (back.wins, back.losses) == (0, 5)


def test_a_mixed_comparison_straddles_one() -> None:
    # a wins two houses, loses two by as much: ratio 1 overall, interval around it
    rows = []
    for h, (ta, tb) in enumerate([(5.0, 10.0), (5.0, 10.0), (10.0, 5.0), (10.0, 5.0)]):
        rows += [ep("a", f"h{h}", 0, True, travelled=ta), ep("b", f"h{h}", 0, True,
                                                              travelled=tb)]
    c = paired_comparison(rows, "a", "b", boot=SMALL)
    assert c.spl_ratio.value == 1.0 and c.spl_ratio.low < 1.0 < c.spl_ratio.high
    assert not c.spl_ratio.excludes(1.0)
    assert (c.wins, c.losses, c.ties) == (2, 2, 0) and c.sr_diff == Interval(0.0, 0.0, 0.0)


def test_pairing_keeps_only_the_episodes_both_ran() -> None:
    rows = [ep("a", "h0", 0, True), ep("a", "h0", 1, True), ep("b", "h0", 0, False),
            ep("b", "h1", 0, True), ep("a", "h0", 0, True, seed=1)]
    c = paired_comparison(rows, "a", "b", boot=SMALL)
    assert c.episodes == 1 and c.clusters == 1 and c.sr_diff.value == 1.0
    assert math.isnan(c.sr_diff.low)  # one house: no interval


def test_clusters_inside_one_house_are_its_episodes() -> None:
    rows = [ep("a", "h0", e, e < 2, seed=s) for e in range(4) for s in range(2)]
    iv = planner_intervals(rows, "a", cluster=by_episode, boot=SMALL)
    assert (iv.clusters, iv.episodes) == (4, 8) and iv.sr.value == 0.5
    assert 0.0 <= iv.sr.low < 0.5 < iv.sr.high <= 1.0


def test_unknown_shortest_paths_are_left_out_of_spl_not_sr() -> None:
    rows = [ep("a", "h0", 0, True, shortest=None), ep("a", "h1", 0, True, travelled=5.0)]
    iv = planner_intervals(rows, "a", boot=SMALL)
    assert iv.sr.value == 1.0 and iv.spl.value == 1.0  # the first has no SPL at all


def test_comparison_pairs() -> None:
    assert comparison_pairs(["random", "scout", "greedy"]) == [("random", "scout"),
                                                                ("greedy", "scout")]
    assert comparison_pairs(["random", "greedy"]) == [("greedy", "random")]
    assert comparison_pairs(["a", "b", "c"], all_pairs=True) == [("b", "a"), ("c", "a"),
                                                                  ("c", "b")]
    assert comparison_pairs(["a", "b"], reference="b") == [("a", "b")]
    with pytest.raises(ValueError, match="not one of the planners"):
        comparison_pairs(["a", "b"], reference="c")


def test_kendall_tau() -> None:
    same = kendall_tau({"a": 0.1, "b": 0.2, "c": 0.3}, {"a": 0.5, "b": 0.6, "c": 0.9})
    assert same.tau == 1.0 and same.planners == ("a", "b", "c")
    flipped = kendall_tau({"a": 0.1, "b": 0.2, "c": 0.3}, {"a": 0.9, "b": 0.6, "c": 0.5})
    assert flipped.tau == -1.0
    # one swapped pair of three: (2 concordant - 1 discordant) / 3
    one = kendall_tau({"a": 1, "b": 2, "c": 3}, {"a": 2, "b": 1, "c": 3, "d": 0})
    assert one.tau == pytest.approx(1 / 3) and one.planners == ("a", "b", "c")
    assert math.isnan(kendall_tau({"a": 1.0}, {"a": 1.0}).tau)
    assert math.isnan(kendall_tau({"a": 1.0, "b": 1.0}, {"a": 1.0, "b": 2.0}).tau)


def _spl(r: EpisodeResult) -> float:
    return r.shortest_m / max(r.travelled_m, r.shortest_m) if r.success else 0.0


def test_kendall_tau_interval_of_an_order_every_house_agrees_on() -> None:
    # three planners, SPL 0.5 / 0.25 / 0 in every house, on both sides: every resample
    # gives tau 1; reversed on one side, -1
    a = [ep(p, f"h{h}", 0, p != "c", travelled=t) for h in range(4)
         for p, t in (("a", 10.0), ("b", 20.0), ("c", 10.0))]
    b = [ep(p, f"h{h}", 0, p != "a", travelled=t) for h in range(4)
         for p, t in (("a", 10.0), ("b", 20.0), ("c", 10.0))]
    assert kendall_tau_interval(a, a, ["a", "b", "c"], _spl, boot=SMALL) == (1.0, 1.0)
    assert kendall_tau_interval(a, b, ["a", "b", "c"], _spl, boot=SMALL) == (-1.0, -1.0)
    assert all(math.isnan(x) for x in kendall_tau_interval(a[:3], a[:3], ["a", "b", "c"],
                                                            _spl, boot=SMALL))  # one house
    # one episode without a shortest path (its SPL NaN) is left out, as the point tau does:
    # the other episodes of its house still count, so the interval stays (1, 1)
    from sgtool.analysis.search_metrics import episode_spl

    def spl(r: EpisodeResult) -> float:
        return episode_spl(r.success, r.shortest_m, r.travelled_m)

    # the other side orders b > a > c: tau 1/3 in every resample (dropping a's pairs in
    # the resamples holding h0 would give 1 there)
    swapped = [ep(p, f"h{h}", 0, p != "c", travelled=t) for h in range(4)
               for p, t in (("a", 20.0), ("b", 10.0), ("c", 10.0))]
    extra = [*a, ep("a", "h0", 1, False, shortest=None)]
    lo, hi = kendall_tau_interval(extra, swapped, ["a", "b", "c"], spl, boot=SMALL)
    assert lo == pytest.approx(1 / 3) and hi == pytest.approx(1 / 3)


def test_kendall_tau_interval_is_scipys_tau_b_on_each_resample() -> None:
    from scipy.stats import kendalltau

    rng = np.random.default_rng(3)
    names = ["p0", "p1", "p2", "p3", "p4"]
    # coarse values make ties, the case tau-b corrects for
    a = [ep(p, f"h{h}", e, bool(rng.random() < 0.7), travelled=float(rng.integers(5, 8)))
         for h in range(5) for e in range(2) for p in names]
    b = [ep(p, f"h{h}", e, bool(rng.random() < 0.6), travelled=float(rng.integers(5, 8)))
         for h in range(5) for e in range(2) for p in names]
    boot = Bootstrap(resamples=300)
    low, high = kendall_tau_interval(a, b, names, _spl, boot=boot)
    houses = [f"h{h}" for h in range(5)]
    taus = []
    for draw in resample_indices(5, boot):
        pick = [houses[k] for k in draw]
        def mean(rs, p, pick=pick):
            vals = [_spl(r) for h in pick for r in rs if r.house == h and r.planner == p]
            return sum(vals) / len(vals)
        x = [mean(a, p) for p in names]
        y = [mean(b, p) for p in names]
        if len(set(x)) > 1 and len(set(y)) > 1:
            taus.append(kendalltau(x, y).statistic)
    assert (low, high) == pytest.approx((np.quantile(taus, 0.025), np.quantile(taus, 0.975)))


def test_an_interval_prints_as_the_tables_show_it() -> None:
    from sgtool.analysis.intervals import Interval

    nan = float("nan")
    assert str(Interval(1.0878, 1.0078, 1.1756)) == "1.088 [1.008, 1.176]"
    assert Interval(0.02, -0.02, 0.055).format(signed=True) == "+0.020 [-0.020, +0.055]"
    assert str(Interval(0.5, nan, nan)) == "0.500 [-]" and str(Interval(nan, nan, nan)) == "-"
    assert str(Interval(2.0, 1.0, float("inf"))) == "2.000 [1.000, inf]"
