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

_CELL = 0.05  # resolution of the in-room free-space checks


class RoomSpace:
    """Free-space bookkeeping of one room for the placement checks."""

    def __init__(self, room: PlanRoom, openings: list[Opening]):
        self.room = room
        self.inner = room.rect.shrink(WALL_T / 2)
        self.cols = int(round(self.inner.width / _CELL))
        self.rows = int(round(self.inner.height / _CELL))
        self.occ = np.zeros((self.rows, self.cols), bool)
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
        r = int(math.floor((y - self.inner.y0) / _CELL))
        c = int(math.floor((x - self.inner.x0) / _CELL))
        return (min(max(r, 0), self.rows - 1), min(max(c, 0), self.cols - 1))

    def _cell_slices(self, box: Rect) -> tuple[slice, slice]:
        c0 = max(int(math.floor((box.x0 - self.inner.x0) / _CELL + 1e-6)), 0)
        c1 = min(int(math.ceil((box.x1 - self.inner.x0) / _CELL - 1e-6)), self.cols)
        r0 = max(int(math.floor((box.y0 - self.inner.y0) / _CELL + 1e-6)), 0)
        r1 = min(int(math.ceil((box.y1 - self.inner.y0) / _CELL - 1e-6)), self.rows)
        return slice(r0, r1), slice(c0, c1)

    def free_ok(self, boxes_to_reach: Sequence[Rect], extra: Rect | None) -> bool:
        """Can the robot cross between all openings and reach every box within REACH?"""
        occ = self.occ.copy()
        if extra is not None:
            occ[self._cell_slices(extra)] = True
        padded = np.pad(occ, 1, constant_values=True)  # the walls
        dist = ndimage.distance_transform_edt(~padded, sampling=_CELL)[1:-1, 1:-1]
        free = dist >= ROBOT_RADIUS + _CELL / 2 - 1e-9
        labels, _ = ndimage.label(free, structure=np.ones((3, 3), bool))
        if not self.approach:
            return True
        lab = {int(labels[a]) for a in self.approach}
        if 0 in lab or len(lab) != 1:
            return False
        main = labels == lab.pop()
        if not boxes_to_reach:
            return True
        ys = self.inner.y0 + (np.arange(self.rows) + 0.5) * _CELL
        xs = self.inner.x0 + (np.arange(self.cols) + 0.5) * _CELL
        for b in boxes_to_reach:
            dx = np.maximum(np.maximum(b.x0 - xs, xs - b.x1), 0.0)
            dy = np.maximum(np.maximum(b.y0 - ys, ys - b.y1), 0.0)
            near = (dy[:, None] ** 2 + dx[None, :] ** 2) <= (REACH - ROBOT_RADIUS) ** 2
            # the robot centre within REACH - radius of the box: its body within REACH
            if not (near & main).any():
                return False
        return True

    def add(self, box: Rect) -> None:
        self.occ[self._cell_slices(box)] = True
