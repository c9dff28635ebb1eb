"""A hand-written check of room priors on everyday objects outside BEHAVIOR-1K's vocabulary.

The distilled priors are trained and judged on BEHAVIOR-1K names; a user asks for "a pot
holder" or "sticky notes". :data:`EVERYDAY_ROOMS` lists everyday objects, none of them a
query name of the knowledge (neither a training query of the shipped priors nor any name of
the evaluation part, compared by :func:`~sgtool.semantics.text.category_text`; the test
checks it), each with the room type a person would search first, chosen where that first
room is not in doubt (a pot holder is in the kitchen; a hair dryer, a slipper or a toy,
which may live in two rooms, is left out). Room types are spelled as in the priors'
``room_types`` metadata.

:func:`room_check` scores any :class:`~sgtool.semantics.priors.RelationScorer` (the learned
containment model, the cosine baseline, the novelty blend of
:mod:`sgtool.planning.calibration`, a user's own priors) on it: the share of objects whose
top-scored room among ``rooms`` is the listed one (top-1 accuracy). The rooms to choose from
are the priors' room types that the learned model can score
(:func:`scoreable_room_types`: what a planner ranks), the same for every scorer compared.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from sgtool.semantics.priors import RelationScorer, can_score_room
from sgtool.semantics.text import category_text


@dataclass(frozen=True)
class EverydayObject:
    name: str
    room: str  # the room type a person searches first (priors' room_types spelling)


def _objects(room: str, names: str) -> tuple[EverydayObject, ...]:
    return tuple(EverydayObject(n.strip(), room) for n in names.split(",") if n.strip())


EVERYDAY_ROOMS: tuple[EverydayObject, ...] = (
    _objects("bathroom", "bath mat, shower curtain, shower gel, loofah, toilet brush, "
                         "toilet paper roll, dental floss, mouthwash, shaving cream, "
                         "cotton swabs, bubble bath, toothbrush holder, washcloth, "
                         "toilet plunger")
    + _objects("kitchen", "oven mitt, potato peeler, can opener, dish soap, cutting board, "
                          "rolling pin, baking sheet, garlic press, cheese grater, tea kettle, "
                          "pot holder, salad spinner, egg beater, pizza cutter, "
                          "ice cream scoop, dish towel")
    + _objects("bedroom", "pillowcase, duvet, bedspread, nightgown, pajamas, sleep mask, "
                          "mattress pad, nightstand lamp, jewelry box, pillow sham, comforter, "
                          "bedside lamp, dresser")
    + _objects("living_room", "tv remote, sofa cushion, coffee table book, fireplace poker, "
                              "game console, armchair cushion, television stand")
    + _objects("dining_room", "napkin ring, table runner, candelabra, china cabinet")
    + _objects("utility_room", "laundry detergent, dryer sheet, laundry basket, clothespin, "
                               "stain remover, washing powder, steam iron")
    + _objects("private_office", "paper clip, printer paper, filing cabinet, computer mouse, "
                                 "sticky notes, hole punch, file folder, desk organizer, "
                                 "ink cartridge, binder clip")
    + _objects("childs_room", "baby monitor, pacifier, baby blanket")
)


@dataclass(frozen=True)
class RoomMiss:
    name: str
    expected: str
    got: str


@dataclass(frozen=True)
class RoomCheck:
    """Top-1 room accuracy of one scorer on a check set."""

    scorer: str
    n: int
    hits: int
    misses: tuple[RoomMiss, ...]

    @property
    def accuracy(self) -> float:
        return self.hits / self.n if self.n else 0.0


def scoreable_room_types(priors: object) -> tuple[str, ...]:
    """The room types of ``priors`` (its ``room_types``) that it can score, sorted."""
    types = getattr(priors, "room_types", ())
    return tuple(sorted(t for t in types if can_score_room(priors, t)))


def top_room(scores: np.ndarray, rooms: Sequence[str]) -> str:
    """The best-scored room; ties go to the room listed first."""
    return rooms[int(np.argmax(scores))]


def room_check(scorer: RelationScorer, rooms: Sequence[str],
               objects: Sequence[EverydayObject] = EVERYDAY_ROOMS) -> RoomCheck:
    """Top-1 accuracy of ``scorer.rooms`` over ``rooms`` on ``objects`` (module doc)."""
    rooms = list(rooms)
    unknown = sorted({o.room for o in objects} - set(rooms))
    if unknown:
        raise ValueError(f"check rooms {unknown} are not among the rooms scored {rooms}")
    misses = []
    for o in objects:
        got = top_room(scorer.rooms(rooms, o.name), rooms)
        if category_text(got) != category_text(o.room):
            misses.append(RoomMiss(o.name, o.room, got))
    return RoomCheck(getattr(scorer, "name", type(scorer).__name__), len(objects),
                     len(objects) - len(misses), tuple(misses))
