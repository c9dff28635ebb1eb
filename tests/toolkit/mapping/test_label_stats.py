"""Per-label frame statistics (sgtool.mapping.label_stats): the shortcuts (labels that
cannot come closer left alone, sums of a few labels alone or of a subset of the points)
give bit for bit the statistics of the plain update with two bincounts over all points."""

from __future__ import annotations

import numpy as np
import pytest

from sgtool.mapping import label_stats as ls
from sgtool.mapping.label_stats import LabelStats, point_sums, update_frame

RES = 0.05


def _plain(st: LabelStats, pts: np.ndarray, labels: np.ndarray, wx: np.ndarray,
           wy: np.ndarray, n_lab: int, viewpoint: tuple[float, float], frame_index: int,
           min_points: int) -> None:
    """The update before the shortcuts: every sum by a bincount over all points."""
    st.grow(n_lab)
    present = np.flatnonzero(pts)
    present = present[present > 0]
    if present.size == 0:
        return
    sx = np.bincount(labels, weights=wx, minlength=n_lab)[present]
    sy = np.bincount(labels, weights=wy, minlength=n_lab)[present]
    p = pts[present]
    st.points_max[present] = np.maximum(st.points_max[present], p)
    st.points_total[present] += p
    st.frames[present] += 1
    st.last_index[present] = frame_index
    dist = np.hypot(sx / p - viewpoint[0], sy / p - viewpoint[1])
    better = (p >= min_points) & (dist < st.view_dist[present])
    sel = present[better]
    st.view_dist[sel] = dist[better]
    st.view_xy[sel] = viewpoint


def _frame(rng: np.random.Generator, n_lab: int) -> tuple[np.ndarray, ...]:
    """Points of a few labels in runs (pixel order), clustered around label centres."""
    n = int(rng.integers(50, 3000))
    runs = rng.integers(0, n_lab, size=n // 20 + 1)
    labels = np.repeat(runs, rng.integers(1, 40, size=runs.size))[:n].astype(np.int64)
    centre = np.stack([np.arange(n_lab) * 0.37 - 3.0, np.arange(n_lab) * -0.21 + 1.0], 1)
    xy = centre[labels] + rng.normal(scale=0.4, size=(labels.size, 2))
    return labels, np.ascontiguousarray(xy[:, 0]), np.ascontiguousarray(xy[:, 1])


def _voxel_means(labels: np.ndarray, wx: np.ndarray, wy: np.ndarray, n_lab: int):
    """Mean voxel centre per label, as the map computes it from its keys."""
    n = np.maximum(np.bincount(labels, minlength=n_lab), 1)
    return tuple(np.bincount(labels, weights=np.floor(w / RES) + 0.5, minlength=n_lab)
                 * RES / n for w in (wx, wy))


@pytest.mark.parametrize("seed", range(12))
def test_update_equals_the_plain_bincounts(seed: int, monkeypatch: pytest.MonkeyPatch) -> None:
    rng = np.random.default_rng(seed)
    monkeypatch.setattr(ls, "FEW", int(rng.integers(0, 4)))
    n_lab = int(rng.integers(2, 12))
    fast, plain = LabelStats(), LabelStats()
    summed, eligible = [], 0
    real = ls.point_sums

    def counted(labels, ws, which, counts, n):
        summed.append(len(which))
        return real(labels, ws, which, counts, n)

    monkeypatch.setattr(ls, "point_sums", counted)
    for i in range(40):
        labels, wx, wy = _frame(rng, n_lab)
        pts = np.bincount(labels, minlength=n_lab).astype(np.int64)
        vp = (float(rng.uniform(-4, 4)), float(rng.uniform(-4, 4)))
        update_frame(fast, pts, lambda labels=labels, wx=wx, wy=wy: _voxel_means(
            labels, wx, wy, n_lab), labels, wx, wy, n_lab, vp, i, 30, RES)
        _plain(plain, pts, labels, wx, wy, n_lab, vp, i, 30)
        eligible += int((pts[1:] >= 30).sum())
    for name in ("points_max", "points_total", "frames", "last_index", "view_dist",
                 "view_xy"):
        np.testing.assert_array_equal(getattr(fast, name), getattr(plain, name))
    assert np.isfinite(plain.view_dist[1:n_lab]).any()  # some viewpoints were kept
    assert 0 < sum(summed) < eligible  # some labels were left alone by the bound


@pytest.mark.parametrize("k", [1, 2, 3, 6])
def test_point_sums_are_bincount_sums(k: int) -> None:
    rng = np.random.default_rng(k)
    labels = np.repeat(rng.integers(0, 8, 300), rng.integers(1, 9, 300)).astype(np.int64)
    w = rng.normal(size=labels.size) * 10.0 ** rng.integers(-3, 4, labels.size)
    which = np.sort(rng.choice(9, size=k, replace=False))  # label 8 has no points
    counts = np.bincount(labels, minlength=9)[which]
    for a, b in zip(point_sums(labels, (w, -w), which, counts, 9),
                    (np.bincount(labels, weights=x, minlength=9)[which] for x in (w, -w)),
                    strict=True):
        assert np.array_equal(a.view(np.int64), b.view(np.int64))  # same bits


def test_negative_zeros_sum_to_positive_zero_as_bincount() -> None:
    labels = np.array([1, 1, 2, 2], dtype=np.int64)
    w = np.array([-0.0, -0.0, -0.0, 1.5])
    got = point_sums(labels, (w,), np.array([1, 2]), np.array([2, 2]), 3)[0]
    ref = np.bincount(labels, weights=w, minlength=3)[[1, 2]]
    assert np.array_equal(got.view(np.int64), ref.view(np.int64))
    assert not np.signbit(got[0])


@pytest.mark.parametrize("seed", range(6))
def test_small_steps_closer_are_never_missed(seed: int) -> None:
    # the same points seen while the robot creeps towards them by 4 mm a frame: every
    # frame is a little closer, far less than the voxel-mean bound's slack
    rng = np.random.default_rng(50 + seed)
    n_lab = 4
    labels = np.repeat(np.arange(1, n_lab), 200).astype(np.int64)
    # each point just above its voxel's lower corner: the voxel centres are 2.4 cm
    # further away on each axis than the points, the bound's worst case
    cells = rng.integers(20, 60, size=(labels.size, 2))
    xy = cells * RES + 0.0005
    wx, wy = np.ascontiguousarray(xy[:, 0]), np.ascontiguousarray(xy[:, 1])
    pts = np.bincount(labels, minlength=n_lab).astype(np.int64)
    fast, plain = LabelStats(), LabelStats()
    for i in range(30):
        vp = (-2.0 + 0.004 * i, -1.0 + 0.003 * i)
        update_frame(fast, pts, lambda: _voxel_means(labels, wx, wy, n_lab), labels, wx, wy,
                     n_lab, vp, i, 30, RES)
        _plain(plain, pts, labels, wx, wy, n_lab, vp, i, 30)
        np.testing.assert_array_equal(fast.view_dist, plain.view_dist)
        np.testing.assert_array_equal(fast.view_xy, plain.view_xy)
    assert plain.view_xy[1, 0] == pytest.approx(-2.0 + 0.004 * 29)  # the last was closest
