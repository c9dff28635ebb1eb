"""Running the simulator calls of one planner action (:mod:`.skill_plan`), two ways:

- :func:`execute_live` (the closed loop's default, ``navigation="live"``): the robot plans
  on its own map (:mod:`.live_skills`); goals come from the nodes of the graph the planner
  decided on and its map layers;
- :func:`execute_privileged` (``navigation="house"``, privileged, kept for comparison): the
  simulator's skills plan on the house's ground-truth occupancy.

Both run the calls until one does not succeed or the target came into view
(:data:`~sgtool.recorders.sim.live_skills.IN_VIEW`: live, the skills ask at every
refresh; privileged, the recorder raises :class:`~.events.TargetInView` at one) and
return an :class:`Executed`.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from sgtool.planning.base import Outcome
from sgtool.recorders.sim.events import StopSimulation, TargetInView
from sgtool.recorders.sim.live_goals import Goal, goal_of_node
from sgtool.recorders.sim.live_skills import IN_VIEW, LiveSkills
from sgtool.recorders.sim.simulation import Simulation, SkillOutcome
from sgtool.recorders.sim.skill_plan import SkillCall
from sgtool.scenegraph.graph import ObjectNode
from sgtool.scenegraph.stream import Refresh


@dataclass(frozen=True)
class Executed:
    outcome: Outcome
    reason: str
    travelled_m: float
    ticks: int
    cut: bool  # the frame budget stopped it


def execute_privileged(sim: Simulation, calls: Sequence[SkillCall]) -> Executed:
    """Run ``calls`` with the simulator's own (ground-truth) skills."""
    t0, d0 = sim.tick_index, sim.travelled_m
    out: SkillOutcome | None = None
    try:
        for c in calls:
            out = sim.look_around() if c.skill == "look_around" else \
                getattr(sim, c.skill)(c.target)
            if not out.success:
                break
    except StopSimulation as e:
        return Executed("failure", f"stopped: {e}", sim.travelled_m - d0,
                        sim.tick_index - t0, True)
    except TargetInView:  # the recorder's graph holds the target: the rest is moot
        return Executed("success", IN_VIEW, sim.travelled_m - d0, sim.tick_index - t0, False)
    assert out is not None
    return Executed(out.outcome, out.reason, sim.travelled_m - d0, sim.tick_index - t0, False)


def execute_live(sim: Simulation, skills: LiveSkills, calls: Sequence[SkillCall],
                 decided: Refresh | None) -> Executed:
    """Run ``calls`` with the robot's skills on its own map; ``decided`` is the refresh
    the planner decided on (its graph names the nodes of the calls)."""
    t0, d0 = sim.tick_index, sim.travelled_m
    outcome: Outcome = "success"
    reason = ""
    try:
        for c in calls:
            if c.skill == "look_around":
                outcome, reason, _ = skills.look_around()
            elif c.skill in ("open", "close"):
                assert isinstance(c.target, int)
                out = getattr(skills.body, c.skill)(c.target)
                outcome, reason = out.outcome, out.reason
                at = _container_at(c, decided) if c.skill == "open" else None
                if outcome == "success" and at is not None:
                    outcome, reason, _ = skills.peek(at)
                    if reason != IN_VIEW:
                        outcome, reason, _ = skills.look_in(at, str(c.node),
                                                            _room_of(c, decided))
            else:
                goal = _goal(c, decided)
                run = skills.explore if c.skill == "explore" else skills.navigate
                outcome, reason, _ = run(goal)
                at = _container_at(c, decided, open_only=True) \
                    if c.skill == "navigate" else None
                if outcome == "success" and reason != IN_VIEW and at is not None:
                    outcome, reason, _ = skills.peek(at)  # examining an open container
            if outcome != "success" or reason == IN_VIEW:
                break  # a failure, or the target came into view: the rest is moot
    except StopSimulation as e:
        return Executed("failure", f"stopped: {e}", sim.travelled_m - d0,
                        sim.tick_index - t0, True)
    return Executed(outcome, reason, sim.travelled_m - d0, sim.tick_index - t0, False)


def _container_at(call: SkillCall, decided: Refresh | None, open_only: bool = False
                  ) -> tuple[float, float, float] | None:
    """Where the object node of ``call`` is in the graph decided on (None: a door, or no
    such node): the container an ``open`` looks into. ``open_only``: only a container
    that is not closed (a navigate to it examines it), else None."""
    node = None if decided is None or call.node is None else decided.graph.node(call.node)
    if not isinstance(node, ObjectNode):
        return None
    if open_only and (node.state == "closed"
                      or all(a.lower() != "container" for a in node.affordances)):
        return None
    x, y, z = node.position
    return float(x), float(y), float(z)


def _room_of(call: SkillCall, decided: Refresh | None) -> str | None:
    """The room of the object node of ``call`` in the graph decided on (None: none)."""
    node = None if decided is None or call.node is None else decided.graph.node(call.node)
    return node.room if isinstance(node, ObjectNode) else None


def _goal(call: SkillCall, decided: Refresh | None) -> Goal:
    node = None
    if decided is not None and call.node is not None:
        node = decided.graph.node(call.node)
    if node is not None:
        return goal_of_node(node, None if decided is None else decided.layers)
    if isinstance(call.target, int):
        raise ValueError(f"instance {call.target} without its graph node")
    xy = np.array([call.target], dtype=np.float64)
    return Goal(f"({xy[0, 0]:.2f}, {xy[0, 1]:.2f})", "point", xy)
