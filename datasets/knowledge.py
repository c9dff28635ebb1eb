"""Household knowledge from BEHAVIOR-1K, read from the installed ``bddl`` package (MIT).

Three files of the package are read, nothing is downloaded:

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

import csv
import functools
import json
import re
from collections import Counter, defaultdict
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from types import MappingProxyType
from typing import Any

RELATIONS = ("inside", "ontop")

# Synsets that are part of the building, wall- or ceiling-mounted, or outdoors: never
# furniture a robot searches in, never a small object to find.
STRUCTURE: frozenset[str] = frozenset({
    "wall.n.01", "floor.n.01", "ceiling.n.01", "door.n.01", "fixed_window.n.01",
    "openable_window.n.01", "window.n.01", "switch.n.01", "wall_socket.n.01",
    "room_light.n.01", "photograph.n.01", "painting.n.01", "mirror.n.01", "showerhead.n.01",
    "range_hood.n.01", "lawn.n.01", "driveway.n.01", "tree.n.01", "scrub.n.01",
    "rail_fence.n.01", "gate.n.01", "car.n.01", "column.n.07", "wall_nail.n.01",
    "wall_clock.n.01", "fire_alarm.n.02", "fire_sprinkler.n.01", "security_camera.n.01",
    "ventilator.n.01", "window_blind.n.01", "flower.n.02", "recreational_vehicle.n.01",
    "swimming_pool.n.01", "hot_tub.n.02", "spotlight.n.02", "chandelier.n.01",
    "pot_plant.n.01", "agent.n.01", "railing.n.01", "elevator.n.01", "stairs.n.01",
    "curtain.n.01", "radiator.n.02", "hand_dryer.n.01", "toilet_paper_dispenser.n.01",
    "paper_towel_dispenser.n.01", "soap_dispenser.n.01", "towel_rack.n.01",
    "grill.n.02", "boulder.n.01", "vine.n.01", "signpost.n.01", "wall_mounted_light.n.01",
})
SUBSTANCE_TYPES = frozenset({"liquid", "macroPhysicalSubstance", "microPhysicalSubstance",
                             "visualSubstance"})
# WordNet lemmas nobody says; the synset stays beside the name everywhere
NAME_OVERRIDES: Mapping[str, str] = MappingProxyType({
    "electric_refrigerator.n.01": "refrigerator",
    "ashcan.n.01": "trash can",
    "television_receiver.n.01": "television",
    "deep-freeze.n.02": "freezer",
    "scrub.n.01": "bush",
    "column.n.07": "pillar",
    "switch.n.01": "light switch",
    "room_light.n.01": "ceiling light",
    "stand.n.04": "nightstand",
    "footstool.n.01": "ottoman",
    "rug.n.01": "carpet",
    "photograph.n.01": "picture",
    "toilet.n.02": "toilet",
    "washer.n.03": "washing machine",
    "stove.n.01": "stove",
    "microwave.n.02": "microwave",
    "sink.n.01": "sink",
    # homonyms whose senses both occur in the activities
    "belt.n.01": "drive belt",
    "belt.n.02": "belt",
    "bow.n.02": "violin bow",
    "bow.n.08": "ribbon bow",
    "package.n.02": "parcel",
})


def bddl_root() -> Path:
    """Folder of the installed ``bddl`` package."""
    import bddl

    return Path(bddl.__file__).resolve().parent


# ----------------------------------------------------------------------------------------
# records
# ----------------------------------------------------------------------------------------
@dataclass(frozen=True)
class SynsetInfo:
    synset: str
    name: str
    hypernyms: tuple[str, ...]
    kind: str  # "furniture" | "object" | "structure" | "substance" | "abstract"
    openable: bool
    fillable: bool
    object_type: str


@dataclass(frozen=True)
class RoomInventory:
    """One room of one scanned scene: synset -> model count."""

    scene: str
    room: str  # "kitchen_0"
    room_type: str  # "kitchen"
    items: tuple[tuple[str, int], ...]


@dataclass(frozen=True)
class RelationRecord:
    """One ``inside``/``ontop`` atom of one activity. ``room_type`` is where the parent is
    (from ``inroom`` of the parent or of what it rests on/in), None when not stated."""

    activity: str
    child: str
    relation: str
    parent: str
    section: str  # "init" | "goal"
    room_type: str | None


@dataclass(frozen=True)
class InRoomRecord:
    activity: str
    synset: str
    room_type: str


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

    def object_vocabulary(self) -> set[str]:
        """Small-object synsets (kind "object") this knowledge mentions."""
        return {s for s in self.vocabulary() if self.kind(s) == "object"}


# ----------------------------------------------------------------------------------------
# names and the synset catalogue
# ----------------------------------------------------------------------------------------
def _lemma(synset: str) -> str:
    base = re.sub(r"\.n\.\d+$", "", synset)
    return base.replace("__", " ").replace("_", " ").replace("-", " ").strip()


def _sense(synset: str) -> int:
    m = re.search(r"\.n\.(\d+)$", synset)
    return int(m.group(1)) if m else 0


@functools.cache
def _names() -> Mapping[str, str]:
    """Readable name of every synset of synsets.csv and category_mapping.csv.

    Rule: an override (:data:`NAME_OVERRIDES`) if any; else the lemma with underscores as
    spaces; when two synsets share a lemma, the lowest sense keeps it and the others take
    their OmniGibson category name (``cabinet.n.03`` -> "locker") or "lemma N".
    """
    root = bddl_root() / "generated_data"
    synsets: set[str] = set()
    with open(root / "synsets.csv", newline="", encoding="utf-8") as fh:
        for row in csv.DictReader(fh):
            synsets.add(row["synset"])
    cats: dict[str, list[str]] = defaultdict(list)
    with open(root / "category_mapping.csv", newline="", encoding="utf-8") as fh:
        for row in csv.DictReader(fh):
            cats[row["synset"]].append(row["category"])
            synsets.add(row["synset"])
    by_lemma: dict[str, list[str]] = defaultdict(list)
    for s in synsets:
        by_lemma[_lemma(s)].append(s)
    taken = {NAME_OVERRIDES.get(s, _lemma(s)) for s in synsets}
    out: dict[str, str] = {}
    for lemma, group in sorted(by_lemma.items()):
        group.sort(key=lambda s: (_sense(s), s))
        for i, s in enumerate(group):
            if s in NAME_OVERRIDES:
                out[s] = NAME_OVERRIDES[s]
            elif i == 0:
                out[s] = lemma
            else:
                alt = [c.replace("_", " ") for c in sorted(cats.get(s, []))
                       if c.replace("_", " ") not in taken]
                out[s] = alt[0] if alt else f"{lemma} {_sense(s)}"
                taken.add(out[s])
    return MappingProxyType(out)


def readable_name(synset: str) -> str:
    """``electric_refrigerator.n.01`` -> "refrigerator", ``pack__of__ground_beef.n.01`` ->
    "pack of ground beef" (synsets unknown to the package: their lemma)."""
    return _names().get(synset) or _lemma(synset)


@functools.cache
def synset_catalogue() -> Mapping[str, SynsetInfo]:
    """Every synset of synsets.csv with flags, hypernyms, readable name and kind."""
    out: dict[str, SynsetInfo] = {}
    path = bddl_root() / "generated_data" / "synsets.csv"
    with open(path, newline="", encoding="utf-8") as fh:
        for row in csv.DictReader(fh):
            s = row["synset"]
            otype = row.get("objectType") or ""
            if s in STRUCTURE:
                kind = "structure"
            elif otype in SUBSTANCE_TYPES:
                kind = "substance"
            elif row.get("sceneObject") == "1":
                kind = "furniture"
            else:
                kind = "object"
            hyp = tuple(h.strip() for h in (row.get("hypernyms") or "").split(",") if h.strip())
            out[s] = SynsetInfo(s, readable_name(s), hyp, kind, row.get("openable") == "1",
                                row.get("fillable") == "1", otype)
    return MappingProxyType(out)


@functools.cache
def ancestors(synset: str) -> frozenset[str]:
    """The synset and all its hypernyms (transitively, as far as synsets.csv knows them)."""
    cat = synset_catalogue()
    seen = {synset}
    stack = [synset]
    while stack:
        s = stack.pop()
        info = cat.get(s)
        if info is None:
            continue
        for h in info.hypernyms:
            if h not in seen:
                seen.add(h)
                stack.append(h)
    return frozenset(seen)


@functools.cache
def category_synsets() -> Mapping[str, str]:
    """OmniGibson category (``bottom_cabinet``) -> synset (``cabinet.n.01``)."""
    out = {}
    path = bddl_root() / "generated_data" / "category_mapping.csv"
    with open(path, newline="", encoding="utf-8") as fh:
        for row in csv.DictReader(fh):
            out[row["category"]] = row["synset"]
    return MappingProxyType(out)


# ----------------------------------------------------------------------------------------
# reading the package
# ----------------------------------------------------------------------------------------
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


_TOKEN = re.compile(r"\(|\)|[^\s()]+")
_QUANT = {"forall", "exists", "forn", "forpairs", "fornpairs"}


def parse_sexp(text: str) -> list[Any]:
    """A BDDL file as nested lists of strings (comments after ';' dropped)."""
    text = re.sub(r";[^\n]*", "", text)
    stack: list[list[Any]] = [[]]
    for tok in _TOKEN.findall(text):
        if tok == "(":
            stack.append([])
        elif tok == ")":
            if len(stack) < 2:
                raise ValueError("unbalanced ')'")
            x = stack.pop()
            stack[-1].append(x)
        else:
            stack[-1].append(tok)
    if len(stack) != 1 or not stack[0]:
        raise ValueError("unbalanced '('")
    return stack[0][0]


def _section(tree: list[Any], key: str) -> list[Any]:
    for x in tree[1:]:
        if isinstance(x, list) and x and x[0] == key:
            return x[1:]
    return []


def _instance_synset(token: str) -> str:
    return re.sub(r"_\d+$", "", token.lstrip("?"))


def _atoms(expr: Any, out: list[tuple[str, ...]], negated: list[tuple[str, ...]],
           neg: bool = False) -> None:
    """Collect (predicate, args...) atoms of ``expr``; atoms under ``not`` go to
    ``negated``."""
    if not isinstance(expr, list) or not expr or not isinstance(expr[0], str):
        return
    head = expr[0]
    if head == "not":
        for x in expr[1:]:
            _atoms(x, out, negated, not neg)
        return
    if head in ("and", "or", "imply") or head in _QUANT:
        for x in expr[1:]:
            if head in _QUANT and isinstance(x, list) and "-" in x:
                continue  # a variable declaration (?x - synset)
            _atoms(x, out, negated, neg)
        return
    if all(isinstance(a, str) for a in expr[1:]):
        (negated if neg else out).append(tuple(expr))


def parse_activity(name: str, text: str) -> tuple[list[RelationRecord], list[InRoomRecord],
                                                   Counter[str]]:
    """Relations and inroom records of one ``problem0.bddl``, and the counts of negated
    relation atoms (which are not relations that hold)."""
    tree = parse_sexp(text)
    init_atoms: list[tuple[str, ...]] = []
    goal_atoms: list[tuple[str, ...]] = []
    neg: list[tuple[str, ...]] = []
    for a in _section(tree, ":init"):
        _atoms(a, init_atoms, neg)
    for a in _section(tree, ":goal"):
        _atoms(a, goal_atoms, neg)
    # where instances are: inroom, then propagated down inside/ontop chains of :init
    room_of: dict[str, str] = {}
    inroom: list[InRoomRecord] = []
    for a in init_atoms:
        if a[0] == "inroom" and len(a) == 3:
            room_of[a[1]] = a[2]
            inroom.append(InRoomRecord(name, _instance_synset(a[1]), a[2]))
    parent_of = {a[1]: a[2] for a in init_atoms if a[0] in RELATIONS and len(a) == 3}
    for _ in range(8):  # chains are short; a fixed bound also guards against cycles
        changed = False
        for child, parent in parent_of.items():
            if child not in room_of and parent in room_of:
                room_of[child] = room_of[parent]
                changed = True
        if not changed:
            break
    # a goal variable stands for every instance of its synset: its room when they agree
    rooms_by_synset: dict[str, set[str]] = defaultdict(set)
    for inst, room in room_of.items():
        rooms_by_synset[_instance_synset(inst)].add(room)

    def room_for(token: str) -> str | None:
        inst = token.lstrip("?")
        if inst in room_of:
            return room_of[inst]
        rs = rooms_by_synset.get(_instance_synset(token), set())
        return next(iter(rs)) if len(rs) == 1 else None

    rels: list[RelationRecord] = []
    for section, atoms in (("init", init_atoms), ("goal", goal_atoms)):
        for a in atoms:
            if a[0] in RELATIONS and len(a) == 3:
                rels.append(RelationRecord(name, _instance_synset(a[1]), a[0],
                                           _instance_synset(a[2]), section, room_for(a[2])))
    negated = Counter(a[0] for a in neg if a[0] in (*RELATIONS, "inroom"))
    return rels, inroom, negated


@dataclass(frozen=True)
class _Raw:
    scenes: tuple[str, ...]
    activities: tuple[str, ...]
    rooms: tuple[RoomInventory, ...]
    relations: tuple[RelationRecord, ...]
    inroom: tuple[InRoomRecord, ...]
    negated: Mapping[str, int]


@functools.cache
def _raw() -> _Raw:
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
    return _Raw(scenes, tuple(activities), rooms, tuple(rels), tuple(inroom),
                MappingProxyType(dict(negated)))


def negated_relation_counts() -> dict[str, int]:
    """Counts of relation atoms under ``not`` in the activities (left out of the tables)."""
    return dict(_raw().negated)


# ----------------------------------------------------------------------------------------
# derived tables
# ----------------------------------------------------------------------------------------
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
    raw = _raw()
    return build_knowledge(raw.scenes, raw.activities, raw.rooms, raw.relations, raw.inroom)


def raw_records() -> _Raw:
    """The raw records of the whole package (for the split)."""
    return _raw()
