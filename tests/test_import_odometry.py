"""Odometry and drift on inputs with known answers: a textured flat wall (where ICP cannot
see lateral motion and the photometric term can), and drift figures of trajectories with a
known error."""

from __future__ import annotations

import cv2
import numpy as np
import pytest

from sgtool.log.frame import CameraIntrinsics
from sgtool.recorders.importers.odometry import drift_against, estimate_trajectory


def wall_frames(n: int = 4, step_m: float = 0.03):
    """A camera sliding right by ``step_m`` per frame in front of a textured wall 2 m away:
    the depth is the same in every frame, only the texture moves (f * step / Z pixels)."""
    rng = np.random.default_rng(0)
    w, h, f, z = 320, 240, 300.0, 2.0
    tex = cv2.GaussianBlur(rng.random((h + 200, w + 400)).astype(np.float32), (0, 0), 3)
    tex = ((tex - tex.min()) / (tex.max() - tex.min()) * 255).astype(np.uint8)
    k = CameraIntrinsics(w, h, f, f, (w - 1) / 2, (h - 1) / 2)
    frames = []
    for i in range(n):
        m = np.float32([[1, 0, 200 + f * step_m * i / z], [0, 1, 100]])
        g = cv2.warpAffine(tex, m, (w, h), flags=cv2.INTER_LINEAR | cv2.WARP_INVERSE_MAP)
        frames.append((np.repeat(g[:, :, None], 3, axis=2), np.full((h, w), z, np.float32)))
    return k, frames


def test_textured_wall_needs_the_photometric_term():
    """Point-to-plane ICP has no constraint along a plane: it reports no motion at all.
    RGB-D odometry (and the default rgbd+icp) follows the texture: 3 cm per frame."""
    k, frames = wall_frames()
    x = {m: [p[0, 3] for p in estimate_trajectory(frames, k, method=m).poses]
         for m in ("icp", "rgbd", "rgbd+icp")}
    assert max(abs(v) for v in x["icp"]) < 1e-3
    for m in ("rgbd", "rgbd+icp"):
        steps = np.diff(x[m])
        assert np.all(np.abs(steps - 0.03) < 0.006), (m, steps)


def test_drift_of_a_known_error():
    """A straight 1 m path in 11 poses; the estimate overshoots by 1 % per step and is
    expressed from another start: ATE and final error follow in closed form."""
    truth = []
    for i in range(11):
        T = np.eye(4)  # noqa: N806
        T[0, 3] = 0.1 * i
        truth.append(T)
    start = np.eye(4)
    start[:3, 3] = (5.0, -2.0, 1.0)
    est = []
    for i in range(11):
        T = start.copy()  # noqa: N806
        T[0, 3] += 0.101 * i
        est.append(T)
    d = drift_against(est, truth)
    errs = 0.001 * np.arange(11)
    assert d.path_length_m == pytest.approx(1.0)
    assert d.final_translation_m == pytest.approx(0.01)
    assert d.ate_rmse_m == pytest.approx(float(np.sqrt(np.mean(errs**2))))
    assert d.rpe_translation_m == pytest.approx(0.001)
    assert d.drift_percent == pytest.approx(1.0)
    assert d.final_rotation_deg == pytest.approx(0.0, abs=1e-9)


def test_odometry_is_repeatable_to_the_bit():
    """Open3D's RGB-D odometry differs between runs in the last bits; the snapped motions
    make two runs identical."""
    k, frames = wall_frames(n=3)
    a = estimate_trajectory(frames, k, method="rgbd+icp").poses
    b = estimate_trajectory(frames, k, method="rgbd+icp").poses
    assert all(np.array_equal(x, y) for x, y in zip(a, b, strict=True))
