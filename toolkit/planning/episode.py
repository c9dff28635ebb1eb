"""The one search-episode loop: observe the graph, decide, execute, feed back, record.

Both search environments, the symbolic benchmark
(:mod:`sgtool.recorders.symbolic_environment`) and the PyBullet closed loop
(:mod:`sgtool.recorders.sim.closed_loop`), run their episodes through :func:`run_search`.
An environment (:class:`SearchEnvironment`) says whether the episode has ended, shows the
graph to decide on and executes an action; a recorder (:class:`SearchRecorder`, optional)
sees each decision before it is executed and each step once its feedback is in. The
planner is built by the caller and reset here with the query and its seed.

Per step: ``graph = env.observe()`` (None: nothing to decide on, the loop ends), then
``action = planner.decide(graph)`` (timed with the wall clock), ``recorder.decided``,
``feedback = env.execute(action)``, ``planner.feedback(feedback)``,
``recorder.executed``; until ``env.ended``. A planner that keeps LLM exchanges
(``exchanges``, moma-llm) has those of each decision in :attr:`SearchStep.exchanges`.

**Success rules** (``success``): ``observed`` (SymSearch, the default): the episode succeeds
when an object of the query comes into view (the environment ends it then). ``done``
(MoMa-LLM): it succeeds only when the planner calls ``done()`` naming an object of the
query in its graph. When the environment ends an episode because the target is in view,
the loop asks the planner once more, on the graph that shows it (a step the environment
does not execute or count): ``done(<an object of the query>)`` confirms the find, anything
else fails the episode (end ``not_confirmed``). A ``done()`` earlier, without the target in
view, fails it as under either rule. :func:`search_success` gives the verdict.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any, Protocol

import numpy as np

from sgtool.errors import SgtoolError, returned_text
from sgtool.planning.base import Action, Feedback, Planner
from sgtool.planning.timing import decision_time
from sgtool.scenegraph.graph import SceneGraph
from sgtool.semantics.text import same_category


class SearchEnvironment(Protocol):
    """Where a search episode happens (module doc)."""

    @property
    def ended(self) -> bool:
        """The episode is over (found, given up, out of steps or frames)."""

    def observe(self) -> SceneGraph | None:
        """The scene graph the planner decides on now; None when there is none."""

    def execute(self, action: Action) -> Feedback:
        """Carry out ``action``; a step is spent whatever the outcome."""


@dataclass(frozen=True)
class SearchStep:
    """One step of an episode: the graph decided on, the action, its feedback and the
    wall-clock seconds of the decision."""

    index: int  # 1, 2, ...
    graph: SceneGraph
    action: Action
    feedback: Feedback
    decision_s: float
    exchanges: tuple[dict[str, Any], ...] = ()  # LLM exchanges of this decision


SUCCESS_RULES = ("observed", "done")
CONFIRMED = "target confirmed by done()"
NOT_CONFIRMED = "not_confirmed"  # the end of an episode the planner did not confirm


class SuccessRuleError(SgtoolError):
    """An unknown success rule."""


def check_success_rule(rule: str) -> str:
    if rule not in SUCCESS_RULES:
        raise SuccessRuleError(f"--success {rule!r}: one of {', '.join(SUCCESS_RULES)}")
    return rule


def confirms(step: SearchStep, query: str) -> bool:
    """``step`` is ``done()`` naming an object of the query in the graph it was decided on."""
    a = step.action
    if a.skill != "done" or a.target is None:
        return False
    node = step.graph.node(a.target)
    return node is not None and same_category(getattr(node, "category", "") or "", query)


def search_success(env_success: bool, steps: Sequence[SearchStep], query: str,
                   rule: str = "observed") -> bool:
    """The episode's success under ``rule`` (module doc), given the environment's verdict
    (the target came into view)."""
    if check_success_rule(rule) == "observed":
        return bool(env_success)
    return bool(env_success) and bool(steps) and confirms(steps[-1], query)


class SearchRecorder(Protocol):
    """Sees the episode as it runs (logs it)."""

    def decided(self, index: int, graph: SceneGraph, action: Action,
                decision_s: float) -> None:
        """The planner chose ``action`` on ``graph`` (before it is executed)."""

    def executed(self, step: SearchStep) -> None:
        """``step`` was executed and its feedback given to the planner."""


def planner_seed(seed: int, house_seed: int, episode_index: int) -> int:
    """The planner's seed for an episode (a 32-bit draw from the three numbers): a run's
    ``seed`` gives every episode its own stream, so a seeded planner's draws are not the
    same sequence in every episode."""
    ss = np.random.SeedSequence([int(seed), int(house_seed), int(episode_index), 1])
    return int(ss.generate_state(1)[0])


def run_search(env: SearchEnvironment, planner: Planner, query: str, *, seed: int = 0,
               recorder: SearchRecorder | None = None,
               success: str = "observed") -> tuple[SearchStep, ...]:
    """Run one episode of ``planner`` searching for ``query`` in ``env`` under the success
    rule ``success`` (module doc); returns its steps."""
    check_success_rule(success)
    planner.reset(query, seed=seed)
    steps: list[SearchStep] = []
    while not env.ended:
        graph = env.observe()
        if graph is None:
            break
        steps.append(_step(planner, graph, len(steps) + 1, recorder, env.execute))
    if success == "done" and getattr(env, "success", False):
        graph = env.observe()
        if graph is not None:
            steps.append(_step(planner, graph, len(steps) + 1, recorder,
                               lambda a: _confirmation(a, graph, query)))
    return tuple(steps)


def _step(planner: Planner, graph: SceneGraph, index: int, recorder: SearchRecorder | None,
          execute: Callable[[Action], Feedback]) -> SearchStep:
    """Decide on ``graph`` (timed), record, execute, feed back, record."""
    kept = getattr(planner, "exchanges", None)
    n0 = len(kept) if isinstance(kept, list) else 0
    t0 = time.perf_counter()
    action = planner.decide(graph)
    dt = time.perf_counter() - t0
    if not isinstance(action, Action):
        raise SgtoolError(f"planner {getattr(planner, 'name', type(planner).__name__)!r}: "
                          f"decide() returned {returned_text(action)}, not an Action")
    dt = decision_time(planner, action, dt)
    kept = getattr(planner, "exchanges", None)
    exchanges = tuple(kept[n0:]) if isinstance(kept, list) else ()
    if recorder is not None:
        recorder.decided(index, graph, action, dt)
    fb = execute(action)
    planner.feedback(fb)
    step = SearchStep(index, graph, action, fb, dt, exchanges)
    if recorder is not None:
        recorder.executed(step)
    return step


def _confirmation(action: Action, graph: SceneGraph, query: str) -> Feedback:
    """The outcome of the decision after the target came into view (``done`` rule)."""
    probe = SearchStep(0, graph, action, Feedback(action, "success"), 0.0)
    if confirms(probe, query):
        return Feedback(action, "success", CONFIRMED)
    return Feedback(action, "failure",
                    f"the {query} was in view but the planner did not call done() on it")
