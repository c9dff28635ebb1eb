"""Plane geometry of house specs: polygon area, centroid and containment, door segments,
box corners (pure functions over (x, y) points)."""

from __future__ import annotations

import math
from collections.abc import Sequence

Point = tuple[float, float]
Vec3 = tuple[float, float, float]


def signed_area(poly: Sequence[Point]) -> float:
    """Shoelace area: positive for a counter-clockwise polygon, negative for clockwise."""
    s = 0.0
    n = len(poly)
    for i in range(n):
        x0, y0 = poly[i]
        x1, y1 = poly[(i + 1) % n]
        s += x0 * y1 - x1 * y0
    return s / 2.0


def polygon_centroid(poly: Sequence[Point]) -> Point:
    """Area centroid (the vertex mean for a degenerate polygon)."""
    a = signed_area(poly)
    if abs(a) < 1e-12:
        return (sum(p[0] for p in poly) / len(poly), sum(p[1] for p in poly) / len(poly))
    cx = cy = 0.0
    n = len(poly)
    for i in range(n):
        x0, y0 = poly[i]
        x1, y1 = poly[(i + 1) % n]
        k = x0 * y1 - x1 * y0
        cx += (x0 + x1) * k
        cy += (y0 + y1) * k
    return (cx / (6 * a), cy / (6 * a))


def point_in_polygon(x: float, y: float, poly: Sequence[Point]) -> bool:
    """Even-odd rule; points on an edge count as inside."""
    n = len(poly)
    inside = False
    for i in range(n):
        x0, y0 = poly[i]
        x1, y1 = poly[(i + 1) % n]
        # on the edge?
        cross = (x1 - x0) * (y - y0) - (y1 - y0) * (x - x0)
        if abs(cross) < 1e-9 and min(x0, x1) - 1e-9 <= x <= max(x0, x1) + 1e-9 \
                and min(y0, y1) - 1e-9 <= y <= max(y0, y1) + 1e-9:
            return True
        if (y0 > y) != (y1 > y):
            xi = x0 + (y - y0) * (x1 - x0) / (y1 - y0)
            if x < xi:
                inside = not inside
    return inside


def opening_segment(center: Sequence[float], width: float, yaw: float) -> tuple[Point, Point]:
    """End points of an opening of ``width`` centred at ``center`` along direction ``yaw``."""
    dx, dy = math.cos(yaw) * width / 2.0, math.sin(yaw) * width / 2.0
    return ((center[0] - dx, center[1] - dy), (center[0] + dx, center[1] + dy))


def box_corners(center: Sequence[float], size: Sequence[float],
                yaw: float) -> tuple[Point, Point, Point, Point]:
    """The four corners of an oriented rectangle, counter-clockwise."""
    c, s = math.cos(yaw), math.sin(yaw)
    hx, hy = size[0] / 2.0, size[1] / 2.0
    out = []
    for lx, ly in ((-hx, -hy), (hx, -hy), (hx, hy), (-hx, hy)):
        out.append((center[0] + c * lx - s * ly, center[1] + s * lx + c * ly))
    return tuple(out)  # type: ignore[return-value]
