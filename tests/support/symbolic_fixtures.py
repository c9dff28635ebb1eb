"""A hand-built three-room house for the symbolic benchmark tests.

Three 4 m x 4 m rooms in a row along x: kitchen [0, 4], living room [4, 8], bedroom
[8, 12] (y in [0, 4]). Door 0 (kitchen-living room, x = 4, y 1.5-2.4) is open; door 1
(living room-bedroom, x = 8, same span) is closed. The kitchen's furniture stands in two
corners, so it has two regions: a fridge (closed, apple inside) and a cabinet (closed,
spoon inside) near (1, 0.4); a countertop (cup on top) and a shelf (book inside, not
openable) near (3, 3.6). The living room has a sofa (nothing to explore) and a coffee table
(remote control on top); the bedroom a closed wardrobe with a sweater inside.
"""

from __future__ import annotations

import math


def _wall(i: int, a: list[float], b: list[float]) -> dict:
    return {"id": f"wall_{i}", "a": a, "b": b, "thickness": 0.1, "height": 2.5}


def _furn(i: int, cat: str, synset: str, room: str, center: list[float], size: list[float],
          affordances: list[str], state: str | None) -> dict:
    return {"id": f"furn_{i}", "category": cat, "synset": synset, "room": room,
            "center": center, "size": size, "yaw": 0, "affordances": affordances,
            "state": state}


def _obj(i: int, cat: str, parent: str, relation: str, room: str, pos: list[float]) -> dict:
    return {"id": f"obj_{i}", "category": cat, "synset": f"{cat.replace(' ', '_')}.n.01",
            "parent": parent, "relation": relation, "room": room, "position": pos,
            "size": [0.08, 0.08, 0.08]}


def three_rooms(door1: str = "closed") -> dict:
    return {
        "version": "1.0", "seed": 11,
        "rooms": [
            {"id": "room_0", "category": "kitchen",
             "polygon": [[0, 0], [4, 0], [4, 4], [0, 4]]},
            {"id": "room_1", "category": "living_room",
             "polygon": [[4, 0], [8, 0], [8, 4], [4, 4]]},
            {"id": "room_2", "category": "bedroom",
             "polygon": [[8, 0], [12, 0], [12, 4], [8, 4]]},
        ],
        "walls": [
            _wall(0, [0, 0], [12, 0]), _wall(1, [0, 4], [12, 4]), _wall(2, [0, 0], [0, 4]),
            _wall(3, [12, 0], [12, 4]), _wall(4, [4, 0], [4, 1.5]), _wall(5, [4, 2.4], [4, 4]),
            _wall(6, [8, 0], [8, 1.5]), _wall(7, [8, 2.4], [8, 4]),
        ],
        "doors": [
            {"id": "door_0", "center": [4, 1.95], "width": 0.9, "yaw": math.pi / 2,
             "state": "open", "rooms": ["room_0", "room_1"]},
            {"id": "door_1", "center": [8, 1.95], "width": 0.9, "yaw": math.pi / 2,
             "state": door1, "rooms": ["room_1", "room_2"]},
        ],
        "furniture": [
            _furn(0, "refrigerator", "electric_refrigerator.n.01", "room_0", [0.5, 0.45, 0.9],
                  [0.8, 0.7, 1.8], ["container", "openable"], "closed"),
            _furn(1, "cabinet", "cabinet.n.01", "room_0", [1.4, 0.35, 0.45], [0.8, 0.5, 0.9],
                  ["container", "openable", "supporter"], "closed"),
            _furn(2, "countertop", "countertop.n.01", "room_0", [3.5, 3.6, 0.45],
                  [0.8, 0.6, 0.9], ["supporter"], None),
            _furn(3, "shelf", "shelf.n.01", "room_0", [2.6, 3.7, 0.9], [0.8, 0.4, 1.8],
                  ["container"], None),
            _furn(4, "sofa", "sofa.n.01", "room_1", [6.0, 3.5, 0.4], [1.8, 0.8, 0.8], [], None),
            _furn(5, "coffee table", "coffee_table.n.01", "room_1", [6.0, 0.8, 0.2],
                  [1.0, 0.5, 0.4], ["supporter"], None),
            _furn(6, "wardrobe", "wardrobe.n.01", "room_2", [11.6, 3.0, 1.0], [0.6, 1.2, 2.0],
                  ["container", "openable"], "closed"),
        ],
        "objects": [
            _obj(0, "apple", "furn_0", "inside", "room_0", [0.5, 0.45, 1.0]),
            _obj(1, "spoon", "furn_1", "inside", "room_0", [1.4, 0.35, 0.3]),
            _obj(2, "cup", "furn_2", "ontop", "room_0", [3.5, 3.6, 0.94]),
            _obj(3, "book", "furn_3", "inside", "room_0", [2.6, 3.7, 1.0]),
            _obj(4, "remote control", "furn_5", "ontop", "room_1", [6.0, 0.8, 0.44]),
            _obj(5, "sweater", "furn_6", "inside", "room_2", [11.6, 3.0, 1.2]),
        ],
        "starts": [{"x": 2.0, "y": 2.0, "yaw": 0, "room": "room_0"}],
    }
