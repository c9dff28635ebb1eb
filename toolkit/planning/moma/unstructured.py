"""``unstructured-llm``: MoMa-LLM's ablation "Unstructured LLM" (the raw JSON scene graph).

MoMa-LLM compares its structured, grounded encoding with giving the same LLM the scene
graph as JSON. :class:`UnstructuredLlmPlanner` is :class:`MomaLlmPlanner` with one change:
the user prompt holds the canonical JSON of the scene graph
(:meth:`~sgtool.scenegraph.graph.SceneGraph.to_json`: ids, categories, states, positions,
rooms, frontiers, doors, travel distances) instead of the structured text. Everything else
is the same: system prompt and skill API, history realigned to the graph, parsing and
grounding of room and object names (room categories and object categories, as the JSON
spells them, are understood: "living_room" is the living room), feedback on invalid
commands, answer constraints, logging; so the invalid-action rate of the two is comparable
(``sgtool eval`` of their logs, :mod:`sgtool.llm.stats`).
"""

from __future__ import annotations

from sgtool.planning.moma.planner import MomaLlmPlanner
from sgtool.scenegraph.graph import SceneGraph

JSON_INTRO = "The scene graph as JSON:"


class UnstructuredLlmPlanner(MomaLlmPlanner):
    name = "unstructured-llm"

    def user_prompt(self, graph: SceneGraph, scene_text: str) -> str:
        """The raw JSON of ``graph`` in place of ``scene_text`` (module doc)."""
        return super().user_prompt(graph, f"{JSON_INTRO}\n{graph.to_json()}")
