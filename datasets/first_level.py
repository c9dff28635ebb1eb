"""Extra first-level pieces of a dense house (the ``symsearch`` preset, step 3 of
:mod:`sgtool.datasets.generator`): floor-standing holders - baskets, boxes, bins, hampers,
chests, side tables, shelves, carts - that SymSearch's InteriorGS scenes hold by the
hundred (SCOUT Table I: about 250 first-level objects per scene), each one a node a planner
can explore (a container or supporter), most of them empty.

Which holders a room gets: the holders of its room type's evidence - the containers and
supporters of the type's furniture rows (any frequency) and the floor-sized holders its real
rooms and activities put there (``Knowledge.room_objects``: a hamper in a bathroom, a toy
box in a child's room) - weighted :data:`EVIDENCE_WEIGHT`, plus :data:`GENERIC_HOLDERS`
(shelves, side tables, baskets, boxes, waste bins: any room of a home) weighted 1."""

from __future__ import annotations

from collections.abc import Mapping
from types import MappingProxyType

import numpy as np

from sgtool.datasets.house_inventory import Inventory
from sgtool.datasets.house_plan import PlanRoom
from sgtool.datasets.presets import GeneratorPreset
from sgtool.datasets.sizes import furniture_size

Size = tuple[float, float, float]

# floor-sized holders of the room-object evidence, with their footprint (w, d) and height
FLOOR_HOLDERS: Mapping[str, Size] = MappingProxyType({
    "wicker_basket.n.01": (0.45, 0.35, 0.35), "packing_box.n.02": (0.5, 0.4, 0.4),
    "ashcan.n.01": (0.35, 0.35, 0.5), "bucket.n.01": (0.3, 0.3, 0.35),
    "hamper.n.02": (0.5, 0.4, 0.6), "recycling_bin.n.01": (0.4, 0.4, 0.6),
    "carton.n.02": (0.45, 0.35, 0.35), "cedar_chest.n.01": (0.9, 0.45, 0.5),
    "toy_box.n.01": (0.7, 0.45, 0.45), "magazine_rack.n.01": (0.4, 0.3, 0.45),
    "compost_bin.n.01": (0.35, 0.35, 0.45), "serving_cart.n.01": (0.7, 0.45, 0.85),
    "cooler.n.01": (0.6, 0.4, 0.45), "hutch.n.01": (1.0, 0.45, 1.9),
    "sack.n.01": (0.4, 0.3, 0.5),
})
# holders any room of a home may have, whatever its evidence
GENERIC_HOLDERS: tuple[str, ...] = (
    "shelf.n.01", "stand.n.04", "wicker_basket.n.01", "packing_box.n.02", "ashcan.n.01",
)
EVIDENCE_WEIGHT = 2.0


def holder_size(synset: str) -> Size:
    return FLOOR_HOLDERS.get(synset) or furniture_size(synset)


def _holds(inv: Inventory, synset: str) -> bool:
    return bool({"container", "supporter"} & set(inv.knowledge.affordances.get(synset, ())))


def _pool(inv: Inventory, room_type: str) -> tuple[tuple[str, ...], tuple[float, ...]]:
    weights: dict[str, float] = {s: 1.0 for s in GENERIC_HOLDERS if _holds(inv, s)}
    evidence = [f.synset for f in inv.furniture.get(room_type, ())]
    evidence += [s for s, _ in inv.knowledge.room_objects.get(room_type, ())
                 if s in FLOOR_HOLDERS]
    for s in evidence:
        if _holds(inv, s):
            weights[s] = EVIDENCE_WEIGHT
    names = tuple(sorted(weights))
    return names, tuple(weights[s] for s in names)


def extra_holders(rng: np.random.Generator, room: PlanRoom, inv: Inventory,
                  preset: GeneratorPreset) -> list[str]:
    """The extra holders wanted in ``room``: ``preset.extra_holders_per_m2`` times its floor
    area (Poisson), drawn from the room type's pool (module doc), largest first."""
    names, w = _pool(inv, room.type)
    if not names or preset.extra_holders_per_m2 <= 0:
        return []
    area = room.rect.width * room.rect.height
    n = int(rng.poisson(area * preset.extra_holders_per_m2))
    p = np.asarray(w) / sum(w)
    out = [names[int(i)] for i in rng.choice(len(names), size=n, p=p)]
    return sorted(out, key=lambda s: (-holder_size(s)[0] * holder_size(s)[1], s))
