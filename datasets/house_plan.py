"""The house generator's floor-plan vocabulary and working records: building dimensions,
room sizes per room type, the plan (axis-aligned rooms, openings) and the furniture pieces
placed into it, and coordinate snapping. See :mod:`sgtool.datasets.generator`."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

WALL_T = 0.1
WALL_H = 2.5
DOOR_W = 0.9
DOOR_H = 2.1
SNAP = 0.05
# room type -> ((width range along the corridor), (depth range away from it)) in metres
ROOM_DIMS: dict[str, tuple[tuple[float, float], tuple[float, float]]] = {
    "kitchen": ((3.2, 5.0), (3.2, 5.0)),
    "living_room": ((4.0, 6.0), (3.8, 6.0)),
    "dining_room": ((3.2, 5.0), (3.2, 4.5)),
    "bedroom": ((3.2, 4.6), (3.2, 4.6)),
    "childs_room": ((3.0, 4.0), (3.0, 4.0)),
    "bathroom": ((2.5, 3.4), (2.5, 3.2)),
    "closet": ((2.5, 3.0), (2.5, 2.8)),
    "storage_room": ((2.5, 3.5), (2.5, 3.2)),
    "pantry_room": ((2.5, 3.0), (2.5, 3.0)),
    "utility_room": ((2.5, 3.5), (2.5, 3.5)),
    "private_office": ((3.0, 4.2), (3.0, 4.0)),
    "playroom": ((3.2, 4.6), (3.2, 4.5)),
    "television_room": ((3.2, 4.6), (3.2, 4.5)),
    "exercise_room": ((3.2, 4.6), (3.2, 4.5)),
    "entryway": ((2.5, 3.5), (2.5, 3.5)),
    "garage": ((4.0, 6.0), (5.0, 6.0)),
}
HOUSE_ROOM_TYPES = tuple(sorted(ROOM_DIMS))


class PlanRetry(Exception):
    """This attempt painted itself into a corner; draw again from the same stream."""


@dataclass
class Rect:
    """An axis-aligned rectangle (m): a room's extent, a piece's footprint, a keep-out."""

    x0: float
    y0: float
    x1: float
    y1: float

    @property
    def width(self) -> float:
        return self.x1 - self.x0

    @property
    def height(self) -> float:
        return self.y1 - self.y0

    def shrink(self, m: float) -> Rect:
        return Rect(self.x0 + m, self.y0 + m, self.x1 - m, self.y1 - m)

    def overlaps(self, o: Rect, gap: float = 0.0) -> bool:
        return (self.x0 < o.x1 + gap - 1e-9 and o.x0 < self.x1 + gap - 1e-9
                and self.y0 < o.y1 + gap - 1e-9 and o.y0 < self.y1 + gap - 1e-9)

    def inside(self, o: Rect) -> bool:
        return (self.x0 >= o.x0 - 1e-9 and self.x1 <= o.x1 + 1e-9
                and self.y0 >= o.y0 - 1e-9 and self.y1 <= o.y1 + 1e-9)


@dataclass
class PlanRoom:
    """One room of the plan; ``idx`` gives its spec id ``room_<idx>``."""

    idx: int
    type: str
    rect: Rect
    side: str  # "c" corridor, "n"/"s" front rooms, "nb"/"sb" back rooms
    group: str | None = None
    host: int | None = None  # back rooms: the room they open into

    @property
    def id(self) -> str:
        return f"room_{self.idx}"


@dataclass
class Opening:
    """A door or a passage between two plan rooms, in a wall along x or y."""

    kind: str  # "door" | "passage"
    center: tuple[float, float]
    width: float
    horizontal: bool  # lies along x (yaw 0) or along y (yaw pi/2)
    rooms: tuple[int, int]
    state: str = "open"


@dataclass
class Piece:
    """One piece of furniture being placed (footprint, height, stacking, state)."""

    synset: str
    room: int
    box: Rect  # axis-aligned footprint
    z0: float
    size: tuple[float, float, float]  # (sx, sy, sz) in the piece's own frame
    yaw: float
    on: int | None = None  # index of the piece it stands on
    top_used: bool = False
    affordances: tuple[str, ...] = ()
    state: str | None = None


@dataclass
class Plan:
    """Rooms and openings of one floor-plan attempt."""

    rooms: list[PlanRoom] = field(default_factory=list)
    openings: list[Opening] = field(default_factory=list)


def snap(v: float, step: float = SNAP) -> float:
    """``v`` rounded to a multiple of ``step`` (4 decimals)."""
    return round(round(v / step) * step, 4)


def uniform_snap(rng: np.random.Generator, lo: float, hi: float, step: float = 0.1) -> float:
    """A uniform draw on [lo, hi], snapped to ``step``."""
    return snap(float(rng.uniform(lo, hi)), step)
