"""The training / evaluation split of the BEHAVIOR-1K knowledge.

Planners learn from the training part (relational priors, co-occurrence tables, embeddings
tuned on relations); benchmark houses are furnished from the evaluation part only. The two
parts share no scene and no activity, so nothing a planner learns comes from the room
inventories or the object relations that furnish the houses it is evaluated in.

The rule (deterministic, no randomness, independent of the machine):

- Scenes are split by *family*, the first ``_``-separated token of the scene name
  (``Pomaria_0_int``, ``Pomaria_1_int`` and ``Pomaria_0_garden`` are the family "Pomaria";
  ``house_single_floor`` and ``house_double_floor_lower`` are "house"), so floors and
  gardens of one building never straddle the split. Families are divided into household
  families (:data:`HOUSEHOLD_FAMILIES`) and the others (offices, shops, schools, ...);
  inside each group the families are ordered by the SHA-256 of ``"sgtool-split-v1:" +
  family`` and every third one (positions 2, 5, 8, ...) goes to evaluation.
- Activities are ordered by the SHA-256 of ``"sgtool-split-v1:" + activity name`` and
  every third one (positions 2, 5, 8, ...) goes to evaluation.

Each part keeps the room inventories of its scenes and the ``inside``/``ontop``/``inroom``
records of its activities, and rebuilds its tables from them alone
(:func:`sgtool.datasets.knowledge.build_knowledge`), affordances included.

Unseen queries (:func:`unseen_queries`): readable names of small-object categories that
the evaluation part can place in a house (the child of an ``inside``/``ontop`` relation
whose parent is furniture) and that occur nowhere in the training part (no room
inventory, no relation, no inroom record, under any synset with that readable name).
"""

from __future__ import annotations

import functools
import hashlib

from sgtool.datasets.knowledge import Knowledge, build_knowledge, raw_records
from sgtool.datasets.synsets import readable_name

SALT = "sgtool-split-v1:"
EVAL_EVERY = 3  # one in three goes to evaluation
HOUSEHOLD_FAMILIES: frozenset[str] = frozenset({
    "Beechwood", "Benevolence", "Ihlen", "Merom", "Pomaria", "Rs", "Wainscott", "house",
    "gates", "hotel",
})


def scene_family(scene: str) -> str:
    return scene.split("_", 1)[0]


def _hash_key(name: str) -> str:
    return hashlib.sha256((SALT + name).encode("utf-8")).hexdigest()


def _every_third(names: list[str]) -> set[str]:
    order = sorted(names, key=lambda n: (_hash_key(n), n))
    return {n for i, n in enumerate(order) if i % EVAL_EVERY == EVAL_EVERY - 1}


@functools.cache
def evaluation_scenes() -> frozenset[str]:
    scenes = raw_records().scenes
    fams = sorted({scene_family(s) for s in scenes})
    house = [f for f in fams if f in HOUSEHOLD_FAMILIES]
    other = [f for f in fams if f not in HOUSEHOLD_FAMILIES]
    ev = _every_third(house) | _every_third(other)
    return frozenset(s for s in scenes if scene_family(s) in ev)


@functools.cache
def evaluation_activities() -> frozenset[str]:
    return frozenset(_every_third(list(raw_records().activities)))


def is_household_scene(scene: str) -> bool:
    """Homes and hotel suites (not offices, shops, restaurants, schools, gardens)."""
    fam = scene_family(scene)
    if fam not in HOUSEHOLD_FAMILIES or scene.endswith("_garden"):
        return False
    return not (fam == "hotel" and "suite" not in scene)


def _knowledge_part(which: str) -> Knowledge:
    raw = raw_records()
    ev_s, ev_a = evaluation_scenes(), evaluation_activities()
    want = which == "eval"
    scenes = [s for s in raw.scenes if (s in ev_s) == want]
    acts = [a for a in raw.activities if (a in ev_a) == want]
    sset, aset = set(scenes), set(acts)
    return build_knowledge(
        scenes, acts,
        (r for r in raw.rooms if r.scene in sset),
        (r for r in raw.relations if r.activity in aset),
        (r for r in raw.inroom if r.activity in aset),
    )


@functools.cache
def training_knowledge() -> Knowledge:
    """What planners may learn from."""
    return _knowledge_part("train")


@functools.cache
def evaluation_knowledge() -> Knowledge:
    """What furnishes benchmark houses (``--split eval``)."""
    return _knowledge_part("eval")


def knowledge_for(split: str) -> Knowledge:
    if split == "train":
        return training_knowledge()
    if split == "eval":
        return evaluation_knowledge()
    raise ValueError(f"split must be 'train' or 'eval', got {split!r}")


def placeable_objects(k: Knowledge) -> set[str]:
    """Small-object synsets ``k`` can put in or on a piece of furniture."""
    return {t.child for t in k.triples.values()
            if k.kind(t.child) == "object" and k.kind(t.parent) in ("furniture", "abstract")}


@functools.cache
def _unseen() -> tuple[str, ...]:
    train = training_knowledge()
    seen = {readable_name(s) for s in train.vocabulary()}
    ev = placeable_objects(evaluation_knowledge())
    return tuple(sorted({readable_name(s) for s in ev} - seen))


def unseen_queries() -> list[str]:
    """Readable names of evaluation object categories absent from training (sorted)."""
    return list(_unseen())
