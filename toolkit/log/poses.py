"""Rigid poses over time: building, interpolating and comparing 4x4 transforms.

Pure functions over numpy arrays. A *pose track* is a sorted list of time-stamped poses of
one frame in another (a ground-truth trajectory, one dynamic ``/tf`` link); a pose between
two samples is interpolated linearly in translation and by spherical linear interpolation
(slerp) in rotation, which is what ``tf2`` does between buffered transforms. Outside the
sampled span a track does not extrapolate beyond a tolerance: a camera pose made up from a
stale transform would put the whole depth image in the wrong place.
"""

from __future__ import annotations

import bisect
import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from sgtool.log.codec import matrix_from_quat, quat_from_matrix


def pose_from_tq(t: Sequence[float] | np.ndarray, q_xyzw: Sequence[float] | np.ndarray
                 ) -> np.ndarray:
    """4x4 pose from a translation and a quaternion (x, y, z, w); the quaternion need not be
    normalised (TUM files round to four decimals)."""
    T = np.eye(4)  # noqa: N806
    T[:3, :3] = matrix_from_quat(*(float(v) for v in q_xyzw))
    T[:3, 3] = [float(v) for v in t]
    return T


def tq_from_pose(T: np.ndarray) -> tuple[np.ndarray, np.ndarray]:  # noqa: N803
    """Translation (3,) and unit quaternion (x, y, z, w) with w >= 0 of a 4x4 pose."""
    return np.asarray(T[:3, 3], dtype=np.float64).copy(), np.array(quat_from_matrix(T[:3, :3]))


def slerp(q0: np.ndarray, q1: np.ndarray, a: float) -> np.ndarray:
    """Spherical linear interpolation of unit quaternions (x, y, z, w), ``a`` in [0, 1],
    along the shorter arc."""
    q0 = np.asarray(q0, dtype=np.float64)
    q1 = np.asarray(q1, dtype=np.float64)
    dot = float(np.dot(q0, q1))
    if dot < 0.0:
        q1, dot = -q1, -dot
    if dot > 0.9995:  # nearly parallel: normalised lerp is exact to ~1e-7
        q = q0 + a * (q1 - q0)
        return q / np.linalg.norm(q)
    theta = np.arccos(min(dot, 1.0))
    s = np.sin(theta)
    return (np.sin((1.0 - a) * theta) * q0 + np.sin(a * theta) * q1) / s


def interpolate(T0: np.ndarray, T1: np.ndarray, a: float) -> np.ndarray:  # noqa: N803
    """The pose a fraction ``a`` of the way from ``T0`` to ``T1``."""
    t0, q0 = tq_from_pose(T0)
    t1, q1 = tq_from_pose(T1)
    q = slerp(q0, q1, a)
    return pose_from_tq(t0 + a * (t1 - t0), q)


def rotation_angle_deg(R: np.ndarray) -> float:  # noqa: N803
    """Angle of a rotation matrix in degrees (0..180)."""
    c = (float(np.trace(R[:3, :3])) - 1.0) / 2.0
    return float(np.degrees(np.arccos(np.clip(c, -1.0, 1.0))))


def pose_difference(A: np.ndarray, B: np.ndarray) -> tuple[float, float]:  # noqa: N803
    """(translation distance in metres, rotation angle in degrees) between two poses."""
    d = np.linalg.inv(A) @ B
    return float(np.linalg.norm(A[:3, 3] - B[:3, 3])), rotation_angle_deg(d)


def planar_fit(source: Sequence[np.ndarray], target: Sequence[np.ndarray]) -> np.ndarray:
    """The rotation about z and translation in x, y (a 4x4) that best carries the poses
    ``source`` onto ``target`` (pairs, 4x4 each): least squares over each pose's position
    and the point 1 m ahead of it along its x axis, so one pose fixes the heading too
    (Kabsch in the plane). The identity when no pairs are given."""
    if len(source) != len(target):
        raise ValueError(f"{len(source)} source poses for {len(target)} target poses")
    out = np.eye(4)
    if not len(source):
        return out
    src, dst = (np.asarray(a, dtype=np.float64).reshape(-1, 4, 4) for a in (source, target))
    p = np.concatenate([src[:, :2, 3], src[:, :2, 3] + src[:, :2, 0]])
    q = np.concatenate([dst[:, :2, 3], dst[:, :2, 3] + dst[:, :2, 0]])
    pm, qm = p.mean(axis=0), q.mean(axis=0)
    h = (p - pm).T @ (q - qm)
    angle = math.atan2(h[0, 1] - h[1, 0], h[0, 0] + h[1, 1])
    c, s = math.cos(angle), math.sin(angle)
    rot = np.array([[c, -s], [s, c]])
    out[:2, :2] = rot
    out[:2, 3] = qm - rot @ pm
    return out


@dataclass(frozen=True)
class PoseTrack:
    """Time-stamped poses of one frame, sorted by time (ns). ``max_gap_ns`` bounds the span
    between two samples that may be interpolated (a longer gap is a dropout: no pose), and
    ``tolerance_ns`` how far before the first or after the last sample the nearest sample
    still counts."""

    times: tuple[int, ...]
    poses: tuple[np.ndarray, ...]
    max_gap_ns: int = 500_000_000
    tolerance_ns: int = 20_000_000

    @classmethod
    def from_samples(
        cls,
        samples: Sequence[tuple[int, np.ndarray]],
        *,
        max_gap_ns: int = 500_000_000,
        tolerance_ns: int = 20_000_000,
    ) -> PoseTrack:
        """From (time, pose) pairs in any order; of several samples at one time the last
        one given wins (a re-published transform)."""
        by_time: dict[int, np.ndarray] = {}
        for t, T in samples:  # noqa: N806
            by_time[int(t)] = np.asarray(T, dtype=np.float64)
        times = tuple(sorted(by_time))
        return cls(times, tuple(by_time[t] for t in times), max_gap_ns, tolerance_ns)

    def __len__(self) -> int:
        return len(self.times)

    def at(self, t_ns: int) -> np.ndarray | None:
        """The pose at ``t_ns`` or None when the track does not cover that time."""
        if not self.times:
            return None
        t_ns = int(t_ns)
        i = bisect.bisect_left(self.times, t_ns)
        if i < len(self.times) and self.times[i] == t_ns:
            return self.poses[i].copy()
        if i == 0:
            return self.poses[0].copy() if self.times[0] - t_ns <= self.tolerance_ns else None
        if i == len(self.times):
            last = self.times[-1]
            return self.poses[-1].copy() if t_ns - last <= self.tolerance_ns else None
        t0, t1 = self.times[i - 1], self.times[i]
        if t1 - t0 > self.max_gap_ns:
            # a dropout: only samples within the tolerance count
            if t_ns - t0 <= self.tolerance_ns:
                return self.poses[i - 1].copy()
            if t1 - t_ns <= self.tolerance_ns:
                return self.poses[i].copy()
            return None
        return interpolate(self.poses[i - 1], self.poses[i], (t_ns - t0) / (t1 - t0))
