"""Synsets of the installed ``bddl`` package (BEHAVIOR-1K, MIT): readable names, the
catalogue of flags and hypernyms, hypernym closure, OmniGibson category -> synset.

Read from ``generated_data/synsets.csv`` and ``generated_data/category_mapping.csv``;
nothing is downloaded. Readable names (:func:`readable_name`): ``electric_refrigerator.n.01``
-> "refrigerator", ``pack__of__ground_beef.n.01`` -> "pack of ground beef"; the synset is
kept alongside everywhere.
"""

from __future__ import annotations

import csv
import functools
import re
from collections import defaultdict
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from types import MappingProxyType

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


@dataclass(frozen=True)
class SynsetInfo:
    synset: str
    name: str
    hypernyms: tuple[str, ...]
    kind: str  # "furniture" | "object" | "structure" | "substance" | "abstract"
    openable: bool


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
            out[s] = SynsetInfo(s, readable_name(s), hyp, kind, row.get("openable") == "1")
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
