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
from scipy.signal import fftconvolve

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


def places(mask: np.ndarray, origin: Sequence[float], resolution: float,
           stride: float) -> list[tuple[float, float]]:
    """One place per block of ``stride`` x ``stride`` metres (of whole cells) that holds a
    cell of ``mask``: that cell's centre nearest the block's centre cell (the first of
    equals by row, then column), blocks in row, then column order. Anchored to the
    blocks, a strip of ``mask`` narrower than ``stride`` gets places wherever the grid
    falls on it."""
    k = max(1, round(stride / resolution))
    rows, cols = np.nonzero(mask)
    if not rows.size:
        return []
    off = (rows % k - k // 2) ** 2 + (cols % k - k // 2) ** 2
    order = np.lexsort((cols, rows, off, cols // k, rows // k))
    block = (rows // k)[order] * (int(cols.max()) // k + 1) + (cols // k)[order]
    first = order[np.r_[True, block[1:] != block[:-1]]]
    return [(origin[0] + (c + 0.5) * resolution, origin[1] + (r + 0.5) * resolution)
            for r, c in zip(rows[first], cols[first], strict=True)]


def best_view(blocked: np.ndarray, origin: Sequence[float], resolution: float,
              floor: np.ndarray, seen: np.ndarray, candidates: Sequence[Sequence[float]],
              reach: float) -> tuple[tuple[float, float], int] | None:
    """The candidate point that would see the most cells of ``floor`` not in ``seen``, and
    how many (the first of equals, in the order given); None without candidates.

    Candidates are weighed in the order of how many such cells lie within reach of them
    at all (an upper bound of what they could see), and the weighing stops where that
    bound falls below the best found: the answer of weighing every one, in a fraction
    of the time in a large room."""
    todo = floor & ~seen
    if not len(candidates):
        return None
    # cells of todo within reach of each cell, with 3 cells to spare (a ray's last sample
    # lies up to half a cell past reach, and marks a cell whose centre is up to 0.71 cell
    # from it; a candidate lies up to 0.71 cell from its cell's centre)
    rows, cols = todo.shape
    # (no wider than the grid's diagonal: every cell is within that of every cell)
    r = min(int(math.ceil(reach / resolution)) + 3, int(math.ceil(math.hypot(rows, cols))))
    yy, xx = np.mgrid[-r:r + 1, -r:r + 1]
    disc = (np.hypot(yy, xx) <= r).astype(np.float64)
    near = fftconvolve(todo.astype(np.float64), disc, mode="same")
    bounds = []
    for p in candidates:
        rr = int(math.floor((p[1] - origin[1]) / resolution))
        cc = int(math.floor((p[0] - origin[0]) / resolution))
        inside = 0 <= rr < rows and 0 <= cc < cols
        bounds.append(int(near[rr, cc] + 0.5) + 1 if inside else int(todo.sum()))
    best: tuple[int, int] | None = None  # (gain, index)
    for i in sorted(range(len(candidates)), key=lambda j: (-bounds[j], j)):
        if best is not None and bounds[i] < best[0]:
            break
        p = candidates[i]
        gain = int(np.count_nonzero(visible(blocked, origin, resolution, p, reach) & todo))
        if best is None or gain > best[0] or (gain == best[0] and i < best[1]):
            best = (gain, i)
    assert best is not None
    p = candidates[best[1]]
    return (float(p[0]), float(p[1])), best[0]
