"""Doors the robot cannot get through: furniture in the doorway, or beyond it cutting the
doorway's side off from the rest of its room.

A door joins its two rooms in the symbolic house by an edge between one place on each side
(:mod:`sgtool.recorders.symbolic_environment.house`); the places are snapped to the nearest
walkable cell of each room, so a door whose opening a bookshelf fills would still be
crossed, straight through the bookshelf. A door is *passable* when, on the occupancy grid
with every door open (obstacles grown by the robot radius, as the rest of the house),
some cell on its opening line is free and joined (4-connected, through free cells of the
two rooms only) to the walkable cells of both its rooms. The bench reads a door
that is not as a wall; the path lengths of ``sgtool scenes episodes`` (a geodesic on the
same grid) agree.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
from scipy import ndimage

from sgtool.house.geometry import box_corners, distance_to_polygon, opening_segment
from sgtool.house.spec import Door, HouseSpec
from sgtool.mapping.occupancy import OccupancyMap
from sgtool.mapping.raster import cell_window, world_to_cell


def opening_cells(occ: OccupancyMap, door: Door) -> list[tuple[int, int]]:
    """The grid cells on ``door``'s opening line (sampled every half cell), in order."""
    p, q = opening_segment(door.center, door.width, door.yaw)
    n = max(2, int(math.ceil(door.width / (occ.resolution / 2.0))) + 1)
    out: list[tuple[int, int]] = []
    for t in np.linspace(0.0, 1.0, n):
        cell = world_to_cell(occ, p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1]))
        if occ.in_bounds(*cell) and cell not in out:
            out.append(cell)
    return out


def blocked_doors(spec: HouseSpec, open_occ: OccupancyMap, rooms: np.ndarray,
                  walkable: Sequence[np.ndarray | None]) -> tuple[int, ...]:
    """Indices into ``spec.doors`` of the doors the robot cannot pass (module doc).
    ``open_occ``: the house's occupancy with every door open; ``rooms``: per cell of it,
    the index of the room holding it (-1 outside); ``walkable``: per room, its walkable
    cells (None: a room the robot does not fit in, searched from its doorway, whose doors
    are never blocked)."""
    free = ~open_occ.blocked
    index = {r.id: i for i, r in enumerate(spec.rooms)}
    out = []
    for di, d in enumerate(spec.doors):
        pair = [index[r] for r in d.rooms]
        sides = [walkable[ri] for ri in pair]
        if any(s is None for s in sides):  # a niche: searched from its doorway
            continue
        cells = [c for c in opening_cells(open_occ, d) if free[c]]
        pts = [p for ri in pair for p in spec.rooms[ri].polygon]
        win = cell_window(open_occ, [p[0] for p in pts], [p[1] for p in pts])
        if not cells or win is None:
            out.append(di)
            continue
        inside = np.isin(rooms[win], pair)
        for r, c in cells:  # the opening itself, in the wall between the two
            inside[r - win[0].start, c - win[1].start] = True
        labels, _ = ndimage.label(free[win] & inside)
        through = sorted({int(labels[r - win[0].start, c - win[1].start]) for r, c in cells})
        if not any(all(bool((labels[s[win]] == k).any()) for s in sides if s is not None)
                   for k in through):  # (no side is None here: niches were skipped)
            out.append(di)
    return tuple(out)


def doorway_pieces(spec: HouseSpec, door: Door, within: float) -> tuple[str, ...]:
    """Ids of the furniture of ``door``'s two rooms whose footprint comes within ``within``
    metres of its opening line (what blocks it, for a message), in spec order."""
    p, q = opening_segment(door.center, door.width, door.yaw)
    pts = [(p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1]))
           for t in np.linspace(0.0, 1.0, 9)]
    return tuple(f.id for f in spec.furniture if f.room in door.rooms and min(
        distance_to_polygon(x, y, box_corners(f.center[:2], f.size[:2], f.yaw))
        for x, y in pts) < within)


__all__ = ["blocked_doors", "doorway_pieces", "opening_cells"]
