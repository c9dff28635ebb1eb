"""Where else to look around in a room that one look-around does not show whole (an L- or
U-shaped room, one longer than the camera reaches, one split by a tall bookcase): the
scripted tour's further viewpoints.

Ground truth, as the rest of the scripted tour (:mod:`.explore`): a floor cell of the room
is *seen* from a point when a ray cast from the point reaches it within ``reach`` metres
without crossing a wall, a closed door or a piece of furniture that stands across the
camera's height (``blockers``). :func:`visible` casts ``rays`` rays in even steps of half
a cell; :func:`best_view` is the candidate that would see the most floor not seen yet.
Pure functions of masks on one grid (row = y, column = x, cell centres at ``origin +
(index + 0.5) * resolution``).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence

import numpy as np

from sgtool.house.spec import HouseSpec
from sgtool.mapping.occupancy import house_occupancy

RAYS = 720  # rays per look: 4.5 m away they are 4 cm apart, below a 5 cm cell


def blockers(spec: HouseSpec, resolution: float, camera_height: float) -> np.ndarray:
    """Cells that stop the camera's view of the floor: walls, closed doors and the pieces
    whose body spans ``camera_height`` (a wardrobe, not a table), on the grid
    :func:`~sgtool.mapping.occupancy.house_occupancy` gives ``spec`` at ``resolution``."""
    tall = tuple(f for f in spec.furniture
                 if f.bottom < camera_height < f.bottom + f.size[2])
    occ = house_occupancy(dataclasses.replace(spec, furniture=tall), resolution,
                          robot_radius=0.0)
    return np.asarray(occ.occupied, bool)


def visible(blocked: np.ndarray, origin: Sequence[float], resolution: float,
            point: Sequence[float], reach: float, rays: int = RAYS) -> np.ndarray:
    """Cells a look-around at ``point`` sees: along each of ``rays`` rays, every cell up to
    and including the first blocked one, within ``reach`` m (a boolean mask like
    ``blocked``)."""
    rows, cols = blocked.shape
    steps = np.arange(1, int(math.ceil(reach / (resolution / 2))) + 1) * (resolution / 2)
    angles = np.arange(rays) * (2.0 * math.pi / rays)
    x = point[0] + np.cos(angles)[:, None] * steps[None, :]
    y = point[1] + np.sin(angles)[:, None] * steps[None, :]
    c = np.floor((x - origin[0]) / resolution).astype(np.int64)
    r = np.floor((y - origin[1]) / resolution).astype(np.int64)
    inside = (r >= 0) & (c >= 0) & (r < rows) & (c < cols)
    hit = np.ones_like(inside)
    hit[inside] = blocked[r[inside], c[inside]]
    # a cell is seen when no earlier sample of its ray was blocked (the blocker itself is)
    before = np.logical_or.accumulate(hit, axis=1)
    before = np.concatenate([np.zeros((rays, 1), bool), before[:, :-1]], axis=1)
    keep = inside & ~before
    out = np.zeros_like(blocked, dtype=bool)
    out[r[keep], c[keep]] = True
    pr = int(math.floor((point[1] - origin[1]) / resolution))
    pc = int(math.floor((point[0] - origin[0]) / resolution))
    if 0 <= pr < rows and 0 <= pc < cols:
        out[pr, pc] = True
    return out


def best_view(blocked: np.ndarray, origin: Sequence[float], resolution: float,
              floor: np.ndarray, seen: np.ndarray, candidates: Sequence[Sequence[float]],
              reach: float) -> tuple[tuple[float, float], int] | None:
    """The candidate point that would see the most cells of ``floor`` not in ``seen``, and
    how many (the first of equals, in the order given); None without candidates."""
    todo = floor & ~seen
    best: tuple[tuple[float, float], int] | None = None
    for p in candidates:
        gain = int(np.count_nonzero(visible(blocked, origin, resolution, p, reach) & todo))
        if best is None or gain > best[1]:
            best = ((float(p[0]), float(p[1])), gain)
    return best
