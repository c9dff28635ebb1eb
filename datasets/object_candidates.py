"""Which small objects may go in or on a piece of furniture of a given room type, with
sampling weights (step 4 of :mod:`sgtool.datasets.generator`, "Small objects"): candidates
are admitted by relations of the split and weighed by the evidence of the piece's room
type only. The ``long_tail`` variant (the ``symsearch`` preset of
:mod:`sgtool.datasets.presets`) also admits categories whose home is the piece's room type
on a single source, and draws them evenly, a share of the draws going to categories unseen
in training."""

from __future__ import annotations

import functools
from collections import Counter
from dataclasses import dataclass

import numpy as np

from sgtool.datasets.split import knowledge_for, unseen_queries
from sgtool.datasets.synsets import ancestors, readable_name

# a category must be held by / put in rooms of
# the piece's room type by at least this many sources (real rooms + activities, the counts
# of Knowledge.room_objects) to be placed there
MIN_SUPPORT = 2
LOCAL_BONUS = 2  # weight of relating the object to this parent in this room type


@dataclass(frozen=True)
class _RoomEvidence:
    """Per room type of one split: how many real rooms of that type hold each small-object
    category, and how many activities put it in a room of that type."""

    rooms: dict[str, Counter[str]]  # room type -> synset -> rooms holding it
    n_rooms: Counter[str]  # room type -> rooms of that type
    acts: dict[str, Counter[str]]  # room type -> synset -> activities placing it there
    n_acts: Counter[str]  # room type -> activities placing any small object there


@functools.cache
def _room_evidence(split: str) -> _RoomEvidence:
    k = knowledge_for(split)
    rooms: dict[str, Counter[str]] = {}
    n_rooms: Counter[str] = Counter()
    for r in k.rooms:
        n_rooms[r.room_type] += 1
        c = rooms.setdefault(r.room_type, Counter())
        c.update(s for s, _ in r.items if k.kind(s) == "object")
    placed: set[tuple[str, str, str]] = set()  # (room type, synset, activity)
    for rel in k.relations:
        if rel.room_type is not None and k.kind(rel.child) == "object":
            placed.add((rel.room_type, rel.child, rel.activity))
    for ir in k.inroom:
        if k.kind(ir.synset) == "object":
            placed.add((ir.room_type, ir.synset, ir.activity))
    acts: dict[str, Counter[str]] = {}
    for rt, s, _ in placed:
        acts.setdefault(rt, Counter())[s] += 1
    n_acts = Counter({rt: len({a for t, _, a in placed if t == rt}) for rt in acts})
    return _RoomEvidence(rooms, n_rooms, acts, n_acts)


@functools.cache
def _home_support(split: str) -> dict[str, int]:
    """Small-object synset -> its support in the room type with the most evidence for it
    (real rooms of the type holding it + activities placing it there)."""
    ev = _room_evidence(split)
    best: Counter[str] = Counter()
    for rt in set(ev.rooms) | set(ev.acts):
        here = ev.rooms.get(rt, Counter()) + ev.acts.get(rt, Counter())
        for s, n in here.items():
            best[s] = max(best[s], n)
    return dict(best)


@functools.cache
def _novel(split: str) -> frozenset[str]:
    """Readable names that ``split`` can place and the other split never mentions (for the
    evaluation split: :func:`sgtool.datasets.split.unseen_queries`; none for training)."""
    return frozenset(unseen_queries()) if split == "eval" else frozenset()


def has_novel(split: str, names: tuple[str, ...]) -> bool:
    """Whether any of the synsets ``names`` is unseen in training (:func:`_novel`)."""
    return any(readable_name(c) in _novel(split) for c in names)


@functools.cache
def candidates(split: str, parent: str, relation: str, room_type: str, long_tail: bool = False,
               novel_share: float = 0.0) -> tuple[tuple[str, ...], np.ndarray]:
    """Small objects that may be ``relation`` ``parent`` (or a hypernym of it) in a room of
    ``room_type``, with sampling weights (step 4, "Small objects", of
    :mod:`sgtool.datasets.generator`).

    Admitted: an object some activity of the split relates to the parent (in any room
    type) that at least :data:`MIN_SUPPORT` sources of the split put in this room type
    (real rooms of the type holding it + activities placing it there, the counts of
    ``Knowledge.room_objects``); when no related object reaches that, the related objects
    with one source there. Weight, from this room type only: the share of its real rooms
    holding the object + the share of the activities placing objects in it that place
    this one + :data:`LOCAL_BONUS` times the share relating it to the parent here.
    Relations stated in other room types only admit, they add no weight; nothing admitted
    gives an empty pool (the piece stays empty).

    ``long_tail``: also admitted, a related object with a single source here when this room
    type is its home (no room type has more sources for it: olive oil in a kitchen cabinet,
    a hair dryer in a bathroom, never a bowl in a bathroom, whose home is the kitchen);
    every admitted object weighs the same, except that ``novel_share`` of the weight goes
    evenly to the admitted objects unseen in training (:func:`_novel`), when there are
    any."""
    k = knowledge_for(split)
    ev = _room_evidence(split)
    anc = ancestors(parent)
    related: set[str] = set()
    local: Counter[str] = Counter()
    seen_local: set[tuple[str, str]] = set()
    for r in k.relations:
        if r.relation != relation or r.parent not in anc or k.kind(r.child) != "object":
            continue
        related.add(r.child)
        if r.room_type == room_type and (r.activity, r.child) not in seen_local:
            seen_local.add((r.activity, r.child))
            local[r.child] += 1
    rooms = ev.rooms.get(room_type, Counter())
    acts = ev.acts.get(room_type, Counter())
    nr = max(ev.n_rooms[room_type], 1)
    na = max(ev.n_acts[room_type], 1)
    support = {c: rooms[c] + acts[c] for c in related}
    need = MIN_SUPPORT if any(n >= MIN_SUPPORT for n in support.values()) else 1
    admitted = {c for c, n in support.items() if n >= need}
    if long_tail:
        home = _home_support(split)
        admitted |= {c for c, n in support.items() if n >= 1 and n >= home.get(c, 0)}
    pool = {c: rooms[c] / nr + (acts[c] + LOCAL_BONUS * local[c]) / na for c in admitted}
    names = tuple(sorted(pool))
    if long_tail:
        return names, _long_tail_weights(split, names, novel_share)
    w = np.array([pool[n] for n in names], float)
    return names, (w / w.sum() if w.size else w)


def _long_tail_weights(split: str, names: tuple[str, ...], novel_share: float) -> np.ndarray:
    """``novel_share`` of the weight spread evenly over the objects unseen in training,
    the rest evenly over the others (all of it evenly when one part is empty)."""
    if not names:
        return np.zeros(0)
    novel = np.array([readable_name(c) in _novel(split) for c in names])
    w = np.full(len(names), 1.0 / len(names))
    if novel.any() and not novel.all():
        w[novel] = novel_share / novel.sum()
        w[~novel] = (1.0 - novel_share) / (~novel).sum()
    return w
