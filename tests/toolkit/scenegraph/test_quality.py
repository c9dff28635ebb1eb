"""Quality figures of a scene graph against ground-truth room polygons."""

from __future__ import annotations

import numpy as np
import pytest

from sgtool.scenegraph.quality import adjusted_rand_index, evaluate, gt_rooms_of

SQUARES = {
    "room_0": [(0.0, 0.0), (4.0, 0.0), (4.0, 4.0), (0.0, 4.0)],
    "room_1": [(4.0, 0.0), (8.0, 0.0), (8.0, 4.0), (4.0, 4.0)],
    "room_2": [(8.0, 0.0), (12.0, 0.0), (12.0, 4.0), (8.0, 4.0)],
}
CATS = {"room_0": "kitchen", "room_1": "living_room", "room_2": "bedroom"}


def test_points_in_polygons() -> None:
    pts = np.array([[1.0, 1.0], [5.0, 3.0], [13.0, 1.0], [11.9, 3.9]])
    assert gt_rooms_of(pts, SQUARES) == ["room_0", "room_1", None, "room_2"]
    l_shape = {"l": [(0, 0), (2, 0), (2, 1), (1, 1), (1, 2), (0, 2)]}
    assert gt_rooms_of(np.array([[0.5, 1.5], [1.5, 1.5]]), l_shape) == ["l", None]


def test_adjusted_rand_index() -> None:
    assert adjusted_rand_index([0, 0, 1, 1], [5, 5, 7, 7]) == pytest.approx(1.0)
    assert adjusted_rand_index([0, 0, 1, 1], [0, 0, 1, 2]) == pytest.approx(0.5714, abs=1e-4)
    assert adjusted_rand_index([0, 0, 0, 0], [0, 0, 0, 0]) == 1.0


def test_open_plan_under_segmentation_strict_and_merged() -> None:
    """Kitchen and living room predicted as one room (open plan), the bedroom right."""
    xy = np.array([[1.0, 2.0], [2.0, 2.0], [3.0, 2.0], [5.0, 2.0], [9.0, 2.0], [10.0, 2.0]])
    rooms = ["room:0", "room:0", "room:0", "room:0", "room:1", "room:1"]
    q = evaluate(xy, rooms, {"room:0": "kitchen", "room:1": "bedroom"},
                 object_rooms={"obj:1": "room:0", "obj:2": "room:0", "obj:3": "room:1"},
                 object_gt={"obj:1": "room_0", "obj:2": "room_1", "obj:3": "room_2"},
                 polygons=SQUARES, gt_categories=CATS)
    assert (q.rooms, q.gt_rooms_seen, q.room_count_error) == (2, 3, -1)
    assert q.purity == pytest.approx(5 / 6)
    assert q.object_accuracy == pytest.approx(2 / 3)  # the living-room object is "wrong"
    assert q.category_accuracy == 1.0
    merged = evaluate(xy, rooms, {"room:0": "living_room", "room:1": "bedroom"},
                      object_rooms={"obj:1": "room:0", "obj:2": "room:0", "obj:3": "room:1"},
                      object_gt={"obj:1": "room_0", "obj:2": "room_1", "obj:3": "room_2"},
                      polygons=SQUARES, gt_categories=CATS,
                      merge={"room_0": "room_0", "room_1": "room_0"})
    assert (merged.gt_rooms, merged.room_count_error) == (2, 0)
    assert merged.purity == 1.0 and merged.ari == pytest.approx(1.0)
    assert merged.object_accuracy == 1.0
    assert merged.category_accuracy == 1.0  # "living_room" names a part of the open plan


def test_rooms_the_camera_stood_in_count_as_seen() -> None:
    """A map that lost most of the house (noisy depth: one room's nodes left) scored over
    what is left would be perfect; the rooms the camera stood in count as seen, so the
    room count error shows the loss. An empty map with a trajectory: every room it
    visited is missing."""
    xy = np.array([[1.0, 2.0], [2.0, 2.0]])
    rooms = ["room:0", "room:0"]
    args = dict(object_rooms={}, object_gt={}, polygons=SQUARES, gt_categories=CATS)
    alone = evaluate(xy, rooms, {"room:0": "kitchen"}, **args)
    assert (alone.rooms, alone.gt_rooms_seen, alone.room_count_error) == (1, 1, 0)
    walked = [(1.0, 1.0), (5.0, 1.0), (9.0, 1.0), (13.0, 1.0)]  # the last outside the house
    q = evaluate(xy, rooms, {"room:0": "kitchen"}, visited=walked, **args)
    assert (q.rooms, q.gt_rooms_seen, q.room_count_error) == (1, 3, -2)
    assert q.purity == 1.0  # the nodes left are in the right room...
    assert q.gt_rooms_with_nodes == 1  # ...but they cover one of the three rooms seen
    empty = evaluate(np.zeros((0, 2)), [], {}, visited=walked[:2], **args)
    assert (empty.rooms, empty.gt_rooms_seen, empty.room_count_error) == (0, 2, -2)


def test_a_map_moved_by_drift_keeps_its_objects_rooms_ari() -> None:
    """The same three rooms and objects, the map moved 3 m along the row (pose drift: the
    graph in the drifted frame): purity and objects right count the shift, the objects'
    rooms ARI asks only which objects share a room and stays 1."""
    xy = np.array([[1.0, 2.0], [2.0, 2.0], [5.0, 2.0], [6.0, 2.0], [9.0, 2.0], [10.0, 2.0]])
    rooms = ["room:0", "room:0", "room:1", "room:1", "room:2", "room:2"]
    objects = {"obj:1": "room:0", "obj:2": "room:0", "obj:3": "room:1", "obj:4": "room:2"}
    gt = {"obj:1": "room_0", "obj:2": "room_0", "obj:3": "room_1", "obj:4": "room_2"}
    cats = {"room:0": "kitchen", "room:1": "living_room", "room:2": "bedroom"}
    right = evaluate(xy, rooms, cats, objects, gt, SQUARES, CATS)
    moved = evaluate(xy + [3.0, 0.0], rooms, cats, objects, gt, SQUARES, CATS)
    assert right.purity == 1.0 and right.object_accuracy == 1.0 and right.object_ari == 1.0
    assert moved.object_accuracy < 1.0 and moved.object_ari == pytest.approx(1.0)
    # objects put in other rooms do move it
    wrong = evaluate(xy, rooms, cats, {**objects, "obj:2": "room:2"}, gt, SQUARES, CATS)
    assert wrong.object_ari < 1.0


def test_room_categories_that_read_the_same_are_one() -> None:
    """A house file that spells its rooms "Living Room" and "Bedroom": the classifier's
    living_room and bedroom are right (they scored 0.0 when compared as strings)."""
    xy = np.array([[5.0, 2.0], [9.0, 2.0]])
    q = evaluate(xy, ["room:0", "room:1"], {"room:0": "living_room", "room:1": "bedroom"},
                 object_rooms={}, object_gt={}, polygons=SQUARES,
                 gt_categories={**CATS, "room_1": "Living Room", "room_2": "Bedroom"})
    assert q.category_accuracy == 1.0
