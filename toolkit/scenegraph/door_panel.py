"""The doorway of a door seen only as its swung-open panel (:func:`opening_from_panel`).

A panel swung open stands at right angles to its wall, hinged at one end of its doorway;
turned back by 90 degrees about that hinge it covers the doorway, the cells the room
segmentation needs as door evidence. Which end is the hinge, and which side the doorway
lies on, is read from the surroundings: the wall running away from the hinge, a clear
opening across the doorway and the far jamb beyond it: the wall continuing in line, or at
a room's corner the wall across the doorway's line, where the doorway then ends.

The hinge need not touch the panel's seen end: near the hinge the panel stands in the
corner between wall and door and is often seen only in part, so the wall line may lie
beyond the seen end, up to the seen panel's own length. A hinge that far is believed only
where the panel's line up to the wall line may be panel: no floor seen on it (a door is
hinged to its wall, so floor seen there says the panel ends before it, as past a panel's
free end, where a counter along the room's wall can look like a wall line with a gap),
and no wall crossed on the way (the line of a door standing partly open runs on through
its doorway's wall).
"""

from __future__ import annotations

import hashlib
from collections.abc import Callable
from typing import Any

import numpy as np
from scipy import ndimage

from sgtool.mapping.grid import grid_at

LINE_LEAST = 0.5  # the wall-line score a hinge needs (0 to 1: wall on both sides, clear)
LINE_MARGIN = 0.25  # and its lead over every other hinge and side
MIN_REACH = 3  # cells past a panel's end the wall line is looked for, at least
OFFSET_SLACK = 0.1  # a wall line this close to the best score of its hinge and side is as good
CROSSING_NEAR, CROSSING_FAR = 0.8, 1.1  # door lengths out a wall across the doorway may stand
CROSSING_REACH = 0.3  # door lengths of wall along the panel's direction a crossing wall has
CROSSING_SHARE = 0.9  # occupied share of those cells

_Candidate = tuple[float, float, float, int, np.ndarray]  # score, end, side, offset, out


def opening_from_panel(rows: np.ndarray, cols: np.ndarray, occupied: np.ndarray,
                       min_width: int = 8, memo: dict[bytes, Any] | None = None,
                       free: np.ndarray | None = None
                       ) -> tuple[np.ndarray, np.ndarray] | None:
    """The doorway (rows, cols) of a door seen only as its swung-open panel (cells ``rows``,
    ``cols`` of the bool grid ``occupied``): the panel's closed position, found by turning
    it by 90 degrees about its hinge (module doc).

    For each end of the panel (along its principal axis), each side across it and each
    offset of the wall line past that end, score how much the surroundings look like a
    doorway seen from the hinge, for a door as long as the panel plus the offset. The
    offsets: 0 to ``MIN_REACH`` cells, beyond 1 only while no cell on the panel's line
    before the wall line was seen free together with its two neighbours across the line;
    when no hinge among those is found and ``free`` is given, up to the panel's length,
    where the panel's line before the wall line holds occupied cells (the panel's thin
    columns) and then unseen ones (its unseen part): no free cell, no cell occupied with its
    two neighbours across the line (a wall it would run through), no occupied cell past an
    unseen one. The score: wall running away on one side (share of occupied cells 0.1-0.45
    door widths along it), a clear opening on the other (share of occupied cells along the
    closed position, which must be low) and the far jamb just beyond it, wall + jamb - 2
    opening; with ``free`` given, the opening's cells not seen free count as closed (a
    doorway is floor seen free: a free end beside a cabinet, with a wall beyond it, would
    otherwise "open" over floor behind the panel that no frame saw). The best hinge and
    side must score well and clearly beat every alternative.
    When none does (a free end whose far-jamb ray hits furniture can come close to a hinge
    whose opening ray, for a panel smeared longer than its doorway, reaches the far wall),
    they are scored again by the wall line alone: the lesser of the wall and jamb shares
    minus the opening's (at least ``LINE_LEAST``, ``LINE_MARGIN`` ahead of every
    alternative). When neither finds one, both are asked again with the far jamb 1.0
    wherever a wall crosses the doorway's line at its far end (:func:`_crossing_walls`: a
    door at a room's corner; the doorway then ends there). Otherwise None (the caller then
    uses the panel's own cells), as for cells that are not one panel at least ``min_width``
    cells long. ``free`` (bool, the shape of ``occupied``; None: no cell known free) is the
    grid's cells seen free; ``memo`` caches answers by panel and surroundings."""
    if len(rows) < 2:
        return None
    # work in a window around the panel: every ray starts at most a panel length past its
    # end and reaches 2.6 lengths across (under 2.8 lengths in all), the panel no longer
    # than its box's diagonal
    diag = float(np.hypot(rows.max() - rows.min(), cols.max() - cols.min())) + 1.0
    pad = int(np.ceil(3.0 * diag)) + 8
    r0, c0 = max(int(rows.min()) - pad, 0), max(int(cols.min()) - pad, 0)
    r1 = min(int(rows.max()) + pad + 1, occupied.shape[0])
    c1 = min(int(cols.max()) + pad + 1, occupied.shape[1])
    window = occupied[r0:r1, c0:c1]
    free_window = None if free is None else free[r0:r1, c0:c1]
    key = None
    if memo is not None:  # the same panel cells in the same surroundings: the same answer
        h = hashlib.blake2b(digest_size=16)
        for a in (rows - r0, cols - c0, window, free_window):
            h.update(b"-" if a is None else np.ascontiguousarray(a).tobytes())
        h.update(repr((window.shape, min_width, r0, c0, rows.dtype.str)).encode())
        key = h.digest()
        if key in memo:
            return memo[key]
    # in the grid's own cells (rounding sees the same coordinates whatever the window)
    out = _opening(rows, cols, window, free_window, min_width, (r0, c0))
    if memo is not None and key is not None:
        if len(memo) > 256:
            memo.clear()
        memo[key] = out
    return out


def _opening(rows: np.ndarray, cols: np.ndarray, occupied: np.ndarray,
             free: np.ndarray | None, min_width: int, origin: tuple[int, int]
             ) -> tuple[np.ndarray, np.ndarray] | None:
    """:func:`opening_from_panel` on the window ``occupied`` / ``free`` of the grid whose
    cell (0, 0) is the grid's cell ``origin`` (row, col); ``rows``, ``cols`` and the
    answer in the grid's cells."""
    pts = np.stack([cols, rows], axis=1).astype(np.float64)
    mean = pts.mean(axis=0)
    cen = pts - mean
    evals, evecs = np.linalg.eigh(cen.T @ cen)
    a = evecs[:, int(np.argmax(evals))]
    proj = cen @ a
    s0, s1 = float(proj.min()), float(proj.max())
    width = s1 - s0 + 1.0
    if width < min_width:
        return None
    t = np.array([-a[1], a[0]])
    grown = ndimage.binary_dilation(occupied, structure=np.ones((3, 3), dtype=bool))
    # far wall lines only where what was seen free is known
    reach = MIN_REACH if free is None else max(MIN_REACH, int(width))

    # every (end, side, offset) of the panel whose gap to the wall line may be panel:
    # the shares of occupied cells along the wall side, the opening and the far jamb,
    # sampled at once (:func:`ray_shares`)
    rays = []
    places: list[tuple[float, float, int, np.ndarray]] = []  # end, side, offset, out
    for s, out in ((s0, -a), (s1, a)):
        far_ok, unseen_run = free is not None, False
        for off in range(reach + 1):
            if off > 1 and free is not None:
                gap = mean + a * s + out * (off - 1)  # the panel's line before the wall line
                across = np.stack([gap, gap + t, gap - t])
                if grid_at(across, free, origin).all():
                    break  # floor seen across the panel's line here: it ends before
                # far out, the line holds the panel's thin columns, then its unseen part:
                # no floor, no wall across it, nothing occupied past an unseen cell
                is_free = bool(grid_at(gap[None, :], free, origin)[0])
                taken = grid_at(across, occupied, origin)
                far_ok = far_ok and not is_free and not taken.all() and not (
                    unseen_run and taken[0])
                unseen_run = unseen_run or not taken[0]
            if off > MIN_REACH and not far_ok:
                break
            end, w = mean + a * s + out * off, width + off
            for sign in (1.0, -1.0):
                d = sign * t
                rays += [(end, -d, 0.1 * w, 0.45 * w, True),
                         (end, d, 0.15 * w, 0.85 * w, False),
                         (end, d, 1.05 * w, 1.3 * w, True)]
                places.append((s, sign, off, out))
    shares = ray_shares(rays, occupied, grown, origin)
    if free is not None:  # a doorway is floor seen free: unseen cells are no opening
        unseen = ray_shares(rays, ~free, grown, origin)
        for i in range(len(places)):
            shares[3 * i + 1] = unseen[3 * i + 1]
    best = _best_place(shares, places, reach)
    crossing: list[float | None] = [None] * len(places)
    if best is None:  # only then a wall across the doorway's line may be its far jamb
        crossing = _crossing_walls(places, mean, a, t, width, occupied, origin)
        crossed = list(shares)
        for i, h in enumerate(crossing):
            if h is not None:
                crossed[3 * i + 2] = 1.0
        best = _best_place(crossed, places, reach)
    if best is None:
        return None
    _, s_end, sign, off, out = best
    end, d, w = mean + a * s_end + out * off, sign * t, width + off
    h = next(h for (s, g, o, _), h in zip(places, crossing, strict=True)
             if (s, g, o) == (s_end, sign, off))
    if h is not None and h < w:
        w = h  # the doorway ends at the wall across it
    f = np.linspace(0.0, w, int(np.ceil(2 * w)) + 1)[:, None]
    p = end[None, :] + d[None, :] * f
    c = np.round(p[:, 0]).astype(np.int64)
    r = np.round(p[:, 1]).astype(np.int64)
    h, w_ = occupied.shape
    ok = (r >= origin[0]) & (r < origin[0] + h) & (c >= origin[1]) & (c < origin[1] + w_)
    return r[ok], c[ok]


def _best_place(shares: list[float], places: list[tuple[float, float, int, np.ndarray]],
                reach: int) -> _Candidate | None:
    """The clear best hinge and side of :func:`opening_from_panel` (its doc), nearest wall
    lines first: by the sum score, else by the wall line alone."""
    for most in (MIN_REACH, reach):
        best = _clear_best(shares, places, most, _sum_score, 1.0, 0.5)
        if best is None:  # ambiguous: ask for the wall line on both sides of the opening
            best = _clear_best(shares, places, most, _line_score, LINE_LEAST, LINE_MARGIN)
        if best is not None:
            return best
    return None


def _crossing_walls(places: list[tuple[float, float, int, np.ndarray]], mean: np.ndarray,
                    a: np.ndarray, t: np.ndarray, width: float, occupied: np.ndarray,
                    origin: tuple[int, int]) -> list[float | None]:
    """Per place (end, side, offset, outward axis), the distance (cells) from its hinge to
    a wall crossing the doorway's line at its far end (``CROSSING_NEAR`` to
    ``CROSSING_FAR`` door lengths out), else None: the jamb of a door at a room's corner,
    whose own wall does not continue past the opening. A wall crosses where an occupied
    cell on the line has ``CROSSING_SHARE`` of the cells occupied along the panel's
    direction on one side of it, ``CROSSING_REACH`` door lengths long (at least
    ``MIN_REACH`` cells); a wall in line with the doorway is thinner than that."""
    points, where = [], []  # every half cell of the far end's stretch of each place
    for i, (s, sign, off, out) in enumerate(places):
        end, d, w = mean + a * s + out * off, sign * t, width + off
        for h in np.arange(CROSSING_NEAR * w, CROSSING_FAR * w + 0.25, 0.5):
            points.append(end + d * h)
            where.append((i, float(h), max(float(MIN_REACH), CROSSING_REACH * w)))
    got: list[float | None] = [None] * len(places)
    on_wall = grid_at(np.array(points).reshape(-1, 2), occupied, origin)
    rays = [(p, e, 1.0, reach, False) for p, (_, _, reach), hit in
            zip(points, where, on_wall.tolist(), strict=True) if hit for e in (a, -a)]
    where = [w for w, hit in zip(where, on_wall.tolist(), strict=True) if hit]
    if not rays:
        return got
    shares = ray_shares(rays, occupied, occupied, origin)
    for k, (i, h, _) in enumerate(where):
        if got[i] is None and max(shares[2 * k], shares[2 * k + 1]) >= CROSSING_SHARE:
            got[i] = h
    return got


def _sum_score(wall: float, opening: float, jamb: float) -> float:
    """Wall on one side, far jamb on the other, a clear opening between."""
    return wall + jamb - 2.0 * opening


def _line_score(wall: float, opening: float, jamb: float) -> float:
    """The wall line on *both* sides of a clear opening: a panel's free end, whose far-jamb
    ray can hit any obstacle in the room, has no wall beside it."""
    return min(wall, jamb) - opening


def _clear_best(shares: list[float], places: list[tuple[float, float, int, np.ndarray]],
                most: int, score: Callable[[float, float, float], float], least: float,
                margin: float) -> _Candidate | None:
    """The (score, end, side sign, offset, outward axis) of the best hinge and side under
    ``score`` of the (wall, opening, jamb) shares of each place (end, side, offset,
    outward axis; three shares each, in order) at most ``most`` cells out, each hinge and
    side at the nearest offset within ``OFFSET_SLACK`` of its best score, when it scores
    at least ``least`` and beats every other hinge and side by ``margin``; else None."""
    of_side: dict[tuple[float, float], list[_Candidate]] = {}
    for i, (s, sign, off, out) in enumerate(places):
        if off <= most:
            value = score(*shares[3 * i:3 * i + 3])
            of_side.setdefault((s, sign), []).append((value, s, sign, off, out))
    scored = []
    for cands in of_side.values():  # in order of offset
        top = max(c[0] for c in cands)
        scored.append(next(c for c in cands if c[0] >= top - OFFSET_SLACK))
    scored.sort(key=lambda x: -x[0])
    if len(scored) < 2:
        return None
    best, second = scored[0], scored[1]
    if best[0] < least or best[0] - second[0] < margin:
        return None
    return best


def ray_shares(rays: list[tuple[np.ndarray, np.ndarray, float, float, bool]],
               occupied: np.ndarray, grown: np.ndarray, origin: tuple[int, int] = (0, 0)
               ) -> list[float]:
    """Per ray (start, direction, from, to, on the grown grid; in (column, row) cells of
    the grid whose cell ``origin`` (row, col) is ``occupied``'s cell (0, 0), ``grown``
    being ``occupied`` dilated): the share of occupied cells at the
    points sampled every half cell from ``start + from * direction`` to
    ``start + to * direction``, rounded to cells (points off the grid skipped; 0.0 with
    none on it). The points of every ray are computed as one ray at a time would, the
    shares counted for all at once."""
    fs = [np.linspace(lo, hi, max(2, int(np.ceil(2 * (hi - lo))))) for _, _, lo, hi, _ in rays]
    sizes = np.fromiter((len(f) for f in fs), dtype=np.int64, count=len(rays))
    ray = np.repeat(np.arange(len(rays)), sizes)
    p0 = np.stack([r[0] for r in rays])[ray]
    direction = np.stack([r[1] for r in rays])[ray]
    p = p0 + direction * np.concatenate(fs)[:, None]
    c = np.round(p[:, 0]).astype(np.int64) - origin[1]
    r = np.round(p[:, 1]).astype(np.int64) - origin[0]
    h, w = occupied.shape
    ok = (r >= 0) & (r < h) & (c >= 0) & (c < w)
    on_grown = np.fromiter((g for *_, g in rays), dtype=bool, count=len(rays))[ray[ok]]
    hit = np.where(on_grown, grown[r[ok], c[ok]], occupied[r[ok], c[ok]])
    count = np.bincount(ray[ok], minlength=len(rays))
    total = np.bincount(ray[ok], weights=hit.astype(np.float64), minlength=len(rays))
    return [float(x / n) if n else 0.0 for x, n in zip(total.tolist(), count.tolist(),
                                                        strict=True)]
