"""The commands that are valid on a scene graph, written as the model would write them.

Every skill of MoMa-LLM's API applied to every room name and object word of the encoded
scene (:mod:`~sgtool.planning.moma.scene_text`); a candidate is kept only when it parses
and grounds (:func:`~sgtool.planning.moma.commands.parse_response`,
:func:`~sgtool.planning.moma.commands.ground`), so the list and the planner's own checks
can never disagree. ``done()`` is valid only when an object of the query is in the graph
(as :func:`ground` says). The list constrains the endpoint's answer
(:mod:`sgtool.llm.constraints`).
"""

from __future__ import annotations

from sgtool.planning.candidates import natural_key
from sgtool.planning.moma.commands import InvalidCommand, ground, parse_response
from sgtool.planning.moma.scene_text import EncodedScene
from sgtool.scenegraph.graph import SceneGraph
from sgtool.semantics.text import category_text

OBJECT_SKILLS = ("navigate", "go_to_and_open", "close")


def _valid(text: str, graph: SceneGraph, scene: EncodedScene, query: str) -> bool:
    try:
        ground(parse_response(f"Command: {text}"), graph, scene, query)
    except InvalidCommand:
        return False
    return True


def valid_commands(graph: SceneGraph, scene: EncodedScene, query: str) -> tuple[str, ...]:
    """The valid commands on ``graph`` (module doc): ``done()`` first, then explore, then
    the object skills, rooms in id order, words in plain order."""
    cands: list[str] = ["done()"]
    rooms = sorted(scene.name_by_room, key=natural_key)
    cands += [f"explore({scene.name_by_room[r]})" for r in rooms]
    for r in rooms:
        words = sorted({category_text(o.category) for o in graph.objects_in(r)})
        if r in scene.door_rooms:
            words.append("door")
        for skill in OBJECT_SKILLS:
            cands += [f"{skill}({scene.name_by_room[r]}, {w})" for w in words]
    return tuple(c for c in cands if _valid(c, graph, scene, query))
