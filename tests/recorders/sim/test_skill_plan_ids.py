"""Node ids whose number is not a plain decimal (a Unicode superscript "²" passes
``str.isdigit`` but ``int`` refuses it) name no instance: the action is invalid, no crash."""

from __future__ import annotations

from sgtool.planning.base import Action
from sgtool.recorders.sim.skill_plan import SkillCall, plan_skills
from sgtool.scenegraph.graph import ObjectNode, RobotState, SceneGraph


def _graph(*ids: str) -> SceneGraph:
    return SceneGraph(robot=RobotState((0.0, 0.0)),
                      objects=tuple(ObjectNode(i, "box", "region:0.0", "room:0",
                                               (1.0, 1.0, 0.5)) for i in ids))


def test_a_superscript_number_names_no_instance() -> None:
    p = plan_skills(_graph("obj:²"), Action("open", "obj:²"))
    assert p.calls == () and p.invalid == "obj:² names no instance"


def test_decimal_numbers_still_name_their_instance() -> None:
    g = _graph("obj:12", "obj:٣")  # Arabic-Indic three is a decimal digit
    assert plan_skills(g, Action("navigate", "obj:12")).calls == (SkillCall("navigate", 12),)
    assert plan_skills(g, Action("navigate", "obj:٣")).calls == (SkillCall("navigate", 3),)
