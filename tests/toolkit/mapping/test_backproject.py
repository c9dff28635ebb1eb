"""Blocked back-projection (sgtool.mapping.backproject) == the plain float64 formulation it
replaced, bit for bit: world coordinates and voxel keys, on recorded frames (the golden
log; the real 7-Scenes frames when the shared data is present) and on random poses far
from the origin; and the run-collapsing key count == np.unique."""

from __future__ import annotations

import os
from pathlib import Path

import cv2
import numpy as np
import pytest

from sgtool.log import LogReader
from sgtool.mapping import backproject as bp
from sgtool.mapping.key_count import count_keys
from sgtool.mapping.voxels import (
    OFFSET,
    SHIFT_X,
    SHIFT_Y,
    SHIFT_Z,
    pack,
)

GOLDEN = Path(__file__).resolve().parents[2] / "golden" / "house6-tour.mcap"
SEVEN = Path(os.environ.get("SGTOOL_SHARED_DATA", Path(__file__).resolve().parents[4]
                            / "shared" / "data")) / "rgbd" / "7scenes-redkitchen-every10"


def plain(depth: np.ndarray, pose: np.ndarray, fx: float, fy: float, cx: float, cy: float,
          res: float) -> tuple[np.ndarray, ...]:
    """The integration's arithmetic before the blocked form (HEAD 35c3dec)."""
    h, w = depth.shape
    ru = np.tile((np.arange(w, dtype=np.float64) - cx) / fx, h)
    rv = np.repeat((np.arange(h, dtype=np.float64) - cy) / fy, w)
    d = depth.reshape(-1)
    idx = np.flatnonzero((d >= 0.1) & (d < 5.0))
    z = d[idx].astype(np.float64)
    xc = ru[idx] * z
    yc = rv[idx] * z
    world = []
    for r in range(3):
        v = pose[r, 0] * xc
        v += pose[r, 1] * yc
        v += pose[r, 2] * z
        v += pose[r, 3]
        world.append(v)
    vox = [np.floor(v * (1.0 / res)).astype(np.int64) for v in world]
    return idx, ru, rv, world, pack(vox[0], vox[1], vox[2], 0)


def check(depth: np.ndarray, pose: np.ndarray, k: tuple[float, float, float, float],
          res: float = 0.05) -> int:
    idx, ru, rv, world, keys = plain(depth, pose, *k, res)
    s = bp.Scratch()
    wx, wy, wz, got, rng = bp.world_voxels(depth.reshape(-1), idx, ru, rv, pose, 1.0 / res,
                                           (SHIFT_X, SHIFT_Y, SHIFT_Z), OFFSET, s)
    for a, b in zip((wx, wy, wz), world, strict=True):
        assert np.array_equal(a.view(np.int64), b.view(np.int64))  # same bits
    assert np.array_equal(got, keys)
    vf = [np.floor(v * (1.0 / res)) for v in world]
    assert rng == [float(f(v)) for v in vf for f in (np.min, np.max)]
    return int(idx.size)


def test_blocked_equals_plain_on_the_golden_log_frames():
    with LogReader(GOLDEN) as r:
        frames = [f for _, f in zip(range(30), r.frames(), strict=False)]
    n = 0
    for f in frames:
        k = f.intrinsics
        n += check(f.depth, np.asarray(f.pose, np.float64), (k.fx, k.fy, k.cx, k.cy))
    assert n > 30 * 1000  # many points checked


@pytest.mark.skipif(not SEVEN.is_dir(), reason="7-Scenes frames not present (shared data)")
def test_blocked_equals_plain_on_real_kinect_frames():
    paths = sorted(SEVEN.glob("frame-*.depth.png"))[::5]
    assert paths
    for p in paths:
        d = cv2.imread(str(p), cv2.IMREAD_UNCHANGED).astype(np.uint16)
        d[d == 65535] = 0
        depth = d.astype(np.float32) / np.float32(1000.0)
        pose = np.loadtxt(str(p).replace(".depth.png", ".pose.txt"))
        assert check(depth, pose, (585.0, 585.0, 320.0, 240.0)) > 100_000


def test_blocked_equals_plain_on_random_poses_far_from_the_origin(monkeypatch):
    monkeypatch.setattr(bp, "BLOCK", 1000)  # many blocks, the last one partial
    rng = np.random.default_rng(7)
    for trial in range(6):
        depth = rng.uniform(0.0, 6.0, (97, 131)).astype(np.float32)
        q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
        pose = np.eye(4)
        pose[:3, :3] = q
        pose[:3, 3] = rng.uniform(-3000, 3000, 3) * (trial % 2)
        check(depth, pose, (100.0, 110.0, 65.3, 48.1), res=0.05 + 0.01 * trial)


def test_count_keys_equals_unique_with_and_without_runs():
    rng = np.random.default_rng(3)
    runs = np.repeat(rng.integers(-50, 50, 800), rng.integers(1, 30, 800))  # mostly runs
    spread = rng.integers(-(1 << 40), 1 << 40, 5000)  # no runs: plain sort path
    for keys in (runs, spread, np.array([5]), np.zeros(0, np.int64)):
        uk, cnt = count_keys(keys.astype(np.int64))
        want_k, want_c = np.unique(keys, return_counts=True)
        assert np.array_equal(uk, want_k) and np.array_equal(cnt, want_c)


def test_the_packing_bound_holds_and_skipping_the_range_keeps_the_keys():
    rng = np.random.default_rng(11)
    h, w, fx, cx = 60, 80, 50.0, 39.5
    ru = np.tile((np.arange(w, dtype=np.float64) - cx) / fx, h)
    rv = np.repeat((np.arange(h, dtype=np.float64) - 29.5) / fx, w)
    inside = 0
    for trial in range(40):
        q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
        pose = np.eye(4)
        pose[:3, :3] = q
        pose[:3, 3] = rng.uniform(-1.3, 1.3, 3) * (OFFSET - 10) * 0.05 * (trial % 4) / 3
        depth = rng.uniform(0.0, 5.0, (h, w)).astype(np.float32)
        ok = bp.within_packing(pose, ru, rv, 5.0, 20.0, OFFSET - 1)
        idx, _, _, world, keys = plain(depth, pose, fx, fx, cx, 29.5, 0.05)
        vox = np.abs(np.floor(np.stack(world) * 20.0))
        if ok:  # the bound is sound: every point well inside
            inside += 1
            assert vox.max() < OFFSET - 3
            wx, wy, wz, got, r = bp.world_voxels(
                depth.reshape(-1), idx, ru, rv, pose, 20.0, (SHIFT_X, SHIFT_Y, SHIFT_Z),
                OFFSET, bp.Scratch(), need_range=False)
            assert r == [] and np.array_equal(got, keys)
    assert 10 < inside < 40  # both outcomes met
    nan = np.full((4, 4), np.nan)
    assert not bp.within_packing(nan, ru, rv, 5.0, 20.0, OFFSET - 1)
    assert not bp.within_packing(np.eye(4), ru, rv, np.inf, 20.0, OFFSET - 1)


def test_float_packing_is_exact_at_the_edges_of_the_packing():
    # one pixel on the optical axis at depth 0: the point is the camera position, so the
    # voxel indices are chosen through the translation; every field at its extremes
    ru = rv = np.zeros(1)
    depth = np.zeros(1, np.float32)
    edge = OFFSET - 3  # the largest magnitude within_packing lets through
    values = (-edge, -edge + 1, -1, 0, 1, edge - 1, edge)
    s = bp.Scratch()
    for vx in values:
        for vy in values:
            for vz in values:
                pose = np.eye(4)
                pose[:3, 3] = (np.array([vx, vy, vz]) + 0.5) * 0.05
                *_, keys, _ = bp.world_voxels(depth, None, ru, rv, pose, 20.0,
                                              (SHIFT_X, SHIFT_Y, SHIFT_Z), OFFSET, s,
                                              need_range=False)
                assert int(keys[0]) == int(pack(np.int64(vx), np.int64(vy), np.int64(vz), 0))
    with pytest.raises(ValueError):  # fields that could not be summed exactly
        bp.world_voxels(depth, None, ru, rv, np.eye(4), 20.0, (50, 29, 12), OFFSET, s)
