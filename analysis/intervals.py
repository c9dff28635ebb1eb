"""Bootstrap intervals and paired planner comparisons over episode records (pure functions).

Every figure here is a ratio of sums over clusters of episodes: SR = successes / episodes,
SPL = summed episode SPL / episodes with a known shortest path (:func:`~sgtool.analysis.
metrics.episode_spl`), and for a pair of planners on the same episodes the SR difference,
the SPL difference and the SPL ratio (planner's mean SPL / reference's). A **cluster** is
the unit of resampling: a house for a benchmark (its episodes and seeds stay together,
since episodes of one house are not independent), an episode (its seeds together) inside
one house.

Cluster bootstrap: draw as many clusters as there are, with replacement, recompute the
figure from the drawn clusters' sums, ``resamples`` times; the interval is the percentile
interval (linear between order statistics, as ``numpy.quantile``) at ``level``. The draws
come from ``numpy.random.default_rng(seed)`` and depend only on the number of clusters,
so the same records give the same bytes on any machine, and every figure over the same
clusters sees the same resamples (the comparisons of a table share their draws). With
fewer than two clusters there is nothing to resample: the interval is NaN (shown "-").
A resample whose denominator is 0 is left out (0/0) or counts as +inf (x/0, x > 0).

Pairing: two planners' episodes are matched on (house, episode, seed, query, shortest path);
only episodes both ran count (the query and the shortest path keep apart runs of other
houses under one generated name, as two runs' files given together may hold). Wins /
losses / ties are counted per cluster on the paired mean SPL (SR where no episode of the
cluster has a known shortest path), equal within 1e-9.

Kendall's tau (:func:`kendall_tau`) compares two orders of the same planners (e.g. the
closed loop's and the symbolic bench's) by a metric: tau-b of ``scipy.stats.kendalltau``.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable, Hashable, Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from sgtool.analysis.search_metrics import episode_spl
from sgtool.errors import SgtoolError
from sgtool.results import EpisodeResult
from sgtool.semantics.text import category_text

RESAMPLES = 10_000  # bootstrap resamples of every interval
BOOTSTRAP_SEED = 0
LEVEL = 0.95
TIE = 1e-9  # per-cluster SPL (or SR) sums closer than this are a tie

Cluster = Callable[[EpisodeResult], Hashable]


def by_house(r: EpisodeResult) -> Hashable:
    """The cluster of a benchmark: the episode's house."""
    return r.house


def by_episode(r: EpisodeResult) -> Hashable:
    """The cluster inside one house: the episode (its seeds together)."""
    return (r.house, r.episode)


@dataclass(frozen=True)
class Bootstrap:
    """The settings of a cluster bootstrap: resamples, seed of the draws, interval level."""

    resamples: int = RESAMPLES
    seed: int = BOOTSTRAP_SEED
    level: float = LEVEL

    def __post_init__(self) -> None:
        if self.resamples < 1:
            raise ValueError(f"resamples must be >= 1, got {self.resamples}")
        if not 0.0 < self.level < 1.0:
            raise ValueError(f"level must be in (0, 1), got {self.level}")

    def statement(self, cluster: str = "house") -> str:
        """One sentence for a table's notes."""
        kept = "an episode's seeds" if cluster == "episode" else \
            f"a {cluster}'s episodes and seeds"
        return (f"{self.level * 100:g} % cluster-bootstrap intervals: {cluster}s resampled "
                f"with replacement ({kept} kept together), "
                f"{self.resamples} resamples, seed {self.seed}, percentile interval")

    def to_dict(self) -> dict[str, object]:
        return {"resamples": self.resamples, "seed": self.seed, "level": self.level,
                "method": "cluster bootstrap, percentile"}


DEFAULT_BOOTSTRAP = Bootstrap()


@dataclass(frozen=True)
class Interval:
    """A figure on all clusters (``value``) and its bootstrap interval [``low``, ``high``]
    (NaN when it has none)."""

    value: float
    low: float
    high: float

    def format(self, spec: str = ".3f", signed: bool = False) -> str:
        """``value [low, high]``; ``value [-]`` without an interval, ``-`` without a value;
        ``signed`` prints a + before positive numbers (differences). ``str()`` is this."""
        def num(x: float) -> str:
            if math.isinf(x):
                return "inf" if x > 0 else "-inf"
            return format(x, ("+" if signed else "") + spec)

        if math.isnan(self.value):
            return "-"
        if math.isnan(self.low) or math.isnan(self.high):
            return f"{num(self.value)} [-]"
        return f"{num(self.value)} [{num(self.low)}, {num(self.high)}]"

    def __str__(self) -> str:
        return self.format()

    def excludes(self, x: float) -> bool:
        """Whether ``x`` lies outside the interval (False when there is no interval)."""
        return bool(self.low > x or self.high < x)

    def to_dict(self) -> dict[str, float | None]:
        """Rounded to 6 decimals; None for NaN or an infinite bound (a ratio over 0)."""
        def num(v: float) -> float | None:
            return None if math.isnan(v) or math.isinf(v) else round(v, 6)

        return {"value": num(self.value), "low": num(self.low), "high": num(self.high)}


@functools.lru_cache(maxsize=8)
def resample_indices(clusters: int, boot: Bootstrap = DEFAULT_BOOTSTRAP) -> np.ndarray:
    """The drawn clusters of every resample: ``(resamples, clusters)`` indices (read-only,
    the same array for the same arguments)."""
    rng = np.random.default_rng(boot.seed)
    out = rng.integers(0, clusters, size=(boot.resamples, clusters))
    out.setflags(write=False)
    return out


def _ratio(num: float, den: float) -> float:
    if den == 0.0:
        return math.inf if num > 0 else (-math.inf if num < 0 else math.nan)
    return num / den


def _quantile(ordered: np.ndarray, q: float) -> float:
    """``numpy.quantile(..., method="linear")`` of sorted values, +-inf kept as such."""
    pos = q * (ordered.size - 1)
    i = int(math.floor(pos))
    a = float(ordered[i])
    b = float(ordered[min(i + 1, ordered.size - 1)])
    frac = pos - i
    return a if frac == 0.0 or a == b else a + (b - a) * frac


def ratio_interval(num: Sequence[float] | np.ndarray, den: Sequence[float] | np.ndarray,
                   boot: Bootstrap = DEFAULT_BOOTSTRAP) -> Interval:
    """sum(num) / sum(den) over the clusters (one entry each) and its cluster-bootstrap
    interval (module doc)."""
    n = np.asarray(num, dtype=float)
    d = np.asarray(den, dtype=float)
    if n.shape != d.shape or n.ndim != 1:
        raise ValueError("num and den need one entry per cluster each")
    value = _ratio(float(n.sum()), float(d.sum())) if n.size else math.nan
    if n.size < 2:
        return Interval(value, math.nan, math.nan)
    idx = resample_indices(n.size, boot)
    top = n[idx].sum(axis=1)
    bottom = d[idx].sum(axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        stats = np.where(bottom != 0.0, top / np.where(bottom != 0.0, bottom, 1.0),
                         np.sign(top) * np.inf)
    stats = np.sort(stats[~np.isnan(stats)])
    if stats.size == 0:
        return Interval(value, math.nan, math.nan)
    tail = (1.0 - boot.level) / 2.0
    return Interval(value, _quantile(stats, tail), _quantile(stats, 1.0 - tail))


# ----------------------------------------------------------------------------------------
# per planner
# ----------------------------------------------------------------------------------------
@dataclass(frozen=True)
class PlannerIntervals:
    """One planner's SR and SPL with their intervals over ``clusters``."""

    planner: str
    clusters: int
    episodes: int
    sr: Interval
    spl: Interval

    def to_dict(self) -> dict[str, object]:
        return {"clusters": self.clusters, "episodes": self.episodes,
                "sr": self.sr.to_dict(), "spl": self.spl.to_dict()}


def _spl_of(r: EpisodeResult) -> float:
    return episode_spl(r.success, r.shortest_m, r.travelled_m)


def _cluster_keys(results: Sequence[EpisodeResult], cluster: Cluster) -> list[Hashable]:
    """The clusters of ``results`` in a fixed order (by their text), whatever the input
    order."""
    keys = {cluster(r) for r in results}
    return sorted(keys, key=lambda k: (str(k), repr(k)))


def _check_planners(results: Sequence[EpisodeResult], *planners: str) -> None:
    """One line for a planner with no episode in ``results`` (a typo gave NaN intervals)."""
    there = sorted({r.planner for r in results})
    for name in planners:
        if name not in there:
            raise SgtoolError(f"planner {name!r} has no episode in the results (there: "
                              f"{', '.join(there) or 'none'})")


def planner_intervals(results: Sequence[EpisodeResult], planner: str,
                      cluster: Cluster = by_house,
                      boot: Bootstrap = DEFAULT_BOOTSTRAP, *,
                      check: bool = True) -> PlannerIntervals:
    """SR and SPL of ``planner``'s episodes in ``results`` (pooled over seeds, as the
    per-house tables) with cluster-bootstrap intervals; ``check``: a planner without an
    episode there is one :class:`~sgtool.errors.SgtoolError` line (else NaN figures)."""
    if check:
        _check_planners(results, planner)
    rs = [r for r in results if r.planner == planner]
    keys = _cluster_keys(rs, cluster)
    pos = {k: i for i, k in enumerate(keys)}
    n, s, p, m = (np.zeros(len(keys)) for _ in range(4))
    for r in rs:
        i = pos[cluster(r)]
        n[i] += 1
        s[i] += 1.0 if r.success else 0.0
        v = _spl_of(r)
        if not math.isnan(v):
            p[i] += v
            m[i] += 1
    return PlannerIntervals(planner, len(keys), len(rs), ratio_interval(s, n, boot),
                            ratio_interval(p, m, boot))


# ----------------------------------------------------------------------------------------
# paired comparisons
# ----------------------------------------------------------------------------------------
@dataclass(frozen=True)
class PairedComparison:
    """``planner`` against ``reference`` on the episodes both ran: the SPL ratio
    (planner / reference), SR and SPL differences (planner - reference) with intervals,
    and the clusters where the planner did better / worse / the same."""

    planner: str
    reference: str
    clusters: int
    episodes: int  # paired episodes
    spl_ratio: Interval
    sr_diff: Interval
    spl_diff: Interval
    wins: int
    losses: int
    ties: int

    def to_dict(self) -> dict[str, object]:
        return {"planner": self.planner, "reference": self.reference,
                "clusters": self.clusters, "episodes": self.episodes,
                "spl_ratio": self.spl_ratio.to_dict(), "sr_diff": self.sr_diff.to_dict(),
                "spl_diff": self.spl_diff.to_dict(), "wins": self.wins,
                "losses": self.losses, "ties": self.ties}


def pair_key(r: EpisodeResult) -> tuple[str, int, int, str, float | None]:
    """(house, episode, seed, query, shortest path to 1 cm): the shortest path keeps apart
    two houses under one name that drew the same query."""
    short = r.shortest_m
    return (r.house, r.episode, r.seed, category_text(r.query),
            round(short, 2) if short is not None and math.isfinite(short) else None)


def paired_comparison(results: Sequence[EpisodeResult], planner: str, reference: str,
                      cluster: Cluster = by_house,
                      boot: Bootstrap = DEFAULT_BOOTSTRAP, *,
                      check: bool = True) -> PairedComparison:
    """``planner`` against ``reference`` on their common episodes of ``results`` (house,
    episode, seed, query, shortest path: module doc); ``check`` as in
    :func:`planner_intervals`."""
    if check:
        _check_planners(results, planner, reference)
    mine = {pair_key(r): r for r in results if r.planner == planner}
    ref = {pair_key(r): r for r in results if r.planner == reference}
    common = sorted(mine.keys() & ref.keys())
    keys = _cluster_keys([mine[k] for k in common], cluster)
    pos = {k: i for i, k in enumerate(keys)}
    n, sa, sb, pa, pb, m = (np.zeros(len(keys)) for _ in range(6))
    for k in common:
        a, b = mine[k], ref[k]
        i = pos[cluster(a)]
        n[i] += 1
        sa[i] += 1.0 if a.success else 0.0
        sb[i] += 1.0 if b.success else 0.0
        va, vb = _spl_of(a), _spl_of(b)
        if not (math.isnan(va) or math.isnan(vb)):
            pa[i] += va
            pb[i] += vb
            m[i] += 1
    wins = losses = ties = 0
    for i in range(len(keys)):
        x, y = (pa[i], pb[i]) if m[i] else (sa[i], sb[i])
        if x > y + TIE:
            wins += 1
        elif x < y - TIE:
            losses += 1
        else:
            ties += 1
    return PairedComparison(planner, reference, len(keys), len(common),
                            ratio_interval(pa, pb, boot), ratio_interval(sa - sb, n, boot),
                            ratio_interval(pa - pb, m, boot), wins, losses, ties)


def comparison_pairs(planners: Sequence[str], reference: str | None = None,
                     all_pairs: bool = False) -> list[tuple[str, str]]:
    """(planner, reference) pairs to compare: every other planner against ``reference``
    (default: ``scout`` when it is among ``planners``, else the first planner); with
    ``all_pairs``, every pair (i < j in ``planners`` order, the later one as planner)
    instead. A ``reference`` not among ``planners`` raises ValueError."""
    names = list(planners)
    if all_pairs:
        return [(b, a) for i, a in enumerate(names) for b in names[i + 1:]]
    if reference is None:
        reference = "scout" if "scout" in names else (names[0] if names else None)
    elif reference not in names:
        raise ValueError(f"reference {reference!r} is not one of the planners "
                         f"({', '.join(names)})")
    return [(p, reference) for p in names if p != reference] if reference else []


# ----------------------------------------------------------------------------------------
# agreement of two orders
# ----------------------------------------------------------------------------------------
@dataclass(frozen=True)
class RankAgreement:
    """Kendall's tau-b between two scores of the same planners, and its two-sided p."""

    metric: str
    planners: tuple[str, ...]
    tau: float
    p_value: float
    low: float = math.nan  # bootstrap interval of tau (:func:`kendall_tau_interval`)
    high: float = math.nan

    def to_dict(self) -> dict[str, object]:
        def num(v: float) -> float | None:
            return None if math.isnan(v) else round(v, 6)

        return {"metric": self.metric, "planners": list(self.planners),
                "tau": num(self.tau), "p_value": num(self.p_value),
                "low": num(self.low), "high": num(self.high)}


def kendall_tau(a: Mapping[str, float], b: Mapping[str, float],
                metric: str = "") -> RankAgreement:
    """Kendall's tau-b (scipy) between the scores ``a`` and ``b`` of the planners both
    hold with a number (NaN scores left out); NaN with fewer than two planners or when
    one side has a single value for all."""
    from scipy.stats import kendalltau

    names = tuple(p for p in a if p in b and not (math.isnan(a[p]) or math.isnan(b[p])))
    if len(names) < 2:
        return RankAgreement(metric, names, math.nan, math.nan)
    xs = [a[p] for p in names]
    ys = [b[p] for p in names]
    if len(set(xs)) < 2 or len(set(ys)) < 2:
        return RankAgreement(metric, names, math.nan, math.nan)
    res = kendalltau(xs, ys)
    return RankAgreement(metric, names, float(res.statistic), float(res.pvalue))


def kendall_tau_interval(a: Sequence[EpisodeResult], b: Sequence[EpisodeResult],
                         planners: Sequence[str], value: Callable[[EpisodeResult], float],
                         cluster: Cluster = by_house,
                         boot: Bootstrap = DEFAULT_BOOTSTRAP) -> tuple[float, float]:
    """Bootstrap interval of Kendall's tau-b between the planners' mean ``value`` over
    ``a`` and over ``b``: the clusters (houses) of ``a`` and ``b`` together are resampled,
    the same draw for both sides, and tau taken on each resample (tau-b = Σ s_x s_y /
    sqrt(Σ s_x² Σ s_y²) over the pairs of planners, s the sign of a pair's difference, as
    scipy's; resamples where it is undefined are left out; an episode whose ``value`` is
    NaN, an SPL without a known shortest path, is left out as the point tau leaves it);
    (NaN, NaN) with fewer than two clusters or planners."""
    keys = _cluster_keys([*a, *b], cluster)
    names = list(dict.fromkeys(planners))
    if len(keys) < 2 or len(names) < 2:
        return math.nan, math.nan
    row = {k: i for i, k in enumerate(keys)}
    col = {p: j for j, p in enumerate(names)}
    sides = []
    for results in (a, b):
        sums = np.zeros((len(keys), len(names)))
        counts = np.zeros((len(keys), len(names)))
        for r in results:
            j = col.get(r.planner)
            v = value(r) if j is not None else math.nan
            if j is not None and not math.isnan(v):  # an SPL without a shortest path: out
                i = row[cluster(r)]
                sums[i, j] += v
                counts[i, j] += 1
        sides.append((sums, counts))
    idx = resample_indices(len(keys), boot)
    means = []
    for sums, counts in sides:
        n = counts[idx].sum(axis=1)
        with np.errstate(invalid="ignore", divide="ignore"):
            means.append(sums[idx].sum(axis=1) / n)
    x, y = means
    lo, hi = np.triu_indices(len(names), k=1)
    ok = np.isfinite(x[:, lo]) & np.isfinite(x[:, hi]) & np.isfinite(y[:, lo]) & \
        np.isfinite(y[:, hi])  # pairs of planners with a score on both sides
    sx = np.where(ok, np.sign(x[:, lo] - x[:, hi]), 0.0)
    sy = np.where(ok, np.sign(y[:, lo] - y[:, hi]), 0.0)
    den = np.sqrt((sx * sx).sum(axis=1) * (sy * sy).sum(axis=1))
    with np.errstate(invalid="ignore", divide="ignore"):  # tau-b: sum sx sy / sqrt(...)
        tau_b = (sx * sy).sum(axis=1) / den
    taus = tau_b[den > 0]
    if not taus.size:
        return math.nan, math.nan
    ordered = np.sort(taus)
    half = (1.0 - boot.level) / 2.0
    return _quantile(ordered, half), _quantile(ordered, 1.0 - half)
