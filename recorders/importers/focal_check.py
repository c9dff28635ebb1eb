"""The focal length checked against metric poses: surfaces seen from two turned views meet.

Back-projecting depth with a focal length ``c`` times too short stretches every point
cloud sideways by ``c`` (depth unchanged). A camera that only moves forward hides that,
but a turn does not: two views turned a few degrees apart, placed by their poses, show
their shared surfaces apart, by centimetres for a focal length a quarter off. For a few
pairs of frames turned :data:`TURN_DEG` apart (spread over the sequence), the median
point-to-plane gap between the pair's surfaces is measured with the focal lengths scaled
by each factor of :data:`FACTORS` (then finer around the best); the factor whose gap is
smallest estimates ``c``.

Only a clear, consistent disagreement counts (:func:`focal_problem`): ``c`` off 1 by more
than :data:`OFF`, the gap at the given focal length :data:`CLEAR` times the best one or
more, and nearly every pair's own best factor on the same side (three pairs at least).
A wrong focal length also misleads the depth scale check of :mod:`.scale_check` (a
stretched cloud moves too far between nearby frames): :func:`check_focal` tells whether
the focal length that fits also makes the depth move as the poses do, and then the focal
length, not the depth scale, is the problem to name.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from sgtool.log.frame import CameraIntrinsics
from sgtool.log.poses import pose_difference
from sgtool.recorders.importers.scale_check import (
    Pairs,
    ScaleFit,
    fit_scale,
    median_gap,
    poses_fit_depth,
    surface_gap,
)

TURN_DEG = (3.0, 25.0)  # the turn of a pair: enough to show a stretch, little enough to overlap
MAX_STEP_M = 0.5  # and at most this much translation
MAX_AHEAD = 30  # frames to look ahead for a turned neighbour
PAIRS = 6
FACTORS = tuple(float(x) for x in np.geomspace(0.5, 2.0, 9))  # 19 % apart, then 6 %
OFF = 0.1  # |c - 1| that is no verdict
CLEAR = 2.5  # gap at the focal length given / at the best factor, at least
AGREE = 0.75  # share of the pairs whose own best factor is off the same way
MIN_PAIRS = 3
SCALE_AS_GOOD = 1.5  # a depth scale whose gap is within this of the focal length's leads


@dataclass(frozen=True)
class FocalFit:
    """The focal length factor ``factor`` at which the surfaces of ``pairs`` turned frame
    pairs meet best (median gap ``gap_mm``), the gap at the focal length given
    (``given_mm``), and how many pairs' own best factor lies off 1 the same way
    (``agree``)."""

    factor: float
    pairs: int
    gap_mm: float
    given_mm: float
    agree: int

    def describe(self) -> str:
        return (f"surfaces of {self.pairs} turned frame pairs meet best at {self.factor:.2f}x "
                f"the focal length (gap {self.gap_mm:.1f} mm; {self.given_mm:.1f} mm as given)")


def turn_pairs(poses: Sequence[np.ndarray], n_pairs: int = PAIRS) -> list[tuple[int, int]]:
    """Up to ``n_pairs`` (i, j) frame pairs spread over the sequence: j the first frame
    after i (within :data:`MAX_AHEAD`) turned at least ``TURN_DEG[0]`` from it, kept when
    turned at most ``TURN_DEG[1]`` and moved at most :data:`MAX_STEP_M` (i from
    ``4 * n_pairs`` starts spread over the sequence)."""
    n = len(poses)
    out: list[tuple[int, int]] = []
    if n < 2:
        return out
    for i in np.unique(np.linspace(0, n - 2, min(4 * n_pairs, n - 1)).round().astype(int)):
        for j in range(int(i) + 1, min(n, int(i) + 1 + MAX_AHEAD)):
            moved, turned = pose_difference(np.asarray(poses[i]), np.asarray(poses[j]))
            if moved > MAX_STEP_M:
                break
            if turned >= TURN_DEG[0]:
                if turned <= TURN_DEG[1]:
                    out.append((int(i), j))
                break
    if len(out) > n_pairs:  # spread over the sequence
        out = [out[i] for i in np.unique(np.linspace(0, len(out) - 1, n_pairs).round()
                                         .astype(int))]
    return out


def fit_focal(pairs: Pairs, k: CameraIntrinsics) -> FocalFit | None:
    """The fit over ``(depth_i, depth_j, pose_i, pose_j)`` (depth in metres, world_T_camera
    poses; module doc); pairs without a gap at the given focal length are left out; None
    without a usable pair."""
    usable, given = [], []
    for d0, d1, p0, p1 in pairs:
        rel = np.linalg.inv(p0) @ p1  # camera j in camera i
        gap = surface_gap(d0, d1, k, rel)
        if gap is not None:
            usable.append((d0, d1, rel))
            given.append(gap)
    if not usable:
        return None

    def gaps(c: float) -> list[float]:
        kc = dataclasses.replace(k, fx=k.fx * c, fy=k.fy * c)
        got = [surface_gap(d0, d1, kc, rel) for d0, d1, rel in usable]
        return [math.inf if g is None else g for g in got]

    table = {1.0: given}
    for c in FACTORS:
        table.setdefault(round(c, 6), gaps(c))
    coarse = min(table, key=lambda c: float(np.median(table[c])))
    for c in np.geomspace(coarse / 1.19, coarse * 1.19, 7).tolist():
        table.setdefault(round(c, 6), gaps(c))
    best = min(table, key=lambda c: float(np.median(table[c])))
    side = math.copysign(1.0, math.log(best)) if best != 1.0 else 0.0
    agree = 0
    for i in range(len(usable)):
        own = min(table, key=lambda c: table[c][i])
        if side and abs(own - 1.0) > OFF and math.copysign(1.0, math.log(own)) == side:
            agree += 1
    return FocalFit(best, len(usable), 1000 * float(np.median(table[best])),
                    1000 * float(np.median(given)), agree)


def focal_problem(fit: FocalFit | None, k: CameraIntrinsics, origin: str) -> str | None:
    """The problem of intrinsics whose focal length the turned pairs clearly disagree with
    (module doc), naming the focal lengths that fit; None otherwise."""
    if fit is None or fit.pairs < MIN_PAIRS or abs(fit.factor - 1.0) <= OFF:
        return None
    if not fit.given_mm >= CLEAR * fit.gap_mm or fit.agree < max(MIN_PAIRS,
                                                                   AGREE * fit.pairs):
        return None
    how = "short" if fit.factor > 1.0 else "long"
    return (f"intrinsics ({origin}): the focal length looks {fit.factor:.2f}x too {how}: "
            f"between {fit.pairs} pairs of turned frames the surfaces seen from both meet "
            f"within {fit.gap_mm:.1f} mm with fx, fy {k.fx * fit.factor:.0f}, "
            f"{k.fy * fit.factor:.0f}, {fit.given_mm:.1f} mm apart with {k.fx:.4g}, {k.fy:.4g} "
            "(a wrong focal length stretches the map): check the camera's intrinsics "
            "(--intrinsics fx,fy,cx,cy)")


def check_focal(turned: Pairs, nearby: Pairs, k: CameraIntrinsics, fit: ScaleFit | None,
                origin: str) -> tuple[FocalFit | None, str | None, bool]:
    """The focal fit of the ``turned`` pairs (:func:`turn_pairs`), its problem
    (:func:`focal_problem`, intrinsics from ``origin``), and whether the problem explains
    the depth scale fit ``fit`` of the ``nearby`` pairs not fitting the poses (with the
    focal lengths the fit names, they fit). A depth scale off stretches the surfaces too:
    when the nearby pairs agree on a scale off 1 and the turned pairs' surfaces, their
    depth read at that scale, meet as closely as with the focal lengths named, the depth
    scale is the lead and the problem is dropped. The problem stands when the nearby pairs
    give no fit or no consistent one (a camera that only turns; a wrong focal length
    scatters the pairs' ratios: the better lead than a pose convention)."""
    focal = fit_focal(turned, k)
    problem = focal_problem(focal, k, origin)
    if problem is None or focal is None or poses_fit_depth(fit):
        return focal, problem, False
    if fit is not None and fit.consistent():
        rescaled = median_gap([(a / fit.ratio, b / fit.ratio, p, q) for a, b, p, q in turned],
                              k)
        if rescaled is not None and 1000 * rescaled <= focal.gap_mm * SCALE_AS_GOOD:
            return focal, None, False
    c = focal.factor
    mended = poses_fit_depth(fit_scale(nearby, dataclasses.replace(k, fx=k.fx * c,
                                                                  fy=k.fy * c)))
    return focal, problem, mended


def along_axis(depth: np.ndarray, k: CameraIntrinsics) -> np.ndarray:
    """``depth`` (metres) read as each pixel's distance along its ray, as the depth along
    the optical axis: ``d / sqrt(1 + ((u - cx) / fx)^2 + ((v - cy) / fy)^2)``."""
    v, u = np.mgrid[0:depth.shape[0], 0:depth.shape[1]]
    return depth / np.sqrt(1.0 + ((u - k.cx) / k.fx) ** 2 + ((v - k.cy) / k.fy) ** 2)


def ray_depth_problem(turned: Pairs, k: CameraIntrinsics, focal: FocalFit | None,
                      origin: str) -> str | None:
    """When the ``turned`` pairs' surfaces meet :data:`CLEAR` times closer with their
    depth read as distances along each pixel's ray (:func:`along_axis`; as many renderers
    and ICL-NUIM's raw files store it) than as given, and closer than with the focal
    length ``focal`` found: the text (depth from ``origin``); None otherwise (fewer than
    :data:`MIN_PAIRS` pairs, or no such gain)."""
    if focal is None or focal.pairs < MIN_PAIRS:
        return None
    as_given = median_gap(turned, k)
    as_ray = median_gap([(along_axis(a, k), along_axis(b, k), p, q) for a, b, p, q in turned],
                        k)
    if as_given is None or as_ray is None or as_ray * CLEAR > as_given or \
            1000 * as_ray > focal.gap_mm:
        return None
    return (f"depth ({origin}) looks like each pixel's distance along its ray, not the depth "
            f"along the optical axis that sgtool reads: between {focal.pairs} pairs of turned "
            f"frames the surfaces seen from both meet within {1000 * as_ray:.1f} mm read so, "
            f"{1000 * as_given:.1f} mm apart as given; convert each pixel first (z = d / "
            "sqrt(1 + ((u - cx) / fx)^2 + ((v - cy) / fy)^2))")


def along_axis_pairs(pairs: Pairs, k: CameraIntrinsics
                     ) -> list[tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]]:
    """``pairs`` with their depth read as distances along each ray (:func:`along_axis`):
    how the other checks judge depth that :func:`ray_depth_problem` found so stored."""
    return [(along_axis(a, k), along_axis(b, k), p, q) for a, b, p, q in pairs]
