"""The tables of ``sgtool run-bench`` that separate planners: bootstrap intervals and paired
comparisons (:mod:`sgtool.analysis.intervals`) over houses and, per house, over its
episodes; SR against the frame budget (per room of the house) with AUC-E on frames; the
agreement of the closed loop's planner order with the symbolic bench's (Kendall's tau).

Pure functions of episode records and their frame counts: text for ``summary.md`` and
JSON-ready dicts for ``summary.json``, nothing read or written here.

Frame-budget curve: an episode that succeeded after ``f`` frames in a house of ``R``
rooms counts as solved for every budget of at least ``f / R`` frames per room; the curve
is MoMa-LLM's efficiency curve on that cost (:func:`sgtool.analysis.search_metrics.curve_of`)
and AUC-E its area over [0, max]. It reads a budget off one unbudgeted run (the planners
do not know the budget), so no single ``--frames-per-room`` decides the table; the max is
the run's own ``--frames-per-room`` when it has one, else the most frames per room any
episode used.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace

from sgtool.analysis.intervals import (
    DEFAULT_BOOTSTRAP,
    Bootstrap,
    RankAgreement,
    by_episode,
    by_house,
    comparison_pairs,
    kendall_tau,
    kendall_tau_interval,
    paired_comparison,
    planner_intervals,
)
from sgtool.analysis.report import fmt_interval, format_intervals, format_paired, pipe_table
from sgtool.analysis.search_metrics import CostModel, auc_e_of, episode_spl, spl, success_rate
from sgtool.results import EpisodeResult

EpisodeKey = tuple[str, int, str, int]  # EpisodeResult.key(): planner, seed, house, episode
BUDGET_FRACTIONS: tuple[float, ...] = (0.25, 0.5, 0.75, 1.0)  # of the curve's max


def frames_model(frames_per_room: Mapping[EpisodeKey, float],
                 budget: float | None = None) -> CostModel:
    """The cost model "frames per room" of the episodes in ``frames_per_room`` (keyed by
    :meth:`~sgtool.results.EpisodeResult.key`); max ``budget``, else the largest cost
    (rounded up; at least 1)."""
    top = budget if budget is not None else \
        max(1.0, math.ceil(max(frames_per_room.values(), default=1.0)))
    return CostModel("frames", "frames per room of the house", float(top),
                     lambda r: float(frames_per_room[r.key()]))


@dataclass(frozen=True)
class FrameCurveRow:
    """One planner's AUC-E on frames and its SR within each budget (frames per room)."""

    planner: str
    episodes: int
    auc_e: float
    sr_within: tuple[float, ...]


def frame_curves(results: Sequence[EpisodeResult], planners: Sequence[str],
                 model: CostModel, budgets: Sequence[float] = ()
                 ) -> tuple[tuple[float, ...], list[FrameCurveRow]]:
    """The budgets (``budgets`` in frames per room, else :data:`BUDGET_FRACTIONS` of the
    model's max, rounded up to whole frames per room) and per planner its AUC-E (over the
    model's max) and SR within each budget: the share of its episodes that succeeded at a
    cost of at most the budget (the curve's value at its steps, not between them)."""
    budgets = tuple(map(float, budgets)) or \
        tuple(float(math.ceil(model.max_cost * f)) for f in BUDGET_FRACTIONS)
    rows = []
    for p in planners:
        rs = [r for r in results if r.planner == p]
        if not rs:
            continue
        costs = [model.cost(r) for r in rs]
        rows.append(FrameCurveRow(p, len(rs), auc_e_of(rs, model), tuple(
            sum(1 for r, c in zip(rs, costs, strict=True) if r.success and c <= b) / len(rs)
            for b in budgets)))
    return budgets, rows


def format_frame_curves(budgets: Sequence[float], rows: Sequence[FrameCurveRow],
                        title: str = "", max_cost: float | None = None) -> str:
    """The SR-within-budget table; ``max_cost``: the AUC-E's upper end (default: the last
    budget, as :func:`frame_curves` chooses them)."""
    top = budgets[-1] if max_cost is None else max_cost
    header = ["Planner", "Episodes", "AUC-E frames ↑",
              *(f"SR ≤ {b:g} f/room" for b in budgets)]
    body = [[r.planner, str(r.episodes), f"{r.auc_e:.3f}",
             *(f"{v:.3f}" for v in r.sr_within)] for r in rows]
    parts = [title] if title else []
    parts.append(pipe_table(header, body))
    parts.append("SR ≤ b: share of all episodes solved within b frames per room of the "
                 f"house; AUC-E frames: MoMa-LLM's area on that cost (a point per "
                 f"episode, joined by straight lines) over [0, {top:.0f}] / {top:.0f}.")
    return "\n".join(parts) + "\n"


def within_budget(results: Sequence[EpisodeResult], model: CostModel,
                  budget: float) -> list[EpisodeResult]:
    """``results`` as a run with ``budget`` would have scored them: an episode whose cost
    exceeds the budget did not succeed (module doc)."""
    return [r if not r.success or model.cost(r) <= budget else replace(r, success=False)
            for r in results]


def budget_comparisons(results: Sequence[EpisodeResult], planners: Sequence[str],
                       model: CostModel, budgets: Sequence[float],
                       reference: str | None = None, all_pairs: bool = False,
                       boot: Bootstrap = DEFAULT_BOOTSTRAP
                       ) -> tuple[str, list[dict[str, object]]]:
    """Per pair of planners (:func:`~sgtool.analysis.intervals.comparison_pairs`), the
    paired SR difference within each frame budget, intervals over houses: text, dicts."""
    present = [p for p in planners if any(r.planner == p for r in results)]
    pairs = comparison_pairs(present, reference if reference in present else None,
                             all_pairs)
    if not pairs:
        return "", []
    scored = [within_budget(results, model, b) for b in budgets]
    body: list[list[str]] = []
    data: list[dict[str, object]] = []
    for a, b in pairs:
        diffs = [paired_comparison(rs, a, b, by_house, boot, check=False).sr_diff for rs in scored]
        body.append([a, b, *(fmt_interval(d, signed=True) for d in diffs)])
        data.append({"planner": a, "reference": b,
                     "sr_diff_within": [d.to_dict() for d in diffs]})
    header = ["Planner", "Reference", *(f"SR diff ≤ {x:g} f/room" for x in budgets)]
    text = "\n".join([
        "Paired SR difference within each frame budget (planner - reference)",
        pipe_table(header, body),
        "An episode over the budget counts as failed; " + boot.statement("house") + "."])
    return text + "\n", data


def symbolic_agreement(closed: Sequence[EpisodeResult], symbolic: Sequence[EpisodeResult],
                       planners: Sequence[str], boot: Bootstrap = DEFAULT_BOOTSTRAP
                       ) -> tuple[int, list[RankAgreement]]:
    """Kendall's tau between the closed loop's and the symbolic bench's planner scores
    (SPL, then SR; episodes pooled), with its cluster-bootstrap interval over houses
    (:func:`~sgtool.analysis.intervals.kendall_tau_interval`). The symbolic episodes are
    those of the same (house, episode, query) as a closed-loop episode when there are any
    (their count is returned, 0 when none match: then all symbolic episodes count)."""
    wanted = {(r.house, r.episode, r.query) for r in closed}
    same = [r for r in symbolic if (r.house, r.episode, r.query) in wanted]
    pool = same or list(symbolic)
    out = []
    for name, fn, value in (("spl", spl, _episode_spl), ("sr", success_rate, _success)):
        a = {p: fn([r for r in closed if r.planner == p]) for p in planners}
        b = {p: fn([r for r in pool if r.planner == p]) for p in planners}
        tau = kendall_tau({p: v for p, v in a.items() if not math.isnan(v)},
                          {p: v for p, v in b.items() if not math.isnan(v)}, name)
        low, high = kendall_tau_interval(closed, pool, tau.planners, value, by_house, boot)
        out.append(replace(tau, low=low, high=high))
    return len(same), out


def _episode_spl(r: EpisodeResult) -> float:
    return episode_spl(r.success, r.shortest_m, r.travelled_m)


def _success(r: EpisodeResult) -> float:
    return float(r.success)


def format_agreement(matched: int, total: int, rows: Sequence[RankAgreement],
                     source: str) -> str:
    what = (f"{matched} symbolic episodes of the same (house, episode, query)" if matched
            else f"all {total} symbolic episodes (none of the same house, episode and query: "
                 "run the bench with the same --episodes)")
    lines = [f"Agreement with the symbolic order ({source}; {what}): Kendall tau-b over the "
             "planners"]
    for r in rows:
        span = "" if math.isnan(r.low) else f" [{r.low:+.3f}, {r.high:+.3f}]"
        tau = "-" if math.isnan(r.tau) else f"{r.tau:+.3f}{span} (p = {r.p_value:.3f})"
        lines.append(f"- by {r.metric.upper()}: {tau}, {len(r.planners)} planners")
    return "\n".join(lines) + "\n"


def interval_tables(results: Sequence[EpisodeResult], planners: Sequence[str],
                    reference: str | None = None, all_pairs: bool = False,
                    boot: Bootstrap = DEFAULT_BOOTSTRAP) -> tuple[str, dict[str, object]]:
    """SR and SPL with intervals over houses, the paired comparisons over houses, then
    the same comparisons in each house (intervals over its episodes): text and dict."""
    present = [p for p in planners if any(r.planner == p for r in results)]
    ivs = [planner_intervals(results, p, by_house, boot, check=False) for p in present]
    pairs = comparison_pairs(present, reference if reference in present else None,
                             all_pairs)
    overall = [paired_comparison(results, a, b, by_house, boot, check=False)
               for a, b in pairs]
    houses = sorted({r.house for r in results})
    per_house = [(h, paired_comparison([r for r in results if r.house == h], a, b,
                                       by_episode, boot, check=False))
                 for h in houses for a, b in pairs]
    ivs_text = format_intervals(ivs, boot, title="SR and SPL with bootstrap intervals over "
                                                 "houses")
    text = ivs_text + "\nPaired comparisons: no two planners to pair.\n" if not pairs else \
        "\n".join([ivs_text, format_paired(overall, boot, title="Paired comparisons over houses"),
                   format_paired([c for _, c in per_house], boot, cluster="episode",
                                 title="Paired comparisons per house (intervals over its "
                                 "episodes)", labels=[h for h, _ in per_house])])
    data: dict[str, object] = {
        "bootstrap": boot.to_dict(),
        "planners": {r.planner: r.to_dict() for r in ivs},
        "paired": [c.to_dict() for c in overall],
        "paired_per_house": [{"house": h, **c.to_dict()} for h, c in per_house]}
    return text, data


# failed-skill reasons, by the first pattern their text matches
REASONS: tuple[tuple[str, str], ...] = (
    ("unreachable on the robot's map", "unreachable on the map"),
    ("no map yet", "unreachable on the map"),
    ("stands on no free cell", "unreachable on the map"),
    ("blocked by an obstacle", "contact"),
    ("re-plans", "no progress"),
    ("out of reach", "out of reach"),
    ("not on free floor", "not on free floor"),
    ("behind closed door", "behind closed doors"),
    ("no collision-free path", "no path"),
    ("already", "already open/closed"),
    ("cannot be opened", "not openable"),
    ("stands in the way", "robot in the way"),
    ("stopped:", "frame budget"),
)


def reason_class(reason: str) -> str:
    """The class of a failed skill's reason (:data:`REASONS`; "other" when none fits)."""
    for pattern, name in REASONS:
        if pattern in reason:
            return name
    return "other"
