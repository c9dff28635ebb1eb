"""Top-1 room-type accuracy of the room classifiers on rooms' ground-truth contents.

For every room of the given houses that holds at least one piece or object, each classifier
of :func:`sgtool.datasets.room_evidence.make_classifier` (``containment``, ``frequency``:
naive Bayes over the training scenes with the containment model for a room none of whose
categories it names) is given the categories of everything in the room, and again a random
half of them (seeded; at least one), the way a robot sees part of a room. A room counts as
right when the classifier's best type is the room's category; an empty answer (unknown)
counts as wrong.

    .venv/bin/python benchmarks/room_classifiers.py [--houses N] [--house-seed S]
        [--house PATH ...] [--json PATH]

Generated houses are the bench's evaluation-split houses (``--rooms 8-16``, symsearch
preset); ``--house`` adds spec files or folders (e.g. ``datasets/data/robothor``, a source
the classifiers were not built from). Figures: docs/experiments/room-classifiers.md.
"""

from __future__ import annotations

import argparse
import random
from collections import defaultdict
from collections.abc import Iterator, Sequence
from pathlib import Path
from typing import Any

from harness import add_output_options, emit

from sgtool.datasets.generator import generate_house
from sgtool.datasets.room_evidence import make_classifier
from sgtool.house.io import load_house
from sgtool.house.spec import HouseSpec

CLASSIFIERS = ("containment", "frequency")
SHARES = (1.0, 0.5)


def _houses(count: int, first: int, paths: Sequence[str]) -> Iterator[tuple[str, HouseSpec]]:
    for seed in range(first, first + count):
        yield "generated", generate_house(seed, rooms=(8, 16), split="eval", preset="symsearch")
    for p in paths:
        path = Path(p)
        files = sorted(path.glob("*.json")) if path.is_dir() else [path]
        for f in files:
            yield path.name, load_house(f)


def room_contents(house: HouseSpec) -> dict[str, list[str]]:
    """Room id -> categories of its pieces and objects, in spec order."""
    out: dict[str, list[str]] = defaultdict(list)
    for f in house.furniture:
        out[f.room].append(f.category)
    for o in house.objects:
        out[o.room].append(o.category)
    return out


def accuracy(houses: Sequence[tuple[str, HouseSpec]], seed: int = 0) -> dict[str, Any]:
    """{source: {share: {"rooms": n, classifier: accuracy}}} (module doc)."""
    clfs = {n: make_classifier(n) for n in CLASSIFIERS}
    rng = random.Random(seed)
    hits: dict[tuple[str, float, str], int] = defaultdict(int)
    for source, house in houses:
        contents = room_contents(house)
        for room in house.rooms:
            cats = contents.get(room.id, [])
            if not cats:
                continue
            for share in SHARES:
                part = [c for c in cats if rng.random() < share] or cats[:1]
                hits[(source, share, "rooms")] += 1
                for name, clf in clfs.items():
                    ranked = clf.classify(part) if clf is not None else []
                    hits[(source, share, name)] += bool(ranked) and ranked[0][0] == room.category
    out: dict[str, Any] = {}
    for (source, share, key), n in sorted(hits.items()):
        out.setdefault(source, {}).setdefault(f"{share:g}", {})[key] = n
    for per_share in out.values():
        for row in per_share.values():
            for name in CLASSIFIERS:
                row[name] = round(row.get(name, 0) / row["rooms"], 3)
    return out


def main(argv: Sequence[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--houses", type=int, default=30, help="generated houses [30]")
    ap.add_argument("--house-seed", type=int, default=100, help="first house seed [100]")
    ap.add_argument("--house", action="append", default=[], help="house spec file or folder")
    add_output_options(ap)
    args = ap.parse_args(argv)
    res = accuracy(list(_houses(args.houses, args.house_seed, args.house)))
    lines = ["| source | share of contents | rooms | " + " | ".join(CLASSIFIERS) + " |",
             "|---|---|---|" + "---|" * len(CLASSIFIERS)]
    for source, per_share in res.items():
        for share, row in per_share.items():
            lines.append(f"| {source} | {share} | {row['rooms']} | "
                         + " | ".join(f"{row[n]:.3f}" for n in CLASSIFIERS) + " |")
    print("\n".join(lines))
    emit(res, args.json_out)


if __name__ == "__main__":
    main()
