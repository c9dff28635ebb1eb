"""The invalid-answer rate of an LLM planner in the bench's summary: per-episode answer counts
(``EpisodeResult.llm_answers``) from the exchanges' verdicts, summed per planner into a line
of summary.md and ``llm_answers`` of summary.json; other planners' records are as before."""

from __future__ import annotations

import json
import re

from sgtool.analysis.bench import BenchConfig, run_benchmark, write_outputs
from sgtool.analysis.report import llm_answer_lines
from sgtool.llm.client import ChatResult
from sgtool.results import EpisodeResult


class EveryThirdInvalid:
    """Every third request a command naming a room no house has; otherwise explores the first
    unexplored room the scene text shows through a door, else done()."""

    model = "every-third"

    def __init__(self) -> None:
        self.calls = 0

    def complete(self, messages) -> ChatResult:
        self.calls += 1
        m = re.search(r"Unexplored rooms seen through doors: ([^(,]+?) \(",
                      messages[-1]["content"])
        cmd = "explore(throne room)" if self.calls % 3 == 1 else \
            f"explore({m.group(1)})" if m else "done()"
        return ChatResult(f"Analysis: a\nReasoning: b\nCommand: {cmd}", self.model, 0.0)


def test_the_summary_has_the_invalid_answer_rate(tmp_path) -> None:
    client = EveryThirdInvalid()
    transcript = tmp_path / "t.jsonl"
    cfg = BenchConfig(planners=("moma-llm", "greedy"), houses=1, episodes=3, seeds=1,
                      planner_options={"moma-llm": {"client": client,
                                                    "transcript": str(transcript)}})
    res = run_benchmark(cfg, progress=False)
    moma = [r for r in res.results if r.planner == "moma-llm"]
    counts = [r.llm_answers for r in moma]
    assert sum(c["requests"] for c in counts) == client.calls
    valid = sum(c["valid"] for c in counts)
    invalid = sum(c["invalid"] for c in counts)
    verdicts = [json.loads(x)["verdict"] for x in transcript.read_text().splitlines()]
    assert len(verdicts) == client.calls
    assert valid == verdicts.count("ok") > 0
    assert invalid == sum(v.startswith("invalid") for v in verdicts)
    assert invalid >= len(range(1, client.calls + 1, 3))  # calls 1, 4, 7, ... at least
    assert valid + invalid == client.calls
    assert all(not r.llm_answers for r in res.results if r.planner == "greedy")
    write_outputs(res, tmp_path)
    md = (tmp_path / "summary.md").read_text()
    (line,) = [x for x in md.splitlines() if x.startswith("LLM answers of")]
    rate = 100 * invalid / (valid + invalid)
    assert line == (f"LLM answers of moma-llm: {client.calls} requests, {valid} valid, "
                    f"{invalid} rejected (invalid-answer rate {rate:.1f}%), 0 faults, "
                    "0 without verdict")
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert summary["llm_answers"] == {"moma-llm": {
        "requests": client.calls, "valid": valid, "invalid": invalid, "faults": 0,
        "unknown": 0}}
    # episodes.jsonl keeps the counts for moma-llm only; old records read as before
    rows = [json.loads(x) for x in (tmp_path / "episodes.jsonl").read_text().splitlines()]
    assert [("llm_answers" in d) for d in rows] == [r.planner == "moma-llm" for r in
                                                    res.results]
    back = EpisodeResult.from_dict(rows[0])
    assert back.llm_answers == moma[0].llm_answers
    old = dict(rows[-1])
    assert EpisodeResult.from_dict(old).llm_answers == {}


def test_no_line_without_llm_answers() -> None:
    r = EpisodeResult("scout", 0, "h", 0, "milk", True, 3, 4.0, 2.0)
    assert llm_answer_lines([r], ["scout"]) == []
    assert "llm_answers" not in r.to_dict()
