"""SR and SPL with bootstrap intervals over houses, and paired comparisons of planners on
the same episodes (all queries, seen ones, unseen ones), as one report: what `sgtool
bench`'s summary and `sgtool eval` print. The figures are those of
:mod:`sgtool.analysis.intervals`; this module picks the pairs and renders text and JSON."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

from sgtool.analysis.intervals import (
    DEFAULT_BOOTSTRAP,
    Bootstrap,
    PairedComparison,
    PlannerIntervals,
    comparison_pairs,
    paired_comparison,
    planner_intervals,
)
from sgtool.analysis.report import format_intervals, format_paired, format_paired_split
from sgtool.results import EpisodeResult


@dataclass(frozen=True)
class IntervalReport:
    """Per planner its SR and SPL intervals; per pair (planner, reference) the comparison on
    every paired episode, on those of seen queries and on those of unseen ones (the same
    pairs in the same order)."""

    planners: tuple[PlannerIntervals, ...]
    paired: tuple[PairedComparison, ...]
    paired_seen: tuple[PairedComparison, ...]
    paired_unseen: tuple[PairedComparison, ...]
    boot: Bootstrap = DEFAULT_BOOTSTRAP

    def text(self) -> str:
        """The three tables, as summary.md has them (the intervals only, with one line
        saying so, when there is no pair to compare)."""
        boot = self.boot
        ivs = format_intervals(self.planners, boot, title="SR and SPL with bootstrap "
                                                          "intervals over houses, episodes "
                                                          "pooled over seeds")
        if not self.paired:
            return ivs + "\nPaired comparisons: no two planners to pair.\n"
        return "\n".join([
            ivs, format_paired(self.paired, boot, title="Paired comparisons on the same "
                                                        "episodes"),
            format_paired_split(self.paired_seen, self.paired_unseen, boot,
                                title="Paired comparisons on seen and on unseen queries")])

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready, as summary.json's ``intervals``."""
        return {"bootstrap": self.boot.to_dict(), "cluster": "house",
                "planners": {r.planner: r.to_dict() for r in self.planners},
                "paired": [c.to_dict() for c in self.paired],
                "paired_seen": [c.to_dict() for c in self.paired_seen],
                "paired_unseen": [c.to_dict() for c in self.paired_unseen]}


def interval_report(results: Sequence[EpisodeResult], planners: Sequence[str],
                    reference: str | None = None, all_pairs: bool = False,
                    boot: Bootstrap = DEFAULT_BOOTSTRAP,
                    pairs: Sequence[tuple[str, str]] | None = None) -> IntervalReport:
    """The report of ``planners`` (in this order) over ``results``: every other planner
    against ``reference`` (default: scout when among them, else the first), or every pair
    with ``all_pairs`` (:func:`~sgtool.analysis.intervals.comparison_pairs`; a reference
    not among ``planners`` raises ValueError); ``pairs`` (planner, reference) instead of
    both."""
    if pairs is None:
        pairs = comparison_pairs(planners, reference, all_pairs)

    def compare(rows: Sequence[EpisodeResult]) -> tuple[PairedComparison, ...]:
        return tuple(paired_comparison(rows, a, b, boot=boot, check=False) for a, b in pairs)

    return IntervalReport(
        tuple(planner_intervals(results, p, boot=boot, check=False) for p in planners),
        compare(results), compare([r for r in results if r.seen is True]),
        compare([r for r in results if r.seen is False]), boot)
