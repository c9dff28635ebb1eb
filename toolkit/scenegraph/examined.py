"""Which pieces the robot has looked at from close by: what stands on or in a piece that is
not closed counts as seen only then.

The symbolic environment reveals what a container or supporter holds when the agent walks
up to it (``navigate`` / ``explore`` it; its node carries the ``examine`` affordance and is
``explored`` afterwards). The live graph follows the same rule from the frames alone: a
piece of furniture with a ``container`` or ``supporter`` affordance, or a small object
with a ``container`` one, is *examinable* (:func:`examinable`, the rule both use), and it is
*examined* once a frame gave it at least ``min_points`` pixels at a mean depth of at most
``max_depth`` metres (the robot stood near it and faced it, as the ``navigate`` skill
leaves it, or drove close past it looking its way). Until then its node is not
``explored`` and offers ``navigate`` (:mod:`sgtool.planning.candidates`); seen from across
a room (a bed whose foot a door panel hid, a towel deep in a hamper) it no longer counts
as searched. A closed piece is opened first; once open, the frames of the ``open`` skill,
taken in front of it, examine it.

Pure functions over one frame's instance-id and depth images; the builder keeps the set.
"""

from __future__ import annotations

from collections.abc import Iterable

import numpy as np

EXAMINE = "examine"  # the affordance of an examinable node (as the symbolic environment's)
CARRIER_AFFORDANCES = frozenset({"container", "supporter"})  # of furniture
OBJECT_CARRIER_AFFORDANCES = frozenset({"container"})  # of a small object
EXAMINE_RANGE_M = 2.0  # mean depth of its pixels at which a piece counts as looked at
_DENSE_IDS = 1 << 20  # below this largest id, count per id without sorting


def examinable(affordances: Iterable[str], small_object: bool = False) -> bool:
    """Whether a piece of furniture (a small object: ``small_object``) with these
    affordances holds things one sees only from close by."""
    kinds = OBJECT_CARRIER_AFFORDANCES if small_object else CARRIER_AFFORDANCES
    return any(a.lower() in kinds for a in affordances)


def close_views(ids: np.ndarray, depth: np.ndarray, min_points: int,
                max_depth: float = EXAMINE_RANGE_M) -> list[int]:
    """The instance ids (> 0) of one frame with at least ``min_points`` pixels of finite,
    positive depth whose mean depth is at most ``max_depth`` m, ascending."""
    lab = np.asarray(ids).ravel()
    d = np.asarray(depth).ravel()
    ok = (lab > 0) & np.isfinite(d) & (d > 0)
    if not ok.any():
        return []
    lab, d = lab[ok].astype(np.int64), d[ok].astype(np.float64)
    if int(lab.max()) < _DENSE_IDS:  # ids index counts directly (the simulator's)
        ids_of, index = None, lab
    else:
        ids_of, index = np.unique(lab, return_inverse=True)
    count = np.bincount(index)
    total = np.bincount(index, weights=d)
    near = np.flatnonzero((count >= max(1, int(min_points))) & (total <= max_depth * count))
    return [int(i) for i in (near if ids_of is None else ids_of[near])]
