"""The depth scale checked against metric poses: geometry must move as the poses do.

Reading depth at a wrong scale ``s`` times too large scales every point cloud by ``s``, so
the motion that aligns two nearby frames has ``s`` times the translation of the true
motion, while poses from ground truth, a trajectory or ``/tf`` stay metric. For a few pairs
of nearby frames (a sample spread over the sequence, each with its neighbour at least
:data:`MIN_STEP_M` away), the poses' rotation is kept and only the factor on their
translation is fitted, point-to-plane ICP style (a full 6-DoF ICP trades a small rotation for
a translation on small steps and misjudges the length); that factor estimates ``s``. The
scale that fits is ``scale * s`` (snapped to a usual scale within 10 %).

Only a clear, consistent disagreement counts: ``s`` outside 1 +- :data:`TOLERANCE` (+-
:data:`PRECISE_TOLERANCE` when four pairs or more agree within 10 %: a depth scale a
fifth off, 4000 units/m read as 5000, is then named), every pair's ratio within 35 % of
it, at least two pairs, and ``s`` between 0.2 and 20 (geometry that barely moves, a scene
that cannot pin the motion down, gives no verdict).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from sgtool.log.frame import CameraIntrinsics
from sgtool.log.poses import pose_difference
from sgtool.recorders.importers.pose_axes import (
    CAMERA_AXES,
    OPTICAL_C2W,
    ReadAs,
    from_optical,
    to_optical,
)
from sgtool.recorders.importers.sanity import KNOWN_SCALES

MIN_STEP_M = 0.02  # pose translation of a pair (m)
MAX_GAP = 6  # frames to look ahead for a neighbour far enough away
TOLERANCE = 0.2  # |s - 1| a scale may be off without a verdict
PRECISE_TOLERANCE = 0.1  # or, when PRECISE_PAIRS pairs or more agree within PRECISE_SPREAD
PRECISE_PAIRS = 4
PRECISE_SPREAD = 0.1
PAIRS = 6


@dataclass(frozen=True)
class ScaleFit:
    """The ratio of geometric to pose translation over ``pairs`` frame pairs, and how far
    the single pairs' ratios spread (max relative deviation from ``ratio``)."""

    ratio: float
    pairs: int
    spread: float
    step_m: float = 0.0  # the median pose translation of the pairs (m)
    matched: float = 1.0  # the median share of a pair's points matched

    def describe(self) -> str:
        return (f"depth moves {self.ratio:.2f}x as far as the poses over {self.pairs} frame "
                f"pairs (spread {self.spread:.2f})")

    def consistent(self) -> bool:
        return self.pairs >= 2 and self.spread <= 0.35 and 0.2 < self.ratio < 20.0

    def within_tolerance(self) -> bool:
        """Whether the ratio is as close to 1 as gives no verdict (module doc; a bound
        itself is within)."""
        precise = self.pairs >= PRECISE_PAIRS and self.spread <= PRECISE_SPREAD
        return abs(self.ratio - 1.0) <= (PRECISE_TOLERANCE if precise else TOLERANCE) + 1e-9


def pair_indices(poses: Sequence[np.ndarray], n_pairs: int = PAIRS) -> list[tuple[int, int]]:
    """(i, j) frame pairs spread over the sequence: j the first frame after i at least
    :data:`MIN_STEP_M` away (within :data:`MAX_GAP` frames)."""
    n = len(poses)
    if n < 2:
        return []
    out = []
    for i in np.unique(np.linspace(0, n - 2, min(n_pairs, n - 1)).round().astype(int)):
        for j in range(i + 1, min(n, i + 1 + MAX_GAP)):
            if np.linalg.norm(poses[j][:3, 3] - poses[i][:3, 3]) >= MIN_STEP_M:
                out.append((int(i), j))
                break
    return out


def _pair_surfaces(d0: np.ndarray, d1: np.ndarray, k: CameraIntrinsics, columns: int
                   ) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
    """Frame i's surface points and normals and frame j's points (each in its own camera
    frame; depth ``d0``, ``d1`` sampled about ``columns`` pixels across); None with fewer
    than 50 of either."""
    from sgtool.recorders.importers.upright import DepthSample, surface_points

    eye = np.eye(4)
    stride = max(1, d0.shape[1] // columns)
    q, nq = surface_points(DepthSample(d0, k, eye), stride=stride)
    p, _ = surface_points(DepthSample(d1, k, eye), stride=stride)
    return None if len(q) < 50 or len(p) < 50 else (q, nq, p)


def translation_scale(d0: np.ndarray, d1: np.ndarray, k: CameraIntrinsics,
                      rel: np.ndarray) -> tuple[float, float, float] | None:
    """The factor ``s`` on the poses' translation that best aligns frame j's points with
    frame i's surfaces, the poses' rotation kept: point-to-plane residuals
    ``n . (R p + s t - q)`` are linear in ``s``, solved by least squares over nearest
    neighbours within 10, 4 then 2 % of the median depth (so the check does not depend on
    the scale it checks), 5 rounds each. Returns (s, share of points matched, RMS of the
    translation along the matched normals in metres at the scale checked: how much the
    pair says about ``s``); None without enough points."""
    from scipy.spatial import cKDTree

    got = _pair_surfaces(d0, d1, k, 160)
    if got is None:
        return None
    q, nq, p = got
    med = float(np.median(q[:, 2]))
    R, t = rel[:3, :3], rel[:3, 3]  # noqa: N806
    pr = p @ R.T
    tree = cKDTree(q)
    s_fit = 1.0
    ok = np.zeros(len(p), bool)
    b = np.zeros(0)
    for frac in (0.10, 0.04, 0.02):
        for _ in range(5):
            dist, idx = tree.query(pr + s_fit * t, distance_upper_bound=frac * med)
            ok = np.isfinite(dist)
            if ok.sum() < 50:
                return None
            n = nq[idx[ok]]
            a = np.einsum("ij,ij->i", n, pr[ok] - q[idx[ok]])
            b = n @ t
            den = float(b @ b)
            if den <= 0:
                return None
            s_fit = -float(a @ b) / den
    return s_fit, float(ok.mean()), float(np.sqrt(np.mean(b**2)))


MIN_MATCHED = 0.3  # share of a pair's points matched
MATCH_REL = 0.1  # a point matches a surface within this share of the median depth
GAP_MATCHED = 0.3  # share of a pair's points that must match for a gap
GAP_CLEAR = 2.5  # a convention whose surfaces meet this much closer is the poses'
MIN_ALONG_M = 0.005  # RMS pose translation along the matched normals


def surface_gap(d0: np.ndarray, d1: np.ndarray, k: CameraIntrinsics,
                rel: np.ndarray) -> float | None:
    """The median |point-to-plane| distance (m) of frame j's points (depth ``d1``, placed
    in frame i's camera by ``rel``) to frame i's surfaces (depth ``d0``), both
    back-projected with ``k``; None when fewer than :data:`GAP_MATCHED` of them (or 50)
    lie within :data:`MATCH_REL` of the median depth of a surface point."""
    from scipy.spatial import cKDTree

    got = _pair_surfaces(d0, d1, k, 80)
    if got is None:
        return None
    q, nq, p = got
    moved = p @ rel[:3, :3].T + rel[:3, 3]
    dist, idx = cKDTree(q).query(moved, distance_upper_bound=MATCH_REL * float(
        np.median(q[:, 2])))
    ok = np.isfinite(dist)
    if ok.sum() < 50 or ok.mean() < GAP_MATCHED:
        return None
    gaps = np.einsum("ij,ij->i", nq[idx[ok]], moved[ok] - q[idx[ok]])
    return float(np.median(np.abs(gaps)))


def median_gap(pairs: Pairs, k: CameraIntrinsics) -> float | None:
    """The median over ``pairs`` (as :func:`fit_scale` takes them) of their
    :func:`surface_gap` (m); None without a pair that has one."""
    gaps = [surface_gap(d0, d1, k, np.linalg.inv(p0) @ p1) for d0, d1, p0, p1 in pairs]
    got = [g for g in gaps if g is not None]
    return float(np.median(got)) if got else None


def fit_scale(pairs: Sequence[tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]],
              k: CameraIntrinsics) -> ScaleFit | None:
    """The fit over ``(depth_i, depth_j, pose_i, pose_j)`` (depth in metres at the scale
    checked; world_T_camera poses): :func:`translation_scale` per pair, pairs matched under
    :data:`MIN_MATCHED` or moving under :data:`MIN_ALONG_M` along the surfaces' normals
    (or of one depth image twice) left out, the rest combined weighted by that motion;
    None without a usable pair."""
    ratios, weights, steps, shares = [], [], [], []
    for d0, d1, p0, p1 in pairs:
        rel = np.linalg.inv(p0) @ p1  # camera j in camera i
        step = float(np.linalg.norm(rel[:3, 3]))
        if step < MIN_STEP_M or _same_image(d0, d1):
            continue
        got = translation_scale(d0, d1, k, rel)
        if got is None or got[1] < MIN_MATCHED or got[2] < MIN_ALONG_M:
            continue
        ratios.append(got[0])
        weights.append(got[2] ** 2)
        steps.append(step)
        shares.append(got[1])
    if not ratios:
        return None
    r = float(np.average(ratios, weights=weights))
    spread = max(abs(x / r - 1.0) for x in ratios) if r > 0 else float("inf")
    return ScaleFit(r, len(ratios), spread, float(np.median(steps)), float(np.median(shares)))


def _same_image(d0: np.ndarray, d1: np.ndarray) -> bool:
    """Whether two depth images are one image (a sensor that repeats its frame, a test's
    fixture): their motion says nothing about the poses'."""
    return d0.shape == d1.shape and bool(np.array_equal(d0, d1))


SNAP = 0.05  # a usual scale this close is the one named (well within PRECISE_TOLERANCE)


def snap_scale(value: float) -> float:
    """A usual depth scale within :data:`SNAP` of ``value``, else ``value`` to 2
    significant digits."""
    for s in KNOWN_SCALES:
        if abs(value / s - 1.0) <= SNAP:
            return s
    return float(f"{value:.2g}")


def geometric_scale_problem(fit: ScaleFit | None, scale: float, origin: str,
                            pose_source: str) -> str | None:
    """The problem of depth at ``scale`` units/m (from ``origin``) whose geometry moves
    ``fit.ratio`` times as far as the metric poses (``pose_source``) say, naming the scale
    that fits; None without a clear, consistent disagreement."""
    if fit is None or not fit.consistent() or fit.within_tolerance():
        return None
    fits = snap_scale(scale * fit.ratio)
    return (f"depth scale {scale:g} units/m ({origin}) disagrees with the {pose_source}: "
            f"between {fit.pairs} pairs of nearby frames the depth geometry moves "
            f"{fit.ratio:.2f}x as far as the poses (the poses' translation fitted to the depth); "
            f"--depth-scale {fits:g} fits; give it, or --depth-scale {scale:g} to keep this one")


def inverted_poses_problem(given: ScaleFit | None, inverted: ScaleFit | None,
                           pose_source: str, read_as: ReadAs = OPTICAL_C2W) -> str | None:
    """When the poses' inverses move as the depth does (a consistent fit within
    :data:`TOLERANCE` of 1) and the poses themselves do not: world-to-camera poses, which
    the depth-scale and motion checks would otherwise take for a wrong scale (a few
    centimetres a pair, a small turn: the inverses' error is systematic, so it fits a
    consistent wrong ratio). The text, naming the flags that read them so (``read_as``: as
    they were read: a constant turn of the world before the inverse is no matter); None
    otherwise."""
    if inverted is None or not clearly_fits(inverted) or poses_fit_depth(given):
        return None
    how = ("no consistent factor" if given is None else f"{given.ratio:.2f}x"
           if given.consistent() else f"{given.ratio:.2f}x on average, the pairs disagreeing,")
    return (f"the poses ({pose_source}) look world-to-camera: between {inverted.pairs} pairs "
            f"of nearby frames the depth moves {how} as far as the poses, and "
            f"{inverted.ratio:.2f}x as far as their inverses; camera-to-world poses are "
            f"expected: {read_as.fix('optical', not read_as.inverse)}, or --estimate-poses to "
            "estimate the poses from the depth")


POSE_UNITS = ((0.01, "centimetres"), (0.001, "millimetres"))

Pairs = Sequence[tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]]


def clearly_fits(fit: ScaleFit | None) -> bool:
    """Whether the fit of poses in another convention (inverted, reordered, in another
    unit or frame) is consistent and within :data:`PRECISE_TOLERANCE` of 1, whatever its
    number of pairs: to blame the poses' convention, the other reading must fit better than
    a depth scale a little off does."""
    return fit is not None and fit.consistent() and abs(fit.ratio - 1.0) <= PRECISE_TOLERANCE


def poses_fit_depth(fit: ScaleFit | None) -> bool:
    """Whether the pairs agree that the depth moves as the poses do (within
    :meth:`ScaleFit.within_tolerance`): metric poses, metric depth."""
    return fit is not None and fit.consistent() and fit.within_tolerance()


def convention_problems(pairs: Pairs, k: CameraIntrinsics, fit: ScaleFit | None,
                        pose_source: str, read_as: ReadAs = OPTICAL_C2W) -> list[str]:
    """When the poses do not fit the depth (``fit``, of ``pairs`` as :func:`fit_scale`
    takes them): the problems of the poses' inverses, their translations in another unit,
    their quaternions in another order or the camera frame's other axes fitting it
    (:func:`inverted_poses_problem`, :func:`pose_units_problem`,
    :func:`quaternion_order_problem`, :func:`camera_axes_problem`), naming the flags that
    read them so (the poses were read as ``read_as`` says); empty when the poses fit, or
    none does."""
    reordered_pairs = [(a, b, _wxyz_read_as_xyzw(p), _wxyz_read_as_xyzw(q))
                       for a, b, p, q in pairs]
    if fit is not None and fit.consistent() and not poses_fit_depth(fit) and \
            abs(fit.ratio - 1.0) <= TOLERANCE:
        return []  # 10-20 % off, the pairs agreeing closely: the depth scale's problem
    if poses_fit_depth(fit):
        # the translation's factor can fit with the rotations wrong, on small steps: the
        # surfaces of a pair then do not meet
        read, other = median_gap(pairs, k), median_gap(reordered_pairs, k)
        if read is None or other is None or other * GAP_CLEAR > read:
            return []
        order = quaternion_order_problem(None, fit_scale(reordered_pairs, k), pose_source,
                                         (read, other))
        return [order] if order is not None else []
    inverted = fit_scale([(a, b, np.linalg.inv(p), np.linalg.inv(q)) for a, b, p, q in pairs],
                         k)
    units = [(unit, fit_scale([(a, b, _in_metres(p, f), _in_metres(q, f))
                               for a, b, p, q in pairs], k)) for f, unit in POSE_UNITS]
    reordered = fit_scale(reordered_pairs, k)
    # each other convention the file may be in (the poses as written: the reading undone);
    # the optical frame's other inversion is the inverted check's
    written = [(a, b, from_optical(p, read_as.axes, read_as.inverse),
                from_optical(q, read_as.axes, read_as.inverse)) for a, b, p, q in pairs]
    axes = {(name, inv): fit_scale([(a, b, to_optical(p, name, inv), to_optical(q, name, inv))
                                    for a, b, p, q in written], k)
            for inv in (False, True) for name in CAMERA_AXES
            if (name, inv) != (read_as.axes, read_as.inverse)
            and (name, inv) != ("optical", not read_as.inverse)}
    found = (inverted_poses_problem(fit, inverted, pose_source, read_as),
             pose_units_problem(units, pose_source),
             quaternion_order_problem(fit, reordered, pose_source),
             camera_axes_problem(fit, axes, pose_source, read_as))
    return [x for x in found if x is not None]


def camera_axes_problem(given: ScaleFit | None,
                        fits: dict[tuple[str, bool], ScaleFit | None],
                        pose_source: str, read_as: ReadAs = OPTICAL_C2W) -> str | None:
    """When the poses taken as those of a camera frame with other axes (``fits``, by name
    of :data:`~.pose_axes.CAMERA_AXES` and whether inverted first: each turned into the
    optical frame's camera-to-world pose) move as the depth does and the poses as read
    (``given``) do not: the poses of OpenGL's camera frame or of ROS's ``camera_link``
    (world-to-camera, perhaps), not of the optical frame sgtool reads depth in. The text,
    naming the flags that read them so (the poses were read as ``read_as`` says: a reading
    inverted after them turns the world by a constant, which is no matter); None
    otherwise."""
    fitting = [(key, fit) for key, fit in fits.items() if fit is not None and clearly_fits(fit)]
    if not fitting or poses_fit_depth(given):
        return None
    (name, inv), fit = min(fitting, key=lambda kf: abs(kf[1].ratio - 1.0))
    moves = ("no consistent factor" if given is None else f"{given.ratio:.2f}x"
             if given.consistent() else f"{given.ratio:.2f}x on average, the pairs disagreeing,")
    other = (", or --tf-frames WORLD:CAMERA_OPTICAL_FRAME where the tree has the optical "
             "frame" if read_as.bag and name == "body" else "")
    fix = read_as.fix(name, inv)
    frame = ("the camera's optical frame (x right, y down, z forward)" if name == "optical"
             else f"a camera frame with {name} axes ({CAMERA_AXES[name][1]})")
    as_read = ("of its optical frame (x right, y down, z forward)" if read_as.axes == "optical"
               else f"of the {read_as.axes} axes --camera-axes {read_as.axes} reads")
    return (f"the poses ({pose_source}) look like those of {frame}"
            f"{', world-to-camera' if inv else ''}, not {as_read}: between {fit.pairs} pairs "
            f"of nearby frames the depth moves {moves} as far as the poses, and "
            f"{fit.ratio:.2f}x as far as the optical frame they imply; "
            f"{fix}{other}, or --estimate-poses to estimate the poses from the depth")


def _wxyz_read_as_xyzw(pose: np.ndarray) -> np.ndarray:
    """``pose`` as it would be had its rotation's quaternion been written w x y z and read
    x y z w (the read (x, y, z, w) is the written (w, x, y, z))."""
    from scipy.spatial.transform import Rotation

    read = Rotation.from_matrix(np.asarray(pose, float)[:3, :3]).as_quat()  # x y z w
    out = np.array(pose, dtype=float)
    out[:3, :3] = Rotation.from_quat([read[1], read[2], read[3], read[0]]).as_matrix()
    return out


def quaternion_order_problem(given: ScaleFit | None, reordered: ScaleFit | None,
                             pose_source: str, gaps: tuple[float, float] | None = None
                             ) -> str | None:
    """When the poses with their quaternions read w x y z (``reordered``) move as the
    depth does and the poses as read (``given``) do not, or (``gaps``: the pairs'
    :func:`median_gap` as read and reordered, in m, the first :data:`GAP_CLEAR` times the
    second or more) the surfaces of the pairs meet only so: quaternions written scalar
    first (as Eigen and many tools print them), read scalar last as TUM's format has them.
    The text; None otherwise."""
    if not clearly_fits(reordered) or (gaps is None and poses_fit_depth(given)):
        return None
    assert reordered is not None
    if gaps is not None:
        how = (f"the surfaces seen from both meet within {1000 * gaps[1]:.1f} mm with them "
               f"read w x y z, {1000 * gaps[0]:.1f} mm apart read x y z w")
    else:
        moves = ("no consistent factor" if given is None else f"{given.ratio:.2f}x"
                 if given.consistent() else
                 f"{given.ratio:.2f}x on average, the pairs disagreeing,")
        how = (f"the depth moves {moves} as far as the poses read x y z w, and "
               f"{reordered.ratio:.2f}x as far with them read w x y z")
    return (f"the poses' quaternions ({pose_source}) look written w x y z: between "
            f"{reordered.pairs} pairs of nearby frames {how}; sgtool reads x y z w "
            "(qx qy qz qw, as TUM files have them): reorder the "
            "columns, or give --estimate-poses to estimate the poses from the depth")


def _in_metres(pose: np.ndarray, unit_m: float) -> np.ndarray:
    """``pose`` with its translation read in units of ``unit_m`` metres."""
    out = np.array(pose, dtype=float)
    out[:3, 3] *= unit_m
    return out


def pose_units_problem(fits: Sequence[tuple[str, ScaleFit | None]],
                       pose_source: str) -> str | None:
    """When the poses' translations, read as one of the units of :data:`POSE_UNITS`
    (``fits``: the unit's name and the fit of the poses with their translations scaled
    to metres from it), move as the depth does: the text naming the unit; else None."""
    for unit, fit in fits:
        if fit is not None and clearly_fits(fit):
            return (f"the poses' translations ({pose_source}) look in {unit}: between "
                    f"{fit.pairs} pairs of nearby frames the depth moves {fit.ratio:.2f}x as "
                    f"far as the poses read in {unit}; sgtool reads metres: convert them, or "
                    "give --estimate-poses to estimate the poses from the depth")
    return None


MIN_RATIO = 0.2  # a depth that moves less than this far (either way) stands still
STILL_PAIRS = 3  # pairs over which depth standing still while the poses move is clear,
STILL_STEP_M = 0.05  # when the pairs' poses move this far (median): well beyond depth noise


def pose_motion_problem(fit: ScaleFit | None, pose_source: str) -> tuple[str, bool] | None:
    """When the depth does not move as the poses (``pose_source``) say, at any one scale,
    over two or more pairs: it moves against them (a ratio below -:data:`MIN_RATIO`: clear),
    it stands still while every pair's poses moved, the pairs disagreeing (a ratio within
    :data:`MIN_RATIO` of 0 spread beyond 35 %: clear over :data:`STILL_PAIRS` pairs or
    more whose poses moved :data:`STILL_STEP_M` or more, as with world-to-camera poses;
    else likely: a camera panning on a tripod moves a few cm a pair, which depth noise
    hides), or the pairs' ratios spread beyond
    35 % (likely). The text and whether it is clear; None otherwise (a ratio of 20 or more,
    or a tiny one the pairs agree on, is the depth scale's problem)."""
    if fit is None or fit.pairs < 2 or fit.consistent() or fit.ratio >= 20.0:
        return None
    if abs(fit.ratio) <= MIN_RATIO and fit.spread <= 0.35:
        return None  # the pairs agree on a tiny ratio: the depth scale's problem
    still = abs(fit.ratio) <= MIN_RATIO
    clear = fit.ratio < -MIN_RATIO or (still and fit.pairs >= STILL_PAIRS
                                       and fit.step_m >= STILL_STEP_M)
    how = (f"hardly moves ({fit.ratio:.2f}x as far as the poses) while they move"
           if still else f"moves {fit.ratio:.2f}x as far as the poses" if clear else
           f"moves {fit.ratio:.2f}x as far as the poses, pair by pair up to "
           f"{fit.spread:.0%} apart")
    return (f"the poses ({pose_source}) do not move as the depth does: between {fit.pairs} "
            f"pairs of nearby frames the depth {how}; poses in another convention are the "
            "usual cause (world-to-camera instead of camera-to-world, a quaternion order "
            "other than x y z w, the pose of a frame other than the camera's optical one): "
            "fix them, or give --estimate-poses to estimate the poses from the depth"), clear


FROZEN_M = 0.001  # poses this close (translation, m) and
FROZEN_DEG = 0.1  # this close (rotation, degrees) to the first stand still
MOVED_M = 0.05  # a pixel whose depth changes this much (or MOVED_REL of it) moved
MOVED_REL = 0.05
FROZEN_CLEAR = 0.5  # share of the pixels that moved between sampled frames: clear
FROZEN_LIKELY = 0.2  # likely (a still camera seeing people walk stays below)


def frozen_poses_problem(poses: Sequence[np.ndarray], depths_m: Sequence[np.ndarray],
                         pose_source: str) -> tuple[str, bool] | None:
    """When all ``poses`` (three or more) stand still while the depth changes: the median,
    over consecutive ``depths_m`` (metres, frames sampled over the sequence, 0 = no
    reading), of the share of pixels read in both whose depth changed by :data:`MOVED_M`
    or :data:`MOVED_REL` is :data:`FROZEN_LIKELY` or more (clear at
    :data:`FROZEN_CLEAR`: a moving camera, where a still one seeing people walk changes a
    few pixels). The text and whether it is clear; None otherwise."""
    if len(poses) < 3 or len(depths_m) < 2:
        return None
    first = np.asarray(poses[0], float)
    for p in poses[1:]:
        moved_m, turned_deg = pose_difference(first, np.asarray(p, float))
        if moved_m > FROZEN_M or turned_deg > FROZEN_DEG:
            return None
    shares = []
    for a, b in zip(depths_m[:-1], depths_m[1:], strict=True):
        if a.shape != b.shape:
            continue
        both = (a > 0) & (b > 0) & np.isfinite(a) & np.isfinite(b)
        if both.sum() < 100:
            continue
        d = np.abs(a[both] - b[both])
        shares.append(float(np.mean(d > np.maximum(MOVED_M, MOVED_REL * np.minimum(
            a[both], b[both])))))
    if not shares or float(np.median(shares)) < FROZEN_LIKELY:
        return None
    share = float(np.median(shares))
    return (f"the poses ({pose_source}) stand still over all {len(poses)} frames while the "
            f"depth changes ({share:.0%} of the pixels move more than {MOVED_M * 100:g} cm "
            "between frames sampled over the sequence): one pose repeated for every frame is "
            "the usual cause (a pose file of the first pose only, poses of a fixed frame); "
            "fix them, or give --estimate-poses to estimate the poses from the depth"), \
        share >= FROZEN_CLEAR
