"""The instance table of a log: what each instance id of the segmentation images is.

The simulator gives ground-truth instance segmentation (as MoMa-LLM's ground-truth semantic
camera does), so semantics come from ids: every non-zero id of a frame's ``ids`` image is a
key of this table. It mirrors the log's ``sgtool.Instances`` record (see
:mod:`sgtool.log.schemas`); :func:`instances_from_record` reads one.

``kind`` decides what the scene graph makes of an instance: ``object`` and ``furniture``
become :class:`~sgtool.scenegraph.graph.ObjectNode`, ``door`` a
:class:`~sgtool.scenegraph.graph.DoorNode` (and door evidence for room segmentation),
``structure`` (walls, floor) is geometry only.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from typing import Any

from sgtool.vocabulary import (
    INSTANCE_KINDS,
    OPEN_STATES,
    RELATIONS,
    InstanceKind,
    OpenState,
    Relation,
)

KINDS: tuple[InstanceKind, ...] = INSTANCE_KINDS


@dataclass(frozen=True)
class InstanceInfo:
    """One instance. ``parent``/``relation`` place nested objects ("inside"/"ontop" another
    instance); ``state`` is "open"/"closed" for openable things, None otherwise."""

    id: int
    category: str
    kind: InstanceKind = "object"
    state: OpenState | None = None
    affordances: tuple[str, ...] = ()
    parent: int | None = None
    relation: Relation | None = None
    synset: str | None = None
    spec_id: str | None = None

    def __post_init__(self) -> None:
        if self.kind not in KINDS:
            raise ValueError(f"instance {self.id}: kind must be one of {KINDS}, got {self.kind!r}")
        if self.state is not None and self.state not in OPEN_STATES:
            raise ValueError(
                f"instance {self.id}: state must be open/closed/None, got {self.state!r}"
            )
        if self.relation is not None and self.relation not in RELATIONS:
            raise ValueError(
                f"instance {self.id}: relation must be inside/ontop/None, got {self.relation!r}"
            )

    def to_record(self) -> dict[str, Any]:
        """The item of an ``sgtool.Instances`` record."""
        return {
            "id": int(self.id), "category": self.category, "kind": self.kind,
            "state": self.state, "affordances": list(self.affordances),
            "parent": self.parent, "relation": self.relation, "synset": self.synset,
            "spec_id": self.spec_id,
        }



def instance_from_record(item: Mapping[str, Any]) -> InstanceInfo:
    parent = item.get("parent")
    return InstanceInfo(
        id=int(item["id"]),
        category=str(item["category"]),
        kind=item.get("kind", "object"),
        state=item.get("state"),
        affordances=tuple(sorted(str(a) for a in item.get("affordances") or ())),
        parent=None if parent is None else int(parent),
        relation=item.get("relation"),
        synset=item.get("synset"),
        spec_id=item.get("spec_id"),
    )


def instances_from_record(record: Mapping[str, Any]) -> dict[int, InstanceInfo]:
    """Instance id -> info from an ``sgtool.Instances`` record ``{"instances": [...]}``."""
    return table_of(instance_from_record(x) for x in record.get("instances", ()))


def table_of(infos: Iterable[InstanceInfo]) -> dict[int, InstanceInfo]:
    """An instance table in id order (ids must be unique and non-zero: 0 means none)."""
    out: dict[int, InstanceInfo] = {}
    for info in sorted(infos, key=lambda i: i.id):
        if info.id == 0:
            raise ValueError("instance id 0 is reserved for 'no instance'")
        if info.id in out:
            raise ValueError(f"instance id {info.id} appears twice")
        out[info.id] = info
    return out
