"""Parse MoMa-LLM's "Analysis / Reasoning / Command" answers and ground the command in the graph.

The skill API (MoMa-LLM Fig. 4): ``navigate(room, object)``, ``go_to_and_open(room,
object)``, ``close(room, object)``, ``explore(room)``, ``done()``. Parsing is lenient about
form (markdown emphasis, quotes, "the", counts, plurals, state words) and strict about
substance: a room or object that is not in the scene the model was shown is an
:class:`InvalidCommand` whose message says what exists instead; the planner sends that
message back to the model and asks again.

Grounding picks among equal objects (the encoding summarises "2 chairs") the one that
matches the skill (a closed one to open, an open one to close, an unexplored one to look
at), then the nearest, then the smallest id.
"""

from __future__ import annotations

import json
import math
import re
from collections.abc import Callable
from dataclasses import dataclass
from typing import TypeVar

from sgtool.planning.base import Action, Skill
from sgtool.planning.candidates import (
    OPEN_AFFORDANCES,
    NaturalKey,
    distance_to,
    door_is_entrance,
    find_target,
    natural_key,
    object_skill,
)
from sgtool.planning.moma.scene_text import EncodedScene, same_name
from sgtool.scenegraph.graph import DoorNode, ObjectNode, RegionNode, SceneGraph
from sgtool.semantics.text import category_text

ARITY = {"navigate": 2, "go_to_and_open": 2, "close": 2, "explore": 1, "done": 0}
_CALL = re.compile(r"\b(navigate|go_to_and_open|close|explore|done)\s*\(([^()]*)\)", re.I)
_COMMAND_LINE = re.compile(r"^[\s>*_#`-]*command[\s*_`]*:(.*)$", re.I | re.M)
_SECTION = (
    r"^[\s>*_#`-]*{name}[\s*_`]*:(.*?)"
    r"(?=^[\s>*_#`-]*(?:analysis|reasoning|command)[\s*_`]*:|\Z)"
)
_STATE_WORDS = {"open", "opened", "closed", "the", "a", "an"}
_DOOR_WORDS = {"door", "doors"}


class InvalidCommand(Exception):
    """The answer has no usable command, or names things that do not exist."""


@dataclass(frozen=True)
class Command:
    name: str
    args: tuple[str, ...]
    analysis: str = ""
    reasoning: str = ""

    def text(self) -> str:
        return f"{self.name}({', '.join(self.args)})"


def _section(text: str, name: str) -> str:
    m = re.search(_SECTION.format(name=name), text, re.I | re.M | re.S)
    return " ".join(m.group(1).split()) if m else ""


def _json_answer(text: str) -> tuple[str, str, str] | None:
    """(command, analysis, reasoning) of a structured-output answer (a JSON object with a
    ``command`` string, :func:`sgtool.llm.constraints.command_schema`), else None."""
    if not text.lstrip().startswith("{"):
        return None
    try:
        obj = json.loads(text)
    except ValueError:
        return None
    if not isinstance(obj, dict) or not isinstance(obj.get("command"), str):
        return None
    return (obj["command"], " ".join(str(obj.get("analysis", "")).split()),
            " ".join(str(obj.get("reasoning", "")).split()))


def parse_response(text: str) -> Command:
    """The command of an answer; the last "Command:" line wins, else the last call. A JSON
    answer (structured outputs) gives its ``command``, ``analysis`` and ``reasoning``."""
    if not isinstance(text, str) or not text.strip():
        raise InvalidCommand("the answer is empty")
    structured = _json_answer(text)
    if structured is not None:
        cmd = parse_response(f"Command: {structured[0]}")
        return Command(cmd.name, cmd.args, structured[1], structured[2])
    call = None
    lines = _COMMAND_LINE.findall(text)
    for line in reversed(lines):
        calls = _CALL.findall(line)
        if calls:
            call = calls[-1]
            break
    if call is None:
        calls = _CALL.findall(text)
        if not calls:
            raise InvalidCommand(
                "no command found; end the answer with a line 'Command: <function call>' "
                "using one of navigate, go_to_and_open, close, explore, done"
            )
        call = calls[-1]
    name = call[0].lower()
    raw = call[1].strip()
    args = tuple(a.strip().strip("'\"`").strip() for a in raw.split(",")) if raw else ()
    args = tuple(a for a in args if a)
    if len(args) != ARITY[name]:
        want = {0: "no arguments", 1: "one argument (room)", 2: "two arguments (room, object)"}
        raise InvalidCommand(f"{name} takes {want[ARITY[name]]}, got {len(args)}: {raw!r}")
    return Command(name, args, _section(text, "analysis"), _section(text, "reasoning"))


def _norm(s: str) -> str:
    return " ".join(category_text(s).split())


def _strip_object_words(name: str) -> tuple[str, str | None]:
    """"the 2 closed cabinets" -> ("cabinets", "closed")."""
    words = _norm(name).split()
    state = None
    kept = []
    for w in words:
        if w in ("open", "opened"):
            state = "open"
        elif w == "closed":
            state = "closed"
        elif w in _STATE_WORDS or w.isdigit():
            continue
        else:
            kept.append(w)
    return " ".join(kept), state


def resolve_room(name: str, scene: EncodedScene) -> str:
    key = _norm(name)
    if key.startswith("the "):
        key = key[4:]
    if key in scene.room_by_name:
        return scene.room_by_name[key]
    # "kitchen" when only "kitchen 1" exists
    prefixed = [n for n in scene.room_by_name if re.fullmatch(re.escape(key) + r" \d+", n)]
    if len(prefixed) == 1:
        return scene.room_by_name[prefixed[0]]
    known = ", ".join(sorted(scene.room_by_name)) or "none"
    if len(prefixed) > 1:
        raise InvalidCommand(f"room '{name}' is ambiguous; rooms are: {known}")
    raise InvalidCommand(f"room '{name}' does not exist; rooms are: {known}")


_Node = TypeVar("_Node", RegionNode, ObjectNode, DoorNode)


def _pick(graph: SceneGraph, nodes: list[_Node], prefer: Callable[[_Node], bool]) -> str:
    """The id of the node of ``nodes`` that ``prefer`` picks, nearest first, then the
    first in natural id order."""

    def key(n: _Node) -> tuple[int, float, NaturalKey]:
        d = distance_to(graph, n)
        return (0 if prefer(n) else 1, math.inf if d is None else d, natural_key(n.id))

    return min(nodes, key=key).id


def _room_objects_text(graph: SceneGraph, room_id: str) -> str:
    names = sorted({category_text(o.category) for o in graph.objects_in(room_id)})
    return ", ".join(names) or "no objects"


def resolve_object(graph: SceneGraph, room_id: str, name: str, skill: str,
                   scene: EncodedScene) -> str:
    """Node id of the object (or door) ``name`` in room ``room_id`` for ``skill``."""
    wanted, state = _strip_object_words(name)
    room_name = scene.name_by_room.get(room_id, room_id)
    if wanted in _DOOR_WORDS:
        # the doors the text shows: a room's closed doors, listed when it is explored
        doors: list[DoorNode] = [d for d in graph.doors if room_id in d.rooms
                                 and d.state == "closed" and room_id in scene.door_rooms]
        if not doors:
            raise InvalidCommand(f"the scene shows no closed door in the {room_name}; it lists "
                                 "only closed doors, under 'Rooms with closed doors'")
        if state == "open" or skill == "close":
            raise InvalidCommand(f"the scene shows no open door in the {room_name}, only "
                                 "closed ones: open one with go_to_and_open(ROOM, door)")
        return _pick(graph, doors, lambda d: door_is_entrance(graph, d))
    objs: list[ObjectNode] = [
        o for o in graph.objects_in(room_id)
        if same_name(wanted, category_text(o.category))
    ]
    if not objs:
        raise InvalidCommand(
            f"there is no '{name}' in the {room_name}; it has: "
            f"{_room_objects_text(graph, room_id)}"
        )
    if state is not None:
        objs = [o for o in objs if o.state == state] or objs
    if skill == "open":
        return _pick(graph, objs, lambda o: o.state == "closed" and not o.explored)
    if skill == "close":
        return _pick(graph, objs, lambda o: o.state == "open")
    return _pick(graph, objs, lambda o: object_skill(o) is not None)


# the skill of a command that names an object
_SKILL_OF: dict[str, Skill] = {"navigate": "navigate", "go_to_and_open": "open", "close": "close"}


def ground(cmd: Command, graph: SceneGraph, scene: EncodedScene, query: str) -> Action:
    """The :class:`Action` a parsed command stands for on ``graph``."""
    reason = cmd.reasoning or cmd.analysis
    if cmd.name == "done":
        found = find_target(graph, query)
        if found is None:
            raise InvalidCommand(
                f"done() is only valid once a {query} has been observed; none is in the "
                "scene yet, keep searching"
            )
        return Action("done", target=found.id, reason=reason)
    room_id = resolve_room(cmd.args[0], scene)
    room = graph.room(room_id)
    room_name = scene.name_by_room[room_id]
    if cmd.name == "explore":
        if room is not None and not room.explored:
            return Action("explore", target=room_id, reason=reason)
        fr = [f for f in graph.frontiers() if f.room == room_id]
        if not fr:
            raise InvalidCommand(
                f"the {room_name} has no unexplored area or space leading out left to explore"
            )
        inside = [f for f in fr if f.frontier_type != "leading out"]
        target = _pick(graph, inside or fr, lambda f: True)
        return Action("explore", target=target, reason=reason)
    if room is not None and not room.explored:
        raise InvalidCommand(
            f"the {room_name} is unexplored; explore({room_name}) first"
        )
    skill = _SKILL_OF[cmd.name]
    target = resolve_object(graph, room_id, cmd.args[1], skill, scene)
    node = graph.node(target)
    if skill == "open" and getattr(node, "state", None) == "open":
        raise InvalidCommand(f"the {cmd.args[1]} in the {room_name} is already open")
    if (skill == "open" and isinstance(node, ObjectNode) and node.state is None
            and not {a.lower() for a in node.affordances} & OPEN_AFFORDANCES):
        raise InvalidCommand(f"the {cmd.args[1]} in the {room_name} cannot be opened")
    if skill == "close" and getattr(node, "state", None) != "open":
        raise InvalidCommand(f"the {cmd.args[1]} in the {room_name} is not open")
    return Action(skill, target=target, reason=reason)
