"""Small hand-built house specs shared by the datasets tests."""

from __future__ import annotations

import math


def two_rooms(door_state: str = "open") -> dict:
    """Two 4 m x 4 m rooms side by side, a 0.9 m door in the shared wall at y 1.5-2.4,
    a fridge (container) holding an apple, a table with a cup on top."""
    return {
        "version": "1.0", "seed": 7,
        "rooms": [
            {"id": "room_0", "category": "kitchen", "polygon": [[0, 0], [4, 0], [4, 4], [0, 4]]},
            {"id": "room_1", "category": "bedroom", "polygon": [[4, 0], [8, 0], [8, 4], [4, 4]]},
        ],
        "walls": [
            {"id": "wall_0", "a": [0, 0], "b": [8, 0], "thickness": 0.1, "height": 2.5},
            {"id": "wall_1", "a": [0, 4], "b": [8, 4], "thickness": 0.1, "height": 2.5},
            {"id": "wall_2", "a": [0, 0], "b": [0, 4], "thickness": 0.1, "height": 2.5},
            {"id": "wall_3", "a": [8, 0], "b": [8, 4], "thickness": 0.1, "height": 2.5},
            {"id": "wall_4", "a": [4, 0], "b": [4, 1.5], "thickness": 0.1, "height": 2.5},
            {"id": "wall_5", "a": [4, 2.4], "b": [4, 4], "thickness": 0.1, "height": 2.5},
        ],
        "doors": [{"id": "door_0", "center": [4, 1.95], "width": 0.9, "yaw": math.pi / 2,
                   "state": door_state, "rooms": ["room_0", "room_1"]}],
        "furniture": [
            {"id": "furn_0", "category": "refrigerator", "synset": "electric_refrigerator.n.01",
             "room": "room_0", "center": [0.5, 3.5, 0.9], "size": [0.8, 0.7, 1.8],
             "yaw": math.pi, "affordances": ["openable", "container"],  # its front faces the room
             "state": "closed"},
            {"id": "furn_1", "category": "table", "synset": "table.n.02", "room": "room_1",
             "center": [6.0, 3.4, 0.375], "size": [1.2, 0.8, 0.75], "yaw": 0,
             "affordances": ["supporter"], "state": None},
        ],
        "objects": [
            {"id": "obj_0", "category": "apple", "synset": "apple.n.01", "parent": "furn_0",
             "relation": "inside", "room": "room_0", "position": [0.5, 3.5, 1.0],
             "size": [0.08, 0.08, 0.08]},
            {"id": "obj_1", "category": "cup", "synset": "cup.n.01", "parent": "furn_1",
             "relation": "ontop", "room": "room_1", "position": [6.0, 3.4, 0.8],
             "size": [0.08, 0.08, 0.1]},
        ],
        "starts": [{"x": 1, "y": 1, "yaw": 0, "room": "room_0"}],
    }


def no_free_floor() -> dict:
    """One 0.6 x 0.6 m room filled by a 0.5 m cabinet: nowhere for the robot to stand."""
    return {"version": "2.0", "seed": 3,
            "rooms": [{"id": "room_0", "category": "kitchen",
                       "polygon": [[0, 0], [0.6, 0], [0.6, 0.6], [0, 0.6]]}],
            "walls": [], "doors": [],
            "furniture": [{"id": "furn_0", "category": "cabinet", "synset": "cabinet.n.01",
                           "room": "room_0", "center": [0.3, 0.3, 0.45],
                           "size": [0.5, 0.5, 0.9],
                           "affordances": ["container", "openable", "supporter"],
                           "state": "closed"}],
            "objects": [{"id": "obj_0", "category": "apple", "synset": "apple.n.01",
                         "parent": "furn_0", "relation": "inside", "room": "room_0",
                         "position": [0.3, 0.3, 0.3], "size": [0.08, 0.08, 0.08]}],
            "starts": []}


def with_closet(door_state: str = "open") -> dict:
    """:func:`two_rooms` with a 0.35 m x 0.6 m closet off the bedroom's north wall (x 6-6.35,
    y 4-4.6; too narrow for the robot), a door filling its opening, a hat on its shelf."""
    d = two_rooms()
    d["rooms"].append({"id": "room_2", "category": "closet",
                       "polygon": [[6, 4], [6.35, 4], [6.35, 4.6], [6, 4.6]]})
    d["walls"] = [w for w in d["walls"] if w["id"] != "wall_1"] + [
        {"id": "wall_1", "a": [0, 4], "b": [6, 4], "thickness": 0.1, "height": 2.5},
        {"id": "wall_6", "a": [6.35, 4], "b": [8, 4], "thickness": 0.1, "height": 2.5},
        {"id": "wall_7", "a": [6, 4], "b": [6, 4.6], "thickness": 0.05, "height": 2.5},
        {"id": "wall_8", "a": [6.35, 4], "b": [6.35, 4.6], "thickness": 0.05, "height": 2.5},
        {"id": "wall_9", "a": [6, 4.6], "b": [6.35, 4.6], "thickness": 0.05, "height": 2.5},
    ]
    d["doors"].append({"id": "door_1", "center": [6.175, 4], "width": 0.35, "yaw": 0.0,
                       "state": door_state, "rooms": ["room_1", "room_2"]})
    d["furniture"][1]["center"] = [5.0, 3.0, 0.375]  # the table, clear of the closet door
    d["objects"][1]["position"] = [5.0, 3.0, 0.8]
    d["furniture"].append({"id": "furn_2", "category": "shelf", "synset": "shelf.n.01",
                           "room": "room_2", "center": [6.175, 4.35, 0.5],
                           "size": [0.25, 0.2, 1.0], "yaw": 0, "affordances": ["supporter"],
                           "state": None})
    d["objects"].append({"id": "obj_2", "category": "hat", "synset": "hat.n.01",
                         "parent": "furn_2", "relation": "ontop", "room": "room_2",
                         "position": [6.175, 4.35, 1.05], "size": [0.1, 0.1, 0.1]})
    return d


def walled_off(d: dict, door: str) -> dict:
    """``d`` with the door ``door`` turned into wall: the rooms behind it cannot be entered."""
    out = {**d, "doors": [x for x in d["doors"] if x["id"] != door]}
    x = next(x for x in d["doors"] if x["id"] == door)
    (cx, cy), half = x["center"], x["width"] / 2
    a, b = ([cx, cy - half], [cx, cy + half]) if abs(math.sin(x["yaw"])) > 0.5 else \
        ([cx - half, cy], [cx + half, cy])
    out["walls"] = d["walls"] + [{"id": "wall_99", "a": a, "b": b, "thickness": 0.1,
                                  "height": 2.5}]
    return out
