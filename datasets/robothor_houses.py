"""House specs from the RoboTHOR apartments shipped in the ``procthor`` PyPI package.

Source: ``procthor/databases/ai2thor-object-metadata.json`` in the ``procthor`` wheel
(version 0.0.1.dev2, Apache-2.0), key ``"robothor"``: 75 artist-made RoboTHOR apartments
(AI2-THOR object metadata: type, axis-aligned box, ``parentReceptacles``, ``openable`` /
``isOpen``), in the file's order (the scene names are not in the file; house ``i`` is entry
``i``). The same file's ``kitchens`` / ``living_rooms`` / ``bedrooms`` / ``bathrooms``
(iTHOR) are not used. Nothing is downloaded at run time: the converter reads an installed
``procthor`` distribution, its wheel (``pip download --no-deps procthor==0.0.1.dev2``) or
the JSON file itself (:func:`read_scenes`).

What is taken from the data and what is derived (docs/houses-robothor.md says why):

- **Coordinates**: AI2-THOR (x, y up, z) -> spec (x, z, y): a mirror image of the scene,
  which changes no distance. Every box is the object's axis-aligned box (``yaw`` 0).
- **Furniture**: every object without a parent receptacle (floor-standing pieces, and
  things lying on the floor such as a baseball bat) and every fixed one (neither
  pickupable nor moveable: a desk AI2-THOR lists "on" the chair pushed under it), except
  wall decoration (:data:`DROPPED`). ``Drawer`` and ``Shelf`` parts join the piece
  whose footprint holds them (:func:`host_of`): a piece with drawers is an openable
  container (closed unless a drawer is open), unless something rests on one of its lower
  shelves (open shelving the reveal rule would otherwise hide); a shelf holding objects
  becomes one of the piece's ``levels`` (height of the objects' bottoms above the piece's
  bottom, 1 cm groups).
- **Small objects**: every other object with a parent receptacle. Its parent is the
  smallest listed receptacle (by box volume); a shelf or drawer stands for its piece. ``Box``
  parents (openable) hold their objects ``inside`` when the box encloses them (centre
  moved into the box if needed), everything else is ``ontop``, its bottom moved onto the
  nearest support surface of the parent (the validator allows 1 cm) and its centre into
  the parent's footprint. Category names split AI2-THOR's CamelCase type
  (``AlarmClock`` -> ``alarm clock``, ``TVStand`` -> ``tv stand``; :func:`type_words`).
- **Rooms** (not in the data, derived): the apartments are long open-plan strips. Anchor
  pieces name room categories (:data:`ANCHORS`); the strip is cut across its long axis in
  a gap free of furniture between consecutive anchors of different categories (the gap
  nearest their midpoint; anchors with no such gap share a room, named by the first in
  :data:`ANCHOR_PRIORITY`). Rooms are the resulting rectangles around all furniture plus
  :data:`MARGIN`, joined by open passages along each cut, in one open-plan group, with
  four outer walls; start poses from :func:`sgtool.datasets.start_poses.with_start_poses`.

CLI: ``python -m sgtool.datasets.robothor_houses OUT [--metadata FILE] [--scenes 0-14]``.
"""

from __future__ import annotations

import argparse
import json
import math
import re
import sys
import zipfile
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from sgtool.datasets.start_poses import with_start_poses
from sgtool.errors import SgtoolError
from sgtool.house.io import save_house
from sgtool.house.parse import parse_house
from sgtool.house.spec import (
    Furniture,
    HouseSpec,
    Passage,
    Room,
    SmallObject,
    Wall,
)

METADATA_MEMBER = "procthor/databases/ai2thor-object-metadata.json"
SOURCE_KEY = "robothor"
DROPPED = frozenset({"Painting"})  # hangs on a wall: no floor footprint, holds nothing
PARTS = frozenset({"Drawer", "Shelf"})
ANCHORS: Mapping[str, str] = {"Bed": "bedroom", "DiningTable": "dining_room",
                              "Sofa": "living_room", "CoffeeTable": "living_room",
                              "Desk": "private_office"}
ANCHOR_PRIORITY = ("bedroom", "dining_room", "living_room", "private_office")
MARGIN = 0.6  # m of floor around the outermost furniture
LEVEL_GROUP = 0.01  # m: shelf-resting objects whose bottoms are this close share a level
_INSET = 0.002  # m an adjusted centre stays inside a parent's box (above the rounding)


@dataclass(frozen=True)
class Thing:
    """One AI2-THOR object, in spec coordinates (x, y ground, z up)."""

    id: str  # AI2-THOR objectId
    type: str  # AI2-THOR objectType
    center: tuple[float, float, float]
    size: tuple[float, float, float]
    parents: tuple[str, ...]
    openable: bool
    is_open: bool
    fixed: bool = False  # neither pickupable nor moveable: a piece of furniture

    @property
    def bottom(self) -> float:
        return self.center[2] - self.size[2] / 2.0

    @property
    def top(self) -> float:
        return self.center[2] + self.size[2] / 2.0

    @property
    def volume(self) -> float:
        return self.size[0] * self.size[1] * self.size[2]

    def holds_xy(self, x: float, y: float) -> bool:
        return (abs(x - self.center[0]) <= self.size[0] / 2.0
                and abs(y - self.center[1]) <= self.size[1] / 2.0)


def thing(obj: Mapping[str, Any]) -> Thing:
    """A :class:`Thing` from one AI2-THOR metadata object (its axis-aligned box)."""
    box = obj["axisAlignedBoundingBox"]
    c, s = box["center"], box["size"]
    return Thing(id=str(obj["objectId"]), type=str(obj["objectType"]),
                 center=(float(c["x"]), float(c["z"]), float(c["y"])),
                 size=(float(s["x"]), float(s["z"]), float(s["y"])),
                 parents=tuple(str(p) for p in obj.get("parentReceptacles") or ()),
                 openable=bool(obj.get("openable")), is_open=bool(obj.get("isOpen")),
                 fixed=not obj.get("pickupable") and not obj.get("moveable"))


def type_words(object_type: str) -> str:
    """AI2-THOR's CamelCase type as lower-case words: ``AlarmClock`` -> ``alarm clock``,
    ``TVStand`` -> ``tv stand``, ``CD`` -> ``cd``."""
    parts = re.findall(r"[A-Z]+(?=[A-Z][a-z])|[A-Z]?[a-z]+|[A-Z]+|\d+", object_type)
    return " ".join(p.lower() for p in parts) or object_type.lower()


def synset_of(category: str) -> str:
    """A WordNet-style name for a category (``alarm clock`` -> ``alarm_clock.n.01``); the
    source has no synsets, so this is a label, not a WordNet look-up."""
    return category.replace(" ", "_") + ".n.01"


def host_of(part: Thing, pieces: Sequence[Thing]) -> Thing | None:
    """The piece of furniture a drawer or shelf belongs to: the smallest footprint holding
    the part's centre whose height range holds the part's centre height (5 cm slack)."""
    x, y, z = part.center
    best: Thing | None = None
    for p in pieces:
        if p.holds_xy(x, y) and p.bottom - 0.05 <= z <= p.top + 0.05:
            if best is None or p.size[0] * p.size[1] < best.size[0] * best.size[1]:
                best = p
    return best


def cut_points(intervals: Sequence[tuple[float, float]],
               anchors: Sequence[tuple[float, str]]) -> tuple[list[float], list[str]]:
    """Where to cut a strip and the categories of the pieces between the cuts.

    ``intervals``: the furniture's extents along the strip; ``anchors``: (position,
    room category) of the anchor pieces. Consecutive anchors of one category form a group;
    between two groups the cut is the middle of the furniture-free gap nearest the
    midpoint of the groups' facing anchors, or, with no free gap there, the groups merge
    (category: first in :data:`ANCHOR_PRIORITY`). Returns ascending cuts and one category
    per room (``len(cuts) + 1``); no anchors: one living room."""
    if not anchors:
        return [], ["living_room"]
    merged: list[list[float]] = []
    for a, b in sorted(intervals):
        if merged and a <= merged[-1][1]:
            merged[-1][1] = max(merged[-1][1], b)
        else:
            merged.append([a, b])
    gaps = [(merged[i][1] + merged[i + 1][0]) / 2.0 for i in range(len(merged) - 1)]
    groups: list[tuple[float, float, list[str]]] = []  # (first u, last u, categories)
    for u, cat in sorted(anchors):
        if groups and groups[-1][2][-1] == cat:
            groups[-1] = (groups[-1][0], u, groups[-1][2])
        else:
            groups.append((u, u, [cat]))
    cuts: list[float] = []
    cats: list[list[str]] = [groups[0][2]]
    last = groups[0][1]
    for first, end, gcats in groups[1:]:
        mid = (last + first) / 2.0
        between = [g for g in gaps if last < g < first]
        if between:
            cuts.append(min(between, key=lambda g: (abs(g - mid), g)))
            cats.append(list(gcats))
        else:
            cats[-1].extend(gcats)
        last = end
    names = [min(c, key=ANCHOR_PRIORITY.index) for c in cats]
    keep = [i for i in range(len(cuts)) if names[i] != names[i + 1]]  # same name: one room
    return [cuts[i] for i in keep], [names[0]] + [names[i + 1] for i in keep]


def convert_scene(objects: Sequence[Mapping[str, Any]], seed: int = 0) -> HouseSpec:
    """One RoboTHOR apartment (its list of AI2-THOR metadata objects) as a checked
    :class:`HouseSpec` (rules in the module docstring); raises :class:`SgtoolError` when
    the scene has no furniture, :class:`~sgtool.errors.SpecError` if the result does not
    validate."""
    things = [thing(o) for o in objects]
    by_id = {t.id: t for t in things}
    kept = [t for t in things if t.type not in DROPPED]
    pieces = [t for t in kept if (t.fixed or not t.parents) and t.type not in PARTS]
    if not pieces:
        raise SgtoolError("robothor scene has no furniture")
    part_host: dict[str, Thing] = {}
    for t in kept:
        if t.type in PARTS and not t.parents:
            host = host_of(t, pieces)
            if host is None:  # a free-standing shelf or drawer: a piece of its own
                pieces.append(t)
            else:
                part_host[t.id] = host
    smalls = [t for t in kept if t.parents and not t.fixed and t.type not in PARTS]

    # ----- parents: the smallest listed receptacle, parts standing for their piece -------
    parent_of: dict[str, Thing] = {}
    on_shelf: set[str] = set()
    holders = {t.id for t in smalls} | {p.id for p in pieces} | set(part_host)
    for t in smalls:
        listed = [by_id[p] for p in t.parents if p in holders]
        if not listed:
            continue
        p = min(listed, key=lambda q: (q.volume, q.id))
        if p.id in part_host:
            if p.type == "Shelf":
                on_shelf.add(t.id)
            p = part_host[p.id]
        parent_of[t.id] = p
    smalls = [t for t in smalls if t.id in parent_of]

    # ----- levels and states of the pieces ------------------------------------------------
    levels: dict[str, list[float]] = {}
    for t in smalls:
        p = parent_of[t.id]
        if t.id in on_shelf and t.bottom < p.top - LEVEL_GROUP:
            h = max(0.0, round(t.bottom - p.bottom, 2))
            lv = levels.setdefault(p.id, [])
            if all(abs(h - q) > LEVEL_GROUP for q in lv):
                lv.append(h)
    drawers: dict[str, list[Thing]] = {}
    for pid, host in part_host.items():
        if by_id[pid].type == "Drawer":
            drawers.setdefault(host.id, []).append(by_id[pid])
    supporting = {parent_of[t.id].id for t in smalls}
    boxes = {parent_of[t.id].id for t in smalls
             if parent_of[t.id].type == "Box" and parent_of[t.id].openable}

    # ----- rooms --------------------------------------------------------------------------
    xs = [c for p in pieces for c in (p.center[0] - p.size[0] / 2, p.center[0] + p.size[0] / 2)]
    ys = [c for p in pieces for c in (p.center[1] - p.size[1] / 2, p.center[1] + p.size[1] / 2)]
    x0, x1 = min(xs) - MARGIN, max(xs) + MARGIN
    y0, y1 = min(ys) - MARGIN, max(ys) + MARGIN
    along_x = (x1 - x0) >= (y1 - y0)
    ax = 0 if along_x else 1
    intervals = [(p.center[ax] - p.size[ax] / 2, p.center[ax] + p.size[ax] / 2) for p in pieces]
    anchors = [(p.center[ax], ANCHORS[p.type]) for p in pieces if p.type in ANCHORS]
    cuts, cats = cut_points(intervals, anchors)
    lo, hi = (x0, x1) if along_x else (y0, y1)
    bounds = [lo, *cuts, hi]
    rooms: list[Room] = []
    for i, cat in enumerate(cats):
        a, b = bounds[i], bounds[i + 1]
        poly = ((a, y0), (b, y0), (b, y1), (a, y1)) if along_x else \
            ((x0, a), (x1, a), (x1, b), (x0, b))
        rooms.append(Room(id=f"room_{i}", category=cat, polygon=poly,
                          open_plan_group="apartment" if cuts else None))
    passages = []
    for i, c in enumerate(cuts):
        if along_x:
            center, width, yaw = (c, (y0 + y1) / 2), (y1 - y0) - 0.2, math.pi / 2
        else:
            center, width, yaw = ((x0 + x1) / 2, c), (x1 - x0) - 0.2, 0.0
        passages.append(Passage(id=f"pass_{i}", center=center, width=width, yaw=round(yaw, 4),
                                rooms=(f"room_{i}", f"room_{i + 1}")))
    corners = [(x0, y0), (x1, y0), (x1, y1), (x0, y1)]
    walls = tuple(Wall(id=f"wall_{i}", a=corners[i], b=corners[(i + 1) % 4]) for i in range(4))

    def room_of(x: float, y: float) -> str:
        u = x if along_x else y
        return f"room_{sum(1 for c in cuts if u > c)}"

    # ----- furniture ----------------------------------------------------------------------
    furn_id: dict[str, str] = {}
    furniture: list[Furniture] = []
    for i, p in enumerate(sorted(pieces, key=lambda q: (q.center, q.id))):
        fid = f"furn_{i}"
        furn_id[p.id] = fid
        aff: set[str] = set()
        state = None
        if p.id in supporting:
            aff.add("supporter")
        lv = sorted(levels.get(p.id, []))
        if p.id in drawers and not lv:
            aff |= {"container", "openable"}
            state = "open" if any(d.is_open for d in drawers[p.id]) else "closed"
        elif p.id in boxes:
            aff |= {"container", "openable"}
            state = "open" if p.is_open else "closed"
        cat = type_words(p.type)
        furniture.append(Furniture(id=fid, category=cat, synset=synset_of(cat),
                                   room=room_of(p.center[0], p.center[1]), center=p.center,
                                   size=p.size, affordances=tuple(sorted(aff)), state=state,
                                   levels=tuple(lv)))
    furn_by = {f.id: f for f in furniture}

    # ----- small objects, parents before children -----------------------------------------
    def depth(t: Thing) -> int:
        d, cur = 0, t
        while cur.id in parent_of and d < 16:
            cur, d = parent_of[cur.id], d + 1
        return d

    placed: dict[str, SmallObject] = {}
    obj_id = {t.id: f"obj_{i}" for i, t in
              enumerate(sorted(smalls, key=lambda q: (depth(q), q.center, q.id)))}
    for t in sorted(smalls, key=lambda q: (depth(q), q.center, q.id)):
        p = parent_of[t.id]
        if p.id in furn_id:
            holder: Furniture | SmallObject = furn_by[furn_id[p.id]]
            room = holder.room
        elif p.id in placed:
            holder = placed[p.id]
            room = holder.room
        else:
            continue
        relation, pos = _place(t, holder, p.id in boxes)
        cat = type_words(t.type)
        box = t.id in boxes  # a box holding something: an openable container
        placed[t.id] = SmallObject(id=obj_id[t.id], category=cat, synset=synset_of(cat),
                                   parent=holder.id, relation=relation, room=room,
                                   position=pos, size=t.size,
                                   affordances=("container", "openable") if box else (),
                                   state=("open" if t.is_open else "closed") if box else None)
    out = sorted(placed.values(), key=lambda q: int(q.id.split("_")[1]))

    spec = HouseSpec(seed=seed, rooms=tuple(rooms), walls=walls, doors=(),
                     furniture=tuple(furniture), objects=tuple(out), starts=(),
                     passages=tuple(passages))
    spec = with_start_poses(spec, seed)
    return parse_house(json.loads(spec.to_json()))  # the validator's verdict, and rounding


def _place(t: Thing, holder: Furniture | SmallObject,
           may_enclose: bool) -> tuple[str, tuple[float, float, float]]:
    """Relation and adjusted position of ``t`` on/in ``holder`` (module docstring)."""
    if isinstance(holder, Furniture):
        hc, hs = holder.center, holder.size
    else:
        hc, hs = holder.position, holder.size

    def clamp(v: float, c: float, half: float, own: float) -> float:
        room = max(0.0, half - own - _INSET)
        return min(max(v, c - room), c + room)

    x, y, z = t.center
    if may_enclose and all(t.size[i] <= hs[i] - 2 * _INSET for i in range(3)):
        x = clamp(x, hc[0], hs[0] / 2, t.size[0] / 2)
        y = clamp(y, hc[1], hs[1] / 2, t.size[1] / 2)
        z = clamp(z, hc[2], hs[2] / 2, t.size[2] / 2)
        return "inside", (x, y, z)
    x = clamp(x, hc[0], hs[0] / 2, 0.0)
    y = clamp(y, hc[1], hs[1] / 2, 0.0)
    s = min(holder.supports, key=lambda q: abs(q - t.bottom))
    return "ontop", (x, y, s + t.size[2] / 2.0)


# ----- I/O ----------------------------------------------------------------------------------
def read_scenes(source: Path | None = None) -> list[list[dict[str, Any]]]:
    """The RoboTHOR scenes: from ``source`` (the JSON file, or a ``procthor`` wheel), else
    from the installed ``procthor`` distribution. Raises :class:`SgtoolError` in one line
    when none is found or the file is not the expected shape."""
    try:
        if source is None:
            from importlib.metadata import PackageNotFoundError, distribution
            try:
                path = Path(str(distribution("procthor").locate_file(METADATA_MEMBER)))
            except PackageNotFoundError:
                raise SgtoolError("procthor is not installed: pip install procthor==0.0.1.dev2 "
                                  "(or pass --metadata FILE)") from None
            text = path.read_text(encoding="utf-8")
        elif zipfile.is_zipfile(source):
            with zipfile.ZipFile(source) as z:
                text = z.read(METADATA_MEMBER).decode("utf-8")
        else:
            text = source.read_text(encoding="utf-8")
        data = json.loads(text)
    except (OSError, KeyError, ValueError) as e:
        raise SgtoolError(f"cannot read the RoboTHOR metadata: {e}") from None
    scenes = data.get(SOURCE_KEY) if isinstance(data, dict) else None
    if not isinstance(scenes, list) or not all(isinstance(s, list) for s in scenes):
        raise SgtoolError(f"the metadata has no list of scenes under {SOURCE_KEY!r}")
    return scenes


def _scene_range(text: str, n: int) -> list[int]:
    a, _, b = text.partition("-")
    try:
        lo, hi = int(a), int(b or a)
    except ValueError:
        raise SgtoolError(f"--scenes: expected N or N-M, got {text!r}") from None
    if not 0 <= lo <= hi < n:
        raise SgtoolError(f"--scenes: {text} is outside 0-{n - 1}")
    return list(range(lo, hi + 1))


def main(argv: Sequence[str] | None = None) -> int:
    """``python -m sgtool.datasets.robothor_houses OUT``: write ``robothor_NN.json`` house
    specs (one per chosen scene) into the folder OUT; prints one line per house."""
    ap = argparse.ArgumentParser(prog="python -m sgtool.datasets.robothor_houses",
                                 description="RoboTHOR apartments (procthor package) as "
                                             "sgtool house specs")
    ap.add_argument("out", type=Path, help="folder for robothor_NN.json")
    ap.add_argument("--metadata", type=Path, default=None,
                    help="ai2thor-object-metadata.json or the procthor wheel "
                         "[default: the installed procthor]")
    ap.add_argument("--scenes", default=None, help="N or N-M (file order) [default: all]")
    args = ap.parse_args(argv)
    try:
        scenes = read_scenes(args.metadata)
        chosen = _scene_range(args.scenes, len(scenes)) if args.scenes else \
            list(range(len(scenes)))
        args.out.mkdir(parents=True, exist_ok=True)
        for i in chosen:
            spec = convert_scene(scenes[i], seed=i)
            save_house(spec, args.out / f"robothor_{i:02d}.json")
            print(f"robothor_{i:02d}: {len(spec.rooms)} rooms "
                  f"({', '.join(r.category for r in spec.rooms)}), "
                  f"{len(spec.furniture)} furniture, {len(spec.objects)} objects")
    except (SgtoolError, OSError) as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
