"""Start poses of a generated house and the check that it is usable: every room reachable
from the first corridor (closed doors passable) and every container approachable within
:data:`REACH`; a house failing it is redrawn (:class:`~sgtool.datasets.house_plan.PlanRetry`)."""

from __future__ import annotations

import math

import numpy as np

from sgtool.datasets.house_plan import PlanRetry
from sgtool.house.spec import HouseSpec
from sgtool.mapping.occupancy import geodesic_distances, house_occupancy
from sgtool.mapping.raster import cell_centers

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
        inside = (X > x0) & (X < x1) & (Y > y0) & (Y < y1) & reach
        if not inside.any():
            raise PlanRetry
        cx, cy = r.centroid
        d2 = np.where(inside, (X - cx) ** 2 + (Y - cy) ** 2, np.inf)
        i = int(np.argmin(d2))
        yaw = round(float(rng.uniform(-math.pi, math.pi)), 4)
        starts.append({"x": round(float(X.ravel()[i]), 4), "y": round(float(Y.ravel()[i]), 4),
                       "yaw": yaw, "room": r.id})
    for f in spec.furniture:
        if not f.affordances:
            continue
        (ax, ay), (bx, by) = f.footprint()[0], f.footprint()[2]
        bx0, bx1 = min(ax, bx), max(ax, bx)
        by0, by1 = min(ay, by), max(ay, by)
        dx = np.maximum(np.maximum(bx0 - X, X - bx1), 0.0)
        dy = np.maximum(np.maximum(by0 - Y, Y - by1), 0.0)
        if not ((dx ** 2 + dy ** 2 <= (REACH - ROBOT_RADIUS) ** 2) & reach).any():
            raise PlanRetry
    return starts
