"""A tiny hand-made BEHAVIOR-1K knowledge whose relational sets can be checked by hand."""

from __future__ import annotations

from sgtool.datasets.knowledge import InRoomRecord, RelationRecord, RoomInventory, build_knowledge

FRIDGE = "electric_refrigerator.n.01"
CABINET = "cabinet.n.01"
SINK = "sink.n.01"
TOILET = "toilet.n.02"
PLATE = "plate.n.04"
MILK = "milk.n.01"
APPLE = "apple.n.01"


def tiny():
    """Two kitchens and a bathroom scanned; three activities."""
    rooms = [
        RoomInventory("A", "kitchen_0", "kitchen", ((FRIDGE, 1), (CABINET, 2), (SINK, 1))),
        RoomInventory("B", "kitchen_0", "kitchen", ((FRIDGE, 1), (CABINET, 1))),
        RoomInventory("A", "bathroom_0", "bathroom", ((SINK, 1), (TOILET, 1), (CABINET, 1))),
    ]
    rels = [
        RelationRecord("cook", APPLE, "inside", FRIDGE, "init", "kitchen"),
        RelationRecord("cook", PLATE, "inside", CABINET, "init", "kitchen"),
        RelationRecord("wash", PLATE, "inside", SINK, "goal", "kitchen"),
        RelationRecord("wash", PLATE, "inside", CABINET, "init", "kitchen"),
        RelationRecord("party", PLATE, "ontop", CABINET, "init", "dining_room"),
    ]
    inroom = [InRoomRecord("cook", FRIDGE, "kitchen"), InRoomRecord("wash", SINK, "kitchen"),
              InRoomRecord("party", CABINET, "dining_room")]
    return build_knowledge(["A", "B"], ["cook", "wash", "party"], rooms, rels, inroom)
