"""Room-type evidence for the scene-graph builder: room classifiers by name.

``containment`` is the distilled model shipped with sgtool
(:class:`~sgtool.semantics.room_classification.ContainmentRoomClassifier`); ``frequency`` is
naive Bayes over the BEHAVIOR-1K training scenes' room inventories, built here because it
reads the knowledge, with the containment model for a room none of whose categories the
inventories name (the default: ``benchmarks/room_classifiers.py`` compares them); ``llm``
is MoMa-LLM's room classification
(:class:`~sgtool.semantics.room_classification.LlmRoomClassifier`) over the containment
model's room types, with the containment model as its fallback, asked through the chat
client the caller gives (an endpoint, or a transcript replayed offline); ``none`` leaves rooms
unclassified.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from typing import Any

from sgtool.datasets.generator import HOUSE_ROOM_TYPES
from sgtool.datasets.split import is_household_scene, training_knowledge
from sgtool.errors import SgtoolError
from sgtool.scenegraph.build_options import CLASSIFIERS
from sgtool.scenegraph.categories import FrequencyRoomClassifier, RoomClassifier
from sgtool.semantics.room_classification import ContainmentRoomClassifier, LlmRoomClassifier


def frequency_room_classifier(room_types: Iterable[str] | None = None, alpha: float = 1.0,
                              small_objects: bool = False,
                              fallback: RoomClassifier | None = None
                              ) -> FrequencyRoomClassifier:
    """A :class:`FrequencyRoomClassifier` from
    :func:`sgtool.datasets.split.training_knowledge`: per room type, in how
    many rooms of the household training scenes each category occurs (document
    frequency: a kitchen's eleven cabinets count once, so one category cannot swamp
    the evidence), restricted to ``room_types`` (default: the room types the house
    generator uses). ``small_objects`` adds the activity-derived small-object counts
    per room type. The small-object counts are off by default: they lowered the room
    accuracy on evaluation-split houses, as raw counts did against document frequencies
    (``docs/experiments/moved-from-docstrings.md``). ``fallback`` answers for a room none of
    whose categories the table names."""
    k = training_knowledge()
    if room_types is None:
        room_types = (*HOUSE_ROOM_TYPES, "corridor")
    wanted = set(room_types)
    table: dict[str, dict[str, float]] = {r: {} for r in sorted(wanted)}
    for inv in k.rooms:
        if inv.room_type not in wanted or not is_household_scene(inv.scene):
            continue
        row = table[inv.room_type]
        for name in sorted({k.name(s) for s, _ in inv.items
                            if k.kind(s) in ("furniture", "object")}):
            row[name] = row.get(name, 0.0) + 1.0
    if small_objects:
        for room, items in k.room_objects.items():
            if room not in wanted:
                continue
            row = table[room]
            for synset, n in items:
                name = k.name(synset)
                row[name] = row.get(name, 0.0) + float(n)
    table = {r: row for r, row in table.items() if row}
    return FrequencyRoomClassifier(table, alpha=alpha, fallback=fallback)


class LlmClassifierError(SgtoolError):
    """``llm`` was asked for without a chat client."""


def make_classifier(name: str, client: Any | None = None, *, constraint: str = "auto",
                    on_exchange: Callable[[dict], None] | None = None,
                    timeout_s: float = 60.0) -> RoomClassifier | None:
    """The room classifier a replay or a live builder uses, by name (``CLASSIFIERS``).
    ``llm`` needs ``client`` (:mod:`sgtool.llm.client`, or a
    :class:`~sgtool.llm.recorded.ReplayChatClient`); ``constraint``, ``on_exchange`` (called
    with every exchange record) and ``timeout_s`` (per request) are its options."""
    if name == "containment":
        return ContainmentRoomClassifier()
    if name == "frequency":
        return frequency_room_classifier(fallback=ContainmentRoomClassifier())
    if name == "llm":
        if client is None:
            raise LlmClassifierError(
                "the llm room classifier needs an endpoint or a recorded transcript "
                "(sgtool replay --classifier llm --llm-base-url URL | --llm-replay FILE)")
        learned = ContainmentRoomClassifier()
        return LlmRoomClassifier(client, learned.room_types, constraint=constraint,
                                 fallback=learned, on_exchange=on_exchange,
                                 timeout_s=timeout_s)
    if name == "none":
        return None
    raise SgtoolError(f"unknown room classifier {name!r}; one of {', '.join(CLASSIFIERS)}")
