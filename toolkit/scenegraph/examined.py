"""Which pieces the robot has looked into from close by: what stands on or in a piece that
is not closed counts as seen only then.

The symbolic environment reveals what a container or supporter holds when the agent walks
up to it (``navigate`` / ``explore`` it; its node carries the ``examine`` affordance and is
``explored`` afterwards). The live graph follows the same rule from the frames alone: a
piece of furniture with a ``container`` or ``supporter`` affordance, or a small object
with a ``container`` one, is *examinable* (:func:`examinable`, the rule both use), and it is
*examined* once

1. a frame gave it at least ``min_points`` pixels at a mean depth of at most
   ``max_depth`` metres (:func:`close_views`: the robot stood near it or drove close
   past it looking its way), and
2. such frames saw *into* it: rays reached the inside of at least :data:`INNER_SHARE` of
   its inner columns (a container), or just above its top (a supporter), or ended on
   something standing there (:class:`PieceView`, :func:`look_into`). A side board hides a
   bucket's inside from a view past its side, a top board the back of a shelf from above;
   the close view alone counted those as searched, and a planner never looked again.

Until then its node is not ``explored`` and offers ``navigate``
(:mod:`sgtool.planning.candidates`); seen from across a room (a bed whose foot a door panel
hid, a towel deep in a hamper) it does not count as searched. A closed piece is opened
first; once open, the frames of the ``open`` skill, taken in front of it, examine it. Other
instances count as looked at from the close view alone (``BuilderConfig.look_inside``
off: every piece so, the older rule).

Pure functions over one frame's instance-id and depth images; the builder keeps the set
and a :class:`PieceView` per examinable piece.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass, field

import numpy as np
from scipy import ndimage

from sgtool.log.frame import CameraIntrinsics

EXAMINE = "examine"  # the affordance of an examinable node (as the symbolic environment's)
CARRIER_AFFORDANCES = frozenset({"container", "supporter"})  # of furniture
OBJECT_CARRIER_AFFORDANCES = frozenset({"container"})  # of a small object
EXAMINE_RANGE_M = 2.0  # mean depth of its pixels at which a piece counts as looked at
_DENSE_IDS = 1 << 20  # below this largest id, count per id without sorting


def carrier_kinds(affordances: Iterable[str], small_object: bool = False
                  ) -> tuple[bool, bool]:
    """(container, supporter): how a piece of furniture (a small object: ``small_object``,
    which only contains) with these affordances holds things."""
    kinds = OBJECT_CARRIER_AFFORDANCES if small_object else CARRIER_AFFORDANCES
    have = {a.lower() for a in affordances} & kinds
    return "container" in have, "supporter" in have


def examinable(affordances: Iterable[str], small_object: bool = False) -> bool:
    """Whether a piece of furniture (a small object: ``small_object``) with these
    affordances holds things one sees only from close by."""
    return any(carrier_kinds(affordances, small_object))


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


# ----- seeing into a piece ---------------------------------------------------------------
INNER_SHARE = 0.3  # share of a piece's inner columns seen into at which it is examined
SAMPLE_LEVELS = (0.25, 0.5, 0.75)  # heights of a container's inside, bottom 0 .. top 1
OVER_TOP = 0.1  # m the camera must be above a piece's top to look onto it
MIN_INNER = 4  # inner columns (of the voxel size) a piece must show before it can count
Cell = tuple[int, int]
_CELL_OFFSET, _CELL_SPAN = 1 << 20, 1 << 21  # a column (i, j) as one int64 key
_NEIGHBOURS = ((1, 0), (-1, 0), (0, 1), (0, -1))


@dataclass
class PieceView:
    """What close frames showed of one examinable piece: its *columns* (the ``resolution``
    x, y cells its points fell in), its height span, and the inner columns seen into.

    A column is *inner* when its four neighbours are columns too (the outer boards and
    rims fall in the outer ring). An inner column is *seen into* when a frame's ray
    reached the piece's inside above it (a container: its middle heights; a supporter:
    just above its top) or ended on something else standing there (:func:`look_into`)."""

    cells: set[Cell] = field(default_factory=set)
    bottom: float = math.inf
    top: float = -math.inf
    seen_in: set[Cell] = field(default_factory=set)  # seen into (a container's inside)
    seen_on: set[Cell] = field(default_factory=set)  # seen onto (a supporter's top)
    eye: float = -math.inf  # the highest camera of those frames (m)
    _inner: tuple[int, list[Cell]] | None = field(default=None, repr=False, compare=False)

    def inner(self) -> list[Cell]:
        """The inner columns, sorted: the columns with the holes among them filled (an
        open top's rim encloses its inside), less the outer ring (a cell is inner when its
        four neighbours are columns too)."""
        if not self.cells:
            return []
        if self._inner is not None and self._inner[0] == len(self.cells):
            return self._inner[1]  # the cells only grow: their number names the set
        ij = np.asarray(sorted(self.cells), dtype=np.int64)
        lo = ij.min(axis=0)
        grid = np.zeros(tuple(ij.max(axis=0) - lo + 1), dtype=bool)
        grid[ij[:, 0] - lo[0], ij[:, 1] - lo[1]] = True
        grid = ndimage.binary_fill_holes(grid)
        core = ndimage.binary_erosion(grid, structure=ndimage.generate_binary_structure(2, 1),
                                      border_value=0)
        out = [(int(a + lo[0]), int(b + lo[1])) for a, b in np.argwhere(core)]
        self._inner = (len(self.cells), out)
        return out

    def shares(self) -> tuple[float, float]:
        """Shares of the inner columns seen into and seen onto; 0 with fewer than
        :data:`MIN_INNER` inner columns (too little of the piece seen to know its inside)."""
        inner = self.inner()
        if len(inner) < MIN_INNER:
            return 0.0, 0.0
        return (sum(k in self.seen_in for k in inner) / len(inner),
                sum(k in self.seen_on for k in inner) / len(inner))

    def searched(self, container: bool, supporter: bool, share: float = INNER_SHARE) -> bool:
        """Whether at least ``share`` of the inner columns were seen into (a container)
        and onto (a supporter); a piece that is both needs both. A top less than
        :data:`OVER_TOP` below the highest camera is out of sight from anywhere the robot
        stands: a supporter that tall holds its things on the shelves inside it, so it
        needs to be seen into instead."""
        if not (container or supporter):
            return False
        s_in, s_on = self.shares()
        top_out = self.top > self.eye - OVER_TOP
        need_on = supporter and not top_out
        need_in = container or (supporter and top_out)
        return (s_in >= share or not need_in) and (s_on >= share or not need_on)


@dataclass(frozen=True)
class FramePoints:
    """One frame for :func:`look_into`: the world points (N, 3) of its pixels with an
    instance id and finite, positive depth, those ids (N,), and the depth image, camera
    pose (camera to world) and intrinsics the rays are cast with."""

    xyz: np.ndarray
    ids: np.ndarray
    cells: np.ndarray  # (N, 2) the columns of the points, of ``resolution``
    depth: np.ndarray
    pose: np.ndarray
    k: CameraIntrinsics
    resolution: float

    @classmethod
    def of(cls, ids: np.ndarray, depth: np.ndarray, pose: np.ndarray, k: CameraIntrinsics,
           resolution: float) -> FramePoints:
        """Back-project the labelled pixels (depth along the optical axis; camera x right,
        y down, z forward) and find their columns (cells of ``resolution`` m)."""
        depth = np.asarray(depth)
        ids = np.asarray(ids)
        rows, cols = np.nonzero((ids > 0) & np.isfinite(depth) & (depth > 0))
        d = depth[rows, cols].astype(np.float64)
        cam = np.stack([(cols - k.cx) / k.fx * d, (rows - k.cy) / k.fy * d, d], axis=1)
        pose = np.asarray(pose, dtype=np.float64)
        xyz = cam @ pose[:3, :3].T + pose[:3, 3]
        return cls(xyz, ids[rows, cols].astype(np.int64),
                   np.floor(xyz[:, :2] / resolution).astype(np.int64), depth, pose, k,
                   float(resolution))


def look_into(view: PieceView, instance: int, frame: FramePoints) -> None:
    """Update ``view`` of piece ``instance`` with one frame (its ``resolution`` is the
    columns' size). The piece's points add columns and widen its height span; then an
    inner column is

    - *seen into* when a point at one of :data:`SAMPLE_LEVELS` of the span above the
      column's centre (those at least 2 ``resolution`` from the bottom and the top, clear
      of the boards) projects into the image with the depth there at least its own less
      half a ``resolution``, or no return there (the ray passed the piece's boards and
      reached its inside), or a point of another instance lies in the column, 1.5
      ``resolution`` above the bottom;
    - *seen onto* the same for a point ``resolution`` above the top, or another
      instance's point at most 1.5 ``resolution`` below the top or above it;

    other instances' points counting up to ``resolution`` over the top plus 0.3 m (what
    stands in or on it is in view). A side board hides the inside from an oblique view:
    the rays to the middle end on it. :meth:`PieceView.searched` says which a piece needs."""
    mine = frame.ids == instance
    pts = frame.xyz[mine]
    if len(pts) == 0:
        return
    pose, resolution = frame.pose, frame.resolution
    view.eye = max(view.eye, float(pose[2, 3]))
    cells = frame.cells[mine] + _CELL_OFFSET
    keys = np.unique(cells[:, 0] * _CELL_SPAN + cells[:, 1])  # 1-D: far faster than rows
    view.cells.update(zip((keys // _CELL_SPAN - _CELL_OFFSET).tolist(),
                          (keys % _CELL_SPAN - _CELL_OFFSET).tolist(), strict=True))
    view.bottom = min(view.bottom, float(pts[:, 2].min()))
    view.top = max(view.top, float(pts[:, 2].max()))
    inner = view.inner()
    if len(inner) < MIN_INNER:
        return
    tol = 1.5 * resolution  # of another instance's point to the bottom or the top
    clear = (view.bottom + 2 * resolution, view.top - 2 * resolution)  # of the boards
    inside = [z for z in (view.bottom + f * (view.top - view.bottom) for f in SAMPLE_LEVELS)
              if clear[0] <= z <= clear[1]]
    jobs: list[tuple[set[Cell], list[float], float]] = [
        (view.seen_in, inside, view.bottom + tol),
        (view.seen_on, [view.top + resolution], view.top - tol)]
    # other instances' points over the inner columns' box, below the top's reach
    ij = np.asarray(inner, dtype=np.int64)
    lo, hi = ij.min(axis=0), ij.max(axis=0)
    fc = frame.cells
    near = ~mine & (fc[:, 0] >= lo[0]) & (fc[:, 0] <= hi[0]) & (fc[:, 1] >= lo[1]) \
        & (fc[:, 1] <= hi[1])
    o, oc = frame.xyz[near], fc[near]
    keep = o[:, 2] <= view.top + resolution + 0.3
    o, oc = o[keep], oc[keep]
    depth = frame.depth
    h, w = depth.shape
    for seen, levels, floor in jobs:
        todo = [c for c in inner if c not in seen]
        if not todo:
            continue
        if levels:
            n = len(todo)
            xy = (np.asarray(todo, dtype=np.float64) + 0.5) * resolution
            samples = np.concatenate([np.column_stack([xy, np.full(n, z)]) for z in levels])
            cam = (samples - pose[:3, 3]) @ pose[:3, :3]
            z = cam[:, 2]
            with np.errstate(divide="ignore", invalid="ignore"):
                u = np.floor(frame.k.fx * cam[:, 0] / z + frame.k.cx)
                v = np.floor(frame.k.fy * cam[:, 1] / z + frame.k.cy)
            ok = (z > 0) & (u >= 0) & (u < w) & (v >= 0) & (v < h)
            hit = np.zeros(len(samples), dtype=bool)
            d = depth[v[ok].astype(np.int64), u[ok].astype(np.int64)].astype(np.float64)
            hit[ok] = ~np.isfinite(d) | (d <= 0) | (d >= z[ok] - resolution / 2)
            seen.update(todo[int(j)] for j in np.flatnonzero(hit) % n)
        if len(o):
            left = set(todo) - seen
            seen.update(c for c in map(tuple, oc[o[:, 2] > floor].tolist()) if c in left)
