"""sgtool.analysis.closed_loop_tables on hand-made episodes: the frame-budget curve, the
agreement with a symbolic order, the interval tables over houses and per house."""

from __future__ import annotations

import math
from dataclasses import replace

import pytest

from sgtool.analysis.closed_loop_tables import (
    budget_comparisons,
    format_agreement,
    format_frame_curves,
    frame_curves,
    frames_model,
    interval_tables,
    symbolic_agreement,
    within_budget,
)
from sgtool.analysis.intervals import Bootstrap
from sgtool.results import EpisodeResult


def ep(planner: str, house: str, episode: int, success: bool, travelled: float = 10.0,
       query: str = "mug", seed: int = 0) -> EpisodeResult:
    return EpisodeResult(planner=planner, seed=seed, house=house, episode=episode,
                         query=query, success=success, steps=3, travelled_m=travelled,
                         shortest_m=5.0)


def test_frame_curves_count_the_episodes_solved_within_each_budget() -> None:
    # "fast" solves its two episodes at 10 and 30 frames per room, "slow" one at 90, fails
    # the other (which used 100)
    rows = [ep("fast", "h", 0, True), ep("fast", "h", 1, True),
            ep("slow", "h", 0, True), ep("slow", "h", 1, False)]
    per_room = {rows[0].key(): 10.0, rows[1].key(): 30.0, rows[2].key(): 90.0,
                rows[3].key(): 100.0}
    model = frames_model(per_room)
    assert model.max_cost == 100.0 and model.name == "frames"
    assert frames_model(per_room, budget=40.0).max_cost == 40.0
    budgets, curves = frame_curves(rows, ["fast", "slow", "absent"], model)
    assert budgets == (25.0, 50.0, 75.0, 100.0)
    fast, slow = curves
    assert fast.sr_within == (0.5, 1.0, 1.0, 1.0) and slow.sr_within == (0.0, 0.0, 0.0, 0.5)
    # AUC-E (trapezoids, MoMa-LLM): fast's curve (0,0)-(10,.5)-(30,1)-(100,1): area
    # 2.5 + 15 + 70 = 87.5 of 100; slow's (0,0)-(90,.5)-(100,.5): 22.5 + 5 = 27.5
    assert fast.auc_e == pytest.approx(0.875) and slow.auc_e == pytest.approx(0.275)
    text = format_frame_curves(budgets, curves)
    assert "| SR ≤ 25 f/room" in text and "| fast " in text and "absent" not in text
    # budgets of the report's choosing: the same counts there, the same AUC-E
    chosen, again = frame_curves(rows, ["fast", "slow"], model, [20, 95])
    assert chosen == (20.0, 95.0)
    assert again[0].sr_within == (0.5, 1.0) and again[1].sr_within == (0.0, 0.5)
    assert again[0].auc_e == fast.auc_e
    assert "over [0, 100] / 100" in format_frame_curves(chosen, again, max_cost=100.0)


def test_symbolic_agreement_uses_the_same_episodes_when_there_are() -> None:
    closed = [ep(p, "h", e, ok) for p, oks in (("a", (1, 1)), ("b", (1, 0)), ("c", (0, 0)))
              for e, ok in enumerate(oks)]
    # the symbolic bench: same order on the same episodes, reversed on another house
    symbolic = [ep(p, "h", e, ok, seed=s) for s in range(2)
                for p, oks in (("a", (1, 1)), ("b", (1, 0)), ("c", (1, 0)))
                for e, ok in enumerate(oks)]
    symbolic += [ep(p, "other", 0, p == "c") for p in "abc"]
    matched, (by_spl, by_sr) = symbolic_agreement(closed, symbolic, ["a", "b", "c"])
    assert matched == 12
    # SR a 1 > b .5 > c 0 in the loop; a 1 > b .5 = c .5 symbolically: tau-b
    # (2 concordant, 0 discordant, one tie on one side) / sqrt(3 * 2) = 0.816
    assert by_sr.tau == pytest.approx(2 / math.sqrt(6)) and by_sr.metric == "sr"
    assert by_spl.tau == pytest.approx(2 / math.sqrt(6))
    # nothing of the same house, episode and query: all symbolic episodes count
    other = [ep(p, "x", 0, p == "c") for p in "abc"]
    matched, (by_spl, by_sr) = symbolic_agreement(closed, other, ["a", "b", "c"])
    # there only c succeeds: (a, c) and (b, c) discordant, (a, b) tied: -2 / sqrt(6)
    assert matched == 0 and by_sr.tau == pytest.approx(-2 / math.sqrt(6))
    flat = [ep(p, "x", 0, True) for p in "abc"]  # one value for all: no order
    matched, (by_spl, by_sr) = symbolic_agreement(closed, flat, ["a", "b", "c"])
    assert math.isnan(by_sr.tau)
    text = format_agreement(0, 3, [by_spl, by_sr], "--symbolic x")
    assert "all 3 symbolic episodes" in text and "by SR: -" in text


def test_interval_tables_over_houses_and_per_house() -> None:
    rows = [ep(p, f"h{h}", e, p == "scout" or e == 0, travelled=5.0)
            for h in range(3) for e in range(2) for p in ("random", "scout")]
    text, data = interval_tables(rows, ["random", "scout", "absent"],
                                 boot=Bootstrap(resamples=500))
    assert "Paired comparisons over houses" in text and "| h2    | random" in text
    assert "episodes resampled with replacement (an episode's seeds kept together)" in text
    (pair,) = data["paired"]
    # random solves one of two in every house at SPL 1, scout both: ratio exactly 0.5
    assert pair["planner"] == "random" and pair["reference"] == "scout"
    assert pair["spl_ratio"] == {"value": 0.5, "low": 0.5, "high": 0.5}
    assert (pair["wins"], pair["losses"], pair["ties"]) == (0, 3, 0)
    per_house = data["paired_per_house"]
    assert [d["house"] for d in per_house] == ["h0", "h1", "h2"]
    assert all((d["wins"], d["losses"], d["ties"]) == (0, 1, 1) for d in per_house)
    assert set(data["planners"]) == {"random", "scout"}
    _, every = interval_tables(rows, ["random", "scout"], all_pairs=True,
                               boot=Bootstrap(resamples=500))
    assert [(d["planner"], d["reference"]) for d in every["paired"]] == [("scout", "random")]


def test_within_a_budget_the_slow_planner_fails() -> None:
    # in each of 3 houses: "fast" solves at 10 frames per room, "slow" at 90
    rows = [ep(p, f"h{h}", 0, True) for h in range(3) for p in ("fast", "slow")]
    per_room = {r.key(): 10.0 if r.planner == "fast" else 90.0 for r in rows}
    model = frames_model(per_room, budget=100.0)
    assert [r.success for r in within_budget(rows, model, 50.0)] == [True, False] * 3
    text, data = budget_comparisons(rows, ["fast", "slow"], model, (50.0, 100.0),
                                    reference="slow", boot=Bootstrap(resamples=500))
    (pair,) = data
    assert (pair["planner"], pair["reference"]) == ("fast", "slow")
    # +1 in every house at 50 frames per room, no difference with 100
    assert pair["sr_diff_within"] == [{"value": 1.0, "low": 1.0, "high": 1.0},
                                      {"value": 0.0, "low": 0.0, "high": 0.0}]
    assert "| SR diff ≤ 50 f/room" in text and "+1.000 [+1.000, +1.000]" in text


def test_one_planner_says_there_is_nothing_to_pair() -> None:
    """A run of one planner: its intervals and one line saying there is no pair, as the
    symbolic bench's summary has it, not empty tables of comparisons."""
    rows = [ep("scout", f"h{h}", 0, True) for h in range(3)]
    text, data = interval_tables(rows, ["scout"], boot=Bootstrap(resamples=200))
    assert "Paired comparisons: no two planners to pair." in text
    assert "Paired comparisons over houses" not in text and data["paired"] == []
    model = frames_model({r.key(): 10.0 for r in rows}, budget=100.0)
    assert budget_comparisons(rows, ["scout"], model, (50.0,)) == ("", [])


def test_symbolic_rows_must_come_from_a_symbolic_bench(tmp_path):
    """--symbolic given a run-bench folder compared the closed loop with itself (tau 1): its
    episodes are refused in one line naming their source; a bench's are read."""
    from sgtool.analysis.closed_loop_bench_run import load_symbolic
    from sgtool.errors import SgtoolError
    from sgtool.results import write_jsonl

    row = EpisodeResult(planner="scout", seed=0, house="h", episode=0, query="cup",
                        success=True, steps=3, travelled_m=2.0, shortest_m=1.0)
    (tmp_path / "bench").mkdir()
    write_jsonl([row], tmp_path / "bench" / "episodes.jsonl")
    assert load_symbolic(tmp_path / "bench") == (row,)
    (tmp_path / "rb").mkdir()
    write_jsonl([replace(row, source="logs/none/scout/h/ep-000.mcap")],
                tmp_path / "rb" / "episodes.jsonl")
    with pytest.raises(SgtoolError, match=r"^--symbolic .*rb: episodes of logs \(source "
                       r"logs/none/scout/h/ep-000.mcap\), not of a `sgtool bench`"):
        load_symbolic(tmp_path / "rb")
