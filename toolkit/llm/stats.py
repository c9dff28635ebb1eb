"""How usable an LLM's answers were: requests, valid and rejected answers, faults.

Computed from ``sgtool.LlmExchange`` records (a transcript, the ``/sgtool/llm`` channel of
logs): a record with an ``error`` is a transport fault; an answer whose ``verdict`` starts
with ``invalid`` was rejected by the planner (no parsable command, or one naming nothing in
the scene: MoMa-LLM's invalid actions), ``ok`` was executed. Records written before the
planner logged verdicts count as answers of unknown verdict. Decisions are the distinct
(query, step) pairs within one source.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from typing import Any


@dataclass(frozen=True)
class AnswerStats:
    requests: int
    faults: int  # transport faults (no answer)
    valid: int
    invalid: int
    unknown: int  # answers without a verdict
    decisions: int
    completion_tokens: int
    latency_s: float  # summed over requests to an endpoint (a replay's are no speed)

    @property
    def invalid_rate(self) -> float:
        """Rejected answers over answers with a verdict."""
        judged = self.valid + self.invalid
        return self.invalid / judged if judged else math.nan

    @property
    def tokens_per_s(self) -> float:
        return self.completion_tokens / self.latency_s if self.latency_s > 0 else math.nan

    def as_dict(self) -> dict[str, Any]:
        return {"requests": self.requests, "faults": self.faults, "valid": self.valid,
                "invalid": self.invalid, "unknown": self.unknown, "decisions": self.decisions,
                "invalid_rate": self.invalid_rate, "completion_tokens": self.completion_tokens,
                "latency_s": round(self.latency_s, 3), "tokens_per_s": self.tokens_per_s}


def answer_stats(records: Iterable[tuple[str, Mapping[str, Any]]]) -> AnswerStats:
    """Stats of (source, exchange record) pairs (module doc)."""
    requests = faults = valid = invalid = unknown = tokens = 0
    latency = 0.0
    decisions: set[tuple[str, Any, Any]] = set()
    for source, r in records:
        requests += 1
        decisions.add((source, r.get("query"), r.get("step")))
        live = r.get("source", "endpoint") != "replay"  # a replay's latency is no speed
        latency += float(r.get("latency_s") or 0.0) if live else 0.0
        if r.get("error") or r.get("response") is None:
            faults += 1
            continue
        tokens += int(r.get("completion_tokens") or 0) if live else 0
        verdict = str(r.get("verdict") or "")
        if verdict == "ok":
            valid += 1
        elif verdict.startswith("invalid"):
            invalid += 1
        else:
            unknown += 1
    return AnswerStats(requests, faults, valid, invalid, unknown, len(decisions), tokens,
                       latency)


COUNTS = ("requests", "valid", "invalid", "faults", "unknown")


def answer_counts(records: Iterable[Mapping[str, Any]]) -> dict[str, int]:
    """The deterministic counts of :class:`AnswerStats` (``COUNTS``) over exchange records
    (an episode's), for an :class:`~sgtool.results.EpisodeResult`; {} when there are none."""
    s = answer_stats(("", r) for r in records)
    return {k: int(getattr(s, k)) for k in COUNTS} if s.requests else {}


def invalid_rate_text(valid: int, invalid: int) -> str:
    """Rejected answers over judged ones as a percentage, "-" when none was judged."""
    return f"{100 * invalid / (valid + invalid):.1f}%" if valid + invalid else "-"


def format_stats(s: AnswerStats, where: str = "") -> str:
    rate = invalid_rate_text(s.valid, s.invalid)
    tps = "-" if math.isnan(s.tokens_per_s) else f"{s.tokens_per_s:.1f}"
    return (f"LLM answers{f' in {where}' if where else ''}: {s.requests} requests for "
            f"{s.decisions} decisions; {s.valid} valid, {s.invalid} rejected (invalid-answer "
            f"rate {rate}), {s.faults} faults, {s.unknown} without verdict; "
            f"{tps} tokens/s over the requests")
