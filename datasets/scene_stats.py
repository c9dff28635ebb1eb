"""Scene statistics in the columns of SCOUT's Table I, for generated houses and for the
real OmniGibson scenes shipped in ``bddl``, beside the rows printed in the paper.

Columns (SCOUT, Table I "Statistics on interactive benchmarks"): number of scenes; distinct
room categories and object categories over all scenes; per scene: rooms, room categories,
object instances ("Obj./Sc."), object categories (the paper's "Obj. Inst./Sc." column,
whose values - 30.6 for single-room AI2-THOR scenes with 46.3 objects - only make sense as
distinct categories per scene), and contained objects (objects nested inside or on top of
another object).

For generated houses, objects are furniture + small objects; contained objects are the
small objects (each has an ``inside`` or ``ontop`` parent); ``inside`` alone is reported
too. For the bddl scenes, objects are the room inventories without walls, floors,
ceilings, doors, windows and lights (the building); nesting is not recorded there.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import asdict, dataclass, field

from sgtool.datasets.knowledge import Knowledge
from sgtool.house.spec import HouseSpec, hidden_objects

COLUMNS = (
    ("scenes", "Scenes"),
    ("room_categories", "Room Cat."),
    ("object_categories", "Obj. Cat."),
    ("rooms_per_scene", "Rooms/Sc."),
    ("room_categories_per_scene", "Room Cat./Sc."),
    ("objects_per_scene", "Obj./Sc."),
    ("object_categories_per_scene", "Obj. Cat./Sc."),
    ("contained_per_scene", "Contained Obj./Sc."),
)

# SCOUT, Table I, as printed (InteriorGS contained objects: annotated scenes only)
PAPER_TABLE_I: dict[str, dict[str, float]] = {
    "AI2-THOR (SCOUT Table I)": {
        "scenes": 120, "room_categories": 4, "object_categories": 117, "rooms_per_scene": 1.0,
        "room_categories_per_scene": 1.0, "objects_per_scene": 46.3,
        "object_categories_per_scene": 30.6, "contained_per_scene": 17.9},
    "OmniGibson (SCOUT Table I)": {
        "scenes": 45, "room_categories": 39, "object_categories": 237, "rooms_per_scene": 7.1,
        "room_categories_per_scene": 5.3, "objects_per_scene": 245.0,
        "object_categories_per_scene": 31.4, "contained_per_scene": 6.3},
    "InteriorGS (SCOUT Table I)": {
        "scenes": 1000, "room_categories": 687, "object_categories": 697,
        "rooms_per_scene": 6.6, "room_categories_per_scene": 5.1, "objects_per_scene": 408.3,
        "object_categories_per_scene": 52.4, "contained_per_scene": 157.5},
}


@dataclass(frozen=True)
class SceneStats:
    scenes: int
    room_categories: int
    object_categories: int
    rooms_per_scene: float
    room_categories_per_scene: float
    objects_per_scene: float
    object_categories_per_scene: float
    contained_per_scene: float | None
    inside_per_scene: float | None = None
    furniture_per_scene: float | None = None
    closed_doors_per_scene: float | None = None
    hidden_per_scene: float | None = None  # small objects inside closed containers

    def to_dict(self) -> dict:
        return asdict(self)


def _mean(xs: Sequence[float]) -> float:
    return sum(xs) / len(xs) if xs else 0.0


def house_stats(specs: Iterable[HouseSpec]) -> SceneStats:
    specs = list(specs)
    room_cats: set[str] = set()
    obj_cats: set[str] = set()
    per: dict[str, list[float]] = {k: [] for k in (
        "rooms", "room_cats", "objects", "obj_cats", "contained", "inside", "furniture",
        "closed", "hidden")}
    for s in specs:
        rc = {r.category for r in s.rooms}
        oc = {f.category for f in s.furniture} | {o.category for o in s.objects}
        room_cats |= rc
        obj_cats |= oc
        per["rooms"].append(len(s.rooms))
        per["room_cats"].append(len(rc))
        per["objects"].append(len(s.furniture) + len(s.objects))
        per["obj_cats"].append(len(oc))
        per["contained"].append(len(s.objects))
        per["inside"].append(sum(o.relation == "inside" for o in s.objects))
        per["furniture"].append(len(s.furniture))
        per["closed"].append(sum(d.state == "closed" for d in s.doors))
        per["hidden"].append(len(hidden_objects(s)))
    return SceneStats(
        scenes=len(specs), room_categories=len(room_cats), object_categories=len(obj_cats),
        rooms_per_scene=_mean(per["rooms"]), room_categories_per_scene=_mean(per["room_cats"]),
        objects_per_scene=_mean(per["objects"]),
        object_categories_per_scene=_mean(per["obj_cats"]),
        contained_per_scene=_mean(per["contained"]), inside_per_scene=_mean(per["inside"]),
        furniture_per_scene=_mean(per["furniture"]),
        closed_doors_per_scene=_mean(per["closed"]), hidden_per_scene=_mean(per["hidden"]),
    )


@dataclass
class _SceneTally:
    """One real scene's counts while :func:`inventory_stats` walks its rooms."""

    rooms: int = 0
    room_cats: set[str] = field(default_factory=set)
    objects: int = 0
    obj_cats: set[str] = field(default_factory=set)


def inventory_stats(k: Knowledge, household_only: bool = False) -> SceneStats:
    """Table I columns of the real scenes in ``k`` (structure synsets left out)."""
    from sgtool.datasets.split import is_household_scene

    rooms = [r for r in k.rooms if not household_only or is_household_scene(r.scene)]
    scenes = sorted({r.scene for r in rooms})
    room_cats: set[str] = set()
    obj_cats: set[str] = set()
    per_scene = {s: _SceneTally() for s in scenes}
    for r in rooms:
        d = per_scene[r.scene]
        d.rooms += 1
        d.room_cats.add(r.room_type)
        room_cats.add(r.room_type)
        for s, n in r.items:
            if k.kind(s) in ("furniture", "object"):
                d.objects += n
                d.obj_cats.add(s)
                obj_cats.add(s)
    vals = list(per_scene.values())
    return SceneStats(
        scenes=len(scenes), room_categories=len(room_cats), object_categories=len(obj_cats),
        rooms_per_scene=_mean([v.rooms for v in vals]),
        room_categories_per_scene=_mean([len(v.room_cats) for v in vals]),
        objects_per_scene=_mean([v.objects for v in vals]),
        object_categories_per_scene=_mean([len(v.obj_cats) for v in vals]),
        contained_per_scene=None,
    )


def format_table(rows: dict[str, dict[str, float | None]]) -> str:
    """Fixed-width text table, one row per source, Table I's columns."""
    heads = ["Source"] + [h for _, h in COLUMNS]
    body = []
    for name, r in rows.items():
        cells = [name]
        for key, _ in COLUMNS:
            v = r.get(key)
            if v is None:
                cells.append("n/a")
            elif key in ("scenes", "room_categories", "object_categories"):
                cells.append(str(int(v)))
            else:
                cells.append(f"{v:.1f}")
        body.append(cells)
    widths = [max(len(heads[i]), *(len(b[i]) for b in body)) for i in range(len(heads))]
    line = "  ".join(h.ljust(widths[i]) if i == 0 else h.rjust(widths[i])
                     for i, h in enumerate(heads))
    out = [line, "-" * len(line)]
    for b in body:
        out.append("  ".join(c.ljust(widths[i]) if i == 0 else c.rjust(widths[i])
                             for i, c in enumerate(b)))
    return "\n".join(out)
