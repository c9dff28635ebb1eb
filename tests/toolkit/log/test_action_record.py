"""One Action type: what a planner returns is the record a log holds once executed."""

from __future__ import annotations

import dataclasses

import pytest

import sgtool
from sgtool.errors import LogFormatError
from sgtool.log import LogReader, LogWriter
from sgtool.log.records import ABSENT, Action
from sgtool.planning import base
from sgtool.planning.timing import TimedPlanner
from sgtool.scenegraph.graph import RobotState, SceneGraph


def test_the_planning_action_is_the_log_record() -> None:
    assert sgtool.Action is sgtool.ActionRecord is base.Action is Action
    a = sgtool.Action("open", "obj:3", reason="fridge", scores={"obj:3": 0.75})
    assert (a.target, a.reason, a.decision_time_s, a.outcome) == ("obj:3", "fridge", 0.0, ABSENT)


def test_an_executed_action_writes_what_the_log_held_before() -> None:
    # the dict the symbolic roll-out wrote field by field before the two types were one
    a = Action("explore", "room:2", reason="nearest", decision_time_s=0.25,
               scores={"room:2": 1.0})
    record = a.executed("failure", 1.23456789, planner="scout", step=4,
                        unknown={"message": "blocked"})
    assert record.to_json() == {
        "skill": "explore", "target": "room:2", "outcome": "failure", "reason": "nearest",
        "travelled_m": 1.2346, "decision_time_s": 0.25, "planner": "scout", "step": 4,
        "message": "blocked"}
    assert record.scores == {"room:2": 1.0}  # kept in memory, never logged
    assert record.executed("success", 0.0, decision_time_s=0.5).decision_time_s == 0.5


def test_a_logged_record_without_planner_fields_is_written_back_as_read(tmp_path) -> None:
    bare = {"skill": "look_around", "outcome": "success"}
    a = Action.from_json(bare)
    assert (a.target, a.reason, a.decision_time_s) == (None, "", 0.0)
    assert a.absent == {"target", "reason", "decision_time_s"}
    assert a.to_json() == bare
    assert Action.from_json({**bare, "target": None}).to_json() == {**bare, "target": None}
    # a field set afterwards is written even though the log lacked it
    assert dataclasses.replace(a, target="door:1").to_json() == {**bare, "target": "door:1"}
    with LogWriter(tmp_path / "a.mcap") as w:
        w.write_record(a, 0)
        w.write_record(Action("done", None).executed("success", 0.0), 1)
    with LogReader(tmp_path / "a.mcap") as r:
        assert [rec for _, rec in r.records(Action)] == [
            a, Action("done", None, outcome="success", travelled_m=0.0)]


def test_scores_are_not_read_from_a_log() -> None:
    a = Action.from_json({"skill": "done", "outcome": "success", "scores": [1, 2]})
    assert a.scores == {} and a.unknown == {"scores": [1, 2]}
    assert a.to_json()["scores"] == [1, 2]


def test_an_action_not_executed_has_no_outcome(tmp_path) -> None:
    a = Action("navigate", "room:0")
    with pytest.raises(LogFormatError, match="no outcome"):
        _ = a.result
    assert a.executed("invalid", 0.0).result == "invalid"
    with LogWriter(tmp_path / "x.mcap") as w, pytest.raises(LogFormatError, match="'outcome'"):
        w.write_record(a, 0)


class _Fixed:
    name = "fixed"

    def __init__(self, action: Action) -> None:
        self.action = action

    def reset(self, query: str, seed: int = 0) -> None:
        pass

    def decide(self, graph: SceneGraph) -> Action:
        return self.action

    def feedback(self, fb: base.Feedback) -> None:
        pass


@pytest.mark.parametrize("action", [
    Action("navigate", "room:1", "r", 9.0, {"room:1": 0.5}),
    Action("done", None, "x", outcome="success", travelled_m=1.5, planner="p", step=2,
           graph_time_ns=None, unknown={"k": 1}, absent=frozenset({"reason"})),
])
def test_the_timed_planner_sets_the_decision_time_and_keeps_every_other_field(action) -> None:
    timed = TimedPlanner(_Fixed(action))
    out = timed.decide(SceneGraph(robot=RobotState(position=(0.0, 0.0), room=None)))
    assert out == dataclasses.replace(action, decision_time_s=timed.decision_times[0])
    assert out.scores == action.scores
