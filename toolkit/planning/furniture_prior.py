"""φ(q) of (B6) in :mod:`sgtool.planning.belief`: the prior that a query names a
first-level piece (furniture, a floor-standing holder) rather than a small object.

The table is knowledge, built outside the core (:mod:`sgtool.datasets.furniture_level`
writes ``furniture_level.json`` next to this module from BEHAVIOR-1K; the core never reads
BEHAVIOR-1K itself): name -> φ, names with φ = 0 left out. A caller may hand in any other
mapping (e.g. the furniture categories of a house spec's vocabulary, each with φ = 1).
"""

from __future__ import annotations

import json
from collections.abc import Iterator, Mapping
from functools import lru_cache
from pathlib import Path

from sgtool.errors import SgtoolError

LEVELS_FILE = Path(__file__).with_name("furniture_level.json")
LEVELS_VERSION = 1


class FurniturePriorError(SgtoolError):
    """A furniture-level table that cannot be read."""


class LevelTable(Mapping[str, float]):
    """A read-only name -> φ table (it pickles, so a planner holding one does)."""

    def __init__(self, levels: Mapping[str, float]) -> None:
        self._levels = dict(levels)

    def __getitem__(self, key: str) -> float:
        return self._levels[key]

    def __iter__(self) -> Iterator[str]:
        return iter(self._levels)

    def __len__(self) -> int:
        return len(self._levels)

    def __repr__(self) -> str:
        return f"LevelTable({len(self._levels)} names)"


def query_key(name: str) -> str:
    """The table's spelling of a name: lower case, words separated by single spaces."""
    return " ".join(name.replace("_", " ").lower().split())


def parse_levels(doc: object, source: str) -> Mapping[str, float]:
    """The name -> φ table of a ``furniture_level.json`` document (checked)."""
    levels = doc.get("levels") if isinstance(doc, dict) else None
    if not isinstance(doc, dict) or doc.get("version") != LEVELS_VERSION or \
            not isinstance(levels, dict):
        raise FurniturePriorError(f"{source}: not a version-{LEVELS_VERSION} furniture-level "
                                  "table (keys 'version', 'levels')")
    out: dict[str, float] = {}
    for k, v in levels.items():
        if not isinstance(v, int | float) or isinstance(v, bool) or not 0.0 <= v <= 1.0:
            raise FurniturePriorError(f"{source}: levels[{k!r}]: {v!r} is not in [0, 1]")
        out[query_key(k)] = float(v)
    return LevelTable(out)


@lru_cache(maxsize=4)
def load_levels(path: str | None = None) -> Mapping[str, float]:
    """The table at ``path`` (default: the shipped one)."""
    p = Path(path) if path else LEVELS_FILE
    try:
        doc = json.loads(p.read_text(encoding="utf-8"))
    except (OSError, ValueError) as e:
        raise FurniturePriorError(f"{p}: cannot read the furniture-level table: {e}") from None
    return parse_levels(doc, str(p))


def furniture_level(levels: Mapping[str, float] | None, query: str) -> float:
    """φ(query): the table's value, 0 for a name it does not list (or no table)."""
    return float(levels.get(query_key(query), 0.0)) if levels else 0.0
