"""Typical real-world sizes (metres) of furniture and small objects, and how furniture is
placed in a room.

``bddl`` says which furniture a room holds and what sits in or on it, but not how big
things are, so the generator takes the dimensions from here: common retail sizes of
household furniture (width along the wall it stands against, depth away from the wall,
height), and rough sizes of small objects by what they are (WordNet hypernyms: a
``bottle__of__wine.n.01`` is a grocery, a ``hardback.n.01`` a book, ...). Unknown
categories get a neutral default; the generator jitters every size by a few percent so two
cabinets are not identical.
"""

from __future__ import annotations

from collections.abc import Mapping
from types import MappingProxyType

from sgtool.datasets.synsets import synset_catalogue

Size = tuple[float, float, float]

# synset -> (width along the wall, depth, height)
FURNITURE_SIZES: Mapping[str, Size] = MappingProxyType({
    "cabinet.n.01": (0.8, 0.6, 0.9),
    "cabinet.n.03": (0.45, 0.5, 1.8),  # locker
    "electric_refrigerator.n.01": (0.8, 0.75, 1.8),
    "deep-freeze.n.02": (0.9, 0.7, 0.9),
    "countertop.n.01": (1.6, 0.65, 0.9),
    "sink.n.01": (0.8, 0.6, 0.9),
    "oven.n.01": (0.6, 0.6, 0.9),
    "stove.n.01": (0.6, 0.6, 0.9),
    "dishwasher.n.01": (0.6, 0.6, 0.85),
    "microwave.n.02": (0.5, 0.4, 0.3),
    "washer.n.03": (0.6, 0.6, 0.85),
    "clothes_dryer.n.01": (0.6, 0.6, 0.85),
    "bookcase.n.01": (0.9, 0.35, 1.9),
    "shelf.n.01": (1.0, 0.35, 1.6),
    "wardrobe.n.01": (1.2, 0.6, 2.0),
    "bed.n.01": (1.6, 2.0, 0.55),
    "crib.n.01": (0.7, 1.3, 0.9),
    "sofa.n.01": (2.0, 0.9, 0.85),
    "armchair.n.01": (0.85, 0.85, 0.9),
    "straight_chair.n.01": (0.45, 0.5, 0.9),
    "swivel_chair.n.01": (0.6, 0.6, 1.0),
    "eames_chair.n.01": (0.8, 0.8, 0.8),
    "folding_chair.n.01": (0.45, 0.5, 0.85),
    "rocking_chair.n.01": (0.65, 0.9, 1.0),
    "highchair.n.01": (0.55, 0.6, 1.0),
    "bench.n.01": (1.2, 0.4, 0.45),
    "coffee_table.n.01": (1.1, 0.6, 0.45),
    "breakfast_table.n.01": (1.2, 0.8, 0.75),
    "kitchen_table.n.01": (1.2, 0.8, 0.75),
    "pedestal_table.n.01": (0.9, 0.9, 0.75),
    "console_table.n.01": (1.1, 0.4, 0.8),
    "desk.n.01": (1.3, 0.7, 0.75),
    "stand.n.04": (0.5, 0.4, 0.55),
    "conference_table.n.01": (2.4, 1.1, 0.75),
    "gaming_table.n.01": (1.0, 1.0, 0.75),
    "pool_table.n.01": (2.5, 1.4, 0.8),
    "floor_lamp.n.01": (0.4, 0.4, 1.6),
    "toilet.n.02": (0.4, 0.7, 0.8),
    "shower_stall.n.01": (0.9, 0.9, 2.1),
    "shower.n.01": (0.9, 0.9, 2.1),
    "bathtub.n.01": (1.7, 0.75, 0.6),
    "piano.n.01": (1.5, 0.6, 1.3),
    "wood_fireplace.n.01": (1.2, 0.5, 1.1),
    "gas_fireplace.n.01": (1.2, 0.5, 1.1),
    "television_receiver.n.01": (1.1, 0.25, 0.65),
    "grandfather_clock.n.01": (0.5, 0.3, 2.0),
    "hallstand.n.01": (0.5, 0.5, 1.8),
    "chaise_longue.n.01": (0.7, 1.8, 0.8),
    "booth.n.01": (1.4, 0.7, 1.0),
    "shoe_rack.n.01": (0.8, 0.3, 0.8),
    "sauna_heater.n.01": (0.5, 0.4, 0.8),
    "chest_of_drawers.n.01": (1.0, 0.5, 1.0),
})
DEFAULT_FURNITURE_SIZE: Size = (0.8, 0.6, 0.8)

# Pieces that stand on another piece's top rather than on the floor, with what may carry
# them (ancestor synsets).
STACKED_ON: Mapping[str, tuple[str, ...]] = MappingProxyType({
    "microwave.n.02": ("countertop.n.01", "cabinet.n.01"),
    "television_receiver.n.01": ("console_table.n.01", "cabinet.n.01", "stand.n.04",
                                 "chest_of_drawers.n.01"),
})
# Pieces placed in the open part of a room (tables), chairs placed around a table.
CENTRAL: frozenset[str] = frozenset({
    "coffee_table.n.01", "breakfast_table.n.01", "kitchen_table.n.01",
    "pedestal_table.n.01", "conference_table.n.01", "gaming_table.n.01", "pool_table.n.01",
})
SEATS: frozenset[str] = frozenset({
    "straight_chair.n.01", "swivel_chair.n.01", "folding_chair.n.01", "highchair.n.01",
})
# How many of one category a generated room may hold at most.
MAX_PER_ROOM: Mapping[str, int] = MappingProxyType({
    "cabinet.n.01": 5, "straight_chair.n.01": 6, "armchair.n.01": 2, "shelf.n.01": 2,
    "countertop.n.01": 2, "bookcase.n.01": 2, "sink.n.01": 1, "toilet.n.02": 1,
    "shower_stall.n.01": 1, "cabinet.n.03": 4, "bench.n.01": 2, "stand.n.04": 2,
    "sofa.n.01": 2, "floor_lamp.n.01": 2, "breakfast_table.n.01": 1,
    "pedestal_table.n.01": 1, "coffee_table.n.01": 1, "bed.n.01": 1,
})
DEFAULT_MAX_PER_ROOM = 1

# ancestor synset -> small-object size; the first ancestor found (in the object's own
# hypernym order, nearest first) wins
OBJECT_SIZES_BY_ANCESTOR: Mapping[str, Size] = MappingProxyType({
    "book.n.02": (0.22, 0.15, 0.04),
    "bottle.n.01": (0.08, 0.08, 0.28),
    "grocery.n.02": (0.12, 0.08, 0.2),
    "box.n.01": (0.2, 0.15, 0.12),
    "carton.n.02": (0.2, 0.15, 0.2),
    "plate.n.04": (0.25, 0.25, 0.03),
    "bowl.n.01": (0.16, 0.16, 0.07),
    "cup.n.01": (0.09, 0.09, 0.1),
    "glass.n.02": (0.08, 0.08, 0.13),
    "pot.n.01": (0.26, 0.26, 0.16),
    "pan.n.01": (0.28, 0.28, 0.06),
    "edible_fruit.n.01": (0.08, 0.08, 0.08),
    "vegetable.n.01": (0.1, 0.1, 0.1),
    "garment.n.01": (0.3, 0.25, 0.05),
    "clothing.n.01": (0.3, 0.25, 0.05),
    "footwear.n.02": (0.28, 0.11, 0.1),
    "towel.n.01": (0.3, 0.2, 0.06),
    "cutlery.n.02": (0.2, 0.03, 0.02),
    "writing_implement.n.01": (0.15, 0.02, 0.02),
    "plaything.n.01": (0.15, 0.15, 0.15),
    "lamp.n.02": (0.25, 0.25, 0.45),
    "bag.n.04": (0.35, 0.15, 0.3),
    "bag.n.06": (0.3, 0.15, 0.3),
    "container.n.01": (0.2, 0.2, 0.2),
    "device.n.01": (0.2, 0.15, 0.1),
})
DEFAULT_OBJECT_SIZE: Size = (0.12, 0.12, 0.12)


def furniture_size(synset: str) -> Size:
    return FURNITURE_SIZES.get(synset, DEFAULT_FURNITURE_SIZE)


def object_size(synset: str) -> Size:
    """Size of a small object from the nearest ancestor with a known size."""
    cat = synset_catalogue()
    # breadth-first over the hypernyms so the nearest ancestor wins
    frontier = [synset]
    seen = {synset}
    while frontier:
        nxt = []
        for s in frontier:
            if s in OBJECT_SIZES_BY_ANCESTOR:
                return OBJECT_SIZES_BY_ANCESTOR[s]
            info = cat.get(s)
            for h in (info.hypernyms if info else ()):
                if h not in seen:
                    seen.add(h)
                    nxt.append(h)
        frontier = nxt
    return DEFAULT_OBJECT_SIZE
