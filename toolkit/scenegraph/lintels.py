"""Doorways seen by their lintel: a gap in a wall that a beam spans overhead (pure).

A doorway whose door leaf is not seen (there is none, or it stands where no camera looked)
leaves no door instance, but its lintel still says "doorway": the wall above the opening,
over floor the robot can walk on. :func:`lintel_doorways` finds such openings on the bird's
eye grid, from the cells whose voxel column holds something only overhead (in a band
above the obstacle band, below a ceiling's usual height) over seen floor:

- the cells that are ``FREE`` on the occupancy grid and hold voxels ``LINTEL_BAND``
  metres above the floor (the builder's :meth:`columns_between`);
- grouped into 8-connected pieces; a piece is a lintel when it is a thin bar
  (``LINTEL_LENGTH`` long along its principal axis, at most ``LINTEL_DEPTH`` across) whose
  line runs into occupied cells past both of its ends (the wall it bridges: the jambs),
  each jamb thin across the line (not a wall running across it, as at a corridor's side
  under a duct, nor a column), with walkable floor off both long sides (the two places
  it joins);
- the bar's cells are door evidence for the room segmentation
  (:mod:`sgtool.scenegraph.room_segmentation`), as a door's opening is.

What passes for a lintel otherwise is ruled out by these: a wall whose lower part a
piece of furniture hides has no floor seen under it; a shelf along a wall has free floor
past its ends and the wall on one side; a duct or beam across a corridor ends at walls
running across it; a ceiling is higher than the band; a lamp is no bar between walls.
"""

from __future__ import annotations

import numpy as np
from scipy import ndimage

from sgtool.mapping.grid import FREE, OCCUPIED, OccupancyGrid, grid_at

LINTEL_BAND = (1.75, 2.3)  # m above the floor: over a walking robot, under most ceilings
LINTEL_LENGTH = (0.5, 1.6)  # m: a doorway's width
LINTEL_DEPTH = 0.6  # m: a wall's thickness, at most (a noisy map smears a lintel deeper)
JAMB_REACH = 2  # cells past a bar's end its wall must start
SIDE_GAP = 2.0  # cells off a bar's long side where the floor of a room must be seen
SIDE_SHARE = 0.7  # of the points along each long side


def lintel_doorways(occ: OccupancyGrid, overhead: np.ndarray) -> np.ndarray:
    """Bool grid over ``occ``: the cells of the lintels (module doc), from ``overhead``
    (bool, ``occ``'s shape: the cells whose voxel column holds something in
    ``LINTEL_BAND``)."""
    out = np.zeros(occ.shape, dtype=bool)
    free = occ.grid == FREE
    bar = overhead & free
    if not bar.any():
        return out
    labels, n = ndimage.label(bar, structure=np.ones((3, 3), dtype=bool))
    occupied = occ.grid == OCCUPIED
    res = occ.resolution
    size = np.bincount(labels.ravel(), minlength=n + 1)
    most = (LINTEL_LENGTH[1] / res + 2) * (LINTEL_DEPTH / res + 2)  # cells of the largest bar
    for i, piece in enumerate(ndimage.find_objects(labels), start=1):
        if piece is None or not LINTEL_LENGTH[0] / res <= size[i] <= most:
            continue  # too few or too many cells for a doorway's bar
        rr, cc = np.nonzero(labels[piece] == i)
        rows, cols = rr + piece[0].start, cc + piece[1].start
        if _is_lintel(rows, cols, occupied, free, res):
            out[rows, cols] = True
    return out


def _is_lintel(rows: np.ndarray, cols: np.ndarray, occupied: np.ndarray, free: np.ndarray,
               res: float) -> bool:
    """Whether the cells (``rows``, ``cols``) are a thin bar of a doorway's length whose
    line runs into ``occupied`` cells within ``JAMB_REACH`` cells past both ends, each of
    those not ``occupied`` on both sides across the line ``SIDE_GAP`` cells past the bar's
    half depth, with ``free`` floor ``SIDE_GAP`` cells off both of its long sides along
    most of it."""
    pts = np.stack([cols, rows], axis=1).astype(np.float64)
    mean = pts.mean(axis=0)
    cen = pts - mean
    evals, evecs = np.linalg.eigh(cen.T @ cen)
    a = evecs[:, int(np.argmax(evals))]
    t = np.array([-a[1], a[0]])
    along, across = cen @ a, cen @ t
    length = (float(along.max() - along.min()) + 1.0) * res
    depth = (float(across.max() - across.min()) + 1.0) * res
    if not (LINTEL_LENGTH[0] <= length <= LINTEL_LENGTH[1] and depth <= LINTEL_DEPTH):
        return False
    half = (float(across.max() - across.min()) + 1.0) / 2.0 + SIDE_GAP
    for end, out in ((float(along.min()), -a), (float(along.max()), a)):
        past = mean + a * end + out * np.arange(1, JAMB_REACH + 1)[:, None]
        hit = grid_at(past, occupied)
        if not hit.any():
            return False
        # the jamb is the wall the bar lies in: thin across, not a wall (or a column)
        # running across the bar's line, as at a corridor's side under a duct
        jamb = past[int(np.argmax(hit))]
        if grid_at(np.stack([jamb + t * half, jamb - t * half]), occupied).all():
            return False
    # walkable floor on both sides, over most of the bar's length: it joins two places
    span = np.linspace(float(along.min()), float(along.max()), 9)[1:-1, None]
    for lo, side in ((float(across.min()), -1.0), (float(across.max()), 1.0)):
        beside = mean + a * span + t * (side * (abs(lo) + SIDE_GAP))
        if grid_at(beside, free).mean() < SIDE_SHARE:
            return False
    return True
