"""`sgtool eval` refuses episodes whose figures contradict each other (one table of rules,
:data:`sgtool.analysis.validity.RULES`): a success that travelled nothing towards a target
9.48 m away scored SR 1, SPL 1 before."""

from __future__ import annotations

import dataclasses
import json
import math

import pytest
from click.testing import CliRunner

from sgtool.analysis.search_metrics import episode_spl
from sgtool.analysis.validity import (
    RULES,
    SHORTFALL_M,
    SHORTFALL_SHARE,
    SIGHT_M,
    episode_problem,
    shortfall_tolerance_m,
)
from sgtool.cli import cli
from sgtool.datasets.episodes import REACH
from sgtool.log import LogWriter
from sgtool.log.records import Action, Episode
from sgtool.results import EpisodeResult, Step, write_jsonl

GOOD = EpisodeResult("greedy", 0, "h", 0, "mug", True, steps=4, travelled_m=10.0,
                     shortest_m=9.48)
# the tolerance below a shortest path of 9.48 m: sight 6 m - reach 1 m + 0.5 m + 10% of
# 9.48 m = 6.448 m; a success must have travelled at least 3.032 m


@pytest.mark.parametrize(("change", "problem"), [
    ({"steps": 0, "travelled_m": 0.0},
     "a success with travelled_m 0 m, less than shortest_m 9.48 m by more than the "
     "tolerance of 6.45 m (a target seen from 6 m, 1 m from the path's end; 0.5 m + 10% of "
     "the shortest path)"),
    ({"steps": 3, "travelled_m": 1.0},
     "a success with travelled_m 1 m, less than shortest_m 9.48 m by more than the "
     "tolerance of 6.45 m (a target seen from 6 m, 1 m from the path's end; 0.5 m + 10% of "
     "the shortest path)"),
    ({"steps": 0, "travelled_m": 1.0}, "steps 0 but travelled_m 1 m: no step, no travel"),
    ({"steps": 0, "travelled_m": 3.0, "success": False},
     "steps 0 but travelled_m 3 m: no step, no travel"),
    ({"n_open": 5}, "n_open 5 is more than steps 4: every open is a step"),
    ({"noise": "symbolic", "steps": 0, "travelled_m": 1.0},  # eval's label, no sensor
     "steps 0 but travelled_m 1 m: no step, no travel"),
    ({"noise": "none", "n_open": 5}, "n_open 5 is more than steps 4: every open is a step"),
    # the closing figures against the actions listed: four steps, three actions
    ({"trace": (Step("navigate", "room_1", "success", 4.0),) * 3},
     "steps 4 but 3 action(s) listed: every step is an action"),
    # four actions that drove 4 m each, a closing record of 10 m
    ({"trace": (Step("navigate", "room_1", "success", 4.0),) * 4},
     "travelled_m 10 m is less than the 16 m its 4 action(s) travelled"),
    ({"noise": "none", "trace": (Step("navigate", "room_1", "success", 4.0),) * 4},
     "travelled_m 10 m is less than the 16 m its 4 action(s) travelled"),
])
def test_contradicting_figures_are_refused_naming_them(change, problem):
    assert episode_problem(dataclasses.replace(GOOD, **change)) == problem


@pytest.mark.parametrize("change", [
    {},
    {"travelled_m": 3.04},  # 9.48 - 3.04 = 6.44 m short: within the 6.448 m tolerance
    {"success": False, "travelled_m": 1.0},  # a failure need not reach the target
    {"success": False, "steps": 0, "travelled_m": 0.0},
    {"steps": 0, "travelled_m": 0.0, "shortest_m": 0.0},  # seen from the start
    {"steps": 0, "travelled_m": 0.0, "shortest_m": 5.9},  # in sight from the start
    {"travelled_m": 0.0, "shortest_m": None},  # no shortest path known: nothing to check
    {"n_open": 4},
    # closed loop: the robot's own exploration drives without a step, and its camera sees
    # the target over a counter the path goes round (it was refused, while run-bench
    # counted it a success)
    {"noise": "none", "steps": 0, "travelled_m": 0.81},
    {"noise": "mild", "steps": 0, "travelled_m": 0.0, "shortest_m": 6.31},
    {"noise": "none", "steps": 3, "travelled_m": 1.0},
    # actions that agree: each 2.5 m rounded on write, the total not (0.1 mm per action)
    {"trace": (Step("navigate", "room_1", "success", 2.50004),) * 4},
    # the closed loop's look-arounds and fallback explores are actions but no steps, and
    # drive between them; a robot may drive more than its actions
    {"noise": "none", "trace": (Step("explore", "frontier_1", "success", 0.5),) * 6},
    {"noise": "none", "trace": (Step("open", "furn_1", "success", 0.0),) * 4},
])
def test_consistent_figures_pass(change):
    assert episode_problem(dataclasses.replace(GOOD, **change)) is None


def test_the_tolerance_is_what_the_docs_say():
    assert (SIGHT_M, REACH, SHORTFALL_M, SHORTFALL_SHARE) == (6.0, 1.0, 0.5, 0.1)
    assert shortfall_tolerance_m(9.48) == pytest.approx(6.448)
    assert shortfall_tolerance_m(0.0) == 5.5
    text = " ".join(CliRunner().invoke(cli, ["eval", "-h"]).output.split())
    assert "less than its shortest path by more than 5.5 m + 10% of it" in text
    assert "the path ends 1 m from the target, a camera sees it from up to 6 m" in text


def test_every_rule_of_the_table_catches_its_own_case():
    cases = {  # one episode per rule, breaking only that rule (first in table order)
        "steps >= 0": {"steps": -1},
        "n_open >= 0": {"n_open": -1},
        "n_invalid >= 0": {"n_invalid": -1},
        "n_failure >= 0": {"n_failure": -1},
        "travelled_m a finite number >= 0": {"travelled_m": math.nan},
        "shortest_m a finite number >= 0 (or unknown)": {"shortest_m": -1.0},
        "steps 0 needs travelled_m 0": {"steps": 0, "success": False},
        "n_open <= steps": {"n_open": 9},
        "steps <= the actions listed": {"trace": (Step("open", "furn_1", "success", 0.0),)},
        "travelled_m >= what the actions travelled":
            {"trace": (Step("navigate", "room_1", "success", 3.0),) * 4},
        "a success travelled at least shortest_m less 5.5 m + 10% of it":
            {"travelled_m": 2.0},
    }
    assert [r.holds for r in RULES] == list(cases)
    for rule in RULES:
        bad = dataclasses.replace(GOOD, **cases[rule.holds])
        assert rule.problem(bad) is not None, rule.holds
        assert episode_problem(bad) == rule.problem(bad)
        assert rule.problem(GOOD) is None


def test_spl_refuses_inputs_that_would_score_one():
    assert episode_spl(True, 9.48, 10.0) == pytest.approx(0.948)
    for travelled in (math.nan, math.inf, -1.0):
        with pytest.raises(ValueError, match="travelled"):
            episode_spl(True, 9.48, travelled)
    with pytest.raises(ValueError, match="negative"):
        episode_spl(True, -9.48, 1.0)
    assert math.isnan(episode_spl(True, None, 1.0))


def test_eval_refuses_the_zero_travel_success_of_a_jsonl(tmp_path):
    bad = dataclasses.replace(GOOD, episode=1, steps=0, travelled_m=0.0)
    eps = write_jsonl([GOOD, bad], tmp_path / "episodes.jsonl")
    r = CliRunner().invoke(cli, ["eval", str(eps), "--json"])
    assert r.exit_code == 0, r.output
    note = (f"{eps}: record 2: refused: a success with travelled_m 0 m, less than "
            "shortest_m 9.48 m by more than the tolerance of 6.45 m (a target seen from 6 m, "
            "1 m from the path's end; 0.5 m + 10% of the shortest path)")
    assert r.stderr.strip().splitlines() == [f"sgtool: note: {note}"]
    doc = json.loads(r.stdout)
    assert doc["episodes"] == 1 and doc["notes"] == [note]
    row = doc["planners"]["greedy"]
    assert row["spl"]["mean"] == pytest.approx(0.948)  # the good episode's 9.48 / 10


def test_eval_refuses_the_zero_travel_success_of_a_log(tmp_path):
    log = tmp_path / "run.mcap"
    with LogWriter(log) as w:
        w.write_record(Episode(kind="search", status="started", planner="greedy",
                               house_id="h", query="mug"), 0)
        w.write_record(Episode(kind="search", status="success", planner="greedy",
                               house_id="h", query="mug", steps=0, travelled_m=0.0,
                               shortest_m=9.48), 10)
    r = CliRunner().invoke(cli, ["eval", str(log)])
    assert r.exit_code == 2
    lines = r.stderr.strip().splitlines()
    assert lines[0].startswith(f"sgtool: note: {log}: episode 0: refused: a success with "
                               "travelled_m 0 m, less than shortest_m 9.48 m")
    assert lines[1].startswith("sgtool: error: no search episodes to score")


def test_eval_refuses_a_closing_record_that_contradicts_the_logs_actions(tmp_path):
    """A hand-written log whose closing record counts more steps and less travel than its
    Action records was scored as the closing record said (an outside lab's log)."""
    log = tmp_path / "run.mcap"
    with LogWriter(log) as w:
        w.write_record(Episode(kind="search", status="started", planner="greedy",
                               house_id="h", query="mug"), 0)
        for i in range(2):
            w.write_record(Action(step=i, skill="navigate", target=f"room_{i}",
                                  outcome="success", travelled_m=6.0, planner="greedy"),
                           1 + i)
        w.write_record(Episode(kind="search", status="success", planner="greedy",
                               house_id="h", query="mug", steps=9, travelled_m=12.0,
                               shortest_m=9.48), 10)
    r = CliRunner().invoke(cli, ["eval", str(log)])
    assert r.exit_code == 2
    assert r.stderr.strip().splitlines()[0] == (
        f"sgtool: note: {log}: episode 0: refused: steps 9 but 2 action(s) listed: every "
        "step is an action")
