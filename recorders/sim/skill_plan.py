"""Planner actions as simulator skills (pure): what the closed loop runs for an action.

Mapping planner actions to skills (:func:`plan_skills`, pure):

=========================================  ===============================================
action                                     simulator calls
=========================================  ===============================================
``navigate(obj:N | door:N)``               ``navigate(N)``
``navigate(room | region | frontier)``     ``navigate((x, y))`` of the node
``explore(frontier | room | region)``      ``explore((x, y))`` (go there, look around)
``explore(obj:N | door:N)``                ``explore(N)``
``open(obj:N | door:N)``                   ``navigate(N)`` then ``open(N)`` (MoMa-LLM's
                                           go_to_and_open): one action, summed distance,
                                           the outcome of the open (or of the navigate
                                           when that fails)
``close(obj:N | door:N)``                  ``navigate(N)`` then ``close(N)``
``open``/``close`` of a room or region     invalid, no motion
a target not in the graph the planner saw  invalid, no motion
``done``                                   ends the episode
=========================================  ===============================================
"""

from __future__ import annotations

from dataclasses import dataclass, field

from sgtool.house.names import decimal_int
from sgtool.planning.base import Action
from sgtool.scenegraph.graph import DoorNode, ObjectNode, RegionNode, RoomNode, SceneGraph

SKILLS = ("navigate", "open", "close", "explore", "done")
DONE_MESSAGE = "episode ended by the planner"


@dataclass(frozen=True)
class SkillCall:
    """One simulator skill: ``navigate``/``explore``/``open``/``close`` of an instance id or
    a point (x, y)."""

    skill: str
    target: int | tuple[float, float]
    node: str | None = field(default=None, compare=False)  # the graph node it came from


@dataclass(frozen=True)
class SkillPlan:
    """What an action means for the simulator: calls run in order until one does not
    succeed; or ``invalid`` (why, nothing moves); or ``done``."""

    calls: tuple[SkillCall, ...] = ()
    invalid: str | None = None
    done: bool = False


def _instance(node: ObjectNode | DoorNode) -> int | None:
    if node.instance >= 0:
        return int(node.instance)
    _, _, num = node.id.partition(":")
    return decimal_int(num)  # "obj:²" names none ("²".isdigit(), but int("²") fails)


def plan_skills(graph: SceneGraph, action: Action) -> SkillPlan:
    """The simulator calls of ``action`` on the graph the planner decided on (module doc)."""
    skill = action.skill
    if skill == "done":
        return SkillPlan(done=True)
    if skill not in SKILLS:
        return SkillPlan(invalid=f"unknown skill {skill!r}; one of {', '.join(SKILLS)}")
    if action.target is None:
        return SkillPlan(invalid=f"{skill} needs a target node")
    node = graph.node(action.target)
    if node is None:
        return SkillPlan(invalid=f"{action.target!r} is not a node of the scene graph the "
                                 "planner saw")
    if isinstance(node, (ObjectNode, DoorNode)):
        iid = _instance(node)
        if iid is None:
            return SkillPlan(invalid=f"{node.id} names no instance")
        if skill in ("open", "close"):
            return SkillPlan((SkillCall("navigate", iid, node.id),
                              SkillCall(skill, iid, node.id)))
        return SkillPlan((SkillCall(skill, iid, node.id),))
    assert isinstance(node, (RoomNode, RegionNode))
    what = "room" if isinstance(node, RoomNode) else (
        "frontier" if node.kind == "frontier" else "region")
    if skill in ("open", "close"):
        return SkillPlan(invalid=f"cannot {skill} a {what} ({node.id})")
    xy = (float(node.position[0]), float(node.position[1]))
    return SkillPlan((SkillCall(skill, xy, node.id),))
