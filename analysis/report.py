"""Text tables in the shape of SCOUT's Table VII (SymSearch columns) and Table IX.

Plain text (a Markdown pipe table), so the same string prints on a terminal, goes into
``summary.md`` and into the README demo. Numbers: SR, SPL and AUC-E with three decimals,
steps with one, decision time in seconds with four (our planners decide in milliseconds,
where SCOUT's two decimals would show zeros).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence

from sgtool.analysis.metrics import CostModel, PlannerSummary, SplitSummary, Stat

_COLUMNS: tuple[tuple[str, str, str], ...] = (
    # (stat key, header, format)
    ("sr", "SR ↑", ".3f"),
    ("spl", "SPL ↑", ".3f"),
    ("steps", "N steps ↓", ".1f"),
    ("decision_s", "Decision time (s) ↓", ".4f"),
    ("auc_e_distance", "AUC-E dist ↑", ".3f"),
    ("auc_e_steps", "AUC-E steps ↑", ".3f"),
)


def _fmt(x: float, spec: str) -> str:
    return "-" if x is None or math.isnan(x) else format(x, spec)


def fmt_stat(s: Stat | None, spec: str) -> str:
    if s is None or math.isnan(s.mean):
        return "-"
    return f"{format(s.mean, spec)} ± {format(s.std, spec)}"


def pipe_table(header: Sequence[str], rows: Sequence[Sequence[str]]) -> str:
    widths = [max(len(h), *(len(r[i]) for r in rows)) if rows else len(h)
              for i, h in enumerate(header)]

    def line(cells: Sequence[str]) -> str:
        return "| " + " | ".join(c.ljust(w) for c, w in zip(cells, widths, strict=True)) + " |"

    sep = "|" + "|".join("-" * (w + 2) for w in widths) + "|"
    return "\n".join([line(header), sep, *(line(r) for r in rows)])


def format_table(summaries: Sequence[PlannerSummary],
                 throughput: Mapping[str, float] | None = None,
                 models: Sequence[CostModel] = (), title: str = "") -> str:
    """Table VII's SymSearch columns plus AUC-E (both cost models) and, when given, the
    measured throughput (episodes per second, a wall-clock figure)."""
    header = ["Planner", *(h for _, h, _ in _COLUMNS), "Episodes"]
    if throughput is not None:
        header.append("Episodes/s")
    rows = []
    for s in summaries:
        row = [s.planner, *(fmt_stat(s.stats.get(k), spec) for k, _, spec in _COLUMNS),
               f"{s.episodes} ({len(s.seeds)} seeds)"]
        if throughput is not None:
            row.append(_fmt(throughput.get(s.planner, math.nan), ".1f"))
        rows.append(row)
    parts = []
    if title:
        parts.append(title)
    parts.append(pipe_table(header, rows))
    notes = ["mean ± std (ddof=1) over seeds; decision time = wall seconds per decision."]
    if models:
        notes.append("AUC-E budgets: " + "; ".join(m.statement() for m in models) + ".")
    parts.append("\n".join(notes))
    return "\n".join(parts) + "\n"


def format_seen_unseen(rows: Sequence[SplitSummary], title: str = "") -> str:
    """SCOUT Table IX: SR and SPL on seen and on unseen queries (episodes pooled over seeds)."""
    header = ["Planner", "Seen SR", "Seen SPL", "Seen n", "Unseen SR", "Unseen SPL", "Unseen n"]
    body = [[r.planner, _fmt(r.seen_sr, ".3f"), _fmt(r.seen_spl, ".3f"), str(r.seen_n),
             _fmt(r.unseen_sr, ".3f"), _fmt(r.unseen_spl, ".3f"), str(r.unseen_n)]
            for r in rows]
    parts = [title] if title else []
    parts.append(pipe_table(header, body))
    return "\n".join(parts) + "\n"


def summary_dict(summaries: Sequence[PlannerSummary]) -> dict[str, dict[str, object]]:
    """JSON-ready summary: planner -> metric -> {mean, std, per_seed}."""
    def num(x: float) -> float | None:
        return None if math.isnan(x) else round(x, 6)

    return {
        s.planner: {
            "episodes": s.episodes,
            "seeds": list(s.seeds),
            **{k: {"mean": num(v.mean), "std": num(v.std),
                   "per_seed": [num(x) for x in v.per_seed]} for k, v in s.stats.items()},
        }
        for s in summaries
    }
