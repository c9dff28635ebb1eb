"""MoMa-LLM's text side without a model: scene encoding, answer parsing, grounding."""

from __future__ import annotations

import dataclasses

import pytest
from support.semantics_fixtures import house

from sgtool.planning.moma.commands import InvalidCommand, ground, parse_response
from sgtool.planning.moma.scene_text import (
    distance_adjective,
    encode_scene,
    plural,
    room_names,
    same_name,
    singular,
    summarise,
)
from sgtool.scenegraph.graph import ObjectNode, RoomNode


def test_distance_adjectives_follow_moma_bins() -> None:
    assert [distance_adjective(d) for d in (0.0, 2.99, 3.0, 9.9, 10.0, 19.9, 20.0, 100.0)] == [
        "very close", "very close", "near", "near", "far", "far", "distant", "distant"]
    assert distance_adjective(None) == "unreachable"


def test_plural_singular_and_counts() -> None:
    for s, p in [("chair", "chairs"), ("glass", "glasses"), ("box", "boxes"),
                 ("bench", "benches"), ("toy", "toys"), ("battery", "batteries"),
                 ("coffee table", "coffee tables"), ("shelf", "shelves"),
                 ("butter knife", "butter knives"), ("chest of drawers", "chests of drawers"),
                 ("bottle of olive oil", "bottles of olive oil"), ("tomato", "tomatoes"),
                 ("house", "houses"), ("cactus", "cacti"),
                 ("cream of tartar shaker", "cream of tartar shakers")]:
        assert plural(s) == p
        assert singular(p) == s
        # what the prompt shows and what a model may write name the category
        assert same_name(p, s) and same_name(s, s) and same_name(singular(p), s)
    assert not same_name("chair", "armchair") and not same_name("shelve", "shelf")
    assert same_name("buses", "bus")  # the plural a prompt shows names it either way
    # a name that reads as a plural is shown as it is, and its singular names it too
    for name in ("shears", "sunglasses", "french fries", "drawers", "long trousers"):
        assert plural(name) == name and same_name(name, name)
    assert same_name("drawer", "drawers") and same_name("plier", "pliers")
    assert summarise(["chair", "closed fridge", "chair"]) == ["2 chairs", "closed fridge"]


def test_room_names_number_duplicates_and_unknowns() -> None:
    g = house()
    rooms = (*g.rooms, RoomNode("room:5", "bathroom", (6.0, 6.0)), RoomNode("room:6", "unknown"))
    names = room_names(dataclasses.replace(g, rooms=rooms))
    assert names == {"room:1": "kitchen", "room:2": "bathroom 1", "room:3": "living room",
                     "room:4": "unexplored room 4", "room:5": "bathroom 2", "room:6": "room 6"}


def test_scene_text_of_the_test_house() -> None:
    s = encode_scene(house())
    assert s.text.splitlines() == [
        "You are in the kitchen. Objects within 2.5 m: 2 chairs, closed bottom cabinet, "
        "closed fridge, countertop.",
        "Observed rooms and their objects:",
        "- kitchen: [2 chairs, closed bottom cabinet, closed fridge, countertop, "
        "unexplored area]",
        "- bathroom: [closed bottom cabinet, sink]",
        "- living room: [coffee table, sofa]",
        "Unexplored rooms seen through doors: unexplored room 4 (far).",
        "Rooms with space leading out: living room (far).",
        "Rooms with closed doors: living room.",
    ]


@pytest.mark.parametrize(
    "text,call",
    [
        ("Analysis: a\nReasoning: b\nCommand: explore(kitchen)", "explore(kitchen)"),
        ("**Analysis:** a\n**Reasoning:** b\n**Command:** `navigate('bathroom', \"sink\")`",
         "navigate(bathroom, sink)"),
        ("Command: done()", "done()"),
        # the last Command line wins over calls mentioned in the reasoning
        ("Reasoning: explore(garage) is pointless\nCommand: go_to_and_open(kitchen, fridge)",
         "go_to_and_open(kitchen, fridge)"),
        # no Command line: the last call in the text
        ("I will call navigate(kitchen, countertop).", "navigate(kitchen, countertop)"),
    ],
)
def test_parse_variants(text: str, call: str) -> None:
    assert parse_response(text).text() == call


def test_parse_sections_and_errors() -> None:
    c = parse_response("Analysis: milk is cold.\nReasoning: fridge first.\n"
                       "Command: go_to_and_open(kitchen, fridge)")
    assert (c.analysis, c.reasoning) == ("milk is cold.", "fridge first.")
    for bad, msg in [("", "empty"), ("I don't know.", "no command found"),
                     ("Command: explore()", "explore takes one argument"),
                     ("Command: navigate(kitchen)", "navigate takes two arguments")]:
        with pytest.raises(InvalidCommand, match=msg):
            parse_response(bad)


def test_grounding_picks_matching_instances() -> None:
    g = house()
    scene = encode_scene(g)

    def act(text: str, query: str = "milk"):
        return ground(parse_response("Command: " + text), g, scene, query)

    assert act("navigate(kitchen, chairs)").target == "obj:13"  # nearest of the two
    assert act("go_to_and_open(the kitchen, closed fridge)").target == "obj:10"
    assert act("go_to_and_open(living room, door)").target == "door:1"
    assert act("explore(unexplored room 4)").target == "room:4"
    assert act("explore(living room)").target == "frontier:2"
    assert act("explore(Kitchen)").target == "frontier:1"
    with pytest.raises(InvalidCommand, match="cannot be opened"):
        act("go_to_and_open(living room, sofa)")
    with pytest.raises(InvalidCommand, match="is not open"):
        act("close(kitchen, fridge)")
    with pytest.raises(InvalidCommand, match="no unexplored area"):
        act("explore(bathroom)")
    with pytest.raises(InvalidCommand, match="unexplored; explore"):
        act("navigate(unexplored room 4, bed)")
    opened = dataclasses.replace(g, objects=tuple(
        dataclasses.replace(o, state="open", explored=True) if o.id == "obj:10" else o
        for o in g.objects))
    assert ground(parse_response("Command: close(kitchen, open fridge)"), opened,
                  encode_scene(opened), "milk").target == "obj:10"
    milk = ObjectNode("obj:50", "milk", "obj:10", "room:1", (1.0, -1.0, 0.5), relation="inside")
    with_milk = dataclasses.replace(g, objects=(*g.objects, milk))
    assert ground(parse_response("Command: done()"), with_milk, encode_scene(with_milk),
                  "Milk").target == "obj:50"


def test_the_prompt_names_the_query_with_the_right_article():
    from sgtool.planning.moma.planner import system_prompt, with_article

    assert with_article("mug") == "a mug"
    assert with_article("apple") == "an apple"
    assert with_article("short pants") == "some short pants"
    assert with_article("wineglass") == "a wineglass"
    assert "find some short pants." in system_prompt("short pants")


def test_a_door_is_named_only_where_the_text_shows_one() -> None:
    """The living room's door is closed: the text lists it, and `go_to_and_open(living room,
    door)` grounds; once the door is open the text shows no door, and a command naming one
    is refused (and not among the valid commands a grammar allows)."""
    from sgtool.planning.moma.choices import valid_commands

    g = house()
    scene = encode_scene(g)
    assert "Rooms with closed doors: living room." in scene.text
    cmd = "go_to_and_open(living room, door)"
    assert ground(parse_response(f"Command: {cmd}"), g, scene, "mug").target == "door:1"
    assert cmd in valid_commands(g, scene, "mug")
    for refused in ("close(living room, door)", "navigate(living room, open door)"):
        with pytest.raises(InvalidCommand, match="no open door in the living room, only"):
            ground(parse_response(f"Command: {refused}"), g, scene, "mug")
    opened = dataclasses.replace(g, doors=tuple(dataclasses.replace(d, state="open")
                                                for d in g.doors))
    scene = encode_scene(opened)
    assert "closed door" not in scene.text
    with pytest.raises(InvalidCommand, match="shows no closed door in the living room"):
        ground(parse_response("Command: navigate(living room, door)"), opened, scene, "mug")
    assert not any("door" in c for c in valid_commands(opened, scene, "mug"))
