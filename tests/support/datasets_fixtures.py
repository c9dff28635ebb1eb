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
             "room": "room_0", "center": [0.5, 3.5, 0.9], "size": [0.8, 0.7, 1.8], "yaw": 0,
             "affordances": ["openable", "container"], "state": "closed"},
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
