"""MoMa-LLM's structured text encoding of a scene graph (MoMa-LLM sec. III-C, Fig. 4).

What the model sees, per the paper and the reference notes:

- the current room and the objects within 2.5 m of the robot;
- every explored room as ``- room: [objects]``, object states in the name ("closed
  fridge"), equal objects summarised with counts ("2 chairs"), and ``unexplored area``
  when the room has a frontier inside it;
- rooms with space *leading out*, with a distance adjective (< 3 m very close, < 10 m
  near, < 20 m far, else distant);
- rooms with closed doors;
- (ours, for SymSearch-style graphs) unexplored rooms known through doors.

Room names are the room categories in plain words ("living room"); two rooms of one
category are numbered in id order ("bedroom 1", "bedroom 2"); a room without a category is
"room N" or "unexplored room N" with N its id number (stable while other rooms get
explored). :class:`EncodedScene` keeps the maps from names back to node ids, so a command
the model writes can be grounded in the graph it was shown.
"""

from __future__ import annotations

import math
from collections import Counter
from dataclasses import dataclass, field

from sgtool.planning.candidates import distance_to, natural_key, node_xy
from sgtool.scenegraph.graph import ObjectNode, RegionNode, SceneGraph
from sgtool.semantics.text import category_text

NEAR_ROBOT_M = 2.5


def distance_adjective(d: float | None) -> str:
    """MoMa-LLM's binning of metric distance into words."""
    if d is None or not math.isfinite(d):
        return "unreachable"
    if d < 3.0:
        return "very close"
    if d < 10.0:
        return "near"
    if d < 20.0:
        return "far"
    return "distant"


# English plurals that the suffix rules get wrong, and names that are their own plural
_IRREGULAR = {
    "shelf": "shelves", "knife": "knives", "leaf": "leaves", "loaf": "loaves",
    "half": "halves", "scarf": "scarves", "wolf": "wolves", "calf": "calves",
    "life": "lives", "wife": "wives", "thief": "thieves", "foot": "feet", "tooth": "teeth",
    "mouse": "mice", "goose": "geese", "person": "people", "child": "children", "man": "men",
    "woman": "women", "potato": "potatoes", "tomato": "tomatoes", "mango": "mangoes",
    "cactus": "cacti", "fungus": "fungi",
}
_SINGULAR = {p: s for s, p in _IRREGULAR.items()}
_OWN_PLURAL = frozenset({"sheep", "fish", "deer", "series", "species"})
# the partitive nouns of "X of Y" names, which take the number ("bottles of olive oil");
# in other "X of Y" names the last word does ("cream of tartar shakers")
_PARTITIVES = frozenset({
    "bag", "bar", "basket", "bottle", "bowl", "box", "bucket", "bunch", "can", "carton",
    "case", "chest", "container", "crate", "cup", "glass", "jar", "jug", "loaf", "mug",
    "pack", "packet", "pair", "piece", "plate", "pot", "roll", "sack", "scoop", "set",
    "sheet", "slice", "stack", "stick", "tin", "tray", "tub", "tube",
})


def _parts(noun: str) -> tuple[str, str, str]:
    """(before, the word that takes the number, after) of a category name in words."""
    first, of, rest = noun.partition(" of ")
    if of and first and " " not in first and _singular_word(first) in _PARTITIVES:
        return "", first, of + rest
    head, _, last = noun.rpartition(" ")
    return (head + " " if head else ""), last, ""


def _plural_look(word: str) -> bool:
    """A word that already reads as a plural ("sunglasses", "fries", "drawers"): -es, or
    -s after a consonant; not -ss, -us, -is, -as, -os ("glass", "bus")."""
    return word.endswith("es") or (word.endswith("s") and len(word) > 2
                                   and word[-2] not in "aeiosu")


def plural(noun: str) -> str:
    """English plural of a category name: its head noun's ("chests of drawers", "coffee
    tables", "cream of tartar shakers"), irregular ones ("shelves", "knives"), and a name
    that already reads as a plural as it is ("sunglasses", "shears")."""
    before, word, after = _parts(noun)
    if word in _IRREGULAR:
        word = _IRREGULAR[word]
    elif word in _OWN_PLURAL or _plural_look(word):
        pass
    elif word.endswith(("s", "x", "z", "ch", "sh")):
        word += "es"
    elif word.endswith("y") and len(word) > 1 and word[-2] not in "aeiou":
        word = word[:-1] + "ies"
    else:
        word += "s"
    return before + word + after


def singular(word: str) -> str:
    """A plural read back by :func:`plural`'s rules, for matching model output ("chairs" ->
    "chair", "chests of drawers" -> "chest of drawers", "shelves" -> "shelf"). Not an exact
    inverse ("pies" -> "py"): :func:`same_name` also compares the category's own plural."""
    before, last, after = _parts(word)
    return before + _singular_word(last) + after


def _singular_word(last: str) -> str:
    """One word's singular by :func:`plural`'s rules, read backwards."""
    if last in _SINGULAR:
        return _SINGULAR[last]
    if last in _OWN_PLURAL:
        return last
    if last.endswith("ies") and len(last) > 3:
        return last[:-3] + "y"
    if last.endswith(("ches", "shes", "sses", "xes", "zes")):
        return last[:-2]
    if last.endswith("s") and not last.endswith(("ss", "us")) and len(last) > 1:
        return last[:-1]
    return last


def same_name(text: str, category: str) -> bool:
    """Whether ``text`` (a model's words, articles, counts and states removed) names
    ``category`` in words: the name itself, its plural as a prompt shows it, or a singular
    or plural a model writes for it ("drawer" for "drawers", "shelves" for "shelf")."""
    if text in (category, plural(category)):
        return True
    return bool({text, singular(text)} & {category, singular(category)})


def object_label(o: ObjectNode) -> str:
    """Category in words with the open/closed state in front ("closed fridge")."""
    name = category_text(o.category)
    return f"{o.state} {name}" if o.state in ("open", "closed") else name


def summarise(labels: list[str]) -> list[str]:
    """["chair", "closed fridge", "chair"] -> ["2 chairs", "closed fridge"] (sorted)."""
    counts = Counter(labels)
    return [f"{n} {plural(lab)}" if n > 1 else lab for lab, n in sorted(counts.items())]


@dataclass(frozen=True)
class EncodedScene:
    text: str
    room_by_name: dict[str, str]
    name_by_room: dict[str, str]
    unexplored_rooms: tuple[str, ...] = ()
    notes: dict[str, str] = field(default_factory=dict)
    # rooms the text lists with closed doors: the only rooms whose "door" a command names
    door_rooms: frozenset[str] = frozenset()


def room_names(graph: SceneGraph) -> dict[str, str]:
    """room id -> display name (module doc)."""
    rooms = sorted(graph.rooms, key=lambda r: natural_key(r.id))
    base: dict[str, str] = {}
    for r in rooms:
        cat = category_text(r.category) if r.explored else ""
        if cat in ("", "unknown", "none"):
            cat = "unexplored room" if not r.explored else "room"
        base[r.id] = cat
    counts = Counter(base.values())
    seen: Counter[str] = Counter()
    out: dict[str, str] = {}
    for r in rooms:
        b = base[r.id]
        suffix = r.id.rpartition(":")[2]
        if b in ("room", "unexplored room") and suffix.isdecimal():
            # rooms without a category keep their id number: "unexplored room 1" must not
            # turn into another room when room 1 gets explored and the others move up
            out[r.id] = f"{b} {int(suffix)}"
        elif counts[b] > 1 or b in ("room", "unexplored room"):
            seen[b] += 1
            out[r.id] = f"{b} {seen[b]}"
        else:
            out[r.id] = b
    return out


def encode_scene(graph: SceneGraph) -> EncodedScene:
    names = room_names(graph)
    lines: list[str] = []
    rx, ry = graph.robot.position

    cur = graph.robot.room
    near = [
        o for o in graph.objects
        if math.hypot(o.position[0] - rx, o.position[1] - ry) <= NEAR_ROBOT_M
    ]
    cur_name = names.get(cur, "unknown") if cur else "unknown"
    near_text = ", ".join(summarise([object_label(o) for o in near])) or "nothing"
    lines.append(f"You are in the {cur_name}. Objects within {NEAR_ROBOT_M:g} m: {near_text}.")

    lines.append("Observed rooms and their objects:")
    explored = [r for r in sorted(graph.rooms, key=lambda r: natural_key(r.id)) if r.explored]
    if not explored:
        lines.append("- none")
    for r in explored:
        labels = [object_label(o) for o in graph.objects_in(r.id)]
        items = summarise(labels)
        if any(f.room == r.id and f.frontier_type != "leading out" for f in graph.frontiers()):
            items.append("unexplored area")
        lines.append(f"- {names[r.id]}: [{', '.join(items)}]")

    unexplored = [r for r in sorted(graph.rooms, key=lambda r: natural_key(r.id)) if not r.explored]
    if unexplored:
        parts = [f"{names[r.id]} ({distance_adjective(distance_to(graph, r))})"
                 for r in unexplored]
        lines.append("Unexplored rooms seen through doors: " + ", ".join(parts) + ".")

    leading: dict[str, float] = {}
    for f in graph.frontiers():
        if f.frontier_type == "leading out" and f.room in names:
            d = distance_to(graph, f)
            dd = math.inf if d is None else d
            leading[f.room] = min(leading.get(f.room, math.inf), dd)
    if leading:
        parts = [f"{names[rid]} ({distance_adjective(d)})"
                 for rid, d in sorted(leading.items(), key=lambda kv: natural_key(kv[0]))]
        lines.append("Rooms with space leading out: " + ", ".join(parts) + ".")

    door_rooms: Counter[str] = Counter()
    for door in graph.doors:
        if door.state != "closed":
            continue
        for rid in door.rooms:
            room = graph.room(rid)
            if room is not None and room.explored:
                door_rooms[rid] += 1
    if door_rooms:
        parts = [
            names[rid] if n == 1 else f"{names[rid]} ({n} doors)"
            for rid, n in sorted(door_rooms.items(), key=lambda kv: natural_key(kv[0]))
        ]
        lines.append("Rooms with closed doors: " + ", ".join(parts) + ".")

    return EncodedScene(
        text="\n".join(lines),
        room_by_name={v: k for k, v in names.items()},
        name_by_room=names,
        unexplored_rooms=tuple(r.id for r in unexplored),
        door_rooms=frozenset(door_rooms),
    )


def room_of(graph: SceneGraph, node_id: str) -> str | None:
    """The room a node belongs to (rooms are their own room)."""
    n = graph.node(node_id)
    if n is None:
        return None
    if graph.room(node_id) is not None:
        return node_id
    room = getattr(n, "room", None)
    if room is not None:
        return room
    rooms = getattr(n, "rooms", ())
    explored = [r for r in rooms if (rn := graph.room(r)) is not None and rn.explored]
    return (explored or list(rooms) or [None])[0]


def nearest_room(graph: SceneGraph, xy: tuple[float, float]) -> str | None:
    """Room of the graph node nearest to ``xy`` (regions and objects, then room centres):
    MoMa-LLM's realignment of a past action's position to the current graph."""
    best: tuple[float, str] | None = None
    nodes: tuple[RegionNode | ObjectNode, ...] = (*graph.regions, *graph.objects)
    for n in nodes:
        x, y = node_xy(n)
        d = math.hypot(x - xy[0], y - xy[1])
        if best is None or (d, n.room) < best:
            best = (d, n.room)
    if best is None:
        for r in graph.rooms:
            x, y = node_xy(r)
            d = math.hypot(x - xy[0], y - xy[1])
            if best is None or (d, r.id) < best:
                best = (d, r.id)
    return None if best is None else best[1]


__all__ = [
    "EncodedScene",
    "distance_adjective",
    "encode_scene",
    "nearest_room",
    "object_label",
    "plural",
    "room_names",
    "room_of",
    "same_name",
    "singular",
    "summarise",
]
