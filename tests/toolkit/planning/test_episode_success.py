"""The episode loop's success rules (observed vs MoMa-LLM's done) and the exchanges it keeps
per step, on a hand-made environment whose target (milk) comes into view after one step."""

from __future__ import annotations

import pytest
from support.semantics_fixtures import house

from sgtool.planning.base import Action, Feedback
from sgtool.planning.episode import (
    CONFIRMED,
    SuccessRuleError,
    run_search,
    search_success,
)
from sgtool.planning.registry import make_planner
from sgtool.scenegraph.graph import ObjectNode

MILK = ObjectNode("obj:15", "milk", "region:1.1", "room:1", (0.2, 1.0, 0.0))


class OneStepEnv:
    """Shows the test house; after the first action the milk is in view and the episode
    ends (SymSearch's rule); ``done`` ends it without success."""

    def __init__(self) -> None:
        self.ended = False
        self.success = False
        self.executed: list[Action] = []

    def observe(self):
        return house([MILK]) if self.success else house()

    def execute(self, action: Action) -> Feedback:
        self.executed.append(action)
        self.ended = True
        self.success = action.skill != "done"
        return Feedback(action, "success", "found milk" if self.success else "ended")


class Scripted:
    """Plays a list of actions; keeps LLM-like exchange records."""

    name = "scripted"

    def __init__(self, actions: list[Action]) -> None:
        self.actions = list(actions)
        self.exchanges: list[dict] = []
        self.told: list[Feedback] = []

    def reset(self, query: str, seed: int = 0) -> None:
        self.exchanges = []

    def decide(self, graph) -> Action:
        self.exchanges.append({"n": len(self.exchanges)})
        return self.actions.pop(0)

    def feedback(self, fb: Feedback) -> None:
        self.told.append(fb)


def test_observed_rule_ends_on_sight() -> None:
    env = OneStepEnv()
    p = Scripted([Action("explore", "frontier:1")])
    steps = run_search(env, p, "milk")
    assert len(steps) == 1 and search_success(env.success, steps, "milk", "observed")
    assert steps[0].exchanges == ({"n": 0},)


def test_done_rule_needs_the_planner_to_confirm() -> None:
    env = OneStepEnv()
    p = Scripted([Action("explore", "frontier:1"), Action("done", "obj:15")])
    steps = run_search(env, p, "milk", success="done")
    assert [s.action.skill for s in steps] == ["explore", "done"]
    assert len(env.executed) == 1  # the confirmation is not executed by the environment
    assert steps[1].graph.node("obj:15") is not None
    assert steps[1].feedback == Feedback(steps[1].action, "success", CONFIRMED)
    assert p.told[-1].message == CONFIRMED
    assert search_success(env.success, steps, "milk", "done")
    assert [s.exchanges for s in steps] == [({"n": 0},), ({"n": 1},)]


@pytest.mark.parametrize("last", [Action("navigate", "obj:15"), Action("done", "obj:10"),
                                  Action("done", None)])
def test_done_rule_fails_without_a_done_on_the_target(last: Action) -> None:
    env = OneStepEnv()
    steps = run_search(env, Scripted([Action("explore", "frontier:1"), last]), "milk",
                       success="done")
    assert steps[-1].feedback.outcome == "failure"
    assert "did not call done()" in steps[-1].feedback.message
    assert search_success(env.success, steps, "milk", "observed")
    assert not search_success(env.success, steps, "milk", "done")


def test_an_early_done_fails_under_both_rules() -> None:
    env = OneStepEnv()
    steps = run_search(env, Scripted([Action("done", "obj:10")]), "milk", success="done")
    assert len(steps) == 1  # nothing in view: no confirmation step
    for rule in ("observed", "done"):
        assert not search_success(env.success, steps, "milk", rule)


def test_node_selection_planners_confirm_on_their_own() -> None:
    env = OneStepEnv()
    steps = run_search(env, make_planner("greedy"), "milk", success="done")
    assert steps[-1].action == Action("done", "obj:15", steps[-1].action.reason,
                                      steps[-1].action.decision_time_s)
    assert search_success(env.success, steps, "milk", "done")


def test_unknown_rule_is_a_user_error() -> None:
    with pytest.raises(SuccessRuleError, match="one of observed, done"):
        run_search(OneStepEnv(), Scripted([]), "milk", success="found")
