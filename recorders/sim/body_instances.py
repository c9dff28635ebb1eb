"""The instance table: every PyBullet body of a house belongs to one log instance.

PyBullet multibodies have no names, and a container is several bodies (its carcass and
its door panels), so the simulator keeps a table body uid -> instance. Instance ids are the
small stable ints the log uses (``sgtool.Instances``), assigned in spec order, never raw
PyBullet uids, so the same house always gives the same ids:

1. the floor (``structure``, category "floor"),
2. the walls in spec order (``structure``, "wall"),
3. the doors in spec order (``door``, "door", openable),
4. one lintel per door, the wall piece above the door opening (``structure``, "wall"),
5. the furniture and containers in spec order (``furniture``),
6. the small objects in spec order (``object``, with parent instance and relation; the
   parent is a piece of furniture or, house spec 2, another small object).

0 is background (no body).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from sgtool.house.spec import HouseSpec

STRUCTURE, DOOR, FURNITURE, OBJECT = "structure", "door", "furniture", "object"


@dataclass(frozen=True)
class Instance:
    """One row of the log's instances table (its state lives in the simulation)."""

    id: int
    category: str
    kind: str
    spec_id: str | None = None
    synset: str | None = None
    affordances: tuple[str, ...] = ()
    parent: int | None = None
    relation: str | None = None

    @property
    def openable(self) -> bool:
        return self.kind == DOOR or "openable" in self.affordances

    def record(self, state: str | None) -> dict[str, Any]:
        """The ``sgtool.Instances`` item for this instance in ``state``."""
        return {
            "id": self.id, "category": self.category, "synset": self.synset,
            "kind": self.kind, "state": state, "affordances": list(self.affordances),
            "parent": self.parent, "relation": self.relation, "spec_id": self.spec_id,
        }


def instance_table(spec: HouseSpec) -> tuple[Instance, ...]:
    """The instances of ``spec`` with ids 1..N in the order of the module docstring."""
    out: list[Instance] = [Instance(1, "floor", STRUCTURE, None, "floor.n.01")]

    def nxt() -> int:
        return len(out) + 1

    for w in spec.walls:
        out.append(Instance(nxt(), "wall", STRUCTURE, w.id, "wall.n.01"))
    for d in spec.doors:
        out.append(Instance(nxt(), "door", DOOR, d.id, "door.n.01", ("openable",)))
    for _ in spec.doors:
        out.append(Instance(nxt(), "wall", STRUCTURE, None, "wall.n.01"))
    ids: dict[str, int] = {}
    for f in spec.furniture:
        ids[f.id] = nxt()
        out.append(Instance(nxt(), f.category, FURNITURE, f.id, f.synset,
                            tuple(f.affordances)))
    first = nxt()
    ids.update((o.id, first + k) for k, o in enumerate(spec.objects))
    for o in spec.objects:
        out.append(Instance(nxt(), o.category, OBJECT, o.id, o.synset, (),
                            ids[o.parent], o.relation))
    return tuple(out)


def initial_states(spec: HouseSpec) -> dict[str, str]:
    """spec id -> "open"/"closed" for every door and openable piece of furniture."""
    states = {d.id: d.state for d in spec.doors}
    for f in spec.furniture:
        if f.is_openable:
            states[f.id] = f.state or "closed"
    return states
