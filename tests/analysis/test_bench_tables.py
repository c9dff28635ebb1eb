"""Per-house and per-query breakdowns, Table IX counts, and our Table VII next to the rows
quoted from the SCOUT paper, on episode records made by hand."""

from __future__ import annotations

import dataclasses

import pytest

from sgtool.analysis.paper_tables import TABLE_IX_SYMSEARCH, TABLE_VII_SYMSEARCH, quoted_for
from sgtool.analysis.report import (
    breakdown_records,
    format_breakdown,
    format_seen_unseen,
    format_side_by_side,
)
from sgtool.analysis.search_metrics import breakdown, seen_unseen, summarize
from sgtool.results import EpisodeResult

BASE = EpisodeResult(planner="random", seed=0, house="villa", episode=0, query="mug",
                     success=True, steps=4, travelled_m=10.0, shortest_m=5.0, seen=True)


def rec(**kw) -> EpisodeResult:
    return dataclasses.replace(BASE, **kw)


RESULTS = [
    rec(),  # villa, mug, SPL 0.5
    rec(seed=1, success=False, steps=50),  # villa, mug, failed
    rec(house="attic", query="lamp", seen=False, travelled_m=5.0, steps=2),  # SPL 1
    rec(planner="greedy", house="attic", query="lamp", seen=False, travelled_m=20.0),  # 0.25
]


def test_breakdown_by_house_and_by_query() -> None:
    rows = breakdown(RESULTS, "house", ["random", "greedy"])
    # house ids in plain string order, planners in the given order
    assert [(r.key, r.planner, r.episodes) for r in rows] == \
        [("attic", "random", 1), ("attic", "greedy", 1), ("villa", "random", 2)]
    villa = rows[2]
    assert villa.sr == 0.5 and villa.spl == pytest.approx(0.25) and villa.steps == 27.0
    assert villa.seen is None
    by_query = breakdown(RESULTS, "query", ["random", "greedy"])
    assert [(r.key, r.planner, r.seen) for r in by_query] == \
        [("lamp", "random", False), ("lamp", "greedy", False), ("mug", "random", True)]
    assert by_query[1].spl == pytest.approx(0.25)
    with pytest.raises(ValueError):
        breakdown(RESULTS, "room")


def test_breakdown_tables_and_records() -> None:
    rows = breakdown(RESULTS, "query", ["random", "greedy"])
    text = format_breakdown(rows, "query", ["random", "greedy"], title="Per query")
    lines = text.splitlines()
    assert lines[0] == "Per query"
    assert lines[1].split("|")[1:4] == [" Query ", " Seen ", " Episodes "]
    assert "| lamp  | no   | 1        | 1.000 / 1.000" in text
    assert "| mug   | yes  | 2        | 0.500 / 0.250" in text and text.count("\n") == 5
    recs = breakdown_records(rows, "query")
    assert recs[0] == {"query": "lamp", "planner": "random", "episodes": 1, "sr": 1.0,
                       "spl": 1.0, "steps": 2.0, "seen": False}
    assert "seen" not in breakdown_records(breakdown(RESULTS, "house"), "house")[0]


def test_table_ix_counts_both_halves_and_quotes_the_paper() -> None:
    rows = seen_unseen(RESULTS + [rec(query="cup", seed=2)], ["random", "greedy"])
    r = rows[0]
    assert (r.seen_n, r.seen_queries, r.unseen_n, r.unseen_queries) == (3, 2, 1, 1)
    assert (rows[1].seen_n, rows[1].unseen_n, rows[1].unseen_queries) == (0, 1, 1)
    text = format_seen_unseen(rows, quoted=TABLE_IX_SYMSEARCH)
    assert "Seen queries" in text and "Unseen queries" in text
    assert "| SCOUT (quoted from SCOUT Table IX) | 0.859   | 0.277" in text
    assert "quoted from" not in format_seen_unseen(rows)


def test_side_by_side_quotes_table_vii() -> None:
    assert quoted_for("scout").sr == (0.876, 0.002)
    assert quoted_for("random").spl == (0.074, 0.012)
    assert quoted_for("greedy") is None
    assert len(TABLE_VII_SYMSEARCH) == 11  # every SymSearch row of the paper
    text = format_side_by_side(summarize(RESULTS, planners=["random", "greedy"]))
    lines = text.splitlines()
    random = next(line for line in lines if line.startswith("| random"))
    assert "Random Agent" in random and "0.381 ± 0.043" in random and "45 ± 2" in random
    greedy = next(line for line in lines if line.startswith("| greedy"))
    assert greedy.count("| -") == 5  # no paper counterpart: agent and four quoted cells
    # the paper's agents we have no planner for still appear, with our cells empty
    assert any(line.startswith("| -") and "GODHS" in line for line in lines)
    assert "quoted from SCOUT Table VII" in text


def test_llm_faults_are_warned_of_even_when_some_answers_were_valid() -> None:
    """No valid answer at all is a setup warning; faults beside valid answers are warned of
    too (a decision none of whose attempts got an answer ended its episode given up)."""
    from sgtool.analysis.report import llm_warnings
    from sgtool.results import EpisodeResult

    def run(planner: str, **counts: int) -> EpisodeResult:
        return EpisodeResult(planner, 0, "house-0", 0, "mug", False, steps=3,
                             travelled_m=1.0, shortest_m=1.0,
                             llm_answers={"requests": 0, "valid": 0, "invalid": 0,
                                          "faults": 0, **counts})

    got = llm_warnings([run("a", requests=5, invalid=2, faults=3),
                        run("b", requests=13, valid=8, faults=5),
                        run("c", requests=4, valid=4), run("greedy")], ["a", "b", "c", "greedy"])
    assert got == [
        "sgtool: warning: a: none of its 5 LLM requests got a valid answer (2 rejected, 3 "
        "faults); check the endpoint and model with `sgtool llm check`",
        "sgtool: warning: b: 5 of its 13 LLM requests failed (timeouts, server errors, "
        "unusable replies); a decision left without an answer ended its episode given up"]
