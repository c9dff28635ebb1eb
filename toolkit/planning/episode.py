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
``recorder.executed``; until ``env.ended``.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Protocol

from sgtool.planning.base import Action, Feedback, Planner
from sgtool.scenegraph.graph import SceneGraph


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


class SearchRecorder(Protocol):
    """Sees the episode as it runs (logs it)."""

    def decided(self, index: int, graph: SceneGraph, action: Action,
                decision_s: float) -> None:
        """The planner chose ``action`` on ``graph`` (before it is executed)."""

    def executed(self, step: SearchStep) -> None:
        """``step`` was executed and its feedback given to the planner."""


def run_search(env: SearchEnvironment, planner: Planner, query: str, *, seed: int = 0,
               recorder: SearchRecorder | None = None) -> tuple[SearchStep, ...]:
    """Run one episode of ``planner`` searching for ``query`` in ``env`` (module doc);
    returns its steps."""
    planner.reset(query, seed=seed)
    steps: list[SearchStep] = []
    while not env.ended:
        graph = env.observe()
        if graph is None:
            break
        t0 = time.perf_counter()
        action = planner.decide(graph)
        dt = time.perf_counter() - t0
        index = len(steps) + 1
        if recorder is not None:
            recorder.decided(index, graph, action, dt)
        fb = env.execute(action)
        planner.feedback(fb)
        step = SearchStep(index, graph, action, fb, dt)
        steps.append(step)
        if recorder is not None:
            recorder.executed(step)
    return tuple(steps)
