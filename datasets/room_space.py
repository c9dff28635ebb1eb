"""Free-space bookkeeping of one room while it is furnished: a fine grid of the room's
inside, keep-out zones in front of its openings, and the check that the robot can still
cross the room between its openings and reach every piece that matters."""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
from scipy import ndimage

from sgtool.datasets.house_plan import WALL_T, Opening, PlanRoom, Rect
from sgtool.datasets.robot_clearance import REACH, ROBOT_RADIUS

CELL = 0.05  # m: side of a cell of a room's free-space grid (RoomSpace: occ, blocked)
_BLOCK_D2 = 20  # squared cell distance below ROBOT_RADIUS + CELL / 2 (see free_ok)
_BLOCK_CELLS = 4  # the largest row or column offset within _BLOCK_D2


class RoomSpace:
    """Free-space bookkeeping of one room for the placement checks."""

    def __init__(self, room: PlanRoom, openings: list[Opening]):
        self.room = room
        self.inner = room.rect.shrink(WALL_T / 2)
        self.cols = int(round(self.inner.width / CELL))
        self.rows = int(round(self.inner.height / CELL))
        self.occ = np.zeros((self.rows, self.cols), bool)
        # cells the robot's centre cannot take: within _BLOCK_D2 (cells^2) of the walls or
        # of an occupied cell; kept up to date by add(), so free_ok() only adds its box
        self.blocked = np.zeros((self.rows, self.cols), bool)
        w = _BLOCK_CELLS
        self.blocked[:w, :] = self.blocked[-w:, :] = True
        self.blocked[:, :w] = self.blocked[:, -w:] = True
        self.ys = self.inner.y0 + (np.arange(self.rows) + 0.5) * CELL
        self.xs = self.inner.x0 + (np.arange(self.cols) + 0.5) * CELL
        self.keepouts: list[Rect] = []
        self.approach: list[tuple[int, int]] = []
        for o in openings:
            if room.idx not in o.rooms:
                continue
            c, half = o.center, o.width / 2 + 0.15
            depth = 1.0
            if o.horizontal:
                inward = 1.0 if c[1] <= room.rect.y0 + 1e-6 else -1.0
                y_in = c[1] + inward * depth
                self.keepouts.append(Rect(c[0] - half, min(c[1], y_in), c[0] + half,
                                           max(c[1], y_in)))
                ap = (c[0], c[1] + inward * 0.4)
            else:
                inward = 1.0 if c[0] <= room.rect.x0 + 1e-6 else -1.0
                x_in = c[0] + inward * depth
                self.keepouts.append(Rect(min(c[0], x_in), c[1] - half, max(c[0], x_in),
                                           c[1] + half))
                ap = (c[0] + inward * 0.4, c[1])
            self.approach.append(self.cell(*ap))

    def cell(self, x: float, y: float) -> tuple[int, int]:
        r = int(math.floor((y - self.inner.y0) / CELL))
        c = int(math.floor((x - self.inner.x0) / CELL))
        return (min(max(r, 0), self.rows - 1), min(max(c, 0), self.cols - 1))

    def _cell_slices(self, box: Rect) -> tuple[slice, slice]:
        c0 = max(int(math.floor((box.x0 - self.inner.x0) / CELL + 1e-6)), 0)
        c1 = min(int(math.ceil((box.x1 - self.inner.x0) / CELL - 1e-6)), self.cols)
        r0 = max(int(math.floor((box.y0 - self.inner.y0) / CELL + 1e-6)), 0)
        r1 = min(int(math.ceil((box.y1 - self.inner.y0) / CELL - 1e-6)), self.rows)
        return slice(r0, r1), slice(c0, c1)

    def _blocked_by(self, box: Rect) -> tuple[tuple[slice, slice], np.ndarray] | None:
        """(window, mask) of the cells within _BLOCK_D2 of ``box``'s cells; None if none."""
        rs, cs = self._cell_slices(box)
        # the cells occ[rs, cs] marks (a negative stop counts from the end, as in numpy)
        r0, r1, _ = rs.indices(self.rows)
        c0, c1, _ = cs.indices(self.cols)
        if r0 >= r1 or c0 >= c1:
            return None
        w = _BLOCK_CELLS
        win = (slice(max(r0 - w, 0), min(r1 + w, self.rows)),
               slice(max(c0 - w, 0), min(c1 + w, self.cols)))
        r = np.arange(win[0].start, win[0].stop)
        c = np.arange(win[1].start, win[1].stop)
        dr = np.maximum(np.maximum(r0 - r, r - (r1 - 1)), 0)
        dc = np.maximum(np.maximum(c0 - c, c - (c1 - 1)), 0)
        return win, dr[:, None] ** 2 + dc[None, :] ** 2 <= _BLOCK_D2

    def free_ok(self, boxes_to_reach: Sequence[Rect], extra: Rect | None) -> bool:
        """Can the robot cross between all openings and reach every box within REACH?

        A cell is free when its centre is at least ROBOT_RADIUS + half a cell from every
        occupied cell and wall cell (the padded grid's Euclidean distance transform, the
        definition ``free_mask_edt`` in tests/support/room_space_reference.py computes); in
        cells that is a squared distance of at least 25 (offsets of squared length 21-24 do
        not exist, 20 is 0.2236 m < 0.225 m), so the blocked cells are those within a squared
        distance of 20 (``_BLOCK_D2``)."""
        blocked = self.blocked
        if extra is not None:
            more = self._blocked_by(extra)
            if more is not None:
                blocked = blocked.copy()
                blocked[more[0]] |= more[1]
        free = ~blocked
        labels, _ = ndimage.label(free, structure=np.ones((3, 3), bool))
        if not self.approach:
            return True
        lab = {int(labels[a]) for a in self.approach}
        if 0 in lab or len(lab) != 1:
            return False
        main = labels == lab.pop()
        if not boxes_to_reach:
            return True
        m = REACH - ROBOT_RADIUS
        for b in boxes_to_reach:
            # only cells within m of the box can be near it: look at those rows and columns
            rs, cs = self._cell_slices(Rect(b.x0 - m - CELL, b.y0 - m - CELL,
                                            b.x1 + m + CELL, b.y1 + m + CELL))
            xs, ys = self.xs[cs], self.ys[rs]
            dx = np.maximum(np.maximum(b.x0 - xs, xs - b.x1), 0.0)
            dy = np.maximum(np.maximum(b.y0 - ys, ys - b.y1), 0.0)
            near = (dy[:, None] ** 2 + dx[None, :] ** 2) <= (REACH - ROBOT_RADIUS) ** 2
            # the robot centre within REACH - radius of the box: its body within REACH
            if not (near & main[rs, cs]).any():
                return False
        return True

    def add(self, box: Rect) -> None:
        self.occ[self._cell_slices(box)] = True
        more = self._blocked_by(box)
        if more is not None:
            self.blocked[more[0]] |= more[1]
