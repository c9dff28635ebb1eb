"""A small house written by hand in the house spec format 1.0, as a user would write one:
three rooms in a row (kitchen, hall, bedroom), a door each side of the hall (the kitchen
one open, the bedroom one closed), five pieces of furniture, five small objects, and no
start poses (the benchmark gives it some)."""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

QUERIES = ("milk", "mug", "pillow", "sweater", "umbrella")


def _box(x0: float, y0: float, x1: float, y1: float) -> list[list[float]]:
    return [[x0, y0], [x1, y0], [x1, y1], [x0, y1]]


def _wall(i: int, a: tuple[float, float], b: tuple[float, float]) -> dict[str, Any]:
    return {"id": f"wall_{i}", "a": list(a), "b": list(b)}


def cottage() -> dict[str, Any]:
    """The house as a parsed JSON document (no ``seed``: the parser's default 0)."""
    walls = [((0, 0), (10, 0)), ((0, 4), (10, 4)), ((0, 0), (0, 4)), ((10, 0), (10, 4)),
             ((4, 0), (4, 1.55)), ((4, 2.45), (4, 4)), ((6, 0), (6, 1.55)), ((6, 2.45), (6, 4))]
    return {
        "version": "1.0",
        "rooms": [
            {"id": "room_kitchen", "category": "kitchen", "polygon": _box(0, 0, 4, 4)},
            {"id": "room_hall", "category": "corridor", "polygon": _box(4, 0, 6, 4)},
            {"id": "room_bed", "category": "bedroom", "polygon": _box(6, 0, 10, 4)},
        ],
        "walls": [_wall(i, a, b) for i, (a, b) in enumerate(walls)],
        "doors": [
            {"id": "door_kitchen", "center": [4, 2], "width": 0.9, "yaw": 1.5708,
             "state": "open", "rooms": ["room_kitchen", "room_hall"]},
            {"id": "door_bed", "center": [6, 2], "width": 0.9, "yaw": 1.5708,
             "state": "closed", "rooms": ["room_hall", "room_bed"]},
        ],
        "furniture": [
            _furniture("fridge", "room_kitchen", (0.5, 3.4, 0.9), (0.8, 0.7, 1.8), "closed",
                       yaw=math.pi),  # against the north wall, facing south
            _furniture("counter", "room_kitchen", (2.0, 0.4, 0.45), (1.6, 0.6, 0.9)),
            _furniture("bench", "room_hall", (5.0, 3.6, 0.25), (1.2, 0.4, 0.5)),
            _furniture("bed", "room_bed", (8.5, 2.0, 0.3), (2.0, 1.6, 0.6)),
            _furniture("wardrobe", "room_bed", (9.6, 3.5, 1.0), (0.8, 0.6, 2.0), "closed",
                       yaw=math.pi / 2),  # against the east wall, facing west
        ],
        "objects": [
            _object("milk", "fridge", "inside", "room_kitchen", (0.5, 3.4, 0.9), 0.2),
            _object("mug", "counter", "ontop", "room_kitchen", (2.0, 0.4, 0.95), 0.1),
            _object("umbrella", "bench", "ontop", "room_hall", (5.0, 3.6, 0.55), 0.1),
            _object("pillow", "bed", "ontop", "room_bed", (8.5, 2.0, 0.675), 0.15),
            _object("sweater", "wardrobe", "inside", "room_bed", (9.6, 3.5, 1.0), 0.1),
        ],
        "starts": [],
    }


def _furniture(name: str, room: str, center: tuple[float, float, float],
               size: tuple[float, float, float], state: str | None = None,
               yaw: float = 0.0) -> dict[str, Any]:
    """A piece; a container's front (local +y) faces the room: yaw = its direction - pi/2."""
    aff = ["container", "openable"] if state else ["supporter"]
    return {"id": f"furn_{name}", "category": name, "synset": f"{name}.n.01", "room": room,
            "center": list(center), "size": list(size), "yaw": yaw, "affordances": aff,
            "state": state}


def _object(name: str, parent: str, relation: str, room: str,
            position: tuple[float, float, float], height: float) -> dict[str, Any]:
    return {"id": f"obj_{name}", "category": name, "synset": f"{name}.n.01",
            "parent": f"furn_{parent}", "relation": relation, "room": room,
            "position": list(position), "size": [0.1, 0.1, height]}


def write_cottage(folder: Path, name: str = "cottage.json", **changes: Any) -> Path:
    """Write the house (with top-level ``changes``) as ``folder/name``."""
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / name
    path.write_text(json.dumps({**cottage(), **changes}, indent=1))
    return path
