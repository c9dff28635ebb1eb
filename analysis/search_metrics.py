"""Object-search metrics as pure functions over episode records.

- Success rate (SR): share of episodes whose target was revealed.
- SPL (Anderson et al.; SCOUT Table VII, MoMa-LLM): per episode
  ``S * l / max(l, p)`` with S the success (0/1), l the shortest path length from the start
  to the target and p the path length travelled; averaged over all episodes. An episode
  with ``l = p = 0`` (target seen from the start) scores S.
- High-level steps: mean number of actions per episode, failures included (SCOUT Table VII
  "N Steps"; a failed episode counts the steps it spent: its full budget when it ran out,
  fewer when it gave up).
- Decision time: mean wall time of one planner decision (total decision seconds over total
  decisions), SCOUT's "Inference Time".
- AUC-E (MoMa-LLM, "Area Under the Efficiency Curve"), as MoMa-LLM's released code
  computes it (``run_agent.py``: ``_plot`` and ``calc_area_under_curve``): one point per
  episode, failures included, at its cost x, with y = the share of ALL episodes solved at
  a cost <= x (tied costs share the full count); the points above the budget maximum are
  left out, the last y is extended to the maximum, (0, 0) is put first, and the trapezoid
  area over the points divided by the maximum lies in [0, 1] (the curve rises linearly
  between points, so its figures compare with the paper's, not with the area of the step
  function y(b)). Two cost models (:data:`DISTANCE_COST`, :data:`STEP_COST`):

  * distance-plus-open cost, MoMa-LLM's low-level variant: low-level steps of 0.1 m
    (travelled / 0.1) plus 30 per open interaction, budget 5000;
  * step cost, MoMa-LLM's high-level variant: number of high-level decisions, budget 50
    (SymSearch's N_max).

Aggregation over seeds (SCOUT: "averaged across 5 different seeds"): every metric is
computed per seed on that seed's episodes, then reported as mean +- sample standard
deviation (ddof = 1; none, "-", with one seed) over seeds. Efficiency curves are drawn
over all seeds' episodes pooled; their legends give the table's AUC-E, the mean of the
seeds' areas (:func:`mean_auc_e`; the pooled curve's own area differs when the seeds'
costs differ).
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable, Hashable, Sequence
from dataclasses import dataclass
from typing import TypeVar

import numpy as np

from sgtool.errors import ArgumentError
from sgtool.results import EpisodeResult, episode_spl


# ----------------------------------------------------------------------------------------
# per-episode quantities
# ----------------------------------------------------------------------------------------
@dataclass(frozen=True)
class CostModel:
    """How an episode's cost is measured for an efficiency curve, and the budget maximum."""

    name: str
    label: str  # axis label / statement in the output
    max_cost: float
    cost: Callable[[EpisodeResult], float]

    def statement(self) -> str:
        return f"{self.name}: {self.label}, budget max {self.max_cost:g}"


LOW_LEVEL_STEP_M = 0.1  # MoMa-LLM: one low-level step ~ 0.1 m
OPEN_COST = 30.0  # MoMa-LLM: an open interaction costs 30 low-level steps
DISTANCE_BUDGET = 5000.0
STEP_BUDGET = 50.0


def distance_cost(r: EpisodeResult, step_m: float = LOW_LEVEL_STEP_M,
                  open_cost: float = OPEN_COST) -> float:
    return float(r.travelled_m) / step_m + open_cost * int(r.n_open)


def step_cost(r: EpisodeResult) -> float:
    return float(r.steps)


DISTANCE_COST = CostModel(
    "distance",
    f"travelled / {LOW_LEVEL_STEP_M:g} m + {OPEN_COST:g} per open (low-level steps)",
    DISTANCE_BUDGET, distance_cost,
)
STEP_COST = CostModel("steps", "high-level steps", STEP_BUDGET, step_cost)
COST_MODELS: tuple[CostModel, ...] = (DISTANCE_COST, STEP_COST)


def cost_models(distance_budget: float = DISTANCE_BUDGET, step_budget: float = STEP_BUDGET,
                step_m: float = LOW_LEVEL_STEP_M, open_cost: float = OPEN_COST
                ) -> tuple[CostModel, CostModel]:
    """The two cost models with other budgets or unit costs."""
    dist = CostModel(
        "distance", f"travelled / {step_m:g} m + {open_cost:g} per open (low-level steps)",
        float(distance_budget), functools.partial(distance_cost, step_m=step_m,
                                                  open_cost=open_cost),
    )
    return dist, CostModel("steps", "high-level steps", float(step_budget), step_cost)


# ----------------------------------------------------------------------------------------
# episode-set metrics
# ----------------------------------------------------------------------------------------
def success_rate(results: Sequence[EpisodeResult]) -> float:
    """The share of ``results`` that succeeded; NaN for no episodes."""
    if not results:
        return math.nan
    return sum(1 for r in results if r.success) / len(results)


def spl(results: Sequence[EpisodeResult]) -> float:
    """Mean SPL over the episodes whose shortest path is known."""
    vals = [episode_spl(r.success, r.shortest_m, r.travelled_m) for r in results]
    vals = [v for v in vals if not math.isnan(v)]
    return float(np.mean(vals)) if vals else math.nan


def mean_steps(results: Sequence[EpisodeResult]) -> float:
    """Mean high-level steps per episode (a failed episode counts all it spent); NaN for
    no episodes."""
    return float(np.mean([r.steps for r in results])) if results else math.nan


def mean_decision_time(results: Sequence[EpisodeResult]) -> float:
    """Total decision seconds over total decisions (s per decision)."""
    n = sum(r.decisions for r in results)
    if n == 0:
        return math.nan
    return sum(r.decision_s for r in results) / n


def efficiency_curve(costs: Sequence[float], successes: Sequence[bool], max_cost: float
                     ) -> tuple[np.ndarray, np.ndarray]:
    """MoMa-LLM's efficiency curve as polyline vertices (x = budget, y = SR within it).

    Vertices (module doc): (0, 0); then for every episode in order of cost, solved or
    not, (cost, share of all episodes solved at a cost <= it), those above ``max_cost``
    left out; finally (max_cost, last y) unless the last cost is ``max_cost``. Costs are
    clipped below at 0.
    """
    if len(costs) != len(successes):
        raise ArgumentError("costs and successes differ in length")
    if not max_cost > 0:
        raise ArgumentError("max_cost must be > 0")
    if any(math.isnan(float(c)) for c in costs):
        raise ArgumentError("costs: a NaN cost has no place on the curve")
    n = len(costs)
    if n == 0:
        return np.array([0.0, float(max_cost)]), np.array([0.0, 0.0])
    cost = np.maximum(np.asarray(costs, dtype=np.float64), 0.0)
    won = np.asarray(successes, dtype=bool)
    xs = np.sort(cost)
    # solved at a cost <= x, for every x (ties get the full count)
    ys = np.searchsorted(np.sort(cost[won]), xs, side="right") / n
    keep = xs <= max_cost
    xs, ys = xs[keep], ys[keep]
    if not xs.size or xs[-1] < max_cost:
        xs = np.append(xs, float(max_cost))
        ys = np.append(ys, ys[-1] if ys.size else 0.0)
    return np.concatenate([[0.0], xs]), np.concatenate([[0.0], ys])


def curve_area(xs: np.ndarray, ys: np.ndarray, max_cost: float) -> float:
    """Trapezoid area under the polyline divided by ``max_cost``."""
    dx = np.diff(xs)
    return float(np.sum(dx * (ys[1:] + ys[:-1]) / 2.0) / max_cost)


def auc_e(costs: Sequence[float], successes: Sequence[bool], max_cost: float) -> float:
    """Area under the efficiency curve over [0, max_cost], divided by max_cost (in [0, 1])."""
    xs, ys = efficiency_curve(costs, successes, max_cost)
    return curve_area(xs, ys, max_cost)


def auc_e_of(results: Sequence[EpisodeResult], model: CostModel) -> float:
    if not results:
        return math.nan
    return auc_e([model.cost(r) for r in results], [r.success for r in results],
                 model.max_cost)


def mean_auc_e(results: Sequence[EpisodeResult], model: CostModel) -> float:
    """The mean over seeds of each seed's AUC-E (the tables' figure; NaN without results)."""
    if not results:
        return math.nan
    by_seed = group_by(results, lambda r: r.seed)
    return float(np.mean([auc_e_of(by_seed[s], model) for s in sorted(by_seed)]))


def curve_of(results: Sequence[EpisodeResult], model: CostModel
             ) -> tuple[np.ndarray, np.ndarray]:
    return efficiency_curve([model.cost(r) for r in results], [r.success for r in results],
                            model.max_cost)


# ----------------------------------------------------------------------------------------
# aggregation over seeds
# ----------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Stat:
    """A metric over seeds: mean, sample std (ddof=1; NaN for one seed: no spread is
    measured), per-seed values."""

    mean: float
    std: float
    per_seed: tuple[float, ...]

    @classmethod
    def of(cls, values: Sequence[float]) -> Stat:
        vals = [float(v) for v in values if not math.isnan(float(v))]
        if not vals:
            return cls(math.nan, math.nan, tuple(float(v) for v in values))
        std = float(np.std(vals, ddof=1)) if len(vals) > 1 else math.nan
        return cls(float(np.mean(vals)), std, tuple(float(v) for v in values))


METRICS: tuple[str, ...] = ("sr", "spl", "steps", "decision_s", "auc_e_distance",
                            "auc_e_steps")


def metrics_of(results: Sequence[EpisodeResult],
               models: Sequence[CostModel] = COST_MODELS) -> dict[str, float]:
    """Every metric of one set of episodes (e.g. one planner, one seed)."""
    out = {
        "sr": success_rate(results),
        "spl": spl(results),
        "steps": mean_steps(results),
        "decision_s": mean_decision_time(results),
    }
    for m in models:
        out[f"auc_e_{m.name}"] = auc_e_of(results, m)
    return out


@dataclass(frozen=True)
class PlannerSummary:
    """One planner's metrics (:func:`summarize`): its ``episodes`` over all seeds, the
    ``seeds``, and per metric name (``sr``, ``spl``, ``steps``, ``decision_s``, one
    ``auc_e_NAME`` per cost model: :data:`METRICS`) a :class:`Stat` over the seeds."""

    planner: str
    episodes: int  # all episodes over all seeds
    seeds: tuple[int, ...]
    stats: dict[str, Stat]


K = TypeVar("K", bound=Hashable)


def group_by(results: Sequence[EpisodeResult], key: Callable[[EpisodeResult], K]
             ) -> dict[K, list[EpisodeResult]]:
    """``results`` by ``key``, each group in input order, keys in order of first appearance."""
    out: dict[K, list[EpisodeResult]] = {}
    for r in results:
        out.setdefault(key(r), []).append(r)
    return out


def planner_order(results: Sequence[EpisodeResult]) -> list[str]:
    """Planners in order of first appearance."""
    seen: dict[str, None] = {}
    for r in results:
        seen.setdefault(r.planner, None)
    return list(seen)


def summarize(results: Sequence[EpisodeResult], models: Sequence[CostModel] = COST_MODELS,
              planners: Sequence[str] | None = None) -> list[PlannerSummary]:
    """Per planner: each metric per seed, then mean +- std over seeds."""
    order = list(planners) if planners is not None else planner_order(results)
    by_planner = group_by(results, lambda r: r.planner)
    out = []
    for p in order:
        rs = by_planner.get(p, [])
        by_seed = group_by(rs, lambda r: r.seed)
        seeds = sorted(by_seed)
        per_seed = [metrics_of(by_seed[s], models) for s in seeds]
        names = list(per_seed[0]) if per_seed else [*METRICS]
        stats = {k: Stat.of([m[k] for m in per_seed]) for k in names}
        out.append(PlannerSummary(p, len(rs), tuple(int(s) for s in seeds), stats))
    return out


@dataclass(frozen=True)
class SplitSummary:
    """SCOUT Table IX: SR and SPL on seen and on unseen queries (pooled over seeds)."""

    planner: str
    seen_n: int
    seen_sr: float
    seen_spl: float
    unseen_n: int
    unseen_sr: float
    unseen_spl: float
    seen_queries: int = 0  # distinct query categories among the seen episodes
    unseen_queries: int = 0


def seen_unseen(results: Sequence[EpisodeResult], planners: Sequence[str] | None = None
                ) -> list[SplitSummary]:
    """Episodes with ``seen`` None are left out of both columns."""
    order = list(planners) if planners is not None else planner_order(results)
    by_planner = group_by(results, lambda r: r.planner)
    out = []
    for p in order:
        rs = by_planner.get(p, [])
        seen = [r for r in rs if r.seen is True]
        unseen = [r for r in rs if r.seen is False]
        out.append(SplitSummary(p, len(seen), success_rate(seen), spl(seen), len(unseen),
                                success_rate(unseen), spl(unseen),
                                len({r.query for r in seen}), len({r.query for r in unseen})))
    return out


@dataclass(frozen=True)
class BreakdownRow:
    """One planner's episodes of one house or one query, pooled over seeds."""

    key: str  # the house id or the query
    planner: str
    episodes: int
    sr: float
    spl: float
    steps: float
    seen: bool | None = None  # per query: seen by the priors (None per house)


def breakdown(results: Sequence[EpisodeResult], by: str,
              planners: Sequence[str] | None = None) -> list[BreakdownRow]:
    """SR, SPL and mean steps per (house or query, planner), ``by`` = "house" or "query";
    rows sorted by key (plain string order), then by planner in ``planners`` order."""
    if by not in ("house", "query"):
        raise ArgumentError(f"by must be 'house' or 'query', got {by!r}")
    order = list(planners) if planners is not None else planner_order(results)
    groups = group_by(results, lambda r: (r.house if by == "house" else r.query, r.planner))
    out = []
    for key in sorted({k for k, _ in groups}):
        for p in order:
            rs = groups.get((key, p))
            if not rs:
                continue
            seen = {r.seen for r in rs}
            out.append(BreakdownRow(str(key), p, len(rs), success_rate(rs), spl(rs),
                                    mean_steps(rs),
                                    seen.pop() if by == "query" and len(seen) == 1 else None))
    return out
