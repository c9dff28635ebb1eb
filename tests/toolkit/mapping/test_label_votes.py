"""Labels are votes over frames (issue 35): forgetting an instance takes the voxels it
wins with every label's votes in them; the robot's body drops the voxels that never had an
instance's label; the winners looked up in a few voxels equal the full scan. Each rule is
checked against a brute-force computation over every entry, on randomised maps."""

from __future__ import annotations

import numpy as np
import pytest

from sgtool.mapping.voxels import (
    AXIS_MASK,
    LABEL_MASK,
    OFFSET,
    SHIFT_Z,
    VOXEL_SHIFT,
    VoxelConfig,
    VoxelMap,
    unpack,
)

RES = 0.05


def noisy_map(seed: int) -> VoxelMap:
    """A map of a few instances voting in overlapping boxes over several frames, some of
    whose points carry label 0 or another instance's id (dropped or swapped labels)."""
    rng = np.random.default_rng(seed)
    vm = VoxelMap(VoxelConfig(resolution=RES, flush_keys=int(rng.integers(50, 5000))))
    ids = np.array([0, 11, 12, 13, 14])
    vm.labels_of(ids[1:])
    for f in range(int(rng.integers(3, 12))):
        parts = []
        for lab in range(1, len(ids)):
            c = rng.uniform(-0.4, 0.4, 3) + np.array([0.0, 0.0, 0.6])
            pts = c + rng.uniform(-0.15, 0.15, (int(rng.integers(20, 200)), 3))
            lab_of = np.full(len(pts), lab)
            flip = rng.random(len(pts)) < rng.uniform(0.0, 0.5)
            lab_of[flip] = rng.integers(0, len(ids), int(flip.sum()))
            parts.append((pts, lab_of))
        xyz = np.concatenate([p[0] for p in parts])
        labs = np.concatenate([p[1] for p in parts])
        vm.integrate_points(xyz, labs, (0.0, 0.0), f)
    return vm


def winners_by_scan(keys: np.ndarray, counts: np.ndarray) -> dict[int, int]:
    """Voxel key -> winning label, one voxel at a time (most votes, then lower label)."""
    best: dict[int, tuple[int, int]] = {}
    for k, c in zip(keys.tolist(), counts.tolist(), strict=True):
        v, lab = k >> VOXEL_SHIFT, k & LABEL_MASK
        if v not in best or c > best[v][0]:
            best[v] = (c, lab)
    return {v: lab for v, (_, lab) in best.items()}


@pytest.mark.parametrize("seed", range(12))
def test_forget_takes_the_voxels_the_instance_wins_with_every_vote(seed: int) -> None:
    vm = noisy_map(seed)
    keys, counts = (a.copy() for a in vm.entries())
    win = winners_by_scan(keys, counts)
    target = 11 + seed % 4
    lab = int(vm.labels_of(np.array([target]))[0])
    gone = np.array([(k & LABEL_MASK) == lab or win[k >> VOXEL_SHIFT] == lab
                     for k in keys.tolist()], dtype=bool)
    removed = vm.forget_instance(target)
    assert removed == int(gone.sum())
    left_k, left_c = vm.entries()
    np.testing.assert_array_equal(left_k, keys[~gone])
    np.testing.assert_array_equal(left_c, counts[~gone])
    # every other instance's statistics equal those of its remaining entries
    for other in (11, 12, 13, 14):
        ol = int(vm.labels_of(np.array([other]))[0])
        obs = vm.observation(other)
        assert obs is not None
        mine = left_k[(left_k & LABEL_MASK) == ol]
        assert obs.voxels == (0 if other == target else len(mine))
        if other != target and len(mine):
            ix, iy, iz, _ = unpack(mine)
            want = (np.array([ix.mean(), iy.mean(), iz.mean()]) + 0.5) * RES
            assert obs.centroid == pytest.approx(tuple(want), abs=1e-9)
    # the map's winners after the removal are those of a scan of what is left
    ijk, wl, _ = vm.voxels()
    left_win = winners_by_scan(left_k, left_c)
    assert sorted(left_win.items()) == sorted(
        zip(np.unique(left_k >> VOXEL_SHIFT).tolist(), wl.tolist(), strict=True))
    assert len(ijk) == len(left_win)


@pytest.mark.parametrize("seed", range(12))
def test_winning_labels_of_a_few_voxels_equal_the_full_scan(seed: int) -> None:
    vm = noisy_map(seed)
    rng = np.random.default_rng(100 + seed)
    ijk, wl, _ = vm.voxels()
    keys, _ = vm.entries()
    vk = np.unique(keys >> VOXEL_SHIFT)
    pick = np.sort(rng.choice(len(vk), size=min(len(vk), int(rng.integers(1, 60))),
                              replace=False))
    vm.integrate_points(np.zeros((0, 3)), np.zeros(0, np.int64), (0.0, 0.0))
    np.testing.assert_array_equal(vm.winning_labels(vk[pick]), wl[pick])
    with pytest.raises(ValueError):
        vm.winning_labels(np.array([vk.max() + 1]))


@pytest.mark.parametrize("seed", range(12))
def test_body_drops_unlabelled_only_voxels_near_its_points(seed: int) -> None:
    rng = np.random.default_rng(200 + seed)
    vm = noisy_map(seed)
    # unlabelled points still pending (not flushed) are looked up too
    vm.integrate_points(rng.uniform(-0.6, 0.6, (300, 3)) + [0, 0, 0.6], np.zeros(300, np.int64),
                        (0.0, 0.0))
    keys, counts = (a.copy() for a in vm.entries())
    pts = rng.uniform(-0.5, 0.5, (int(rng.integers(1, 5)), 2))
    radius, zlo, zhi = 0.2, 5, 20
    vk = keys >> VOXEL_SHIFT
    alone = np.array([int((vk == v).sum()) == 1 for v in vk.tolist()])
    ix, iy, iz, lab = unpack(keys)
    cx, cy = (ix + 0.5) * RES, (iy + 0.5) * RES
    near = np.zeros(len(keys), dtype=bool)
    for px, py in pts.tolist():
        near |= (cx - px) ** 2 + (cy - py) ** 2 <= radius * radius
    gone = near & alone & (lab == 0) & (iz >= zlo) & (iz <= zhi)
    removals = vm.removals
    assert vm.clear_unlabelled_around(pts, radius, zlo, zhi) == int(gone.sum())
    left_k, left_c = vm.entries()
    np.testing.assert_array_equal(left_k, keys[~gone])
    np.testing.assert_array_equal(left_c, counts[~gone])
    assert vm.removals == removals + int(gone.any())
    np.testing.assert_array_equal(np.sort(vm.drain_removed_keys()), keys[gone])
    lo, hist = vm.level_histogram()  # the height histogram follows the removal
    want = np.bincount(((left_k >> SHIFT_Z) & AXIS_MASK) - OFFSET - lo, minlength=len(hist))
    np.testing.assert_array_equal(hist, want[:len(hist)])


def test_body_clears_an_unlabelled_phantom_but_not_a_labelled_wall() -> None:
    vm = VoxelMap(VoxelConfig(resolution=RES))
    lab = int(vm.labels_of(np.array([7]))[0])
    grid = np.stack(np.meshgrid(np.arange(-0.1, 0.1, 0.02), np.arange(-0.1, 0.1, 0.02),
                                np.arange(0.2, 1.4, 0.02)), -1).reshape(-1, 3)
    vm.integrate_points(grid, np.zeros(len(grid), np.int64), (0.0, 0.0))  # a phantom
    vm.integrate_points(grid + [2.0, 0, 0], np.full(len(grid), lab), (0.0, 0.0))  # a wall
    n0 = len(vm)
    got = vm.clear_unlabelled_around(np.array([[0.0, 0.0], [2.0, 0.0]]), 0.2, 3, 32)
    assert got > 0 and len(vm) == n0 - got
    _, wl, _ = vm.voxels()
    assert set(wl.tolist()) == {lab}  # the labelled wall stays whole
    assert vm.clear_unlabelled_around(np.array([[0.0, 0.0]]), 0.2, 3, 32) == 0
