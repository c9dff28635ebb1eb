"""Episode records: JSONL round trip, digest without wall-clock, log mapping, tables, PNG."""

from __future__ import annotations

import dataclasses
import json
import math

import pytest

from sgtool.analysis.curves import plot_efficiency
from sgtool.analysis.report import format_seen_unseen, format_table, summary_dict
from sgtool.analysis.search_metrics import COST_MODELS, STEP_COST, seen_unseen, summarize
from sgtool.log.records import Action, Episode
from sgtool.results import (
    EpisodeResult,
    ResultsFormatError,
    Step,
    read_jsonl,
    result_from_log_records,
    results_digest,
    write_jsonl,
)


def _result(wall: float = 0.01, success: bool = True, planner: str = "scout") -> EpisodeResult:
    return EpisodeResult(
        planner=planner, seed=3, house="house-7", episode=2, query="cup", success=success,
        steps=3, travelled_m=7.25, shortest_m=4.0, n_open=1, n_invalid=1, seen=False,
        end="found", trace=(Step("explore", "room:2", "success", 4.0),
                            Step("open", "obj:9", "success", 3.25),
                            Step("open", "obj:99", "invalid", 0.0)),
        wall={"decision_s": wall, "decisions": 3, "episode_s": 2 * wall},
    )


def test_jsonl_round_trip(tmp_path):
    rs = [_result(), _result(success=False, planner="random")]
    p = write_jsonl(rs, tmp_path / "out" / "episodes.jsonl")
    back = read_jsonl(p)
    assert back == rs
    assert [json.loads(line)["planner"] for line in p.read_text().splitlines()] == [
        "scout", "random"]
    assert not list((tmp_path / "out").glob(".*.tmp"))  # no temp file left behind


def test_digest_ignores_wall_clock_only():
    a, b = _result(wall=0.01), _result(wall=0.5)
    assert a.to_json() != b.to_json()
    assert results_digest([a]) == results_digest([b])
    assert results_digest([a]) != results_digest([_result(success=False)])


def test_read_errors_name_the_line(tmp_path):
    p = tmp_path / "bad.jsonl"
    p.write_text(_result().to_json() + "\n{not json\n")
    with pytest.raises(ResultsFormatError, match=r"bad.jsonl:2"):
        read_jsonl(p)
    p.write_text('{"planner": "x"}\n')
    with pytest.raises(ResultsFormatError, match="success"):
        read_jsonl(p)
    with pytest.raises(ResultsFormatError, match="no such file"):
        read_jsonl(tmp_path / "missing.jsonl")


@pytest.mark.parametrize(("key", "value", "message"), [
    ("success", "false", 'success: expected true or false, got "false"'),
    ("success", 1, "success: expected true or false, got 1"),
    ("steps", 3.5, "steps: expected a whole number, got 3.5"),
    ("steps", 1e30, "steps: expected a whole number, got 1e+30"),
    ("steps", True, "steps: expected a whole number, got true"),
    ("travelled_m", "7", 'travelled_m: expected a number, got "7"'),
    ("planner", 5, "planner: expected text, got 5"),
    ("house", None, "house: expected text, got null"),
    ("seen", "no", 'seen: expected true or false, got "no"'),
    ("trace", "x", "trace: expected a list"),
])
def test_a_field_of_the_wrong_type_is_refused_not_coerced(tmp_path, key, value, message):
    """A record is read as written, never coerced: "false" is no success, 3.5 steps are
    not 3 (eval would score them)."""
    p = tmp_path / "e.jsonl"
    p.write_text(json.dumps({**_result().to_dict(), key: value}) + "\n")
    with pytest.raises(ResultsFormatError) as e:
        read_jsonl(p)
    assert str(e.value) == f"{p}:1: {message}"
    p.write_text(json.dumps({**_result().to_dict(), "seen": None, "shortest_m": None}) + "\n")
    assert read_jsonl(p)[0].seen is None and read_jsonl(p)[0].shortest_m is None


def test_result_from_log_records_derives_counts():
    episode = {"kind": "search", "status": "success", "query": "cup", "planner": "scout",
               "house_id": "house-1", "steps": 3, "travelled_m": 6.5, "shortest_m": 5.0,
               "extra": {"seed": 4, "episode": 1, "seen": True}}
    actions = [
        {"skill": "explore", "target": "room:1", "outcome": "success", "travelled_m": 4.0,
         "decision_time_s": 0.02},
        {"skill": "open", "target": "door:0", "outcome": "success", "travelled_m": 2.5,
         "decision_time_s": 0.03},
        {"skill": "open", "target": "obj:5", "outcome": "invalid", "travelled_m": 0.0,
         "decision_time_s": 0.01},
    ]
    episode, actions = Episode.from_json(episode), [Action.from_json(a) for a in actions]
    r = result_from_log_records(episode, actions)
    assert (r.success, r.steps, r.n_open, r.n_invalid, r.seed, r.episode, r.seen) == (
        True, 3, 1, 1, 4, 1, True)
    assert r.decision_s == pytest.approx(0.06) and r.decisions == 3
    r2 = result_from_log_records(Episode(kind="search", status="failure"), actions)
    assert not r2.success and r2.steps == 3 and r2.travelled_m == pytest.approx(6.5)
    assert r2.shortest_m is None and r2.planner == "unknown"
    # actions that do not say how long they took (a hand-written log): no decision time,
    # not a mean of 0 s
    from sgtool.analysis.search_metrics import mean_decision_time

    untimed = [dataclasses.replace(a, decision_time_s=None) for a in actions]
    r3 = result_from_log_records(Episode(kind="search", status="failure"), untimed)
    assert r3.decisions == 0 and math.isnan(mean_decision_time([r3]))


def test_a_closed_loop_log_cut_short_counts_planner_steps_only():
    """No closing record (a killed run, recovered): steps are the actions a planner
    decided, not the opening look-around or the fallback explores (planner null), nor the
    explores that went on after one, as the closing record of a whole run counts them."""
    from sgtool.log.records import WENT_ON

    def act(skill, planner, reason=""):
        return Action.from_json({"skill": skill, "target": "frontier:1", "outcome": "success",
                                 "planner": planner, "reason": reason})

    actions = [act("look_around", None), act("explore", "greedy"), act("navigate", "greedy"),
               act("explore", "greedy", WENT_ON), act("explore", None, "fallback: gave up"),
               act("open", "greedy")]
    cut = result_from_log_records(Episode(kind="search", status="started"), actions)
    assert cut.steps == 3 and cut.decisions == 6
    closed = result_from_log_records(Episode(kind="search", status="failure", steps=3),
                                     actions)
    assert closed.steps == 3


def test_tables_and_summary_dict():
    rs = [_result(), _result(success=False, planner="random")]
    sums = summarize(rs)
    text = format_table(sums, throughput={"scout": 12.0}, models=COST_MODELS, title="T")
    lines = text.splitlines()
    assert lines[0] == "T"
    assert lines[1].startswith("| Planner") and "AUC-E dist" in lines[1]
    row = next(ln for ln in lines if ln.startswith("| scout"))
    assert "1.000 ± -" in row and "12.0" in row  # one seed: no spread
    # an LLM planner's few episodes a second keep their digits (not "0.0")
    slow = format_table(sums, throughput={"scout": 0.0333}, models=COST_MODELS)
    assert next(ln for ln in slow.splitlines() if ln.startswith("| scout")).split("|")[-2].strip() \
        == "0.033"
    assert "budget max 5000" in text and "budget max 50" in text
    split = format_seen_unseen(seen_unseen(rs))
    assert "| scout" in split and "Unseen SR" in split
    d = summary_dict(sums)
    assert d["scout"]["sr"]["mean"] == 1.0 and d["random"]["sr"]["mean"] == 0.0


def test_plot_writes_png(tmp_path):
    import matplotlib.image as mpimg

    rs = [_result(), _result(success=False, planner="random")]
    p = plot_efficiency([("scout", rs[:1]), ("random", rs[1:])], STEP_COST,
                        tmp_path / "curve.png")
    assert p.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    img = mpimg.imread(p)
    assert img.shape[0] > 100 and img.shape[1] > 100


def test_source_log_finds_a_row_s_log_beside_its_table(tmp_path):
    """run-bench rows name their logs relative to the run folder: found from anywhere;
    a symbolic row, or a log moved away, has none."""
    from sgtool.results import source_log

    log = tmp_path / "run" / "logs" / "ep-000.mcap"
    log.parent.mkdir(parents=True)
    log.write_bytes(b"")
    def row(source: str) -> EpisodeResult:
        return dataclasses.replace(_result(), source=source)

    assert source_log(row("logs/ep-000.mcap"), tmp_path / "run" / "episodes.jsonl") == log
    assert source_log(row(str(log)), tmp_path / "x.jsonl") == log
    assert source_log(row("symbolic"), tmp_path / "run" / "episodes.jsonl") is None
    # beside the table first: another run's logs of the same names in the working
    # directory are not this row's
    other = tmp_path / "logs" / "ep-000.mcap"
    other.parent.mkdir()
    other.write_bytes(b"")
    import os

    here = os.getcwd()
    try:
        os.chdir(tmp_path)
        assert source_log(row("logs/ep-000.mcap"), tmp_path / "run" / "episodes.jsonl") == log
    finally:
        os.chdir(here)
