"""φ(q), the prior that a query names a first-level piece, for
:mod:`sgtool.planning.furniture_prior` and (B6) of :mod:`sgtool.planning.belief`.

A first-level piece stands in a room on its own (a sofa, a dishwasher, a floor-standing
bin): it is seen when its space is revealed and no carrier ever holds it. Which names can be
one is the vocabulary V of first-level categories: the synsets BEHAVIOR-1K's ontology marks
as furniture (``kind == "furniture"``, the scene's furniture and fixtures) and the
floor-standing holders a dense house stands in its rooms
(:data:`sgtool.datasets.first_level.FLOOR_HOLDERS`, ``GENERIC_HOLDERS``). A name outside V
is a small object: φ = 0. A name in V may still be placed inside or on something (a sack,
a carton), so its share is estimated from the training knowledge
(:func:`sgtool.datasets.split.training_knowledge`): n_F(q) counts the rooms of the scanned
scenes that hold q (furniture only: a scan also lists the small things lying on its
furniture) and the activity atoms that stand q on the floor, n_O(q) the atoms that put it
inside or on an object or piece of furniture. With a Beta prior of strength s = 2 around the
pooled share m_k of q's kind k (furniture or object, pooled over V),

    φ(q) = (n_F(q) + s m_k) / (n_F(q) + n_O(q) + s)    for q ∈ V,                    (F1)
    φ(q) = 0                                            otherwise,

the posterior mean of "an instance of q stands alone" (empirical Bayes: a name of V the
knowledge never mentions gets its kind's pooled share). Worked values from the training
knowledge are in ``docs/experiments/moved-from-docstrings.md``.

:func:`write_levels` writes the table the core ships (``furniture_level.json``, names with
φ > 0, rounded to 3 decimals); ``tests/datasets/test_furniture_level.py`` checks that the
shipped file is what this module builds.
"""

from __future__ import annotations

import json
import os
from collections import Counter
from pathlib import Path

from sgtool.datasets.first_level import FLOOR_HOLDERS, GENERIC_HOLDERS
from sgtool.datasets.knowledge import Knowledge
from sgtool.datasets.synsets import readable_name, synset_catalogue

KINDS = ("furniture", "object")
STRENGTH = 2.0  # s of (F1)
DECIMALS = 3


def first_level_vocabulary() -> dict[str, str]:
    """V of (F1): name -> kind ("furniture" or "object")."""
    cat = synset_catalogue()
    out = {readable_name(s): "furniture" for s, info in sorted(cat.items())
           if info.kind == "furniture"}
    for s in (*FLOOR_HOLDERS, *GENERIC_HOLDERS):
        out.setdefault(readable_name(s), cat[s].kind if s in cat else "object")
    return out


def first_level_counts(k: Knowledge) -> tuple[Counter[str], Counter[str]]:
    """(n_F, n_O) of (F1) per readable name."""
    n_f: Counter[str] = Counter()
    n_o: Counter[str] = Counter()
    for room in k.rooms:
        for s, _ in room.items:
            if k.kind(s) == "furniture":
                n_f[k.name(s)] += 1
    for r in k.relations:
        if k.kind(r.child) in KINDS:
            (n_o if k.kind(r.parent) in KINDS else n_f)[k.name(r.child)] += 1
    return n_f, n_o


def furniture_levels(k: Knowledge) -> dict[str, float]:
    """name -> φ of (F1) for the names of V, sorted by name."""
    vocab = first_level_vocabulary()
    n_f, n_o = first_level_counts(k)
    pooled: dict[str, float] = {}
    for kind in KINDS:
        names = [n for n, kd in vocab.items() if kd == kind]
        f, o = sum(n_f[n] for n in names), sum(n_o[n] for n in names)
        pooled[kind] = f / (f + o) if f + o else 0.5
    return {n: round((n_f[n] + STRENGTH * pooled[kd]) / (n_f[n] + n_o[n] + STRENGTH),
                     DECIMALS) for n, kd in sorted(vocab.items())}


def levels_document(k: Knowledge) -> str:
    """The text of ``furniture_level.json`` for ``k``."""
    doc = {"version": 1, "source": "BEHAVIOR-1K training knowledge, (F1) of "
           "sgtool.datasets.furniture_level", "levels": furniture_levels(k)}
    return json.dumps(doc, indent=1, sort_keys=True) + "\n"


def write_levels(path: str | os.PathLike[str] | None = None) -> Path:
    """Write the training knowledge's table to ``path`` (default: the core's shipped file)."""
    from sgtool.datasets.split import training_knowledge
    from sgtool.files import atomic_write
    from sgtool.planning.furniture_prior import LEVELS_FILE

    return atomic_write(path or LEVELS_FILE, levels_document(training_knowledge()))


if __name__ == "__main__":  # python -m sgtool.datasets.furniture_level
    print(write_levels())
