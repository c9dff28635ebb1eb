"""The merged score of rooms joined by a doorless passage takes the graph's form: one room
when the graph holds them in one, two when it splits them correctly."""

from __future__ import annotations

import numpy as np

from sgtool.replayers.score import split_groups_kept_apart

# two 4 x 4 rooms side by side, joined by a passage (one group), and a third alone
POLYGONS = {"room_a": ((0, 0), (4, 0), (4, 4), (0, 4)),
            "room_b": ((4, 0), (8, 0), (8, 4), (4, 4)),
            "room_c": ((8, 0), (12, 0), (12, 4), (8, 4))}
MERGE = {"room_a": "room_a", "room_b": "room_a"}
NODES = np.array([[1, 2], [2, 2], [3, 2], [5, 2], [6, 2], [7, 2], [10, 2]], dtype=float)


def test_a_group_the_graph_holds_in_one_room_stays_merged() -> None:
    rooms = ["room:0"] * 6 + ["room:1"]
    assert split_groups_kept_apart(MERGE, NODES, rooms, POLYGONS) == MERGE


def test_a_group_the_graph_splits_is_scored_room_by_room() -> None:
    rooms = ["room:0"] * 3 + ["room:1"] * 3 + ["room:2"]
    assert split_groups_kept_apart(MERGE, NODES, rooms, POLYGONS) == {}
    # a stray node of b in a's predicted room does not undo the split
    rooms[3] = "room:0"
    assert split_groups_kept_apart(MERGE, NODES, rooms, POLYGONS) == {}
    # nodes of neither room of the group in any predicted room: merged, as before
    assert split_groups_kept_apart(MERGE, NODES, [None] * 7, POLYGONS) == MERGE
