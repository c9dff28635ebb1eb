"""Plane geometry of house specs: polygon area, centroid and containment, door segments,
box corners, distances to segments and polygons, triangulation and the area two polygons
share (pure functions over (x, y) points)."""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

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

    def corner(lx: float, ly: float) -> Point:
        return (center[0] + c * lx - s * ly, center[1] + s * lx + c * ly)

    return corner(-hx, -hy), corner(hx, -hy), corner(hx, hy), corner(-hx, hy)


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
    return distance_to_border(x, y, poly)


def distance_to_border(x: float, y: float, poly: Sequence[Point]) -> float:
    """Distance from (x, y), inside or outside, to the border of ``poly``."""
    n = len(poly)
    return min(segment_distance(x, y, poly[i], poly[(i + 1) % n]) for i in range(n))


def nearest_edge_direction(x: float, y: float, poly: Sequence[Point]) -> float:
    """The direction (radians, in [0, pi)) of the edge of ``poly`` nearest (x, y)."""
    n = len(poly)
    i = min(range(n), key=lambda k: segment_distance(x, y, poly[k], poly[(k + 1) % n]))
    (ax, ay), (bx, by) = poly[i], poly[(i + 1) % n]
    return math.atan2(by - ay, bx - ax) % math.pi


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


def self_crossing(poly: Sequence[Point], eps: float = 1e-9) -> tuple[int, int, bool] | None:
    """Two edges of ``poly`` that make it not simple, as (i, j, proper) with edge k from
    point k to point k + 1, or None for a simple polygon. ``proper``: edges that are not
    neighbours meet (cross or touch); else two neighbouring edges fold back over each
    other. Repeated consecutive points are skipped; O(n^2) in the points."""
    keep = [k for k in range(len(poly)) if poly[k] != poly[(k + 1) % len(poly)]]
    n = len(keep)
    if n < 3:
        return None
    pts = [poly[k] for k in keep]
    edges = [(pts[k], pts[(k + 1) % n]) for k in range(n)]
    folded = None
    for i in range(n):
        for j in range(i + 1, n):
            (a, b), (c, d) = edges[i], edges[j]
            if j == i + 1 or (i == 0 and j == n - 1):
                # neighbours share one point: they fold back when collinear and opposite
                o, p, q = (b, a, d) if j == i + 1 else (a, b, c)
                if folded is None and \
                        abs(_cross(o, p, q)) <= eps * (1 + math.dist(o, p) * math.dist(o, q)) \
                        and (p[0] - o[0]) * (q[0] - o[0]) + (p[1] - o[1]) * (q[1] - o[1]) > 0:
                    folded = (keep[i], keep[j], False)
            elif _segments_meet(a, b, c, d, eps):
                return (keep[i], keep[j], True)
    return folded


def _segments_meet(a: Point, b: Point, c: Point, d: Point, eps: float) -> bool:
    """Whether the closed segments a-b and c-d share a point (within ``eps``)."""
    if max(a[0], b[0]) < min(c[0], d[0]) - eps or max(c[0], d[0]) < min(a[0], b[0]) - eps \
            or max(a[1], b[1]) < min(c[1], d[1]) - eps \
            or max(c[1], d[1]) < min(a[1], b[1]) - eps:
        return False
    d1, d2 = _cross(a, b, c), _cross(a, b, d)
    d3, d4 = _cross(c, d, a), _cross(c, d, b)
    if ((d1 > eps and d2 < -eps) or (d1 < -eps and d2 > eps)) and \
            ((d3 > eps and d4 < -eps) or (d3 < -eps and d4 > eps)):
        return True
    return segment_distance(c[0], c[1], a, b) <= eps or segment_distance(d[0], d[1], a, b) <= eps \
        or segment_distance(a[0], a[1], c, d) <= eps or segment_distance(b[0], b[1], c, d) <= eps


def segments_cross(p: Point, q: Point, a: Point, b: Point) -> bool:
    """Whether segment p-q passes from one side of segment a-b to the other: each strictly
    separates the other's end points (touching or running along does not count)."""
    d1, d2 = _cross(a, b, p), _cross(a, b, q)
    d3, d4 = _cross(p, q, a), _cross(p, q, b)
    return d1 * d2 < 0.0 and d3 * d4 < 0.0


def length_in_strip(p: Point, q: Point, a: Point, b: Point, half_width: float) -> float:
    """Length of the part of segment p-q inside the rectangle around segment a-b of
    half-width ``half_width`` (a wall's body: no caps beyond a and b); Liang-Barsky."""
    length = math.dist(a, b)
    if length == 0:
        return 0.0
    ux, uy = (b[0] - a[0]) / length, (b[1] - a[1]) / length

    def local(r: Point) -> Point:
        dx, dy = r[0] - a[0], r[1] - a[1]
        return (dx * ux + dy * uy, -dx * uy + dy * ux)

    (u0, v0), (u1, v1) = local(p), local(q)
    t0, t1 = 0.0, 1.0
    for d, lo, hi, start in ((u1 - u0, 0.0, length, u0), (v1 - v0, -half_width, half_width, v0)):
        if d == 0:
            if not lo <= start <= hi:
                return 0.0
            continue
        ta, tb = (lo - start) / d, (hi - start) / d
        t0, t1 = max(t0, min(ta, tb)), min(t1, max(ta, tb))
        if t0 >= t1:
            return 0.0
    return (t1 - t0) * math.dist(p, q)


def shared_borders(a: Sequence[Point], b: Sequence[Point],
                   tol: float) -> list[tuple[Point, Point]]:
    """The pieces of ``a``'s edges that lie along an edge of ``b`` (parallel, within
    ``tol`` of it, overlapping by more than ``tol``): the border two rooms share. All edge
    pairs at once (numpy), so 64-point rooms cost little."""
    pa, pb = np.asarray(a, dtype=np.float64), np.asarray(b, dtype=np.float64)
    lengths = np.hypot(*(np.roll(pa, -1, axis=0) - pa).T)
    u = (np.roll(pa, -1, axis=0) - pa) / np.maximum(lengths, 1e-300)[:, None]

    def along_across(pts: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        d = pts[None, :, :] - pa[:, None, :]  # (edge of a, point of b)
        return (d[..., 0] * u[:, None, 0] + d[..., 1] * u[:, None, 1],
                np.abs(-d[..., 0] * u[:, None, 1] + d[..., 1] * u[:, None, 0]))

    tc, oc = along_across(pb)
    td, od = along_across(np.roll(pb, -1, axis=0))
    t0 = np.maximum(0.0, np.minimum(tc, td))
    t1 = np.minimum(lengths[:, None], np.maximum(tc, td))
    hit = (oc <= tol) & (od <= tol) & (lengths > tol)[:, None] & (t1 - t0 > tol)
    out = []
    for i, j in np.argwhere(hit):
        (px, py), (ux, uy) = pa[i], u[i]
        out.append(((float(px + t0[i, j] * ux), float(py + t0[i, j] * uy)),
                    (float(px + t1[i, j] * ux), float(py + t1[i, j] * uy))))
    return out


def longest_uncovered(p: Point, q: Point, covers: Sequence[tuple[Point, Point, float]],
                      tol: float) -> tuple[float, Point]:
    """(length, midpoint) of the longest piece of segment p-q that none of ``covers``
    (segments a-b with a half-width: walls) lies along; a cover counts when both its ends
    are within its half-width plus ``tol`` of the line of p-q."""
    length = math.dist(p, q)
    ux, uy = (q[0] - p[0]) / length, (q[1] - p[1]) / length
    spans = []
    for a, b, half in covers:
        off = max(abs(-(a[0] - p[0]) * uy + (a[1] - p[1]) * ux),
                  abs(-(b[0] - p[0]) * uy + (b[1] - p[1]) * ux))
        if off <= half + tol:
            ta = (a[0] - p[0]) * ux + (a[1] - p[1]) * uy
            tb = (b[0] - p[0]) * ux + (b[1] - p[1]) * uy
            spans.append((min(ta, tb), max(ta, tb)))
    best, at, t = 0.0, 0.0, 0.0
    for s0, s1 in sorted(spans) + [(length, length)]:
        s0 = min(s0, length)
        if s0 - t > best:
            best, at = s0 - t, (t + s0) / 2
        t = max(t, s1)
        if t >= length:
            break
    return best, (p[0] + at * ux, p[1] + at * uy)
