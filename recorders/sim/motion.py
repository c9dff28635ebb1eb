"""Motion that sees while it moves (pure): per-frame poses that turn while driving, and
the headings a look-around needs on the robot's own map.

- :func:`drive_while_turning`: the positions follow the path's polyline exactly (the
  segments the planner checked free), ``step`` metres a frame; the heading turns at most
  ``turn_step`` a frame toward the path a ``lookahead`` ahead, so it comes round before a
  corner instead of stopping at it. The base only turns on the spot while the heading is
  more than ``max_off`` radians off the segment it is on (the start of a path that leaves
  behind the robot, a sharp corner); at the end it turns to ``final_yaw`` when given.
- :func:`sweep`: the turn (signed radians) that brings every bearing of unknown space
  near the robot into the camera's horizontal field of view, the shorter way round;
  0 when nothing around is unknown. Given what the camera cannot see over (the voxel
  columns reaching above it: walls, wardrobes), only unknown space in sight counts, so
  the robot does not turn to the room behind a wall; space behind a table or a bed does.
- :func:`peek_tilt` and :func:`head_tilts`: the camera tilt that aims into an opened
  container seen from where the robot stands (the optical axis at half the height of the
  container's node above the floor below it, so a floor-standing piece's lower shelves
  and bottom board are in view), and the per-frame tilts of the head's motion there and
  back.
"""

from __future__ import annotations

import bisect
import math
from collections.abc import Sequence

import numpy as np

from sgtool.mapping.bev import line_of_sight
from sgtool.mapping.grid import OccupancyGrid
from sgtool.recorders.sim.navigation import Pose2, turn_poses, wrap_angle


def _along(pts: list[tuple[float, float]], cum: list[float], s: float) -> tuple[float, float]:
    """The point ``s`` metres along the polyline ``pts`` (cumulative lengths ``cum``)."""
    if s >= cum[-1]:
        return pts[-1]
    k = bisect.bisect_right(cum, s) - 1  # the last i with cum[i] <= s
    seg = cum[k + 1] - cum[k]
    t = 0.0 if seg <= 0 else (s - cum[k]) / seg
    a, b = pts[k], pts[k + 1]
    return a[0] + (b[0] - a[0]) * t, a[1] + (b[1] - a[1]) * t


def drive_while_turning(pose: Pose2, waypoints: Sequence[Sequence[float]], step: float,
                        turn_step: float, final_yaw: float | None = None,
                        lookahead: float = 0.5, max_off: float = math.radians(50.0)
                        ) -> list[Pose2]:
    """Per-frame poses along ``waypoints`` from ``pose`` (module doc). Every position is
    on the polyline from ``pose`` through the waypoints; consecutive positions are at most
    ``step`` apart and headings at most ``turn_step`` (radians) apart."""
    pts: list[tuple[float, float]] = [(float(pose[0]), float(pose[1]))]
    for w in waypoints:
        if math.dist(pts[-1], w) >= 1e-3:
            pts.append((float(w[0]), float(w[1])))
    out: list[Pose2] = []
    x, y, a = float(pose[0]), float(pose[1]), float(pose[2])
    if len(pts) > 1:
        cum = [0.0]
        for p, q in zip(pts, pts[1:], strict=False):
            cum.append(cum[-1] + math.dist(p, q))
        total, s = cum[-1], 0.0
        while True:  # each frame advances, or turns toward the segment (then advances)
            if total - s < 1e-9:
                break
            k = min(bisect.bisect_right(cum, s + 1e-12), len(cum) - 1) - 1
            seg_dir = math.atan2(pts[k + 1][1] - pts[k][1], pts[k + 1][0] - pts[k][0])
            ax, ay = _along(pts, cum, min(s + lookahead, total))
            want = math.atan2(ay - y, ax - x) if math.hypot(ax - x, ay - y) > 1e-9 \
                else seg_dir
            off = wrap_angle(a - seg_dir)
            if abs(off) > max_off + 1e-9:  # too far off the segment: turn on the spot
                a = wrap_angle(a + max(-turn_step, min(turn_step, -off)))
            else:  # drive, turning toward the path ahead but never off the segment
                to = max(-max_off, min(max_off, wrap_angle(want - seg_dir)))
                da = wrap_angle(seg_dir + to - a)
                a = wrap_angle(a + max(-turn_step, min(turn_step, da)))
                s = min(s + step, total)
                x, y = _along(pts, cum, s)
            out.append((x, y, a))
    if final_yaw is not None:
        out += turn_poses((x, y, a), final_yaw, turn_step)
    return out


def sweep(grid: OccupancyGrid, pose: Pose2, hfov: float, radius: float = 3.0,
          sectors: int = 24, min_cells: int = 4, blockers: np.ndarray | None = None
          ) -> float:
    """The turn (radians, + counter-clockwise) from ``pose``'s heading that brings every
    sector of bearings holding at least ``min_cells`` unknown cells within ``radius`` m
    into the horizontal field of view ``hfov`` (module doc); the shorter way round, 0 when
    no sector qualifies, at most one full turn. Cells outside the grid count as unknown
    (the map has not reached them). With ``blockers`` (a bool mask over ``grid``: what the
    camera cannot see over) only unknown cells in sight count: the straight line to them
    crosses no blocker."""
    x, y, a = pose
    res = grid.resolution
    n = int(math.ceil(radius / res))
    r0, c0 = grid.cell_of(x, y)
    rr, cc = np.mgrid[int(r0) - n:int(r0) + n + 1, int(c0) - n:int(c0) + n + 1]
    cx = grid.origin[0] + (cc + 0.5) * res
    cy = grid.origin[1] + (rr + 0.5) * res
    d = np.hypot(cx - x, cy - y)
    near = (d <= radius) & (d > 2 * res)
    h, w = grid.shape
    inside = (rr >= 0) & (rr < h) & (cc >= 0) & (cc < w)
    unknown = ~inside
    unknown[inside] = grid.grid[rr[inside], cc[inside]] == -1
    sel = near & unknown
    if blockers is not None and sel.any():  # the cell itself may hold what blocks
        ends = np.stack([cx[sel], cy[sel]], axis=1)
        sel[sel] = line_of_sight(blockers, grid, np.broadcast_to([x, y], ends.shape), ends,
                                 skip_end=res, outside_blocks=False)
    if not sel.any():
        return 0.0
    bearing = np.arctan2(cy[sel] - y, cx[sel] - x)
    k = np.floor((bearing + math.pi) / (2 * math.pi) * sectors).astype(int) % sectors
    counts = np.bincount(k, minlength=sectors)
    wanted = [-math.pi + (i + 0.5) * 2 * math.pi / sectors
              for i in range(sectors) if counts[i] >= min_cells]
    if not wanted:
        return 0.0
    half = hfov / 2
    two_pi = 2 * math.pi
    plus = minus = 0.0
    for b in wanted:
        u = (b - a) % two_pi  # counter-clockwise from the heading
        if half < u < two_pi - half:
            plus = max(plus, u - half)
            minus = max(minus, (two_pi - u) - half)
    if plus == 0.0 and minus == 0.0:
        return 0.0
    best = plus if plus <= minus else -minus
    return max(-two_pi, min(two_pi, best))


def peek_tilt(mount_height: float, tilt_deg: float, base_xy: Sequence[float],
              at: Sequence[float], max_tilt: float = 75.0, min_gain: float = 5.0
              ) -> float | None:
    """The downward tilt (degrees) that puts the optical axis of a camera ``mount_height``
    above the floor at ``base_xy`` on the point at half the height of ``at`` (x, y, z: a
    container node's position) above the floor under it, at most ``max_tilt``; None when
    that is less than ``min_gain`` degrees below the configured ``tilt_deg`` (the camera
    sees there already)."""
    d = math.hypot(float(at[0]) - float(base_xy[0]), float(at[1]) - float(base_xy[1]))
    z = 0.5 * max(float(at[2]), 0.0)
    tilt = min(math.degrees(math.atan2(mount_height - z, max(d, 1e-6))), max_tilt)
    return tilt if tilt >= tilt_deg + min_gain else None


def head_tilts(start: float, goal: float, step: float) -> list[float]:
    """Tilts (degrees) from ``start`` to ``goal``, at most ``step`` apart, ending on
    ``goal`` and excluding ``start``; empty when they are equal."""
    if step <= 0.0:
        raise ValueError(f"head step {step}: must be > 0")
    n = math.ceil(abs(goal - start) / step - 1e-9)
    return [start + (goal - start) * k / n for k in range(1, n + 1)]
