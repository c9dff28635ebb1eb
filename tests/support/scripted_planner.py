"""A planner that plays fixed actions (or functions of the graph) and keeps its feedback."""

from __future__ import annotations

from collections.abc import Callable, Iterable

from sgtool.planning.base import Action, Feedback
from sgtool.scenegraph.graph import SceneGraph


class Scripted:
    """A planner that plays fixed actions and remembers the feedback it gets."""

    name = "scripted"

    def __init__(self, actions: Iterable[Action | Callable[[SceneGraph], Action]]) -> None:
        self.actions = list(actions)
        self.feedbacks: list[Feedback] = []
        self.graphs: list[SceneGraph] = []

    def reset(self, query: str, seed: int = 0) -> None:
        pass

    def decide(self, graph: SceneGraph) -> Action:
        self.graphs.append(graph)
        a = self.actions.pop(0)
        return a(graph) if callable(a) else a

    def feedback(self, fb: Feedback) -> None:
        self.feedbacks.append(fb)
