"""Start poses and reachability of any house, generated or hand-made.

:func:`reachability` answers, for a :class:`~sgtool.house.spec.HouseSpec`, where a robot of
radius :data:`ROBOT_RADIUS` can stand: the free cells of the occupancy grid (closed doors
passable, since the robot may open them) reachable from an origin room, a start pose per
reachable room (the reachable cell of the room's polygon nearest to its centroid), and
which rooms and which pieces of furniture with affordances (containers, supporters) it
cannot reach (a piece is reached when the robot can stand within :data:`REACH` of its
footprint). :func:`with_start_poses` gives a house without
start poses (a house written by hand) one per reachable room, so that
:func:`sgtool.datasets.episodes.list_episodes` can list its episodes.

The origin is the room named, else the first room of the spec from which the most rooms
can be reached (a room walled off, listed first, does not make the rest of the house
unreachable); its point is the free cell of that room nearest to the room's centroid.
Yaws are drawn from ``numpy.random.default_rng(seed)``, one per room in spec order, so the
result is a function of the house and the seed.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from sgtool.datasets.footprint_reach import near_footprint
from sgtool.house.spec import HouseSpec, Room, StartPose
from sgtool.mapping.occupancy import geodesic_distances, house_occupancy
from sgtool.mapping.raster import cell_centers, polygon_mask

ROBOT_RADIUS = 0.2
REACH = 1.0  # the robot must be able to stand within this of a container (m)


@dataclass(frozen=True)
class Reachability:
    """Where the robot can go in a house, from :func:`reachability`."""

    origin_room: str
    starts: tuple[StartPose, ...]  # one per reachable room, in spec order
    unreachable_rooms: tuple[str, ...]  # room ids, spec order
    unreachable_furniture: tuple[str, ...]  # ids of furniture with affordances, spec order

    @property
    def complete(self) -> bool:
        """Every room and every piece of furniture with affordances can be reached."""
        return not self.unreachable_rooms and not self.unreachable_furniture


def reachability(spec: HouseSpec, seed: int = 0, origin_room: str | None = None,
                 robot_radius: float = ROBOT_RADIUS, reach: float = REACH) -> Reachability:
    """Reachable rooms, start poses and unreachable furniture of ``spec`` (module doc).

    Raises ``KeyError`` for an ``origin_room`` that is not a room id of the spec.
    """
    origins = [spec.room(origin_room)] if origin_room is not None else list(spec.rooms)
    occ = house_occupancy(spec, closed_doors_free=True, robot_radius=robot_radius)
    X, Y = cell_centers(occ)
    free = ~occ.blocked
    masks = {r.id: polygon_mask(occ, r.polygon) & free for r in spec.rooms}
    best: tuple[int, Room, np.ndarray] | None = None
    seen: set[str] = set()  # rooms reached from an origin tried: the same part of the house
    for room in origins:
        if room.id in seen:
            continue
        ox, oy = _nearest_cell(masks[room.id], X, Y, room.centroid) or room.centroid
        reached = np.isfinite(geodesic_distances(occ, (ox, oy), max_snap=1.0))
        rooms = {r.id for r in spec.rooms if (masks[r.id] & reached).any()} | {room.id}
        seen |= rooms
        if best is None or len(rooms) > best[0]:
            best = (len(rooms), room, reached)
        if len(rooms) == len(spec.rooms):
            break
    assert best is not None  # a spec has a room
    _, origin, ok = best
    rng = np.random.default_rng(seed)
    starts, lost_rooms = [], []
    for r in spec.rooms:
        yaw = round(float(rng.uniform(-math.pi, math.pi)), 4)
        at = _nearest_cell(masks[r.id] & ok, X, Y, r.centroid)
        if at is None:
            lost_rooms.append(r.id)
            continue
        starts.append(StartPose(x=round(at[0], 4), y=round(at[1], 4), yaw=yaw, room=r.id))
    lost_furniture = []
    for f in spec.furniture:
        if not f.affordances:
            continue
        near = near_footprint(occ, X, Y, f, reach - robot_radius)
        if near is None or not (near[1] & ok[near[0]]).any():
            lost_furniture.append(f.id)
    return Reachability(origin.id, tuple(starts), tuple(lost_rooms), tuple(lost_furniture))


def start_poses(spec: HouseSpec, seed: int = 0) -> tuple[StartPose, ...]:
    """One start pose per room reachable from the origin room (module doc)."""
    return reachability(spec, seed).starts


def with_start_poses(spec: HouseSpec, seed: int = 0) -> HouseSpec:
    """``spec`` itself when it has start poses, else a copy with :func:`start_poses`."""
    if spec.starts:
        return spec
    return dataclasses.replace(spec, starts=start_poses(spec, seed))


def _nearest_cell(mask: np.ndarray, X: np.ndarray, Y: np.ndarray,
                  point: tuple[float, float]) -> tuple[float, float] | None:
    if not mask.any():
        return None
    d2 = np.where(mask, (X - point[0]) ** 2 + (Y - point[1]) ** 2, np.inf)
    i = int(np.argmin(d2))
    return float(X.ravel()[i]), float(Y.ravel()[i])
