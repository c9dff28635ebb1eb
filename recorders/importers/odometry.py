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

Measured with ``benchmarks/import_.py`` (frame to frame over the whole sequence):

=================================  ========  =========  ===============  ============
sequence                            method    ATE (m)    final error      ms per pair
=================================  ========  =========  ===============  ============
7-Scenes redkitchen, 100 frames     rgbd       0.542      0.95 m, 48 deg   ~540
(every 10th Kinect frame, 6.75 m)   icp        0.156      0.15 m, 1.5 deg  ~240
                                    rgbd+icp   0.154      0.15 m, 1.5 deg  ~1250
ICL-NUIM livingroom1, 211 frames    rgbd       0.037      0.05 m, 2.0 deg  ~640
(3.71 m; reference: Open3D's        icp        0.022      0.02 m, 1.1 deg  ~150
reconstruction, not ground truth)   rgbd+icp   0.022      0.02 m, 1.1 deg  ~800
=================================  ========  =========  ===============  ============

RGB-D odometry alone loses track on 7-Scenes' large steps (0.1 m / 4 degrees between the
kept frames; its depth is also not registered to the colour); ICP gets the same accuracy
with or without the RGB-D start on these sequences and is 4-5x faster. The default keeps
the photometric start because ICP alone slides along geometry without structure (a bare
wall, a corridor), where the image texture still constrains the motion (on a textured
wall ICP reports no motion at all while RGB-D odometry follows the 3 cm steps:
``tests/test_import_odometry.py``); ``--odometry icp``
is the fast choice for cluttered rooms. (Times on 2 shared cores, with other work running.)

A step whose odometry reports failure keeps the previous motion and is counted.

Determinism: Open3D's RGB-D odometry (and multi-threaded ICP) differ between runs in the
last bits (measured: up to 1e-15). Each relative motion is therefore snapped to a grid of
1e-8 (translation in metres, rotation vector in radians) before it is composed, so the
same frames give the same poses and the same log bytes; a value within 1e-15 of a grid
boundary could still flip, a chance of about 2e-7 per number.

Drift (:func:`drift_against`) compares an estimate with ground truth after expressing both
from the same first pose: absolute trajectory error (RMSE of camera positions), the final
position and rotation error, the mean relative pose error between consecutive frames, and
the final error as a percentage of the path length.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Sequence
from dataclasses import asdict, dataclass

import numpy as np

from sgtool.errors import SgtoolError
from sgtool.log.frame import CameraIntrinsics
from sgtool.recorders.importers.poses import pose_difference, rotation_angle_deg

METHODS = ("rgbd+icp", "rgbd", "icp")


@dataclass(frozen=True)
class OdometryResult:
    poses: tuple[np.ndarray, ...]  # world_T_camera per frame
    method: str
    failures: int  # steps where the odometry reported failure (previous motion kept)


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
    drift_percent: float  # final translation error / path length

    def as_dict(self) -> dict[str, float]:
        return {k: (round(v, 6) if isinstance(v, float) else v) for k, v in asdict(self).items()}

    def summary(self) -> str:
        return (
            f"{self.frames} frames, path {self.path_length_m:.2f} m: ATE RMSE "
            f"{self.ate_rmse_m:.3f} m, final error {self.final_translation_m:.3f} m "
            f"({self.drift_percent:.1f} % of the path) and {self.final_rotation_deg:.1f} deg, "
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
        drift_percent=float(100.0 * terr[-1] / path) if path > 0 else 0.0,
    )


class _Odometer:
    """Open3D state for one sequence (one camera)."""

    def __init__(self, k: CameraIntrinsics, method: str, depth_max: float) -> None:
        import open3d as o3d

        if method not in METHODS:
            raise SgtoolError(f"unknown odometry method {method!r} ({', '.join(METHODS)})")
        self.o3d = o3d
        self.method = method
        self.depth_max = depth_max
        self.intr = o3d.camera.PinholeCameraIntrinsic(k.width, k.height, k.fx, k.fy, k.cx, k.cy)
        self.jacobian = o3d.pipelines.odometry.RGBDOdometryJacobianFromHybridTerm()
        self.option = o3d.pipelines.odometry.OdometryOption(
            o3d.utility.IntVector([20, 10, 5]), 0.07, 0.0, depth_max
        )
        self.icp_est = o3d.pipelines.registration.TransformationEstimationPointToPlane()
        self.icp_crit = o3d.pipelines.registration.ICPConvergenceCriteria(max_iteration=30)

    def prepare(self, rgb: np.ndarray | None, depth_m: np.ndarray) -> tuple[object, object]:
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
        return rgbd, cloud

    def motion(
        self, prev: tuple[object, object], cur: tuple[object, object], init: np.ndarray
    ) -> tuple[np.ndarray, bool]:
        """prev_T_cur (the current camera in the previous one) and success."""
        o3d = self.o3d
        T, ok = init, True  # noqa: N806
        if cur[0] is not None and prev[0] is not None:
            ok, T_rgbd, _ = o3d.pipelines.odometry.compute_rgbd_odometry(  # noqa: N806
                cur[0], prev[0], self.intr, init, self.jacobian, self.option
            )
            T = T_rgbd if ok else init  # noqa: N806
        if cur[1] is not None and prev[1] is not None:
            if len(cur[1].points) < 50 or len(prev[1].points) < 50:
                return T, False
            for radius in (0.2, 0.08, 0.03):
                reg = o3d.pipelines.registration.registration_icp(
                    cur[1], prev[1], radius, T, self.icp_est, self.icp_crit
                )
                T = reg.transformation  # noqa: N806
            ok = bool(reg.fitness > 0.3)
        return np.asarray(T), bool(ok)


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
    progress: Callable[[int], None] | None = None,
) -> OdometryResult:
    """Poses of (rgb or None, depth in metres) frames by frame-to-frame odometry."""
    odo = _Odometer(intrinsics, method, depth_max)
    poses: list[np.ndarray] = []
    prev = None
    last = np.eye(4)
    failures = 0
    for i, (rgb, depth) in enumerate(frames):
        cur = odo.prepare(rgb, depth)
        if prev is None:
            poses.append(np.eye(4) if start is None else np.asarray(start, dtype=np.float64))
        else:
            T, ok = odo.motion(prev, cur, last)  # noqa: N806
            if not ok:
                failures += 1
                T = last  # noqa: N806
            T = snap_motion(T)  # noqa: N806
            poses.append(poses[-1] @ T)
            last = T
        prev = cur
        if progress is not None:
            progress(i)
    return OdometryResult(tuple(poses), method, failures)
