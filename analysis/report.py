"""Text tables in the shape of SCOUT's Table VII (SymSearch columns) and Table IX, the same
columns next to the rows quoted from the paper (:mod:`sgtool.analysis.paper_tables`), and
the per-house and per-query breakdowns.

Plain text (a Markdown pipe table), so the same string prints on a terminal, goes into
``summary.md`` and into the README demo. Numbers: SR, SPL and AUC-E with three decimals,
steps with one, decision time in seconds with four (our planners decide in milliseconds,
where SCOUT's two decimals would show zeros).
"""

from __future__ import annotations

import math
import re
from collections.abc import Mapping, Sequence

from sgtool.analysis.intervals import Bootstrap, Interval, PairedComparison, PlannerIntervals
from sgtool.analysis.paper_tables import (
    SOURCE,
    SOURCE_IX,
    TABLE_VII_SYMSEARCH,
    QuotedRow,
    QuotedSplit,
    quoted_for,
)
from sgtool.analysis.search_metrics import (
    BreakdownRow,
    CostModel,
    PlannerSummary,
    SplitSummary,
    Stat,
)
from sgtool.llm.stats import COUNTS, invalid_rate_text
from sgtool.results import EpisodeResult

_COLUMNS: tuple[tuple[str, str, str], ...] = (
    # (stat key, header, format)
    ("sr", "SR ↑", ".3f"),
    ("spl", "SPL ↑", ".3f"),
    ("steps", "N steps ↓", ".1f"),
    ("decision_s", "Decision time (s) ↓", ".4f"),
    ("auc_e_distance", "AUC-E dist ↑", ".3f"),
    ("auc_e_steps", "AUC-E steps ↑", ".3f"),
)


_SHORT = {"distance": "dist"}  # cost model names shortened in column headers


def _fmt(x: float, spec: str) -> str:
    return "-" if x is None or math.isnan(x) else format(x, spec)


def _rate_text(rate: float) -> str:
    """A rate with one decimal, or two significant digits below 1 (an LLM planner's few
    episodes a second), never in exponent notation; "-" when unknown."""
    if rate is None or not math.isfinite(rate):
        return "-"
    if rate > 0:
        rate = float(f"{rate:.2g}")  # two significant digits first, then the decimals
    if rate >= 1 or rate <= 0:
        return f"{rate:.1f}"
    return f"{rate:.{1 - math.floor(math.log10(rate))}f}"


def fmt_stat(s: Stat | None, spec: str) -> str:
    """``mean ± std``; ``mean ± -`` over one seed (no spread measured); "-" for none."""
    if s is None or math.isnan(s.mean):
        return "-"
    return f"{format(s.mean, spec)} ± {'-' if math.isnan(s.std) else format(s.std, spec)}"


# a line break of any kind (those str.splitlines knows) inside a table cell
_LINE_BREAK = re.compile("\r\n|[\n\r\v\f\x1c\x1d\x1e\x85\u2028\u2029]")


def table_cell(text: str) -> str:
    """``text`` as one Markdown table cell: ``|`` escaped as ``\\|``, a line break shown as
    ``\\n`` (a name given by the user, a house id or a category, stays in its cell)."""
    return _LINE_BREAK.sub(r"\\n", text.replace("|", "\\|"))


def pipe_table(header: Sequence[str], rows: Sequence[Sequence[str]]) -> str:
    """A Markdown pipe table, columns padded to their widest cell; every cell goes through
    :func:`table_cell`."""
    header = [table_cell(h) for h in header]
    rows = [[table_cell(c) for c in r] for r in rows]
    widths = [max(len(h), *(len(r[i]) for r in rows)) if rows else len(h)
              for i, h in enumerate(header)]

    def line(cells: Sequence[str]) -> str:
        return "| " + " | ".join(c.ljust(w) for c, w in zip(cells, widths, strict=True)) + " |"

    sep = "|" + "|".join("-" * (w + 2) for w in widths) + "|"
    return "\n".join([line(header), sep, *(line(r) for r in rows)])


def format_table(summaries: Sequence[PlannerSummary],
                 throughput: Mapping[str, float] | None = None,
                 models: Sequence[CostModel] = (), title: str = "",
                 timing: bool = True) -> str:
    """Table VII's SymSearch columns plus AUC-E (a column per cost model of ``models``;
    none given: the distance and step models) and, when given, the measured throughput
    (episodes per second, a wall-clock figure). ``timing=False`` leaves out the decision
    time (wall clock), so the table depends on the results alone."""
    columns = [c for c in _COLUMNS if timing or c[0] != "decision_s"]
    if models:
        columns = [c for c in columns if not c[0].startswith("auc_e_")] + [
            (f"auc_e_{m.name}", f"AUC-E {_SHORT.get(m.name, m.name)} ↑", ".3f")
            for m in models]
    header = ["Planner", *(h for _, h, _ in columns), "Episodes"]
    if throughput is not None:
        header.append("Episodes/s")
    rows = []
    for s in summaries:
        row = [s.planner, *(fmt_stat(s.stats.get(k), spec) for k, _, spec in columns),
               f"{s.episodes} ({len(s.seeds)} seeds)"]
        if throughput is not None:
            row.append(_rate_text(throughput.get(s.planner, math.nan)))
        rows.append(row)
    parts = []
    if title:
        parts.append(title)
    parts.append(pipe_table(header, rows))
    notes = ["mean ± std (ddof=1) over seeds"
             + ("; decision time = wall seconds per decision." if timing else ".")]
    if models:
        notes.append("AUC-E budgets: " + "; ".join(m.statement() for m in models) + ".")
    parts.append("\n".join(notes))
    return "\n".join(parts) + "\n"


def format_seen_unseen(rows: Sequence[SplitSummary], title: str = "",
                       quoted: QuotedSplit | None = None) -> str:
    """SCOUT Table IX: SR and SPL on seen and on unseen queries (episodes pooled over
    seeds), with the episode and distinct-query counts of each half; then, with ``quoted``
    (e.g. :data:`~sgtool.analysis.paper_tables.TABLE_IX_SYMSEARCH`), the paper's own row,
    marked as quoted."""
    header = ["Planner", "Seen SR", "Seen SPL", "Seen n", "Seen queries", "Unseen SR",
              "Unseen SPL", "Unseen n", "Unseen queries"]
    body = [[r.planner, _fmt(r.seen_sr, ".3f"), _fmt(r.seen_spl, ".3f"), str(r.seen_n),
             str(r.seen_queries), _fmt(r.unseen_sr, ".3f"), _fmt(r.unseen_spl, ".3f"),
             str(r.unseen_n), str(r.unseen_queries)]
            for r in rows]
    if quoted is not None:
        body.append([f"{quoted.agent} (quoted from SCOUT Table IX)", f"{quoted.seen_sr:.3f}",
                     f"{quoted.seen_spl:.3f}", "-", "-", f"{quoted.unseen_sr:.3f}",
                     f"{quoted.unseen_spl:.3f}", "-", "-"])
    parts = [title] if title else []
    parts.append(pipe_table(header, body))
    if quoted is not None:
        parts.append(f"Last row quoted from {SOURCE_IX}: SymSearch scenes, not these houses.")
    return "\n".join(parts) + "\n"


def format_side_by_side(summaries: Sequence[PlannerSummary], title: str = "",
                        timing: bool = True) -> str:
    """Our Table VII columns next to the SymSearch rows quoted from SCOUT Table VII: one row
    per planner of ours (with the paper's agent of the same design, when there is one),
    then the paper's agents we have no planner for. ``timing=False`` leaves out our
    decision time (wall clock)."""
    header = ["Planner", "SCOUT agent (quoted)", "SR ours", "SR quoted", "SPL ours",
              "SPL quoted", "N steps ours", "N steps quoted", "Decision (s) ours",
              "Inference (s) quoted"]

    def quote(q: QuotedRow | None, field: str, spec: str) -> str:
        if q is None:
            return "-"
        mean, std = getattr(q, field)
        return f"{format(mean, spec)} ± {format(std, spec)}"

    def row(planner: str, s: PlannerSummary | None, q: QuotedRow | None) -> list[str]:
        ours = [fmt_stat(s.stats.get(k), spec) if s is not None else "-"
                for k, spec in (("sr", ".3f"), ("spl", ".3f"), ("steps", ".1f"),
                                ("decision_s", ".4f"))]
        return [planner, q.agent if q is not None else "-",
                ours[0], quote(q, "sr", ".3f"), ours[1], quote(q, "spl", ".3f"),
                ours[2], quote(q, "steps", ".0f"), ours[3], quote(q, "inference_s", ".2f")]

    rows = [row(s.planner, s, quoted_for(s.planner)) for s in summaries]
    ours = {s.planner for s in summaries}
    rows += [row("-", None, q) for q in TABLE_VII_SYMSEARCH if q.planner not in ours]
    if not timing:
        drop = header.index("Decision (s) ours")
        header = header[:drop] + header[drop + 1:]
        rows = [r[:drop] + r[drop + 1:] for r in rows]
    parts = [title] if title else []
    parts.append(pipe_table(header, rows))
    parts.append(f"Columns \"quoted\" are quoted from SCOUT Table VII ({SOURCE}): mean ± "
                 "std over 5 seeds on SymSearch's scenes with SCOUT's LLM-distilled priors. "
                 "They show the regime of the published benchmark; ours are these houses.")
    return "\n".join(parts) + "\n"


def format_breakdown(rows: Sequence[BreakdownRow], by: str, planners: Sequence[str],
                     title: str = "") -> str:
    """Per-house or per-query table (``by`` = "house" or "query"): one line per house or
    query, ``SR / SPL`` per planner, episodes per planner (pooled over seeds), and for
    queries whether the priors saw them in training."""
    keys = list(dict.fromkeys(r.key for r in rows))
    cell = {(r.key, r.planner): r for r in rows}
    header = ["House" if by == "house" else "Query"]
    if by == "query":
        header.append("Seen")
    header += ["Episodes", *(f"{p} SR / SPL" for p in planners)]
    body = []
    for k in keys:
        got = [cell[(k, p)] for p in planners if (k, p) in cell]
        line = [k]
        if by == "query":
            seen = got[0].seen if got else None
            line.append("-" if seen is None else ("yes" if seen else "no"))
        line.append(str(got[0].episodes) if got else "0")
        line += [f"{_fmt(cell[(k, p)].sr, '.3f')} / {_fmt(cell[(k, p)].spl, '.3f')}"
                 if (k, p) in cell else "-" for p in planners]
        body.append(line)
    parts = [title] if title else []
    parts.append(pipe_table(header, body))
    return "\n".join(parts) + "\n"


def breakdown_records(rows: Sequence[BreakdownRow], by: str) -> list[dict[str, object]]:
    """JSON-ready rows of a breakdown (NaN as null), one per (house or query, planner)."""
    def num(x: float) -> float | None:
        return None if math.isnan(x) else round(x, 6)

    out: list[dict[str, object]] = []
    for r in rows:
        d: dict[str, object] = {by: r.key, "planner": r.planner, "episodes": r.episodes,
                                "sr": num(r.sr), "spl": num(r.spl), "steps": num(r.steps)}
        if by == "query":
            d["seen"] = r.seen
        out.append(d)
    return out


def summary_dict(summaries: Sequence[PlannerSummary],
                 timing: bool = True) -> dict[str, dict[str, object]]:
    """JSON-ready summary: planner -> metric -> {mean, std, per_seed}; ``timing=False``
    leaves out the decision time (wall clock)."""
    def num(x: float) -> float | None:
        return None if math.isnan(x) else round(x, 6)

    return {
        s.planner: {
            "episodes": s.episodes,
            "seeds": list(s.seeds),
            **{k: {"mean": num(v.mean), "std": num(v.std),
                   "per_seed": [num(x) for x in v.per_seed]} for k, v in s.stats.items()
               if timing or k != "decision_s"},
        }
        for s in summaries
    }


def llm_answer_totals(results: Sequence[EpisodeResult], planners: Sequence[str]
                      ) -> dict[str, dict[str, int]]:
    """planner -> summed LLM answer counts (``EpisodeResult.llm_answers``), for the planners
    that asked an LLM."""
    out = {}
    for p in planners:
        tot = {k: 0 for k in COUNTS}
        for r in results:
            if r.planner == p:
                for k in COUNTS:
                    tot[k] += int(r.llm_answers.get(k, 0))
        if tot["requests"]:
            out[p] = tot
    return out


def llm_warnings(results: Sequence[EpisodeResult], planners: Sequence[str]) -> list[str]:
    """A warning line per planner that asked an LLM and got no valid answer at all (a
    wrong endpoint or model, one answering garbage), or met faults (timeouts, server
    errors, unusable replies: a decision none of whose attempts got an answer ended its
    episode given up)."""
    out = []
    for p, t in llm_answer_totals(results, planners).items():
        if not t["valid"]:
            out.append(f"sgtool: warning: {p}: none of its {t['requests']} LLM requests got "
                       f"a valid answer ({t['invalid']} rejected, {t['faults']} faults); "
                       "check the endpoint and model with `sgtool llm check`")
        elif t["faults"]:
            out.append(f"sgtool: warning: {p}: {t['faults']} of its {t['requests']} LLM "
                       "requests failed (timeouts, server errors, unusable replies); a "
                       "decision left without an answer ended its episode given up")
    return out


def invalid_action_notes(results: Sequence[EpisodeResult], planners: Sequence[str]
                         ) -> list[str]:
    """A note per planner some of whose actions were invalid (a target that is no node of
    the scene graph it was given, a skill its node does not offer): each spent a step and
    did nothing, so a planner that names nodes wrongly looks like one that searches badly
    unless told (summary.md's lines; the commands show them as notes)."""
    out = []
    for p in planners:
        rs = [r for r in results if r.planner == p]
        bad = sum(r.n_invalid for r in rs)
        if bad:
            out.append(f"{p}: {bad} of its {sum(r.steps for r in rs)} actions "
                       f"(in {sum(1 for r in rs if r.n_invalid)} of {len(rs)} episodes) were "
                       "invalid, a target that is no node of the scene graph it was given or "
                       "a skill the node does not offer, and spent a step each (n_invalid in "
                       "episodes.jsonl)")
    return out


def llm_answer_lines(results: Sequence[EpisodeResult], planners: Sequence[str]) -> list[str]:
    """One line per planner that asked an LLM: its requests, valid and rejected answers (the
    invalid-answer rate) and transport faults."""
    return [f"LLM answers of {p}: {t['requests']} requests, {t['valid']} valid, "
            f"{t['invalid']} rejected (invalid-answer rate "
            f"{invalid_rate_text(t['valid'], t['invalid'])}), {t['faults']} faults, "
            f"{t['unknown']} without verdict"
            for p, t in llm_answer_totals(results, planners).items()]


def fmt_interval(iv: Interval, spec: str = ".3f", signed: bool = False) -> str:
    """:meth:`Interval.format <sgtool.analysis.intervals.Interval.format>`."""
    return iv.format(spec, signed)


def format_intervals(rows: Sequence[PlannerIntervals], boot: Bootstrap,
                     cluster: str = "house", title: str = "") -> str:
    """SR and SPL per planner with their cluster-bootstrap intervals (episodes pooled over
    seeds), then the bootstrap settings."""
    header = ["Planner", f"{cluster.capitalize()}s", "Episodes", "SR [95 % CI]",
              "SPL [95 % CI]"]
    if boot.level != 0.95:
        header = [h.replace("95 %", f"{boot.level * 100:g} %") for h in header]
    body = [[r.planner, str(r.clusters), str(r.episodes), fmt_interval(r.sr),
             fmt_interval(r.spl)] for r in rows]
    parts = [title] if title else []
    parts.append(pipe_table(header, body))
    parts.append(boot.statement(cluster) + "; an interval needs two or more "
                 f"{cluster}s (\"[-]\" otherwise).")
    return "\n".join(parts) + "\n"


def format_paired(rows: Sequence[PairedComparison], boot: Bootstrap, cluster: str = "house",
                  title: str = "", labels: Sequence[str] | None = None,
                  label_header: str = "House") -> str:
    """Paired comparisons, one row each: SPL ratio, SR and SPL differences with intervals
    and the wins / losses / ties over clusters; ``labels`` adds a first column (e.g. the
    house of a per-house comparison)."""
    level = f"{boot.level * 100:g} %"
    header = ["Planner", "Reference", "Paired episodes", f"SPL ratio [{level} CI]",
              f"SR diff [{level} CI]", f"SPL diff [{level} CI]",
              f"{cluster.capitalize()}s W/L/T"]
    body = [[r.planner, r.reference, str(r.episodes), fmt_interval(r.spl_ratio),
             fmt_interval(r.sr_diff, signed=True), fmt_interval(r.spl_diff, signed=True),
             f"{r.wins}/{r.losses}/{r.ties}"] for r in rows]
    if labels is not None:
        header = [label_header, *header]
        body = [[label, *row] for label, row in zip(labels, body, strict=True)]
    parts = [title] if title else []
    parts.append(pipe_table(header, body))
    parts.append(f"Same episodes (house, episode, seed, query, shortest path) for both "
                 f"planners. SPL ratio = the planner's mean SPL / the reference's; diff = "
                 f"planner - reference; W/L/T = {cluster}s where the planner's paired SPL "
                 "is higher / lower / equal. "
                 + boot.statement(cluster) + ".")
    return "\n".join(parts) + "\n"


def format_paired_split(seen: Sequence[PairedComparison], unseen: Sequence[PairedComparison],
                        boot: Bootstrap, title: str = "") -> str:
    """The paired comparisons on seen and on unseen queries side by side (the same pairs in
    the same order): paired episodes, SPL ratio and SR difference of each half."""
    level = f"{boot.level * 100:g} %"
    header = ["Planner", "Reference", "Seen n (houses)", f"Seen SPL ratio [{level} CI]",
              f"Seen SR diff [{level} CI]", "Unseen n (houses)",
              f"Unseen SPL ratio [{level} CI]", f"Unseen SR diff [{level} CI]"]
    body = [[s.planner, s.reference, f"{s.episodes} ({s.clusters})", fmt_interval(s.spl_ratio),
             fmt_interval(s.sr_diff, signed=True), f"{u.episodes} ({u.clusters})",
             fmt_interval(u.spl_ratio), fmt_interval(u.sr_diff, signed=True)]
            for s, u in zip(seen, unseen, strict=True)]
    parts = [title] if title else []
    parts.append(pipe_table(header, body))
    parts.append("Seen / unseen: the query is / is not a training query of the priors; "
                 "intervals over the houses holding such episodes (in brackets), as above.")
    return "\n".join(parts) + "\n"
