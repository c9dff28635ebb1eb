"""A small house written by hand in house spec 2.0, the way another tool would export one:
ids without running numbers, containment three objects deep, a lower shelf.

Two 4 m x 4 m rooms along x, kitchen [0, 4] and den [4, 8] (y in [0, 4]), an open door at
x = 4, y 1.5-2.4. Kitchen: a closed cabinet (1 m wide, 1 m high, a lower shelf 0.45 m up)
at (1, 0.35) with a vase on its top, a book on its lower shelf and, inside it, a closed
lidded box holding a closed tin holding a candy (candy in tin in box in cabinet); a counter
at (3, 3.6) with a bowl on top and an apple in the bowl. Den: an open bookcase (shelves at
0.3 and 0.8 m) with a mug on its lowest shelf. One start pose in the den.
"""

from __future__ import annotations

import math
from typing import Any


def _obj(oid: str, cat: str, parent: str, relation: str, room: str, pos: list[float],
         size: list[float], **extra: Any) -> dict[str, Any]:
    return {"id": oid, "category": cat, "synset": f"{cat}.n.01", "parent": parent,
            "relation": relation, "room": room, "position": pos, "size": size, **extra}


def nested_house() -> dict[str, Any]:
    walls = [((0, 0), (8, 0)), ((0, 4), (8, 4)), ((0, 0), (0, 4)), ((8, 0), (8, 4)),
             ((4, 0), (4, 1.5)), ((4, 2.4), (4, 4))]
    return {
        "version": "2.0", "seed": 3,
        "rooms": [
            {"id": "room_kitchen", "category": "kitchen",
             "polygon": [[0, 0], [4, 0], [4, 4], [0, 4]]},
            {"id": "room_den", "category": "living_room",
             "polygon": [[4, 0], [8, 0], [8, 4], [4, 4]]},
        ],
        "walls": [{"id": f"wall_{n}", "a": list(a), "b": list(b)}
                  for n, (a, b) in zip("abcdef", walls, strict=True)],
        "doors": [{"id": "door_main", "center": [4, 1.95], "width": 0.9, "yaw": math.pi / 2,
                   "state": "open", "rooms": ["room_kitchen", "room_den"]}],
        "furniture": [
            {"id": "furn_cabinet", "category": "cabinet", "synset": "cabinet.n.01",
             "room": "room_kitchen", "center": [1.0, 0.35, 0.5], "size": [1.0, 0.5, 1.0],
             "affordances": ["container", "openable", "supporter"], "state": "closed",
             "levels": [0.45]},
            {"id": "furn_counter", "category": "countertop", "synset": "countertop.n.01",
             "room": "room_kitchen", "center": [3.0, 3.6, 0.45], "size": [1.2, 0.6, 0.9],
             "affordances": ["supporter"]},
            {"id": "furn_bookcase", "category": "bookcase", "synset": "bookcase.n.01",
             "room": "room_den", "center": [6.0, 3.75, 0.8], "size": [0.8, 0.3, 1.6],
             "affordances": ["supporter"], "levels": [0.3, 0.8]},
        ],
        "objects": [
            _obj("obj_vase", "vase", "furn_cabinet", "ontop", "room_kitchen",
                 [1.2, 0.35, 1.1], [0.12, 0.12, 0.2]),
            _obj("obj_book", "book", "furn_cabinet", "ontop", "room_kitchen",
                 [0.7, 0.35, 0.475], [0.2, 0.15, 0.05]),
            # listed before its parent: parents may come later in the list
            _obj("obj_tin", "tin", "obj_box", "inside", "room_kitchen",
                 [1.0, 0.35, 0.1], [0.1, 0.1, 0.08],
                 affordances=["container", "openable"], state="closed"),
            _obj("obj_box", "box", "furn_cabinet", "inside", "room_kitchen",
                 [1.0, 0.35, 0.1], [0.3, 0.2, 0.15],
                 affordances=["openable", "container"], state="closed"),
            _obj("obj_candy", "candy", "obj_tin", "inside", "room_kitchen",
                 [1.0, 0.35, 0.1], [0.03, 0.03, 0.03]),
            _obj("obj_bowl", "bowl", "furn_counter", "ontop", "room_kitchen",
                 [3.0, 3.6, 0.94], [0.2, 0.2, 0.08], affordances=["container"]),
            _obj("obj_apple", "apple", "obj_bowl", "inside", "room_kitchen",
                 [3.0, 3.6, 0.94], [0.06, 0.06, 0.06]),
            _obj("obj_mug", "mug", "furn_bookcase", "ontop", "room_den",
                 [6.0, 3.75, 0.35], [0.08, 0.08, 0.1]),
        ],
        "starts": [{"x": 6.0, "y": 1.0, "yaw": 0, "room": "room_den"}],
    }
