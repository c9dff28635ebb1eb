"""Ids and file names that end in characters str.isdigit() accepts but int() does not
(superscripts) sort as text instead of crashing; decimal digits of any script sort by value.
File names: tests/recorders/importers/test_folder_inputs.py."""

from __future__ import annotations

from sgtool.log.inspect import house_seed_of
from sgtool.planning.candidates import natural_key
from sgtool.scenegraph.graph import ObjectNode, RobotState, RoomNode, SceneGraph


def test_node_ids_with_superscripts_sort_as_text() -> None:
    assert natural_key("obj:²") == ("obj", ((1, "²"),))
    assert sorted(["obj:10", "obj:²", "obj:2"], key=natural_key) == ["obj:2", "obj:10", "obj:²"]
    assert natural_key("room:١٢") == ("room", ((0, 12),))  # Arabic-Indic digits: a number


def test_the_canonical_graph_lists_nodes_in_natural_id_order() -> None:
    objects = tuple(ObjectNode(i, "cup", "region:1.1", "room:1", (0.0, 0.0, 0.0))
                    for i in ("obj:10", "obj:²", "obj:2"))
    rooms = (RoomNode("room:١٢"), RoomNode("room:3"))
    graph = SceneGraph(RobotState((0.0, 0.0)), rooms=rooms, objects=objects).to_dict()
    assert [o["id"] for o in graph["objects"]] == ["obj:2", "obj:10", "obj:²"]
    assert [r["id"] for r in graph["rooms"]] == ["room:3", "room:١٢"]  # 12 after 3


def test_a_house_seed_that_is_no_integer_is_none() -> None:
    assert [house_seed_of(s) for s in ("12", "-3", "--5", "²", "1-", "", "١٢")] == \
        [12, -3, None, None, None, None, 12]
