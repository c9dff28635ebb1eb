"""A small two-room house for the simulator and recorder tests.

Living room [0, 4] x [0, 3] and kitchen [4, 7] x [0, 3], walls 0.1 m thick, 2.5 m high,
joined by door_0 in the wall x = 4 (y 1.05-1.95), closed. Living room: a closed cabinet
against the south wall (front facing +y, into the room) with a mug inside and a book on
top, a table in the open with an apple on it. Kitchen: a closed refrigerator against the
east wall (yaw pi/2: its front faces -x, into the room) with milk inside, an open-fronted
shelf against the north wall (yaw pi: front faces -y) with a bowl inside. Starts: one
per room.
"""

from __future__ import annotations

import math

from sgtool.house.io import load_house
from sgtool.house.spec import HouseSpec


def _wall(i: int, a: list[float], b: list[float]) -> dict:
    return {"id": f"wall_{i}", "a": a, "b": b, "thickness": 0.1, "height": 2.5}


def _furn(i: int, cat: str, room: str, center: list[float], size: list[float], yaw: float,
          affordances: list[str], state: str | None) -> dict:
    return {"id": f"furn_{i}", "category": cat, "synset": f"{cat}.n.01", "room": room,
            "center": center, "size": size, "yaw": yaw, "affordances": affordances,
            "state": state}


def _obj(i: int, cat: str, parent: str, relation: str, room: str, pos: list[float],
         size: list[float]) -> dict:
    return {"id": f"obj_{i}", "category": cat, "synset": f"{cat}.n.01", "parent": parent,
            "relation": relation, "room": room, "position": pos, "size": size}


def small_house_dict(door: str = "closed") -> dict:
    return {
        "version": "1.0", "seed": 5,
        "rooms": [
            {"id": "room_0", "category": "living_room",
             "polygon": [[0, 0], [4, 0], [4, 3], [0, 3]]},
            {"id": "room_1", "category": "kitchen",
             "polygon": [[4, 0], [7, 0], [7, 3], [4, 3]]},
        ],
        "walls": [
            _wall(0, [0, 0], [7, 0]), _wall(1, [0, 3], [7, 3]), _wall(2, [0, 0], [0, 3]),
            _wall(3, [7, 0], [7, 3]), _wall(4, [4, 0], [4, 1.05]), _wall(5, [4, 1.95], [4, 3]),
        ],
        "doors": [
            {"id": "door_0", "center": [4, 1.5], "width": 0.9, "yaw": math.pi / 2,
             "state": door, "rooms": ["room_0", "room_1"]},
        ],
        "furniture": [
            _furn(0, "cabinet", "room_0", [1.0, 0.35, 0.45], [0.8, 0.5, 0.9], 0.0,
                  ["container", "openable", "supporter"], "closed"),
            _furn(1, "table", "room_0", [2.5, 2.2, 0.375], [1.0, 0.6, 0.75], 0.0,
                  ["supporter"], None),
            _furn(2, "refrigerator", "room_1", [6.5, 1.5, 0.9], [0.7, 0.7, 1.8], math.pi / 2,
                  ["container", "openable"], "closed"),
            _furn(3, "shelf", "room_1", [5.5, 2.7, 0.6], [0.8, 0.4, 1.2], math.pi,
                  ["container"], None),
        ],
        "objects": [
            _obj(0, "mug", "furn_0", "inside", "room_0", [1.0, 0.35, 0.3], [0.12, 0.12, 0.1]),
            _obj(1, "book", "furn_0", "ontop", "room_0", [1.0, 0.35, 0.95], [0.2, 0.15, 0.1]),
            _obj(2, "apple", "furn_1", "ontop", "room_0", [2.5, 2.2, 0.8], [0.1, 0.1, 0.1]),
            _obj(3, "milk", "furn_2", "inside", "room_1", [6.5, 1.5, 1.0], [0.1, 0.1, 0.2]),
            _obj(4, "bowl", "furn_3", "inside", "room_1", [5.5, 2.7, 0.5], [0.15, 0.15, 0.08]),
        ],
        "starts": [{"x": 2.0, "y": 1.2, "yaw": 0.0, "room": "room_0"},
                   {"x": 5.3, "y": 1.2, "yaw": math.pi, "room": "room_1"}],
    }


def small_house(door: str = "closed") -> HouseSpec:
    return load_house(small_house_dict(door))
