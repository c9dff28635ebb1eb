"""Household knowledge from BEHAVIOR-1K, read from the installed ``bddl`` package (MIT).

Three files of the package are read, nothing is downloaded (synsets and names:
:mod:`sgtool.datasets.synsets`; the activity parser: :mod:`sgtool.datasets.activities`):

- ``generated_data/combined_room_object_list.json``: the 51 scanned OmniGibson scenes,
  374 rooms (``kitchen_0``), per room the object models it holds with counts
  (``bottom_cabinet-rvpunw: 1``); models map to categories (``bottom_cabinet``) and
  categories to WordNet synsets (``cabinet.n.01``) through ``category_mapping.csv``;
- ``generated_data/synsets.csv``: per synset its hypernyms and flags (``openable``,
  ``fillable``, ``sceneObject`` = a piece of the scene's furniture or fixtures, ``objectType``
  = rigid body, cloth, liquid, ...);
- ``activity_definitions/*/problem0.bddl``: 1,016 activities; every ``inside``, ``ontop``
  and ``inroom`` atom of ``:init`` and ``:goal`` that is not under a ``not`` becomes a
  record (instances such as ``apple.n.01_1`` and goal variables ``?apple.n.01`` resolve to
  their synset; ``inroom`` of an object's parent chain gives the room type of a relation).

:func:`load_knowledge` keeps the raw records (so :mod:`sgtool.datasets.split` can keep a
subset of scenes and activities and rebuild the tables with :func:`build_knowledge`) and
the derived tables:

- ``room_furniture``: room type -> furniture categories with the share of rooms of that
  type holding them and the mean count per holding room;
- ``triples``: (object, relation, parent) -> atom count and number of activities;
- ``room_objects``: room type -> small-object counts (rooms of that type holding it in
  the scenes + activities placing it in that room type);
- ``affordances``: synset -> ("container", "openable", "supporter") subset.

Planners must learn only from :func:`sgtool.datasets.split.training_knowledge`;
:func:`load_knowledge` holds both parts and is for figures and for the split itself.

Categories have readable names (:func:`readable_name`): ``electric_refrigerator.n.01`` ->
"refrigerator", ``pack__of__ground_beef.n.01`` -> "pack of ground beef"; the synset is kept
alongside everywhere.
"""


from __future__ import annotations

import functools
import json
import re
from collections import Counter, defaultdict
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from types import MappingProxyType

from sgtool.datasets.activities import InRoomRecord, RelationRecord, parse_activity
from sgtool.datasets.synsets import (
    SynsetInfo,
    ancestors,
    bddl_root,
    category_synsets,
    readable_name,
    synset_catalogue,
)


@dataclass(frozen=True)
class RoomInventory:
    """One room of one scanned scene: synset -> model count."""

    scene: str
    room: str  # "kitchen_0"
    room_type: str  # "kitchen"
    items: tuple[tuple[str, int], ...]


@dataclass(frozen=True)
class FurnitureFreq:
    synset: str
    name: str
    frequency: float  # share of rooms of the type holding at least one
    mean_count: float  # mean number in the rooms holding it


@dataclass(frozen=True)
class TripleStat:
    child: str
    relation: str
    parent: str
    count: int  # atoms
    activities: int  # distinct activities


@dataclass(frozen=True)
class Knowledge:
    """Raw records and derived tables (see the module docstring)."""

    scenes: tuple[str, ...]
    activities: tuple[str, ...]
    rooms: tuple[RoomInventory, ...]
    relations: tuple[RelationRecord, ...]
    inroom: tuple[InRoomRecord, ...]
    catalogue: Mapping[str, SynsetInfo] = field(repr=False)
    room_furniture: Mapping[str, tuple[FurnitureFreq, ...]] = field(repr=False)
    triples: Mapping[tuple[str, str, str], TripleStat] = field(repr=False)
    room_objects: Mapping[str, tuple[tuple[str, int], ...]] = field(repr=False)
    affordances: Mapping[str, tuple[str, ...]] = field(repr=False)
    room_type_counts: Mapping[str, int] = field(repr=False)

    def name(self, synset: str) -> str:
        return readable_name(synset)

    def kind(self, synset: str) -> str:
        info = self.catalogue.get(synset)
        return info.kind if info else "abstract"

    def relation_counts(self) -> dict[str, int]:
        """Atom counts per relation ("inside", "ontop", "inroom")."""
        c = Counter(r.relation for r in self.relations)
        return {"inside": c["inside"], "ontop": c["ontop"], "inroom": len(self.inroom)}

    def vocabulary(self) -> set[str]:
        """Every synset this knowledge mentions (rooms, relations, inroom)."""
        out = {s for r in self.rooms for s, _ in r.items}
        out |= {r.child for r in self.relations} | {r.parent for r in self.relations}
        out |= {r.synset for r in self.inroom}
        return out


def read_room_inventories() -> tuple[RoomInventory, ...]:
    path = bddl_root() / "generated_data" / "combined_room_object_list.json"
    data = json.loads(path.read_text(encoding="utf-8"))
    cats = category_synsets()
    out = []
    for scene in sorted(data["scenes"]):
        for room in sorted(data["scenes"][scene]):
            counts: Counter[str] = Counter()
            for model, n in data["scenes"][scene][room].items():
                category = model.rsplit("-", 1)[0]
                synset = cats.get(category)
                if synset is not None:
                    counts[synset] += int(n)
            room_type = re.sub(r"_\d+$", "", room)
            out.append(RoomInventory(scene, room, room_type, tuple(sorted(counts.items()))))
    return tuple(out)


@dataclass(frozen=True)
class RawRecords:
    """Every record of the package, before any table is derived (the split keeps subsets)."""

    scenes: tuple[str, ...]
    activities: tuple[str, ...]
    rooms: tuple[RoomInventory, ...]
    relations: tuple[RelationRecord, ...]
    inroom: tuple[InRoomRecord, ...]
    negated: Mapping[str, int]


@functools.cache
def raw_records() -> RawRecords:
    """The raw records of the whole package (cached; the split keeps subsets of them)."""
    base = bddl_root() / "activity_definitions"
    activities = sorted(p.name for p in base.iterdir()
                        if p.is_dir() and (p / "problem0.bddl").is_file())
    rels: list[RelationRecord] = []
    inroom: list[InRoomRecord] = []
    negated: Counter[str] = Counter()
    for act in activities:
        r, i, n = parse_activity(act, (base / act / "problem0.bddl").read_text(encoding="utf-8"))
        rels += r
        inroom += i
        negated += n
    rooms = read_room_inventories()
    scenes = tuple(sorted({r.scene for r in rooms}))
    return RawRecords(scenes, tuple(activities), rooms, tuple(rels), tuple(inroom),
                      MappingProxyType(dict(negated)))


def negated_relation_counts() -> dict[str, int]:
    """Counts of relation atoms under ``not`` in the activities (left out of the tables)."""
    return dict(raw_records().negated)


def build_knowledge(scenes: Iterable[str], activities: Iterable[str],
                    rooms: Iterable[RoomInventory], relations: Iterable[RelationRecord],
                    inroom: Iterable[InRoomRecord]) -> Knowledge:
    """Derive the tables from raw records (any subset of the package's records)."""
    cat = synset_catalogue()
    rooms = tuple(rooms)
    relations = tuple(relations)
    inroom = tuple(inroom)

    def kind(s: str) -> str:
        info = cat.get(s)
        return info.kind if info else "abstract"

    # room type -> furniture frequencies
    type_counts: Counter[str] = Counter(r.room_type for r in rooms)
    holding: dict[str, Counter[str]] = defaultdict(Counter)
    totals: dict[str, Counter[str]] = defaultdict(Counter)
    room_objects: dict[str, Counter[str]] = defaultdict(Counter)
    for r in rooms:
        for s, n in r.items:
            k = kind(s)
            if k == "furniture":
                holding[r.room_type][s] += 1
                totals[r.room_type][s] += n
            elif k == "object":
                room_objects[r.room_type][s] += 1
    room_furniture = {}
    for rt in sorted(holding):
        rows = [FurnitureFreq(s, readable_name(s), holding[rt][s] / type_counts[rt],
                              totals[rt][s] / holding[rt][s]) for s in holding[rt]]
        rows.sort(key=lambda f: (-f.frequency, f.synset))
        room_furniture[rt] = tuple(rows)

    # triples
    atoms: Counter[tuple[str, str, str]] = Counter()
    acts: dict[tuple[str, str, str], set[str]] = defaultdict(set)
    placed: set[tuple[str, str, str]] = set()  # (activity, synset, room type)
    for rel in relations:
        key = (rel.child, rel.relation, rel.parent)
        atoms[key] += 1
        acts[key].add(rel.activity)
        if rel.room_type is not None and kind(rel.child) == "object":
            placed.add((rel.activity, rel.child, rel.room_type))
    for ir in inroom:
        if kind(ir.synset) == "object":
            placed.add((ir.activity, ir.synset, ir.room_type))
    for _, s, rt in placed:
        room_objects[rt][s] += 1
    triples = {k: TripleStat(*k, atoms[k], len(acts[k])) for k in sorted(atoms)}

    # affordances: openable from the flags; container = openable furniture, or the parent
    # of an "inside" relation here; supporter = the parent of an "ontop" relation here, or
    # furniture with a flat top (tables, counters, shelves, beds: hypernym checks)
    inside_parents = {k[2] for k in atoms if k[1] == "inside"}
    ontop_parents = {k[2] for k in atoms if k[1] == "ontop"}
    aff: dict[str, tuple[str, ...]] = {}
    for s in sorted(cat):
        info = cat[s]
        if info.kind not in ("furniture", "object"):
            continue
        a = set()
        if info.openable:
            a.add("openable")
        anc = ancestors(s)
        if (info.openable and info.kind == "furniture") or anc & inside_parents:
            a.add("container")
        if anc & ontop_parents or anc & _FLAT_TOPS:
            a.add("supporter")
        if a:
            aff[s] = tuple(sorted(a))
    return Knowledge(
        scenes=tuple(sorted(set(scenes))), activities=tuple(sorted(set(activities))),
        rooms=rooms, relations=relations, inroom=inroom, catalogue=cat,
        room_furniture=MappingProxyType(room_furniture),
        triples=MappingProxyType(triples),
        room_objects=MappingProxyType({rt: tuple(sorted(c.items(), key=lambda x: (-x[1], x[0])))
                                       for rt, c in sorted(room_objects.items())}),
        affordances=MappingProxyType(aff),
        room_type_counts=MappingProxyType(dict(sorted(type_counts.items()))),
    )

_FLAT_TOPS = frozenset({"table.n.02", "countertop.n.01", "shelf.n.01", "bed.n.01",
                        "desk.n.01", "tabletop.n.01", "stand.n.04", "bookcase.n.01",
                        "chest_of_drawers.n.01", "sofa.n.01"})


@functools.cache
def load_knowledge() -> Knowledge:
    """All of the package's knowledge (cached per process)."""
    raw = raw_records()
    return build_knowledge(raw.scenes, raw.activities, raw.rooms, raw.relations, raw.inroom)

