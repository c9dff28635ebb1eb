"""The houses of a benchmark run: generated evaluation houses and house spec files.

A :class:`BenchHouse` names a house by an id string and says where its spec comes from:
a seed of the generator (``house-<seed>``, furnished from the evaluation split) or a spec
given by the user (a file, or a folder of ``*.json`` files). A given house is named by the
spec's own ``id`` when it has one, else by its file name without ``.json``.

:func:`load_house_files` reads and checks every given file before anything runs and refuses
the lot with one line per bad file (file and field, from :func:`sgtool.house.io.load_house`,
plus the benchmark's own needs: at least one small object to search for, no id given
twice). :func:`bench_episodes` lists a house's episodes with
:func:`sgtool.datasets.episodes.list_episodes`; a house without start poses gets one per
reachable room first (:func:`sgtool.datasets.start_poses.with_start_poses`).
"""

from __future__ import annotations

import json
import os
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from sgtool.errors import SgtoolError, SpecError
from sgtool.house.spec import HouseSpec


class HouseFilesError(SgtoolError):
    """House files that cannot be benchmarked; the message has one line per problem."""


@dataclass(frozen=True)
class BenchHouse:
    """One house of a run: ``spec`` for a given file, ``seed`` for a generated house."""

    id: str
    source: str  # the file, or "generated"
    spec: HouseSpec | None = None
    seed: int | None = None

    def load(self, rooms: tuple[int, int], preset: str = "default") -> HouseSpec:
        """The spec (generated on demand with ``rooms`` and the generator ``preset`` for a
        generated house)."""
        if self.spec is not None:
            return self.spec
        from sgtool.datasets.generator import generate_house

        return generate_house(int(self.seed or 0), rooms=rooms, split="eval", preset=preset)


def generated_houses(count: int, first_seed: int) -> tuple[BenchHouse, ...]:
    return tuple(BenchHouse(f"house-{first_seed + i}", "generated", seed=first_seed + i)
                 for i in range(count))


def house_paths(paths: Iterable[str | os.PathLike[str]]) -> list[Path]:
    """Files as given, folders as their ``*.json`` files (sorted by name); a path that is
    neither is kept, so that loading it reports it."""
    out: list[Path] = []
    for p in map(Path, paths):
        out.extend(sorted(p.glob("*.json")) if p.is_dir() else [p])
    return out


def load_house_files(paths: Sequence[str | os.PathLike[str]],
                     taken: Iterable[str] = ()) -> tuple[BenchHouse, ...]:
    """Load and check every house file (module doc); ``taken`` are ids already in the run
    (the generated houses). Raises :class:`HouseFilesError` listing every problem."""
    from sgtool.house.io import load_house

    files = house_paths(paths)
    problems: list[str] = []
    if paths and not files:
        problems.append(f"{', '.join(map(str, paths))}: no *.json house files there")
    houses: list[BenchHouse] = []
    ids = {i: "a generated house" for i in taken}
    for f in files:
        try:
            spec = load_house(f)
        except SpecError as e:
            problems.append(str(e))
            continue
        if not spec.objects:
            problems.append(f"{f}: objects: no small objects, nothing to search for")
            continue
        hid = _house_id(spec, f)
        if hid in ids:
            problems.append(f"{f}: id: house id {hid!r} is already used by {ids[hid]}")
            continue
        ids[hid] = str(f)
        houses.append(BenchHouse(hid, str(f), spec=spec))
    if problems:
        raise HouseFilesError("\n".join(problems))
    return tuple(houses)


def _house_id(spec: HouseSpec, path: Path) -> str:
    own = getattr(spec, "id", None)
    if not own:
        try:
            raw: Any = json.loads(path.read_text(encoding="utf-8"))
            own = raw.get("id") if isinstance(raw, dict) else None
        except (OSError, ValueError):
            own = None
    return own if isinstance(own, str) and own.strip() else path.stem


def bench_episodes(spec: HouseSpec, count: int, preset: str = "default") -> list[Any]:
    """``count`` episodes of the house, drawn with the house's seed (the same for every
    bench seed), start poses added when the spec has none. The ``symsearch`` preset mixes
    in furniture-level (non-interactive) targets as SymSearch does
    (:func:`sgtool.datasets.episode_mix.symsearch_episodes`)."""
    from sgtool.datasets.episode_mix import symsearch_episodes
    from sgtool.datasets.episodes import list_episodes
    from sgtool.datasets.start_poses import with_start_poses

    spec = with_start_poses(spec, spec.seed)
    if preset == "symsearch":
        return symsearch_episodes(spec, count, seed=spec.seed)
    return list_episodes(spec, count, seed=spec.seed)
