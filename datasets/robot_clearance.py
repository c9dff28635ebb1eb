"""Start poses of a generated house and the check that it is usable: every room reachable
from the first corridor (closed doors passable) and every container approachable within
:data:`REACH`; a house failing it is redrawn (:class:`~sgtool.datasets.house_plan.PlanRetry`)."""

from __future__ import annotations

import math

import numpy as np

from sgtool.datasets.house_plan import PlanRetry
from sgtool.house.spec import HouseSpec
from sgtool.mapping.occupancy import geodesic_distances, house_occupancy
from sgtool.mapping.raster import cell_centers, cell_window

ROBOT_RADIUS = 0.2
REACH = 1.0  # the robot must be able to stand within this of every container (m)


def start_poses(rng: np.random.Generator, spec: HouseSpec) -> list[dict]:
    """A start pose per room (free cell nearest the room's centre, reachable from the
    first corridor with closed doors passable); raises PlanRetry when a room or a container
    cannot be reached."""
    occ = house_occupancy(spec, closed_doors_free=True, robot_radius=ROBOT_RADIUS)
    c0 = spec.rooms[0].centroid
    dist = geodesic_distances(occ, c0, max_snap=1.0)
    reach = np.isfinite(dist)
    if not reach.any():
        raise PlanRetry
    X, Y = cell_centers(occ)
    starts = []
    for r in spec.rooms:
        x0, y0, x1, y1 = r.bounds
        # every cell centre strictly inside the room lies in this window (row-major order
        # kept, so argmin picks the same first cell as over the whole grid)
        win = cell_window(occ, [x0, x1], [y0, y1])
        if win is None:
            raise PlanRetry
        Xw, Yw = X[win], Y[win]
        inside = (Xw > x0) & (Xw < x1) & (Yw > y0) & (Yw < y1) & reach[win]
        if not inside.any():
            raise PlanRetry
        cx, cy = r.centroid
        d2 = np.where(inside, (Xw - cx) ** 2 + (Yw - cy) ** 2, np.inf)
        i = int(np.argmin(d2))
        yaw = round(float(rng.uniform(-math.pi, math.pi)), 4)
        starts.append({"x": round(float(Xw.ravel()[i]), 4), "y": round(float(Yw.ravel()[i]), 4),
                       "yaw": yaw, "room": r.id})
    m = REACH - ROBOT_RADIUS
    for f in spec.furniture:
        if not f.affordances:
            continue
        (ax, ay), (bx, by) = f.footprint()[0], f.footprint()[2]
        bx0, bx1 = min(ax, bx), max(ax, bx)
        by0, by1 = min(ay, by), max(ay, by)
        # cells farther than m from the box cannot count: look at the box grown by m
        win = cell_window(occ, [bx0 - m, bx1 + m], [by0 - m, by1 + m])
        if win is None:
            raise PlanRetry
        Xw, Yw = X[win], Y[win]
        dx = np.maximum(np.maximum(bx0 - Xw, Xw - bx1), 0.0)
        dy = np.maximum(np.maximum(by0 - Yw, Yw - by1), 0.0)
        if not ((dx ** 2 + dy ** 2 <= m ** 2) & reach[win]).any():
            raise PlanRetry
    return starts
