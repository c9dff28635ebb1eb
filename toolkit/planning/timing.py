"""Decision time, measured around every ``decide`` call.

SCOUT reports inference time per decision (Table VII); we measure it for every planner the
same way: wall time of ``decide`` (monotonic ``perf_counter``), including LLM round trips
for ``moma-llm``. The value is written into ``Action.decision_time_s`` so it travels with
the action into the log (``sgtool.Action.decision_time_s``). It is a measurement, not
derived data, so it is the one field of an action that differs between two runs.

A plug-in that draws from Python's ``random`` or numpy's global generator instead of the
``seed`` its ``reset`` gets would make a bench differ from run to run. The wrapper gives a
plug-in's calls generators of its own, seeded by that ``seed`` at every ``reset`` and
swapped in around each call (the caller's global generators are left as they were), so
the same episode draws the same numbers in any process and order; a plug-in's constructor
runs with them seeded by 0 (:func:`seeded_globals`, from
:func:`~sgtool.planning.plugins.build_plugin`).
"""

from __future__ import annotations

import contextlib
import dataclasses
import random
import threading
import time
from collections.abc import Iterator
from typing import Any

import numpy as np

from sgtool.errors import SgtoolError, raised_text, returned_text
from sgtool.planning.base import Action, Feedback, Planner
from sgtool.scenegraph.graph import SceneGraph
from sgtool.vocabulary import SKILLS

# Action's fields in order, as TimedPlanner.decide builds one (else it uses replace)
_PLAIN = tuple(f.name for f in dataclasses.fields(Action)) == (
    "unknown", "skill", "target", "reason", "decision_time_s", "scores", "outcome", "travelled_m",
    "planner", "step", "graph_time_ns", "absent")


# a process has one set of global generators: a plug-in's swap holds them for its call
_GLOBALS_LOCK = threading.RLock()


def decision_time(planner: Planner, action: Action, outer_s: float) -> float:
    """The time ``planner`` took for ``action``: a measuring :class:`TimedPlanner`'s own
    figure (the inner call alone, without a plug-in's generator swap), else ``outer_s``,
    the caller's measure around ``decide``."""
    if isinstance(planner, TimedPlanner) and planner.measure and \
            isinstance(action.decision_time_s, float):
        return action.decision_time_s
    return outer_s


_Globals = tuple[Any, Any]  # Python's and numpy's global generator states


def seeded_state(seed: int) -> _Globals:
    """The global generators' states right after seeding both with ``seed``."""
    return random.Random(seed).getstate(), np.random.RandomState(seed % 2**32).get_state()


@contextlib.contextmanager
def swapped_globals(inner: _Globals) -> Iterator[list[_Globals]]:
    """The global generators set to ``inner`` inside the block (one block at a time in a
    process), the caller's put back after; the block's list holds their states at its
    end."""
    with _GLOBALS_LOCK:
        outer = random.getstate(), np.random.get_state()
        random.setstate(inner[0])
        np.random.set_state(inner[1])
        after = [inner]
        try:
            yield after
        finally:
            after[0] = random.getstate(), np.random.get_state()
            random.setstate(outer[0])
            np.random.set_state(outer[1])


@contextlib.contextmanager
def seeded_globals(seed: int = 0) -> Iterator[None]:
    """Python's and numpy's global generators seeded with ``seed`` inside the block, the
    caller's put back after: a plug-in's constructor that draws from them draws the same
    numbers in any process and order (module doc)."""
    with swapped_globals(seeded_state(seed)):
        yield


class PlannerContractError(SgtoolError):
    """A planner broke the :class:`~sgtool.planning.base.Planner` contract (its ``decide``
    returned something that is not an :class:`~sgtool.planning.base.Action`)."""


class TimedPlanner:
    """Wraps a planner; ``decide`` returns the action with ``decision_time_s`` filled, and
    raises :class:`PlannerContractError` naming the planner when ``decide`` returns no
    :class:`~sgtool.planning.base.Action` (a plug-in's mistake, caught where it happens),
    or, for a ``plugin``, when its ``reset``, ``decide`` or ``feedback`` raises or its
    action names no skill (:data:`~sgtool.vocabulary.SKILLS`) or a target that is no node
    id (text) or None. Without ``measure`` the checks stay and the action keeps the
    decision time the planner gave it."""

    def __init__(self, inner: Planner, plugin: bool = False, measure: bool = True) -> None:
        self.inner = inner
        self.name = getattr(inner, "name", "planner")  # (run_one takes a planner without)
        self.decision_times: list[float] = []
        self.plugin = plugin  # a user's planner: what it raises is one line, not a traceback
        self.measure = measure
        self._globals: tuple[Any, Any] | None = None  # a plug-in's random, numpy states
        self.given_options: dict[str, Any] = {}  # make_planner's options (recorded in logs)

    @contextlib.contextmanager
    def _own_randomness(self) -> Iterator[None]:
        """A plug-in's global generators swapped in for the call (module doc)."""
        if self._globals is None:
            yield
            return
        after: list[_Globals] = []
        try:
            with swapped_globals(self._globals) as after:
                yield
        finally:  # (a call that raised keeps what it drew, as one that returned)
            if after:
                self._globals = after[0]

    def reset(self, query: str, seed: int = 0) -> None:
        self.decision_times = []
        if self.plugin:
            self._globals = seeded_state(seed)
        try:
            with self._own_randomness():
                self.inner.reset(query, seed)
        except (Exception, SystemExit) as e:
            raise self._failed("reset", e) from e

    def decide(self, graph: SceneGraph) -> Action:
        try:
            with self._own_randomness():  # (its swap is no part of the decision's time)
                t0 = time.perf_counter()
                action = self.inner.decide(graph)
                dt = time.perf_counter() - t0
        except (Exception, SystemExit) as e:
            raise self._failed("decide", e) from e
        self.decision_times.append(dt)
        if self.plugin and isinstance(action, Action):
            self._check(action)
        if not self.measure and isinstance(action, Action):
            return action
        if _PLAIN and type(action) is Action:  # dataclasses.replace without its field walk
            return Action(action.skill, action.target, action.reason, dt, action.scores,
                          action.outcome, action.travelled_m, action.planner, action.step,
                          action.graph_time_ns, unknown=action.unknown, absent=action.absent)
        if not isinstance(action, Action):
            raise PlannerContractError(
                f"planner {self.name!r}: decide() returned {returned_text(action)}, not an "
                "sgtool.Action (e.g. Action('navigate', node_id))")
        return dataclasses.replace(action, decision_time_s=dt)

    def _check(self, action: Action) -> None:
        """A plug-in's action names a skill and a node id (text) or no target."""
        if action.skill not in SKILLS:
            raise PlannerContractError(
                f"planner {self.name!r}: decide() returned an Action with skill "
                f"{action.skill!r}; the skills are {', '.join(SKILLS)}")
        if action.target is not None and not isinstance(action.target, str):
            raise PlannerContractError(
                f"planner {self.name!r}: decide() returned an Action whose target is "
                f"{action.target!r} ({type(action.target).__name__}); a target is a node id "
                "(text, e.g. a candidate's node_id) or None")
        if not isinstance(action.reason, str):
            raise PlannerContractError(
                f"planner {self.name!r}: decide() returned an Action whose reason is "
                f"{action.reason!r} ({type(action.reason).__name__}); a reason is text")

    @property
    def exchanges(self) -> object:
        """The wrapped planner's LLM exchanges (moma-llm), None when it keeps none: asked
        before and after every decision, so not through :meth:`__getattr__`'s failure."""
        return getattr(self.inner, "exchanges", None)

    def feedback(self, fb: Feedback) -> None:
        try:
            with self._own_randomness():
                self.inner.feedback(fb)
        except (Exception, SystemExit) as e:
            raise self._failed("feedback", e) from e

    def _failed(self, method: str, e: BaseException) -> BaseException:
        """What to raise when the wrapped planner's ``method`` raised ``e``: for a plug-in,
        one :class:`PlannerContractError` line naming it (an :class:`SgtoolError` as it
        is); for a built-in, ``e`` itself (a bug, with its traceback)."""
        if not self.plugin or isinstance(e, SgtoolError):
            return e
        if isinstance(e, SystemExit):
            return PlannerContractError(f"planner {self.name!r}: {method}() "
                                        f"{raised_text(e)}")
        return PlannerContractError(f"planner {self.name!r}: {method}() raised "
                                    f"{raised_text(e)}")

    def __getattr__(self, item: str) -> object:
        """Expose the wrapped planner's extras (e.g. ``exchanges`` of moma-llm)."""
        if item == "inner":
            raise AttributeError(item)
        return getattr(self.inner, item)
