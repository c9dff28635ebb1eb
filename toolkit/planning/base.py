"""The planner interface: scene graph + query -> action.

Every planner (random, greedy, sbert, scout, moma-llm) implements :class:`Planner`. A planner
never touches a simulator; it sees only :class:`~sgtool.scenegraph.graph.SceneGraph`s and
returns :class:`Action`s whose ``target`` is the id of a node of the graph it was given
(or None for ``done``). Whoever executes the action (the symbolic benchmark, the PyBullet
closed loop) reports the outcome back through :meth:`Planner.feedback`.

:class:`Action` is the one action type of planning and logs
(:class:`sgtool.log.records.Action`, re-exported here): the record an executor writes is
the planner's action with its outcome filled in.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol

from sgtool.log.records import Action
from sgtool.scenegraph.graph import SceneGraph
from sgtool.vocabulary import Outcome, Skill

__all__ = ["Action", "Feedback", "Outcome", "Planner", "Skill"]


@dataclass(frozen=True)
class Feedback:
    """The outcome of an executed :class:`Action`, passed to :meth:`Planner.feedback`:
    ``outcome`` (success, failure, invalid), the executor's ``message`` (why it failed,
    what it revealed) and the metres ``travelled_m`` it took."""

    action: Action
    outcome: Outcome
    message: str = ""
    travelled_m: float = 0.0


class Planner(Protocol):
    """What every planner implements. A :class:`typing.Protocol`: any object with these
    members is a planner, no base class needed. ``name`` labels its rows in tables and
    logs; :meth:`reset` starts each episode; :meth:`decide` is called once per step with
    the scene graph in force and returns an :class:`Action` whose ``target`` is a node id
    of that graph (or ``done``); :meth:`feedback` then reports that action's outcome.
    A planner never touches a simulator."""

    name: str

    def reset(self, query: str, seed: int = 0) -> None:
        """Start a new episode searching for ``query`` (an object category, free text).
        Draw any randomness from ``seed`` (e.g. ``numpy.random.default_rng(seed)``): the
        same episode then decides the same in any run. (A plug-in's Python ``random`` and
        numpy global generator are seeded from it too: :mod:`sgtool.planning.timing`.)"""

    def decide(self, graph: SceneGraph) -> Action:
        """Choose the next action on ``graph``."""

    def feedback(self, fb: Feedback) -> None:
        """Learn the outcome of the last action (planners may ignore it)."""
