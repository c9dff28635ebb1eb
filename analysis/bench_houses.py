"""The houses of a benchmark run: generated evaluation houses and house spec files.

A :class:`BenchHouse` names a house by an id string and says where its spec comes from:
a seed of the generator (``house-<seed>``, furnished from the evaluation split) or a spec
given by the user (a file, or a folder of ``*.json`` files). A given house is named by the
spec's own ``id`` when it has one, else by its file name without ``.json``.

:func:`load_house_files` reads and checks every given file before anything runs and refuses
the lot with one line per bad file (file and field, from :func:`sgtool.house.io.load_house`,
plus the benchmark's own needs: at least one small object to search for, a symbolic
house that can be built (:func:`symbolic_house_problem`: every room has free floor), an id
that can name a log folder (:func:`folder_name_problem`), no id given twice); a folder
without house files is a problem too, and a file of a folder that holds no house spec at
all (a stray ``manifest.json``) says that a folder is read as houses (:func:`folder_note`).
Generated houses are opt-in next to house files (:func:`generated_count`).
:func:`bench_episodes` lists a house's episodes with
:func:`sgtool.datasets.episodes.list_episodes`; a house without start poses gets one per
reachable room first (:func:`sgtool.datasets.start_poses.with_start_poses`).
"""

from __future__ import annotations

import json
import math
import os
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from sgtool.errors import SgtoolError, SpecError
from sgtool.files import quoted
from sgtool.house.consistency import wall_gaps
from sgtool.house.geometry import distance_to_polygon
from sgtool.house.io import house_file_id
from sgtool.house.spec import HouseSpec, SpecLimits
from sgtool.semantics.text import category_text


class HouseFilesError(SgtoolError):
    """House files that cannot be benchmarked; the message has one line per problem."""


@dataclass(frozen=True)
class BenchHouse:
    """One house of a run: ``spec`` for a given file, ``seed`` for a generated house."""

    id: str
    source: str  # the file, or "generated"
    spec: HouseSpec | None = None
    seed: int | None = None
    notes: tuple[str, ...] = ()  # what a user should know of a given house (walled-off rooms)

    def load(self, rooms: tuple[int, int], preset: str = "default") -> HouseSpec:
        """The spec (generated on demand with ``rooms`` and the generator ``preset`` for a
        generated house)."""
        if self.spec is not None:
            return self.spec
        from sgtool.datasets.generator import generate_house

        return generate_house(int(self.seed or 0), rooms=rooms, split="eval", preset=preset)


def generated_count(given: int | None, house_files: Sequence[str], default: int) -> int:
    """How many generated houses a run benches: ``given`` when the user gave a number;
    otherwise ``default`` without house files and none with them (next to a user's own
    houses, generated ones are opt-in, so that the tables hold only the user's houses)."""
    if given is not None:
        return given
    return 0 if house_files else default


def generated_houses(count: int, first_seed: int) -> tuple[BenchHouse, ...]:
    return tuple(BenchHouse(f"house-{first_seed + i}", "generated", seed=first_seed + i)
                 for i in range(count))


def folder_houses(folder: Path) -> list[Path]:
    """The house files of a folder: its ``*.json`` entries, the suffix in any case
    (``HOUSE.JSON``), sorted by name."""
    return sorted(p for p in folder.iterdir() if p.name.lower().endswith(".json"))


def _house_sources(paths: Iterable[str | os.PathLike[str]]) -> list[tuple[Path, Path | None]]:
    """Files as given, folders as their house files (:func:`folder_houses`), each with the
    folder it was found in (None: given as a file); a path that is neither is kept, so that
    loading it reports it."""
    out: list[tuple[Path, Path | None]] = []
    for p in map(Path, paths):
        try:
            is_dir = p.is_dir()
        except (OSError, ValueError) as e:  # a name too long, a NUL in it
            raise SgtoolError(f"{quoted(str(p))[:120]}: not a house file or folder "
                              f"({type(e).__name__}: {getattr(e, 'strerror', None) or e})"
                              ) from None
        out.extend([(f, p) for f in folder_houses(p)] if is_dir else [(p, None)])
    return out


def _not_a_house(path: Path) -> bool:
    """A file that holds no house spec at all (not a JSON object with ``rooms``)."""
    try:
        raw: Any = json.loads(path.read_text(encoding="utf-8-sig"))
    except (OSError, ValueError, RecursionError):
        return True
    return not (isinstance(raw, dict) and "rooms" in raw)


def folder_note(path: Path, folder: Path) -> str:
    """What a problem of ``path``, found in ``folder``, ends with when ``path`` is no house
    spec (a stray ``manifest.json``): that a folder is read as houses, and how to give
    files instead."""
    if not _not_a_house(path):
        return ""
    return (f" (a folder given to --house is read as houses: every *.json in {folder} is "
            "one; give the house files one by one with --house FILE, or move the other "
            "file out)")


def load_house_files(paths: Sequence[str | os.PathLike[str]],
                     taken: Iterable[str] | Mapping[str, str] = ()) -> tuple[BenchHouse, ...]:
    """Load and check every house file (module doc); ``taken`` are ids already in the run
    (the generated houses; a mapping: id -> what holds it, as a message names it). Raises
    :class:`HouseFilesError` listing every problem."""
    from sgtool.house.io import load_house

    files = _house_sources(paths)
    problems = [f"{p}: no *.json house files there" for p in map(Path, paths)
                if p.is_dir() and not folder_houses(p)]
    houses: list[BenchHouse] = []
    ids = dict(taken) if isinstance(taken, Mapping) else \
        {i: "a generated house" for i in taken}
    for f, folder in files:
        try:
            spec = load_house(f)
        except SpecError as e:
            problems.append(str(e) + (folder_note(f, folder) if folder is not None else ""))
            continue
        if not spec.objects:
            problems.append(f"{f}: objects: no small objects, nothing to search for")
            continue
        house, bad = symbolic_house(spec, f)
        if bad:
            problems.append(bad)
            continue
        hid = house_file_id(f)
        bad = folder_name_problem(hid)
        if bad:
            problems.append(f"{f}: id: the house id {hid!r} (its \"id\", else the file "
                            f"name) cannot name a log folder: {bad}")
            continue
        if hid in ids:
            again = ids[hid] == str(f) or (Path(ids[hid]).exists() and f.exists()
                                           and Path(ids[hid]).samefile(f))
            problems.append(f"{f}: given twice (a --house named it, or a folder holding it, "
                            "more than once): give it once" if again else
                            f"{f}: id: house id {hid!r} is already used by {ids[hid]}")
            continue
        ids[hid] = str(f)
        notes = house_notes(house) + completion_notes(f, spec)
        houses.append(BenchHouse(hid, str(f), spec=spec, notes=notes))
    if problems:
        raise HouseFilesError("\n".join(problems))
    return tuple(houses)


def check_house_files(paths: Sequence[str | os.PathLike[str]],
                      emit: Callable[[str], None] | None = None) -> tuple[list[str], bool]:
    """The checks of a bench run (:func:`load_house_files`) file by file: one line per
    house file (``ok FILE: id, counts`` and its notes, or the problem) and whether every
    file passed, ids across files included; ``emit`` gets each file's lines as soon as it
    is checked (a folder of big houses takes minutes)."""
    lines: list[str] = []

    def add(new: Iterable[str]) -> None:  # kept, and to ``emit`` at once
        for line in new:
            lines.append(line)
            if emit is not None:
                emit(line)

    add(f"error {p}: no *.json house files there" for p in map(Path, paths)
        if p.is_dir() and not folder_houses(p))
    empty = bool(lines)
    ids: dict[str, str] = {}  # the ids of the files that passed, each loaded once
    sources = _house_sources(paths)
    for f, _ in sources:
        try:
            (h,) = load_house_files([f], taken=ids)
        except HouseFilesError as e:  # its own problem, or an id an earlier file holds
            add(f"error {line}" for line in str(e).splitlines())
            continue
        spec = h.spec
        assert spec is not None
        queries = len({category_text(o.category) for o in spec.objects})
        counts = ", ".join(f"{n} {word}" for n, word in (
            (len(spec.rooms), "room(s)"), (len(spec.furniture), "piece(s) of furniture"),
            (len(spec.objects), "small object(s)"), (queries, "query category(ies)")))
        add([f"ok {f}: {h.id}: {counts}", *(f"   note: {n}" for n in h.notes)])
        if not spec.starts:  # (the symbolic bench draws its own starts: no note there)
            add(["   note: no start poses: the closed loop (run, run-bench) adds its own "
                 "(sgtool.datasets.start_poses)"])
        ids[h.id] = str(f)
    return lines, len(ids) == len(sources) and not empty


def symbolic_house_problem(spec: HouseSpec, where: str | os.PathLike[str]) -> str | None:
    """Why the benchmark's symbolic house cannot be built from ``spec`` (read from
    ``where``), as one line naming ``where`` and the room (a room without free floor for
    the robot that no door or passage joins to one with), or None. The check of
    :func:`load_house_files`, before any episode."""
    return symbolic_house(spec, where)[1]


def symbolic_house(spec: HouseSpec, where: str | os.PathLike[str]) -> tuple[Any, str | None]:
    """The benchmark's :class:`~sgtool.recorders.symbolic_environment.house.SymbolicHouse`
    of ``spec`` and None, or None and why it cannot be built
    (:func:`symbolic_house_problem`)."""
    from sgtool.recorders.symbolic_environment.house import SymbolicHouse

    try:
        return SymbolicHouse(spec), None
    except ValueError as e:  # "room room_0 has no free floor and no door or passage ..."
        return None, f"{where}: rooms: {e}"


DOOR_GAP = 0.02  # m between a door's two rooms: any gap is floor of neither (rounding)


def _classifier_room_types() -> frozenset[str]:
    """The room types (category text) the shipped priors' room classifier names; empty when
    their metadata cannot be read."""
    from sgtool.semantics.priors import PriorsVocabularyError, weights_metadata

    try:
        types = weights_metadata(None).get("room_types", ())
    except PriorsVocabularyError:
        return frozenset()
    return frozenset(category_text(t) for t in types if isinstance(t, str))


def house_notes(house: Any) -> tuple[str, ...]:
    """What a user should know of a house that loads: doors furniture blocks (read as
    walls), rooms walled off from the rest (their targets are searched from inside, the
    others' from outside), containers whose front is blocked, pieces no camera sees,
    pieces reaching through a wall, walls through a room's inside and starts nearer to
    walls or furniture than the robot's radius
    (:mod:`sgtool.house.clearance`)."""
    from sgtool.house.clearance import (
        CORNER_WALL,
        FRONT_CLEAR,
        back_is_clear,
        blocked_fronts,
        cramped_starts,
        doors_at_corners,
        hidden_pieces,
        pieces_in_walls,
        walls_in_rooms,
    )
    from sgtool.recorders.symbolic_environment.doorways import doorway_pieces

    spec = house.spec
    notes = []
    for di in sorted(house.blocked_doors):
        d = spec.doors[di]
        gap = sum(distance_to_polygon(d.center[0], d.center[1], spec.room(r).polygon)
                  for r in d.rooms)
        if gap > DOOR_GAP:
            notes.append(f"{d.id} ({' - '.join(d.rooms)}): the rooms are {gap:.2f} m apart at "
                         "the door: no floor joins them through it; read as a wall (move a "
                         "room's border to the door, or the door to where they meet)")
            continue
        near = doorway_pieces(spec, d, 1.0)
        notes.append(f"{d.id} ({' - '.join(d.rooms)}): the robot (radius "
                     f"{house.robot_radius:g} m) cannot get through it from one room's free "
                     "floor to the other's (" + (f"furniture within 1 m: {', '.join(near)}"
                                                 if near else "too narrow, or furniture "
                                                 "farther in cuts the door's side off") +
                     "); read as a wall")
    for di, room, left in doors_at_corners(spec):
        d = spec.doors[di]
        notes.append(f"{d.id} ({' - '.join(d.rooms)}): its opening ends {left:.2f} m from a "
                     f"corner of {room}: the replay may not find a door with no wall beside "
                     "it (where furniture stands near its swung leaf; the two rooms then "
                     f"merge): leave {CORNER_WALL:g} m of wall beside it")
    cut = house.isolated_rooms()
    if cut:
        notes.append(f"{', '.join(cut)}: no door or passage leads there from the rest of "
                     "the house; a search for a target inside starts there, any other outside")
    for k, what in blocked_fronts(spec):
        f = spec.furniture[k]
        fix = ("turn it to face the room: yaw + pi" if back_is_clear(spec, k) else
               f"move {what} away from it" if what.startswith("furn") else
               "move it away from the wall, or turn it to face open floor")
        notes.append(f"furniture[{k}] ({f.id}, {f.category}): {what} is within "
                     f"{FRONT_CLEAR:g} m of its front (its local +y face, where it opens); the "
                     f"closed loop cannot look into it ({fix})")
    for k, why in hidden_pieces(spec):
        f = spec.furniture[k]
        notes.append(f"furniture[{k}] ({f.id}, {f.category}): {why}: no camera sees it or "
                     "what it holds, which the symbolic bench finds all the same (furniture "
                     "centres are at half their height above the floor)")
    for k, wall, area, depth in pieces_in_walls(spec):
        f = spec.furniture[k]
        notes.append(f"furniture[{k}] ({f.id}, {f.category}): {area:.2f} m² of its "
                     f"footprint lies past {wall}'s far face, up to {depth:.2f} m: it "
                     "reaches through the wall (the simulator shows it on both sides; set it "
                     "against the wall's face)")
    for room, walls, inside in walls_in_rooms(spec):
        names = ", ".join(f"walls[{i}] ({spec.walls[i].id})" for i in walls[:4])
        more = f" and {len(walls) - 4} more" if len(walls) > 4 else ""
        notes.append(f"{names}{more} run {inside:.1f} m through {room}'s inside, not along "
                     "its border: the room is cut by them (give each part its own room) or "
                     "has a wall standing in it")
    turned = [f"{kind}[{i}] ({x.yaw:g})" for kind, items in (("furniture", spec.furniture),
                                                             ("starts", spec.starts))
              for i, x in enumerate(items) if abs(x.yaw) > 2 * math.pi + 1e-9]
    if turned:
        notes.append(f"yaw beyond 2 pi: {', '.join(turned[:5])}"
                     f"{f' and {len(turned) - 5} more' if len(turned) > 5 else ''}; yaws "
                     "are radians (degrees given by mistake turn a piece the wrong way)")
    parents = {x.parent for x in spec.objects}
    lidded = [o for o in spec.objects if o.is_openable and o.state == "closed"
              and o.id in parents]
    if lidded:
        notes.append(f"{', '.join(f'{o.id} ({o.category})' for o in lidded)}: closed small "
                     "object(s) holding others; the symbolic bench opens them, the closed "
                     "loop cannot (it opens furniture only): what is inside is not found "
                     "there")
    for i, gap in cramped_starts(spec, house.robot_radius):
        s = spec.starts[i]
        notes.append(f"starts[{i}] ({s.x:g}, {s.y:g}): {gap:.2f} m from a wall or a piece, "
                     f"less than the robot's radius ({house.robot_radius:g} m): the simulator "
                     "starts the robot at the nearest place clear of it")
    notes += unreachable_notes(spec)
    for j, i, gap, (gx, gy) in wall_gaps(spec, SpecLimits().opening_offset):
        notes.append(f"the walls between {spec.rooms[j].id} and {spec.rooms[i].id} have a "
                     f"{gap:.2f} m gap at ({gx:.2f}, {gy:.2f}) beside their door(s) or "
                     "passage(s): a hole in the wall the robot passes through, closed doors "
                     "or not (add a wall, or widen the opening)")
    named = _classifier_room_types()
    odd = sorted({r.category for r in spec.rooms} - {
        r.category for r in spec.rooms if category_text(r.category) in named})
    if named and odd:
        notes.append(f"room categories {', '.join(map(repr, odd))}: not a room type the "
                     "replay's room classifier names, so `replay --score` counts every such "
                     "room's category wrong; its types: " + ", ".join(sorted(named)))
    for ri in house.niches:
        notes.append(f"{spec.rooms[ri].id}: no free floor the robot (radius "
                     f"{house.robot_radius:g} m) fits on: the symbolic bench searches it from "
                     "the rooms next to it, the closed loop only sees into it from there")
    if not spec.walls:
        from sgtool.house.outline import outline_walls

        notes.append(f"no walls: the closed loop stands {len(outline_walls(spec))} along the "
                     "house's outer outline (gaps at its doors); inside, rooms meet on open "
                     "floor (the symbolic bench needs no walls)")
    for a, b in house.open_floor:
        notes.append(f"{spec.rooms[a].id} and {spec.rooms[b].id} share open floor (no wall) "
                     "but no door or passage: read as a passage (give the opening a passage "
                     "or a door, or the border a wall)")
    return tuple(notes)


def unreachable_notes(spec: HouseSpec) -> list[str]:
    """A note per piece holding small objects that the robot cannot get within reach of
    from the house's start poses, in a room it does enter
    (:meth:`~sgtool.datasets.episodes.EpisodeGeometry.unreachable_holders`; none without
    start poses)."""
    from sgtool.datasets.episodes import REACH, EpisodeGeometry

    if not spec.starts or not spec.objects:
        return []
    index = {f.id: k for k, f in enumerate(spec.furniture)}
    by_id = spec.object_by_id()
    notes = []
    for piece, ids in EpisodeGeometry(spec).unreachable_holders():
        held = ", ".join(f"{i} ({by_id[i].category})" for i in ids[:4])
        more = f" and {len(ids) - 4} more" if len(ids) > 4 else ""
        notes.append(f"furniture[{index[piece.id]}] ({piece.id}, {piece.category}) holds "
                     f"{held}{more}, but the robot cannot get within {REACH:g} m of it from "
                     "any start (furniture around it closes the way): the closed loop finds "
                     "what it holds by sight only and cannot open it (leave the robot a way "
                     "in); the symbolic bench reaches it all the same")
    return notes


def completion_notes(path: Path, spec: HouseSpec) -> tuple[str, ...]:
    """What the loader added to the file at ``path`` (``spec`` is what it loaded): the
    categories whose pieces it reads as supporters
    (:func:`sgtool.house.nesting.with_supporters`), found by comparing the two."""
    try:
        raw: Any = json.loads(path.read_text(encoding="utf-8-sig"))
        given = {str(x["id"]): set(x.get("affordances") or ())
                 for part in ("furniture", "objects") for x in raw.get(part) or ()}
    except (OSError, ValueError, TypeError, KeyError, AttributeError):
        return ()
    pieces = [(f.id, f.category, f.affordances) for f in spec.furniture] + \
        [(o.id, o.category, o.affordances) for o in spec.objects]
    added = sorted({cat for pid, cat, aff in pieces
                    if "supporter" in aff and "supporter" not in given.get(pid, {"supporter"})})
    if not added:
        return ()
    return (f"read as supporters, with something on top and no 'supporter' in the file: "
            f"{', '.join(added)}",)


MAX_NAME_BYTES = 255  # a file-name component on common file systems (NAME_MAX)


def folder_name_problem(name: str) -> str | None:
    """Why ``name`` cannot be one folder name of an output (a house id in a log path), or
    None: the rules of a house id (:func:`sgtool.house.names.folder_id_problem`) and the
    byte limit of a file-name component."""
    from sgtool.house.names import folder_id_problem

    bad = folder_id_problem(name)
    if bad is None and len(name.encode("utf-8", "surrogatepass")) > MAX_NAME_BYTES:
        bad = f"more than {MAX_NAME_BYTES} bytes as a file name"
    return bad


def output_path(root: str | os.PathLike[str], *names: str) -> Path:
    """``root / names[0] / names[1] / ...``, each name one folder or file name that stays
    inside ``root`` (:func:`folder_name_problem`); otherwise an :class:`SgtoolError`, before
    anything is written (the house files are checked first; this is the second defence)."""
    for n in names:
        bad = folder_name_problem(n)
        if bad:
            raise SgtoolError(f"{n!r} cannot name a folder or file inside {root}: "
                              f"{bad}")
    return Path(root).joinpath(*names)


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
