"""Relational training sets for SCOUT's distilled priors (SCOUT sec. IV-C, Eqs. 6-7).

SCOUT asks an LLM, per query object, for (a) a score per room type ("how likely is q found
in room r", continuous, D_contain) and (b) a list of objects labelled 1/0 ("do they appear
at the same place", D_co-occur). Offline, the same two relations are read from the
*training* part of the BEHAVIOR-1K knowledge (:func:`sgtool.datasets.split.training_knowledge`;
nothing from the evaluation part is used, so the benchmark houses stay unseen).

Texts are readable names (:func:`sgtool.datasets.knowledge.readable_name`) in canonical form
(:func:`sgtool.semantics.text.category_text`); synsets with the same text are merged.
Only furniture and small objects take part (no structure such as floors or walls, no
substances, no abstract synsets).

Containment, D_contain = {((r, q), y)}: for every query q the room types where it was
seen, with graded scores, and sampled room types where it never was, with score 0:

- evidence e(q, r) = s(q, r) + a(q, r) where s is the share of scanned rooms of type r
  holding q (the furniture frequency of the room inventories, with 3 empty pseudo-rooms
  added per type so that 1 of 2 spas does not outweigh 10 of 41 bathrooms) and a is the
  share of the activity placements of q (``inroom`` records and ``inside``/``ontop``
  relations whose parent is in a known room) that are in room type r;
- y(q, r) = sqrt(e(q, r) / max_r' e(q, r')): 1 for q's most likely room, graded below it
  (the square root lifts second rooms the way an LLM's "kitchen 0.9, dining room 0.6"
  does);
- negatives: 8 times as many room types as q has rooms with evidence (at least 16), drawn
  uniformly from the room types q was never seen in (seeded; uniform, unlike the
  co-occurrence negatives, because how many things a room type holds is a fair prior for
  "q is in r" and kitchens should stay likely). Not every room type per object: most of
  those targets would be zero and an MSE model on them learns the constant 0; 8 negatives
  per positive rather than 2, which left the model varying with the sample (the runs
  behind both choices: ``docs/experiments/moved-from-docstrings.md``).

Co-occurrence, D_co-occur = {((o, q), y)} with binary y (SCOUT found binary labels better
for this relation): does o stand at the places where q is found? A *place* is a scanned
room (its inventory) or a room of an activity (everything the activity puts in that room
type, :func:`place_units`). With n(q) the places holding q and n(o, q) those holding both,
(o, q) is positive when

- n(o, q) >= 2 and n(o, q) / n(q) >= 0.2 (o is at a fifth of q's places: the sink for a
  toothbrush, 7 of 13, but not the sofa, 2 of 13), or
- o and q are related directly (one ``inside``/``ontop`` the other, or both in/on one
  parent) in >= 2 activities (the plate in the cabinet), or
- they are related directly once and q has fewer than 2 places (all there is to know).

The label is asymmetric (o for q); a pair with weaker evidence is neither positive nor a
candidate negative. Negatives are sampled the way SCOUT's LLM lists them: per query, as
many objects labelled 0 as it has positives, drawn without replacement from the objects
never found with it, popular objects more often (:func:`sample_negatives`; seeded numpy
Generator).
"""

from __future__ import annotations

import functools
import hashlib
import json
from collections import Counter, defaultdict
from dataclasses import dataclass
from itertools import combinations

import numpy as np

from sgtool.semantics.relational_set import RelationalSet, table_to_set
from sgtool.semantics.text import category_text

KINDS = ("furniture", "object")
PSEUDO_ROOMS = 3  # shrinks the holding share of room types with few scanned rooms
ROOM_NEGATIVES_PER_POSITIVE = 8  # containment: rooms scored 0 per room with evidence
MIN_ROOM_NEGATIVES = 16
MIN_SUPPORT = 2  # co-occurrence: shared places, or activities relating the two
MIN_SHARE = 0.2  # co-occurrence: share of the query's places that hold the node


def sample_negatives(pool: list[str], degree: Counter[str], k: int,
                     rng: np.random.Generator) -> list[str]:
    """``k`` distinct items of ``pool`` drawn with probability ~ (positive degree + 1)^0.75.

    Uniform negatives are mostly rare names, so a model could separate the classes by how
    popular a node is (a sink is positive for half of all queries) without looking at the
    query; drawing negatives as often as nodes appear among positives (the smoothed
    unigram rule of word2vec) makes every popular node a negative for the queries it does
    not go with.
    """
    if k <= 0 or not pool:
        return []
    w = np.array([(degree.get(x, 0) + 1.0) ** 0.75 for x in pool])
    idx = rng.choice(len(pool), size=min(k, len(pool)), replace=False, p=w / w.sum())
    return [pool[i] for i in sorted(idx.tolist())]


def _synset_text(knowledge, synset: str) -> str | None:
    """Canonical text of a furniture/object synset, None for anything else."""
    from sgtool.datasets.synsets import readable_name

    if knowledge.kind(synset) not in KINDS:
        return None
    t = category_text(readable_name(synset))
    return t or None


def containment_set(knowledge, seed: int = 0, negatives: str = "uniform") -> RelationalSet:
    """D_contain (module doc)."""
    # share of scanned rooms of each type holding the object
    rooms_of_type: Counter[str] = Counter(r.room_type for r in knowledge.rooms)
    holding: dict[tuple[str, str], set[str]] = defaultdict(set)
    for r in knowledge.rooms:
        for s, _ in r.items:
            t = _synset_text(knowledge, s)
            if t is not None:
                holding[(t, r.room_type)].add(f"{r.scene}/{r.room}")
    scene_share = {k: len(v) / (rooms_of_type[k[1]] + PSEUDO_ROOMS) for k, v in holding.items()}
    # activity placements: (activity, text, room type) once each
    placed: set[tuple[str, str, str]] = set()
    for rel in knowledge.relations:
        t = _synset_text(knowledge, rel.child)
        if t is not None and rel.room_type is not None:
            placed.add((rel.activity, t, rel.room_type))
    for ir in knowledge.inroom:
        t = _synset_text(knowledge, ir.synset)
        if t is not None:
            placed.add((ir.activity, t, ir.room_type))
    per_obj: Counter[str] = Counter(t for _, t, _ in placed)
    per_pair: Counter[tuple[str, str]] = Counter((t, rt) for _, t, rt in placed)
    act_share = {k: n / per_obj[k[0]] for k, n in per_pair.items()}

    room_types = sorted(set(rooms_of_type) | {rt for _, _, rt in placed})
    evidence: dict[str, dict[str, float]] = defaultdict(dict)
    for (t, rt), v in (*scene_share.items(), *act_share.items()):
        evidence[t][rt] = evidence[t].get(rt, 0.0) + v
    if negatives not in ("popular", "uniform"):
        raise ValueError(f"negatives must be 'popular' or 'uniform', not {negatives!r}")
    degree: Counter[str] = Counter()
    if negatives == "popular":
        degree.update(rt for e in evidence.values() for rt in e)
    rng = np.random.default_rng(seed)
    table: dict[tuple[str, str], float] = {}
    for t in sorted(evidence):
        e = evidence[t]
        top = max(e.values())
        seen = sorted(rt for rt in e if e[rt] > 0)
        for rt in seen:
            table[(category_text(rt), t)] = float(np.sqrt(e[rt] / top))
        pool = [rt for rt in room_types if rt not in e]
        k = min(len(pool), max(MIN_ROOM_NEGATIVES, ROOM_NEGATIVES_PER_POSITIVE * len(seen)))
        for rt in sample_negatives(pool, degree, k, rng):
            table[(category_text(rt), t)] = 0.0
    return table_to_set("containment", table)


def place_units(knowledge) -> list[frozenset[str]]:
    """Places where things are found together: every scanned room (its inventory) and every
    room of every activity (what the activity puts in that room type through ``inroom`` or
    through ``inside``/``ontop`` on something in that room)."""
    units: list[frozenset[str]] = []
    for r in knowledge.rooms:
        items = frozenset(t for s, _ in r.items if (t := _synset_text(knowledge, s)) is not None)
        if items:
            units.append(items)
    by_room: dict[tuple[str, str], set[str]] = defaultdict(set)
    for rel in knowledge.relations:
        if rel.room_type is None:
            continue
        for s in (rel.child, rel.parent):
            if (t := _synset_text(knowledge, s)) is not None:
                by_room[(rel.activity, rel.room_type)].add(t)
    for ir in knowledge.inroom:
        if (t := _synset_text(knowledge, ir.synset)) is not None:
            by_room[(ir.activity, ir.room_type)].add(t)
    units.extend(frozenset(v) for _, v in sorted(by_room.items()) if v)
    return units


def cooccurrence_labels(knowledge) -> tuple[set[tuple[str, str]], set[tuple[str, str]]]:
    """(positive, related) ordered pairs (node o, query q); see the module doc."""
    direct: dict[tuple[str, str], set[str]] = defaultdict(set)  # unordered pair -> activities

    def key(a: str, b: str) -> tuple[str, str]:
        return (a, b) if a < b else (b, a)

    siblings: dict[tuple[str, str], set[str]] = defaultdict(set)
    for rel in knowledge.relations:
        c, p = _synset_text(knowledge, rel.child), _synset_text(knowledge, rel.parent)
        if c and p and c != p:
            direct[key(c, p)].add(rel.activity)
        if c is not None:
            siblings[(rel.activity, rel.parent)].add(c)
    for (act, _), group in siblings.items():
        for a, b in combinations(sorted(group), 2):
            direct[(a, b)].add(act)
    n: Counter[str] = Counter()
    nab: Counter[tuple[str, str]] = Counter()
    for u in place_units(knowledge):
        items = sorted(u)
        n.update(items)
        nab.update(combinations(items, 2))
    pos: set[tuple[str, str]] = set()
    related: set[tuple[str, str]] = set()
    for a, b in set(nab) | set(direct):
        both = nab.get((a, b), 0)
        acts = len(direct.get((a, b), ()))
        for o, q in ((a, b), (b, a)):
            related.add((o, q))
            share = both / n[q] if n[q] else 0.0
            if ((both >= MIN_SUPPORT and share >= MIN_SHARE) or acts >= MIN_SUPPORT
                    or (acts >= 1 and n[q] < MIN_SUPPORT)):
                pos.add((o, q))
    return pos, related


def cooccurrence_set(knowledge, seed: int = 0, negatives: str = "popular") -> RelationalSet:
    """D_co-occur with sampled negatives (module doc)."""
    pos, related = cooccurrence_labels(knowledge)
    partners: dict[str, set[str]] = defaultdict(set)
    for o, q in pos:
        partners[q].add(o)
    near: dict[str, set[str]] = defaultdict(set)
    for o, q in related:
        near[q].add(o)
    vocab = sorted({t for s in knowledge.vocabulary() if (t := _synset_text(knowledge, s))})
    if negatives not in ("popular", "uniform"):
        raise ValueError(f"negatives must be 'popular' or 'uniform', not {negatives!r}")
    degree: Counter[str] = Counter(o for o, _ in pos) if negatives == "popular" else Counter()
    rng = np.random.default_rng(seed)
    table: dict[tuple[str, str], float] = {}
    for q in sorted(partners):
        mine = partners[q]
        for o in mine:
            table[(o, q)] = 1.0
        pool = [o for o in vocab if o != q and o not in mine and o not in near[q]]
        for o in sample_negatives(pool, degree, min(len(mine), len(pool)), rng):
            table[(o, q)] = 0.0
    return table_to_set("cooccurrence", table)


@dataclass(frozen=True)
class TrainingSets:
    containment: RelationalSet
    cooccurrence: RelationalSet
    room_types: tuple[str, ...]  # household room types of the training scenes (raw spelling)
    split_fingerprint: str


def knowledge_fingerprint(knowledge) -> str:
    """SHA-256 of the scenes and activities a knowledge part was built from."""
    doc = {"scenes": list(knowledge.scenes), "activities": list(knowledge.activities)}
    return hashlib.sha256(json.dumps(doc, sort_keys=True).encode()).hexdigest()


def household_room_types(knowledge) -> tuple[str, ...]:
    """Room types of the household scenes of ``knowledge`` (raw spelling, sorted)."""
    from sgtool.datasets.split import is_household_scene

    return tuple(sorted({r.room_type for r in knowledge.rooms if is_household_scene(r.scene)}))


@functools.cache
def training_sets(seed: int = 0) -> TrainingSets:
    """Both sets from the training knowledge only."""
    from sgtool.datasets.split import training_knowledge

    k = training_knowledge()
    return TrainingSets(
        containment=containment_set(k, seed),
        cooccurrence=cooccurrence_set(k, seed),
        room_types=household_room_types(k),
        split_fingerprint=knowledge_fingerprint(k),
    )


@functools.cache
def evaluation_sets(seed: int = 0) -> tuple[RelationalSet, RelationalSet]:
    """(containment, co-occurrence) pairs of the *unseen* query categories, built from the
    evaluation part: objects no training record mentions
    (:func:`sgtool.datasets.split.unseen_queries`). For reporting only; nothing is ever
    trained on them."""
    from sgtool.datasets.split import evaluation_knowledge, unseen_queries

    k = evaluation_knowledge()
    unseen = {category_text(q) for q in unseen_queries()}
    return (containment_set(k, seed).subset_queries(unseen),
            cooccurrence_set(k, seed).subset_queries(unseen))
