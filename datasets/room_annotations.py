"""ProcTHOR's room-type annotations of AI2-THOR object types, as containment targets.

Source: ``procthor/databases/placement-annotations.json`` in the ``procthor`` wheel
(version 0.0.1.dev2, Apache-2.0): for each of ~100 AI2-THOR object types, the authors'
annotation of how often it is placed in each of the four room types ProcTHOR builds
(``inKitchens``, ``inLivingRooms``, ``inBedrooms``, ``inBathrooms``: 0 never, 1 sometimes,
2 often; ``null`` for structure such as windows). These are annotations, not scenes: no
iTHOR or RoboTHOR room inventory is read. The converter writes the small derived table
:data:`SHIPPED` (``datasets/data/procthor_room_annotations.json``) so that training needs
no ``procthor`` install; nothing is downloaded at run time.

Targets (:func:`room_targets`): 2 -> 1.0 (the name's room), 1 -> :data:`SOMETIMES`, 0 -> 0.0
(never: a trained negative). Types with a ``null`` or no room above 0 are left out. Names
are the types' words (``SoapBar`` -> ``soap bar``,
:func:`sgtool.datasets.robothor_houses.type_words`), room types spelled as the
knowledge's (``living_room``).

CLI: ``python -m sgtool.datasets.room_annotations [--source WHEEL_OR_JSON]`` rewrites
:data:`SHIPPED` from the installed ``procthor`` (or the given wheel / JSON file).
"""

from __future__ import annotations

import argparse
import json
import sys
import zipfile
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from sgtool.datasets.robothor_houses import type_words
from sgtool.errors import SgtoolError

MEMBER = "procthor/databases/placement-annotations.json"
SHIPPED = Path(__file__).resolve().parent / "data" / "procthor_room_annotations.json"
ROOM_KEYS = {"inKitchens": "kitchen", "inLivingRooms": "living_room",
             "inBedrooms": "bedroom", "inBathrooms": "bathroom"}
SOMETIMES = 0.25  # target of a "sometimes" (1) annotation: a weak positive


def read_annotations(source: Path | None = None) -> dict[str, Any]:
    """The annotation JSON: from ``source`` (the file or a ``procthor`` wheel), else from
    the installed ``procthor`` distribution; one-line :class:`SgtoolError` otherwise."""
    try:
        if source is None:
            from importlib.metadata import PackageNotFoundError, distribution
            try:
                path = Path(str(distribution("procthor").locate_file(MEMBER)))
            except PackageNotFoundError:
                raise SgtoolError("procthor is not installed: pip install procthor==0.0.1.dev2 "
                                  "(or pass --source FILE)") from None
            text = path.read_text(encoding="utf-8")
        elif zipfile.is_zipfile(source):
            with zipfile.ZipFile(source) as z:
                text = z.read(MEMBER).decode("utf-8")
        else:
            text = source.read_text(encoding="utf-8")
        data = json.loads(text)
    except (OSError, KeyError, ValueError) as e:
        raise SgtoolError(f"cannot read the ProcTHOR placement annotations: {e}") from None
    if not isinstance(data, dict) or not all(isinstance(data.get(k), dict) for k in ROOM_KEYS):
        raise SgtoolError(f"the placement annotations lack one of {sorted(ROOM_KEYS)}")
    return data


def annotation_levels(data: dict[str, Any]) -> dict[str, dict[str, int]]:
    """``{name: {room type: 0 | 1 | 2}}`` of the types annotated in every room type and
    placed in at least one (sorted by name)."""
    out: dict[str, dict[str, int]] = {}
    for obj in sorted(data["inKitchens"]):
        levels = {room: data[key].get(obj) for key, room in ROOM_KEYS.items()}
        if any(not isinstance(v, int) or v not in (0, 1, 2) for v in levels.values()):
            continue
        if max(levels.values()) > 0:
            out[type_words(obj)] = {r: int(v) for r, v in sorted(levels.items())}
    return dict(sorted(out.items()))


def load_levels(path: Path = SHIPPED) -> dict[str, dict[str, int]]:
    """The shipped (or given) table of :func:`annotation_levels`."""
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
        return {str(n): {str(r): int(v) for r, v in rooms.items()}
                for n, rooms in data["levels"].items()}
    except (OSError, KeyError, ValueError, AttributeError) as e:
        raise SgtoolError(f"{path}: not a room-annotation table ({e})") from None


def room_targets(levels: dict[str, dict[str, int]]) -> dict[str, dict[str, float]]:
    """Containment targets of the annotation levels (module doc)."""
    value = {0: 0.0, 1: SOMETIMES, 2: 1.0}
    return {n: {r: value[v] for r, v in rooms.items()} for n, rooms in levels.items()}


def main(argv: Sequence[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m sgtool.datasets.room_annotations",
                                 description="ProcTHOR room annotations -> " + SHIPPED.name)
    ap.add_argument("--source", type=Path, default=None,
                    help="placement-annotations.json or the procthor wheel "
                         "[default: the installed procthor]")
    ap.add_argument("--out", type=Path, default=SHIPPED, help=f"[default: {SHIPPED}]")
    args = ap.parse_args(argv)
    try:
        levels = annotation_levels(read_annotations(args.source))
    except SgtoolError as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    from sgtool.files import atomic_write

    doc = {"source": f"procthor 0.0.1.dev2 {MEMBER} (Apache-2.0)",
           "levels": levels}
    atomic_write(args.out, json.dumps(doc, indent=1, sort_keys=True) + "\n")
    print(f"{len(levels)} object types -> {args.out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
