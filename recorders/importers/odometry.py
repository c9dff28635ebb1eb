"""Camera poses from RGB-D frames when a source has none, and their drift.

Frame-to-frame visual odometry with Open3D; each frame's motion relative to the previous
one is composed into a trajectory that starts at a given pose (the first ground-truth pose
when there is one, else the identity). Three methods:

- ``rgbd``: Open3D's dense RGB-D odometry (``compute_rgbd_odometry`` with the hybrid
  photometric + geometric term of Steinbruecker et al. 2011 / Kerl et al. 2013), started
  from the previous motion (constant velocity);
- ``icp``: multi-scale point-to-plane ICP (Chen and Medioni 1992) on 2 cm voxelised
  depth clouds, correspondence radii 0.2, 0.08, 0.03 m, started from the previous motion;
- ``rgbd+icp`` (default): RGB-D odometry for the initial motion, refined by ICP.

The default keeps the photometric start because ICP alone slides along geometry without
structure (a bare wall, a corridor), where the image texture still constrains the motion
(on a textured wall ICP reports no motion at all while RGB-D odometry follows the 3 cm
steps: ``tests/recorders/importers/test_odometry.py``); ``--odometry icp`` is the cheaper
choice for cluttered rooms. Accuracy and time per method on 7-Scenes and ICL-NUIM
(``benchmarks/import_.py``) are in ``docs/experiments/moved-from-docstrings.md``.

A step fails, keeps the previous motion (constant velocity) and is counted when
- Open3D reports failure (RGB-D odometry did not converge, a depth image has under 50
  points for ICP), or
- too little of the frame was matched: RGB-D odometry found correspondences (its
  information matrix counts them) for under :attr:`MotionLimits.min_matched` of the
  frame's valid depth pixels, or ICP's fitness is under :attr:`MotionLimits.min_fitness`;
- the motion is implausible for the time between the two frames: faster than
  :attr:`MotionLimits.max_speed` or :attr:`MotionLimits.max_turn_deg` plus a fixed
  allowance per step (checked when the frame times are given).

Odometry that loses track often still "succeeds" (on plain walls seen by a robot turning
in place, the first frames of ``sgtool record``, Open3D's RGB-D odometry reports success
for steps of metres); the checks turn those steps into failures. The default limits are
set to leave the correct steps of 7-Scenes, ICL-NUIM and TUM alone (the matched shares and
step speeds seen there: ``docs/experiments/moved-from-docstrings.md``).

Determinism: Open3D's RGB-D odometry (and multi-threaded ICP) may differ between runs in
the last bits. Each relative motion is therefore snapped to a grid of 1e-8 (translation in
metres, rotation vector in radians) before it is composed, so the same frames give the
same poses and the same log bytes; a value closer to a grid boundary than the run-to-run
difference could still flip (a chance of that difference over the grid step per number).

Drift (:func:`drift_against`) compares an estimate with a reference trajectory (ground
truth where the dataset has it) after expressing both from the same first pose: absolute
trajectory error (RMSE of camera positions), the final position and rotation error, the
mean relative pose error between consecutive frames, and the final error as a percentage
of the path length. Of the failure checks, the motion check tests the snapped motion; the
matched share is a whole count of pixels, which a last-bit difference changes only for a
pixel exactly on Open3D's depth-difference bound.
"""

from __future__ import annotations

import sys
from collections.abc import Callable, Iterable, Sequence
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np

from sgtool.errors import SgtoolError
from sgtool.log.frame import CameraIntrinsics
from sgtool.log.poses import pose_difference, rotation_angle_deg

METHODS = ("rgbd+icp", "rgbd", "icp")


@dataclass(frozen=True)
class MotionLimits:
    """When a frame-to-frame motion counts as failed (see the module docstring). The
    defaults allow a hand-held camera or an indoor robot: 1.5 m/s (a brisk walk) and
    180 deg/s, plus 2 cm and 2 degrees per step for time-stamp jitter and noise."""

    max_speed: float = 1.5  # m/s
    max_turn_deg: float = 180.0  # deg/s
    slack_m: float = 0.02  # per step
    slack_deg: float = 2.0  # per step
    min_matched: float = 0.2  # RGB-D odometry: correspondences / valid depth pixels
    min_fitness: float = 0.3  # ICP: share of points with a correspondence


FAILURE_REASONS = ("reported", "matches", "motion")
UNRELIABLE_SHARE = 0.25  # more failed steps than this: the import says the poses are unreliable


@dataclass(frozen=True)
class FailedStep:
    """The motion from frame ``frame - 1`` to ``frame`` failed for ``reason`` (a key of
    :data:`FAILURE_REASONS`)."""

    frame: int
    reason: str
    detail: str = ""
    dt_s: float = 0.0  # "motion": the time between the frames,
    dist_m: float = 0.0  # the distance moved,
    needed_s: float = 0.0  # and the time that motion needs within the limits


@dataclass(frozen=True)
class OdometryResult:
    poses: tuple[np.ndarray, ...]  # world_T_camera per frame
    method: str
    failed: tuple[FailedStep, ...] = ()  # steps where the previous motion was kept
    limits: MotionLimits = MotionLimits()

    @property
    def failures(self) -> int:
        return len(self.failed)

    @property
    def steps(self) -> int:
        return max(len(self.poses) - 1, 0)

    def reasons(self) -> dict[str, int]:
        """Failed steps per reason (every reason, zeros included)."""
        return {r: sum(f.reason == r for f in self.failed) for r in FAILURE_REASONS}

    def summary(self) -> str:
        """One line for the import report."""
        head = f"{self.failures} of {self.steps} steps failed (previous motion kept)"
        counts = self.reasons()
        if not self.failed:
            return head
        lim = self.limits
        words = {
            "reported": "reported by Open3D",
            "matches": "too little matched ("
            + (f"under {lim.min_matched:.0%} of the depth pixels)" if self.method == "rgbd"
               else f"ICP fitness under {lim.min_fitness:g})"),
            "motion": f"implausible motion (faster than {lim.max_speed:g} m/s or "
            f"{lim.max_turn_deg:g} deg/s)",
        }
        parts = [f"{n} {words[r]}" for r, n in counts.items() if n]
        return f"{head}: " + ", ".join(parts)

    def warning(self, share: float = UNRELIABLE_SHARE) -> str | None:
        """A note for the import when more than ``share`` of the steps failed; when most
        failures are motion too fast for the time between the frames, it names that
        time and the spacing the motion needs (frames skipped at a frame rate taken as the
        camera's)."""
        if not self.steps or self.failures <= share * self.steps:
            return None
        head = (f"odometry failed on {self.failures / self.steps:.0%} of the steps: the "
                "estimated poses are unreliable")
        fast = [f for f in self.failed if f.reason == "motion"]
        if 2 * len(fast) < self.failures:
            return f"{head} (give the poses, or try another --odometry)"
        dt = float(np.median([f.dt_s for f in fast]))
        dist = float(np.median([f.dist_m for f in fast]))
        need = float(np.median([f.needed_s for f in fast]))
        rate = f"{1 / dt:.3g} fps" if dt > 0 else "no time"
        return (f"{head}; {len(fast)} of the failures are motion too fast for the time between "
                f"the frames: they are {dt:.3g} s apart in the log ({rate}) and moved a median "
                f"{dist:.3f} m per step, plausible only ~{need:.2g} s apart; if frames were "
                f"skipped, give the real spacing (folders: --fps {1 / max(need, 1e-3):.2g} or "
                "less), else give the poses or try another --odometry")


MIN_PATH_M = 0.01  # shorter reference paths get no drift percentage


@dataclass(frozen=True)
class DriftReport:
    """Errors of an estimated trajectory against a reference (both from the same start)."""

    frames: int
    path_length_m: float
    ate_rmse_m: float
    max_translation_m: float
    final_translation_m: float
    final_rotation_deg: float
    rpe_translation_m: float  # mean per consecutive pair
    rpe_rotation_deg: float
    # final translation error / path length; None when the path is under MIN_PATH_M (a
    # camera turning in place), where a percentage says nothing
    drift_percent: float | None

    def as_dict(self) -> dict[str, float | None]:
        return {k: (round(v, 6) if isinstance(v, float) else v) for k, v in asdict(self).items()}

    def summary(self) -> str:
        return (
            f"{self.frames} frames, path {self.path_length_m:.2f} m: ATE RMSE "
            f"{self.ate_rmse_m:.3f} m, final error {self.final_translation_m:.3f} m "
            + (f"({self.drift_percent:.1f} % of the path) " if self.drift_percent is not None
               else "")
            + f"and {self.final_rotation_deg:.1f} deg, "
            f"per-frame RPE {self.rpe_translation_m * 100:.1f} cm / "
            f"{self.rpe_rotation_deg:.2f} deg"
        )


def drift_against(estimated: Sequence[np.ndarray], truth: Sequence[np.ndarray]) -> DriftReport:
    """See the module docstring. The estimate is re-anchored at ``truth[0]`` first."""
    if len(estimated) != len(truth) or len(truth) < 2:
        raise ValueError("drift needs two trajectories of the same length >= 2")
    anchor = np.asarray(truth[0]) @ np.linalg.inv(estimated[0])
    est = [anchor @ E for E in estimated]
    errs = [pose_difference(G, E) for G, E in zip(truth, est, strict=True)]
    terr = np.array([e[0] for e in errs])
    path = sum(
        float(np.linalg.norm(truth[i][:3, 3] - truth[i - 1][:3, 3])) for i in range(1, len(truth))
    )
    rpe_t, rpe_r = [], []
    for i in range(1, len(truth)):
        dg = np.linalg.inv(truth[i - 1]) @ truth[i]
        de = np.linalg.inv(est[i - 1]) @ est[i]
        d = np.linalg.inv(dg) @ de
        rpe_t.append(float(np.linalg.norm(d[:3, 3])))
        rpe_r.append(rotation_angle_deg(d))
    return DriftReport(
        frames=len(truth),
        path_length_m=path,
        ate_rmse_m=float(np.sqrt(np.mean(terr**2))),
        max_translation_m=float(terr.max()),
        final_translation_m=float(terr[-1]),
        final_rotation_deg=float(errs[-1][1]),
        rpe_translation_m=float(np.mean(rpe_t)),
        rpe_rotation_deg=float(np.mean(rpe_r)),
        drift_percent=float(100.0 * terr[-1] / path) if path >= MIN_PATH_M else None,
    )


@dataclass(frozen=True)
class _Prepared:
    """One frame ready for Open3D: the RGB-D image (None for ``icp``), the voxelised cloud
    with normals (None for ``rgbd``) and the count of depth pixels within range."""

    rgbd: Any
    cloud: Any
    valid_pixels: int


class _Odometer:
    """Open3D state for one sequence (one camera)."""

    def __init__(self, k: CameraIntrinsics, method: str, depth_max: float,
                 limits: MotionLimits) -> None:
        import open3d as o3d

        if method not in METHODS:
            raise SgtoolError(f"unknown odometry method {method!r} ({', '.join(METHODS)})")
        self.o3d = o3d
        self.method = method
        self.depth_max = depth_max
        self.limits = limits
        self.intr = o3d.camera.PinholeCameraIntrinsic(k.width, k.height, k.fx, k.fy, k.cx, k.cy)
        self.jacobian = o3d.pipelines.odometry.RGBDOdometryJacobianFromHybridTerm()
        self.option = o3d.pipelines.odometry.OdometryOption(
            o3d.utility.IntVector([20, 10, 5]), 0.07, 0.0, depth_max
        )
        self.icp_est = o3d.pipelines.registration.TransformationEstimationPointToPlane()
        self.icp_crit = o3d.pipelines.registration.ICPConvergenceCriteria(max_iteration=30)

    def prepare(self, rgb: np.ndarray | None, depth_m: np.ndarray) -> _Prepared:
        o3d = self.o3d
        d = np.ascontiguousarray(depth_m, dtype=np.float32)
        rgbd = None
        if self.method != "icp" and rgb is not None:
            rgbd = o3d.geometry.RGBDImage.create_from_color_and_depth(
                o3d.geometry.Image(np.ascontiguousarray(rgb)), o3d.geometry.Image(d),
                depth_scale=1.0, depth_trunc=self.depth_max, convert_rgb_to_intensity=True,
            )
        cloud = None
        if self.method != "rgbd":
            cloud = o3d.geometry.PointCloud.create_from_depth_image(
                o3d.geometry.Image(d), self.intr, depth_scale=1.0, depth_trunc=self.depth_max
            ).voxel_down_sample(0.02)
            cloud.estimate_normals(o3d.geometry.KDTreeSearchParamHybrid(radius=0.08, max_nn=30))
        valid = int(np.count_nonzero((d > 0.0) & (d < self.depth_max)))
        return _Prepared(rgbd, cloud, valid)

    def motion(
        self, prev: _Prepared, cur: _Prepared, init: np.ndarray
    ) -> tuple[np.ndarray, tuple[str, str] | None]:
        """prev_T_cur (the current camera in the previous one) and, when the step failed,
        (reason, detail)."""
        o3d = self.o3d
        T = init  # noqa: N806
        failed: tuple[str, str] | None = None
        if cur.rgbd is not None and prev.rgbd is not None:
            ok, T_rgbd, info = o3d.pipelines.odometry.compute_rgbd_odometry(  # noqa: N806
                cur.rgbd, prev.rgbd, self.intr, init, self.jacobian, self.option
            )
            # the information matrix's translation block counts the correspondences
            matched = float(np.asarray(info)[5, 5]) / max(cur.valid_pixels, 1)
            if not ok:
                failed = ("reported", "RGB-D odometry did not converge")
            elif matched < self.limits.min_matched:
                failed = ("matches", f"RGB-D odometry matched {matched:.0%} of the depth "
                          "pixels")
            T = T_rgbd if failed is None else init  # noqa: N806
        if cur.cloud is not None and prev.cloud is not None:
            if len(cur.cloud.points) < 50 or len(prev.cloud.points) < 50:
                return np.asarray(T), ("reported", "under 50 depth points")
            for radius in (0.2, 0.08, 0.03):
                reg = o3d.pipelines.registration.registration_icp(
                    cur.cloud, prev.cloud, radius, T, self.icp_est, self.icp_crit
                )
                T = reg.transformation  # noqa: N806
            failed = None
            if not reg.fitness > self.limits.min_fitness:
                failed = ("matches", f"ICP fitness {reg.fitness:.2f}")
        return np.asarray(T), failed


def motion_time_needed(T: np.ndarray, limits: MotionLimits) -> float:  # noqa: N803
    """The least time (s) in which the relative motion ``T`` is plausible under ``limits``."""
    dist = float(np.linalg.norm(np.asarray(T)[:3, 3]))
    turn = rotation_angle_deg(np.asarray(T))
    return max((dist - limits.slack_m) / limits.max_speed,
               (turn - limits.slack_deg) / limits.max_turn_deg, 0.0)


def implausible_motion(T: np.ndarray, dt_s: float, limits: MotionLimits) -> str | None:  # noqa: N803
    """Why the relative motion ``T`` (prev_T_cur) cannot have happened in ``dt_s`` seconds
    under ``limits``, or None when it can."""
    dt = max(float(dt_s), 0.0)
    dist = float(np.linalg.norm(np.asarray(T)[:3, 3]))
    turn = rotation_angle_deg(np.asarray(T))
    t_max = limits.max_speed * dt + limits.slack_m
    r_max = limits.max_turn_deg * dt + limits.slack_deg
    if dist > t_max:
        return f"{dist:.3f} m in {dt:.3f} s (at most {t_max:.3f} m)"
    if turn > r_max:
        return f"{turn:.1f} deg in {dt:.3f} s (at most {r_max:.1f} deg)"
    return None


SNAP = 1e-8


def snap_motion(T: np.ndarray) -> np.ndarray:  # noqa: N803
    """``T`` with translation and rotation vector rounded to :data:`SNAP` (a rotation again,
    exactly, through Rodrigues' formula)."""
    from scipy.spatial.transform import Rotation

    out = np.eye(4)
    rv = np.round(Rotation.from_matrix(np.asarray(T)[:3, :3]).as_rotvec() / SNAP) * SNAP
    out[:3, :3] = Rotation.from_rotvec(rv).as_matrix()
    out[:3, 3] = np.round(np.asarray(T)[:3, 3] / SNAP) * SNAP
    return out


def estimate_trajectory(
    frames: Iterable[tuple[np.ndarray | None, np.ndarray]],
    intrinsics: CameraIntrinsics,
    *,
    method: str = "rgbd+icp",
    start: np.ndarray | None = None,
    depth_max: float = 4.0,
    times_ns: Sequence[int] | None = None,
    limits: MotionLimits | None = None,
    progress: Callable[[int], None] | None = None,
) -> OdometryResult:
    """Poses of (rgb or None, depth in metres) frames by frame-to-frame odometry.
    ``times_ns`` (one per frame) enables the check of each motion against the time between
    the frames (see the module docstring)."""
    limits = limits or MotionLimits()
    odo = _Odometer(intrinsics, method, depth_max, limits)
    poses: list[np.ndarray] = []
    prev = None
    last = np.eye(4)
    failed: list[FailedStep] = []
    for i, (rgb, depth) in enumerate(frames):
        if times_ns is not None and i >= len(times_ns):
            raise ValueError(f"{len(times_ns)} frame times for more frames")
        cur = odo.prepare(rgb, depth)
        if prev is None:
            poses.append(np.eye(4) if start is None else np.asarray(start, dtype=np.float64))
        else:
            T, why = odo.motion(prev, cur, last)  # noqa: N806
            T = snap_motion(T)  # noqa: N806
            step: FailedStep | None = None
            if why is not None:
                step = FailedStep(i, *why)
            elif times_ns is not None:
                dt = (times_ns[i] - times_ns[i - 1]) / 1e9
                detail = implausible_motion(T, dt, limits)
                if detail:
                    step = FailedStep(i, "motion", detail, dt, float(np.linalg.norm(T[:3, 3])),
                                      motion_time_needed(T, limits))
            if step is not None:
                failed.append(step)
                T = last  # noqa: N806
            poses.append(poses[-1] @ T)
            last = T
        prev = cur
        if progress is not None:
            progress(i)
    if times_ns is not None and len(times_ns) != len(poses):
        raise ValueError(f"{len(times_ns)} frame times for {len(poses)} frames")
    return OdometryResult(tuple(poses), method, tuple(failed), limits)


def estimate_with_progress(
    frames: Iterable[tuple[np.ndarray | None, np.ndarray]],
    intrinsics: CameraIntrinsics,
    total: int,
    *,
    method: str,
    start: np.ndarray | None,
    depth_max: float,
    times_ns: Sequence[int],
    progress: bool,
) -> OdometryResult:
    """:func:`estimate_trajectory` of ``total`` frames behind a progress bar on stderr
    (none when ``progress`` is False)."""
    from tqdm import tqdm

    bar = tqdm(total=total, unit="frame", desc="odometry", file=sys.stderr,
               disable=None if progress else True, leave=False)
    try:
        return estimate_trajectory(frames, intrinsics, method=method, start=start,
                                   depth_max=depth_max, times_ns=times_ns,
                                   progress=lambda i: bar.update(1))
    finally:
        bar.close()


def drift_where_known(estimated: Sequence[np.ndarray],
                      reference: Sequence[np.ndarray | None]) -> DriftReport | None:
    """The drift of ``estimated`` against the frames that have a ``reference`` pose (None:
    that frame has none); None when fewer than two have one."""
    known = [(i, p) for i, p in enumerate(reference) if p is not None]
    if len(known) < 2:
        return None
    return drift_against([estimated[i] for i, _ in known], [p for _, p in known])
