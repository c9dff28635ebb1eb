"""Room knowledge for the containment prior: more of it for the thin room types, as data.

The containment set (:mod:`sgtool.datasets.relational`) knows kitchens and living rooms well
and bedrooms, offices and children's rooms thinly: the scanned scenes put office supplies
in *shared offices*, *copy rooms* and *phone rooms*, room types a house does not have, so
that knowledge never reaches the *private office* a planner scores. Two pure steps widen
the knowledge that the models are trained on, and one extracts the table the neighbour
scorer (:mod:`sgtool.semantics.room_blend`) reads at run time:

- :func:`fold_room_types`: a room type outside the scored set is folded into the scored
  type whose *contents* are most alike (cosine of the two room types' target columns over
  all query names: a room type is the vector of how likely each object is in it), when
  that likeness is at least ``min_likeness``. Folding sets the scored room's target of
  each name to the larger of its own and the folded room's. The likeness comes from the
  data, not from the room names (whose sentence similarity puts a pantry next to a dining
  room and a storage room next to a bedroom).
- :func:`add_room_targets`: room targets of another source. A name the set already knows
  gets, for each room type the other source annotates, the mean of the two sources'
  targets (:data:`MEAN`; a room type the set has no pair for counts 0 there: the name was
  never seen in it); its other pairs stay. Two sources that disagree (ProcTHOR places a
  pillow "often" in living rooms, BEHAVIOR-1K's scenes and activities only in bedrooms)
  then give a graded answer, not a tie at 1 that the largest room type wins. New names
  bring their pairs as they are, zeros included, so "a soap bar is never in a kitchen" is
  trained as such. (:data:`MAX`, the larger target, is the rule of the first widening.)
- :func:`room_table`: per scored room type, the names whose target there is at least
  ``min_target`` (sorted), the neighbour scorer's evidence.

All three are functions of their inputs only (sorted vocabularies, no randomness).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np

from sgtool.semantics.relational_set import RelationalSet, table_to_set
from sgtool.semantics.text import category_text

# a folded room type must share at least this content likeness with its scored room type
MIN_LIKENESS = 0.25
# a name is evidence for a room type in the neighbour table from this target on
MIN_TARGET = 0.5
# how add_room_targets merges a known name's pair with another source's
MEAN = "mean"
MAX = "max"


def set_to_table(rs: RelationalSet) -> dict[tuple[str, str], float]:
    """``{(node, query): target}`` of a set (the inverse of :func:`table_to_set`)."""
    return {(rs.nodes[int(n)], rs.queries[int(q)]): float(y)
            for (n, q), y in zip(rs.pairs, rs.targets, strict=True)}


def content_likeness(rs: RelationalSet) -> tuple[tuple[str, ...], np.ndarray]:
    """Room types (``rs.nodes``) and their pairwise content likeness: the cosine of their
    target columns over the query names (0 for a room type with no positive target)."""
    m = np.zeros((len(rs.queries), len(rs.nodes)), np.float64)
    m[rs.pairs[:, 1], rs.pairs[:, 0]] = rs.targets
    norm = np.linalg.norm(m, axis=0)
    m = m / np.where(norm > 0, norm, 1.0)
    return rs.nodes, m.T @ m


def fold_targets(rs: RelationalSet, scored: Sequence[str],
                 min_likeness: float = MIN_LIKENESS) -> dict[str, str]:
    """Which room type is folded into which: ``{other type: scored type}`` for every type
    of ``rs`` outside ``scored`` (compared by :func:`category_text`) whose most alike
    scored type (ties: the first in sorted order) has a likeness of at least
    ``min_likeness``."""
    nodes, like = content_likeness(rs)
    keep = {category_text(s) for s in scored}
    cols = [i for i, n in enumerate(nodes) if category_text(n) in keep]
    out: dict[str, str] = {}
    if not cols:
        return out
    for i, n in enumerate(nodes):
        if category_text(n) in keep:
            continue
        j = cols[int(np.argmax(like[i, cols]))]
        if like[i, j] >= min_likeness:
            out[n] = nodes[j]
    return out


def fold_room_types(rs: RelationalSet, scored: Sequence[str],
                    min_likeness: float = MIN_LIKENESS) -> RelationalSet:
    """The containment set with room types outside ``scored`` folded into their most alike
    scored type (module doc); the pairs of the folded types themselves stay."""
    folds = fold_targets(rs, scored, min_likeness)
    table = set_to_table(rs)
    by_query: dict[str, dict[str, float]] = {}
    for (node, query), y in table.items():
        by_query.setdefault(query, {})[node] = y
    for query, rooms in by_query.items():
        for other, into in folds.items():
            y = rooms.get(other, 0.0)
            if y > 0 and y > table.get((into, query), 0.0):
                table[(into, query)] = y
    return table_to_set(rs.relation, table)


def add_room_targets(rs: RelationalSet, extra: Mapping[str, Mapping[str, float]],
                     merge: str = MEAN) -> RelationalSet:
    """``rs`` with the room targets ``extra`` (``{name: {room type: target}}``, names and
    room types compared by :func:`category_text`, room types matched to the set's
    spelling where the set has them) added. For a name with pairs in ``rs``, each room type
    of ``extra`` gets the mean of the two targets (``merge`` :data:`MEAN`; a missing pair
    counts 0) or the larger one (:data:`MAX`); a name new to ``rs`` brings its pairs."""
    if merge not in (MEAN, MAX):
        raise ValueError(f"merge is {MEAN!r} or {MAX!r}, not {merge!r}")
    table = set_to_table(rs)
    known = {q for (_, q) in table}
    spelling = {category_text(n): n for n in rs.nodes}
    for name in sorted(extra):
        q = category_text(name)
        for room, y in sorted(extra[name].items()):
            node = spelling.get(category_text(room), room)
            old = table.get((node, q), 0.0)
            if q not in known or merge == MAX:
                table[(node, q)] = max(float(y), old)
            else:
                table[(node, q)] = (float(y) + old) / 2.0
    return table_to_set(rs.relation, table)


def room_table(rs: RelationalSet, rooms: Sequence[str],
               min_target: float = MIN_TARGET) -> dict[str, list[str]]:
    """``{room type: sorted names with a target >= min_target there}`` for each of
    ``rooms`` (as spelled in ``rooms``; a room type without such names maps to [])."""
    table = set_to_table(rs)
    out: dict[str, list[str]] = {r: [] for r in rooms}
    key = {category_text(r): r for r in rooms}
    for (node, query), y in table.items():
        r = key.get(category_text(node))
        if r is not None and y >= min_target:
            out[r].append(query)
    return {r: sorted(set(v)) for r, v in out.items()}
