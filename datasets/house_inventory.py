"""What the house generator furnishes from, per knowledge split: the furniture rows of each
room type over the split's household scenes, and how often each room type occurs there."""

from __future__ import annotations

import functools
from collections import Counter
from dataclasses import dataclass

from sgtool.datasets.house_plan import HOUSE_ROOM_TYPES
from sgtool.datasets.knowledge import FurnitureFreq, Knowledge, build_knowledge
from sgtool.datasets.split import is_household_scene, knowledge_for

# shop and school fittings that some room inventories hold but a home generator skips
NOT_IN_HOMES = frozenset({
    "shopping_cart.n.01", "checkout.n.03", "cash_register.n.01", "grocery_shelf.n.01",
    "grocery_fridge.n.01", "display_panel.n.01", "blackboard.n.01",
})


@dataclass(frozen=True)
class Inventory:
    """One split's knowledge, its furniture rows per room type (household scenes first,
    shop fittings dropped) and room-type weights (household rooms of each type)."""

    knowledge: Knowledge
    furniture: dict[str, tuple[FurnitureFreq, ...]]
    type_weights: dict[str, float]


@functools.cache
def house_inventory(split: str) -> Inventory:
    """The :class:`Inventory` of ``split`` ("eval" or "train"), cached."""
    k = knowledge_for(split)
    household = [r for r in k.rooms if is_household_scene(r.scene)]
    kh = build_knowledge(k.scenes, (), household, (), ())
    furniture: dict[str, tuple[FurnitureFreq, ...]] = {}
    for rt in HOUSE_ROOM_TYPES + ("corridor",):
        rows = kh.room_furniture.get(rt) or k.room_furniture.get(rt) or ()
        furniture[rt] = tuple(f for f in rows if f.synset not in NOT_IN_HOMES)
    counts = Counter(r.room_type for r in household)
    weights = {rt: float(counts.get(rt, 0)) for rt in HOUSE_ROOM_TYPES}
    return Inventory(k, furniture, weights)
