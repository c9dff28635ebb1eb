"""Doorways seen by their lintel: a gap in a wall that a beam spans overhead (pure).

A doorway whose door leaf is not seen (there is none, or it stands where no camera looked)
leaves no door instance, but its lintel still says "doorway": the wall above the opening,
over floor the robot can walk on. :func:`lintel_doorways` finds such openings on the bird's
eye grid, from the cells whose voxel column holds something only overhead (in a band
above the obstacle band, below a ceiling's usual height) over seen floor:

- the cells that are ``FREE`` on the occupancy grid and hold voxels ``LINTEL_BAND``
  metres above the floor (the builder's :meth:`columns_between`);
- grouped into 8-connected pieces; a piece is a lintel when it is a thin bar
  (``LINTEL_LENGTH`` long along its principal axis, at most ``LINTEL_DEPTH`` across; its
  length that of its body, where it is at least half as deep as where it is deepest: a
  noisy map's lintel runs on in thin tails between two smeared copies of its wall) whose
  line runs into occupied cells past both of its ends (the wall it bridges: the jambs),
  each jamb thin across the line (not a wall running across it, as at a corridor's side
  under a duct, nor a column), with walkable floor off both long sides (the two places
  it joins);
- the bar's cells (of its body, when the whole is too long) are door evidence for the
  room segmentation
  (:mod:`sgtool.scenegraph.room_segmentation`), as a door's opening is; a bar measured
  by its body adds nothing beside a seen door's evidence (that doorway has its evidence;
  the body would make it deeper than the doorway).

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


def lintel_doorways(occ: OccupancyGrid, overhead: np.ndarray,
                    doors: np.ndarray | None = None) -> np.ndarray:
    """Bool grid over ``occ``: the cells of the lintels (module doc), from ``overhead``
    (bool, ``occ``'s shape: the cells whose voxel column holds something in
    ``LINTEL_BAND``); a bar measured by its body (too long with its tails) next to
    ``doors`` (bool, the evidence of seen doors) is left out: that doorway has its
    evidence."""
    out = np.zeros(occ.shape, dtype=bool)
    free = occ.grid == FREE
    bar = overhead & free
    if not bar.any():
        return out
    labels, n = ndimage.label(bar, structure=np.ones((3, 3), dtype=bool))
    near = None if doors is None or not doors.any() else \
        ndimage.binary_dilation(doors, structure=np.ones((3, 3), dtype=bool))
    occupied = occ.grid == OCCUPIED
    res = occ.resolution
    size = np.bincount(labels.ravel(), minlength=n + 1)
    most = (LINTEL_LENGTH[1] / res + 2) * (LINTEL_DEPTH / res + 2)  # cells of the largest bar
    for i, piece in enumerate(ndimage.find_objects(labels), start=1):
        if piece is None or not LINTEL_LENGTH[0] / res <= size[i] <= most:
            continue  # too few or too many cells for a doorway's bar
        rr, cc = np.nonzero(labels[piece] == i)
        rows, cols = rr + piece[0].start, cc + piece[1].start
        body = _lintel_body(rows, cols, occupied, free, res)
        if body is None or (not body.all() and near is not None and near[rows, cols].any()):
            continue  # none; or a bar cut from its tails beside a seen door's evidence
        out[rows[body], cols[body]] = True
    return out


def _lintel_body(rows: np.ndarray, cols: np.ndarray, occupied: np.ndarray,
                 free: np.ndarray, res: float) -> np.ndarray | None:
    """Which of the cells (``rows``, ``cols``) are a lintel's (bool per cell; None: they
    are none): when they are a thin bar of a doorway's length whose line runs into
    ``occupied`` cells within ``JAMB_REACH`` cells past both ends, each of those not
    ``occupied`` on both sides across the line ``SIDE_GAP`` cells past the bar's half
    depth, with ``free`` floor ``SIDE_GAP`` cells off both of its long sides along most
    of it: all of them. When they are longer than a doorway, the same of the bar's body
    (:func:`_body`) and its cells: a noisy map's lintel runs on in thin tails along the
    wall's line (free cells between two smeared copies of the wall, under the wall's
    top), which are no doorway; the jambs are then looked for from the body's ends to
    past the tails' tips."""
    pts = np.stack([cols, rows], axis=1).astype(np.float64)
    mean = pts.mean(axis=0)
    cen = pts - mean
    evals, evecs = np.linalg.eigh(cen.T @ cen)
    a = evecs[:, int(np.argmax(evals))]
    t = np.array([-a[1], a[0]])
    along, across = cen @ a, cen @ t
    whole = (float(along.max() - along.min()) + 1.0) * res
    lo, hi = (float(along.min()), float(along.max()))
    if whole > LINTEL_LENGTH[1]:  # too long: without its tails?
        lo, hi = _body(along)
    length = (hi - lo + 1.0) * res
    depth = (float(across.max() - across.min()) + 1.0) * res
    if not (LINTEL_LENGTH[0] <= whole and length <= LINTEL_LENGTH[1]
            and depth <= LINTEL_DEPTH):
        return None
    half = (float(across.max() - across.min()) + 1.0) / 2.0 + SIDE_GAP
    for end, tip, out in ((lo, float(along.min()), -a), (hi, float(along.max()), a)):
        # from the body's end to past the tip of its tail (none: the same)
        steps = np.arange(1, round(abs(tip - end)) + JAMB_REACH + 1)
        past = mean + a * end + out * steps[:, None]
        hit = grid_at(past, occupied)
        if not hit.any():
            return None
        # the jamb is the wall the bar lies in: thin across, not a wall (or a column)
        # running across the bar's line, as at a corridor's side under a duct
        jamb = past[int(np.argmax(hit))]
        if grid_at(np.stack([jamb + t * half, jamb - t * half]), occupied).all():
            return None
    # walkable floor on both sides, over most of its length: it joins two places
    span = np.linspace(lo, hi, 9)[1:-1, None]
    for edge, side in ((float(across.min()), -1.0), (float(across.max()), 1.0)):
        beside = mean + a * span + t * (side * (abs(edge) + SIDE_GAP))
        if grid_at(beside, free).mean() < SIDE_SHARE:
            return None
    on = np.round(along)
    return (on >= np.floor(lo)) & (on <= np.ceil(hi))  # whole: all of it


def _body(along: np.ndarray) -> tuple[float, float]:
    """The first and last position (cells along the bar's axis, rounded) of the bar's
    body: where it is at least half as deep (cells across it) as where it is deepest;
    past them, the bar's thin tails."""
    pos, count = np.unique(np.round(along), return_counts=True)
    body = pos[count * 2 >= count.max()]
    return float(body.min()), float(body.max())
