"""Plane geometry of house specs: polygon area, centroid and containment, door segments,
box corners, distances to segments and polygons, triangulation and the area two polygons
share (pure functions over (x, y) points)."""

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


def segment_distance(x: float, y: float, a: Point, b: Point) -> float:
    """Distance from (x, y) to the segment a-b."""
    dx, dy = b[0] - a[0], b[1] - a[1]
    n = dx * dx + dy * dy
    t = 0.0 if n == 0 else max(0.0, min(1.0, ((x - a[0]) * dx + (y - a[1]) * dy) / n))
    return math.hypot(x - a[0] - t * dx, y - a[1] - t * dy)


def distance_to_polygon(x: float, y: float, poly: Sequence[Point]) -> float:
    """0 inside (or on the border of) ``poly``, else the distance to its border."""
    if point_in_polygon(x, y, poly):
        return 0.0
    n = len(poly)
    return min(segment_distance(x, y, poly[i], poly[(i + 1) % n]) for i in range(n))


def triangulate(poly: Sequence[Point]) -> list[tuple[Point, Point, Point]]:
    """Counter-clockwise triangles covering a simple polygon (ear clipping, O(n^2))."""
    pts = list(poly) if signed_area(poly) > 0 else list(reversed(poly))
    idx = list(range(len(pts)))
    out: list[tuple[Point, Point, Point]] = []
    guard = 0
    while len(idx) > 3 and guard < 2 * len(pts) ** 2:
        guard += 1
        for k in range(len(idx)):
            a, b, c = pts[idx[k - 1]], pts[idx[k]], pts[idx[(k + 1) % len(idx)]]
            if _cross(a, b, c) <= 1e-12:
                continue  # reflex or flat corner: not an ear
            if any(_in_triangle(pts[j], a, b, c) for j in idx
                   if j not in (idx[k - 1], idx[k], idx[(k + 1) % len(idx)])):
                continue
            out.append((a, b, c))
            del idx[k]
            break
        else:
            break  # no ear left (self-intersecting input): keep what was found
    if len(idx) == 3:
        out.append((pts[idx[0]], pts[idx[1]], pts[idx[2]]))
    return out


def _cross(a: Point, b: Point, c: Point) -> float:
    return (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])


def _in_triangle(p: Point, a: Point, b: Point, c: Point) -> bool:
    return _cross(a, b, p) >= 0 and _cross(b, c, p) >= 0 and _cross(c, a, p) >= 0


def clip_convex(subject: Sequence[Point], clip: Sequence[Point]) -> list[Point]:
    """``subject`` clipped to the convex counter-clockwise polygon ``clip``
    (Sutherland-Hodgman)."""
    out = list(subject)
    n = len(clip)
    for i in range(n):
        if not out:
            break
        a, b = clip[i], clip[(i + 1) % n]
        src, out = out, []
        for j in range(len(src)):
            p, q = src[j - 1], src[j]
            pin, qin = _cross(a, b, p) >= 0, _cross(a, b, q) >= 0
            if qin:
                if not pin:
                    out.append(_intersection(a, b, p, q))
                out.append(q)
            elif pin:
                out.append(_intersection(a, b, p, q))
    return out


def _intersection(a: Point, b: Point, p: Point, q: Point) -> Point:
    """Where the segment p-q crosses the line a-b."""
    dp, dq = _cross(a, b, p), _cross(a, b, q)
    t = dp / (dp - dq)
    return (p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1]))


def overlap_area(a: Sequence[Point], b: Sequence[Point]) -> float:
    """Area shared by two simple polygons (sum over pairs of their triangles)."""
    ta, tb = triangulate(a), triangulate(b)
    total = 0.0
    for t in ta:
        bt = _bounds(t)
        for u in tb:
            if _boxes_meet(bt, _bounds(u)):
                piece = clip_convex(t, u)
                if len(piece) >= 3:
                    total += abs(signed_area(piece))
    return total


def _bounds(poly: Sequence[Point]) -> tuple[float, float, float, float]:
    xs = [p[0] for p in poly]
    ys = [p[1] for p in poly]
    return (min(xs), min(ys), max(xs), max(ys))


def _boxes_meet(a: tuple[float, float, float, float], b: tuple[float, float, float, float]) -> bool:
    return a[0] < b[2] and b[0] < a[2] and a[1] < b[3] and b[1] < a[3]
