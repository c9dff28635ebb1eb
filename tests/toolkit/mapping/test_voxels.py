"""Sparse semantic voxel map: packing, back-projection geometry, votes, observations."""

from __future__ import annotations

import math

import numpy as np
import pytest
from support.synthetic_world import Box, BoxWorld, camera_pose, make_frame

from sgtool.log.frame import CameraIntrinsics, Frame
from sgtool.mapping.voxels import VoxelConfig, VoxelMap, pack, unpack

K = CameraIntrinsics.from_fov(40, 30, 60)


def wall_frame(distance: float, ids: int | None = 7, index: int = 0,
               depth_value: float | None = None) -> Frame:
    """A camera at the origin (height 1 m) facing +x, every pixel on a plane x = distance
    (depth along the optical axis is the same for every pixel)."""
    pose = camera_pose(0.0, 0.0, 0.0, height=1.0)
    depth = np.full((K.height, K.width), distance if depth_value is None else depth_value,
                    dtype=np.float32)
    id_img = None if ids is None else np.full((K.height, K.width), ids, dtype=np.int32)
    return Frame(index, index, None, depth, id_img, pose, K)


def test_pack_roundtrip_with_negative_indices() -> None:
    ix = np.array([-65000, -1, 0, 5, 65000])
    iy = np.array([3, -7, 0, -65000, 12])
    iz = np.array([0, -2, 1, 100, -40])
    lab = np.array([0, 1, 4094, 17, 4095])
    keys = pack(ix, iy, iz, lab)
    assert (keys >= 0).all()
    got = unpack(keys)
    for a, b in zip(got, (ix, iy, iz, lab), strict=True):
        np.testing.assert_array_equal(a, b)
    # sorting keys sorts columns (x, y) first, then height
    order = np.argsort(keys)
    cols = [(int(ix[i]), int(iy[i])) for i in order]
    assert cols == sorted(cols)


def test_wall_points_land_in_one_voxel_layer() -> None:
    vm = VoxelMap(VoxelConfig(resolution=0.05))
    n = vm.integrate(wall_frame(2.0))
    assert n == K.width * K.height
    ijk, lab, total = vm.voxels()
    # every point has world x = 2.0 (depth along the optical axis is x here): index 40
    assert set(ijk[:, 0].tolist()) == {40}
    assert int(total.sum()) == n
    assert set(vm.label_ids()[lab].tolist()) == {7}
    # the vertical extent follows the field of view: z = 1 +- 2 tan(30 deg)
    half = 2.0 * math.tan(math.radians(30))
    assert ijk[:, 2].min() * 0.05 == pytest.approx(1.0 - half, abs=0.06)
    assert (ijk[:, 2].max() + 1) * 0.05 == pytest.approx(1.0 + half, abs=0.06)


def test_range_limits_and_invalid_depth() -> None:
    vm = VoxelMap(VoxelConfig(min_range=0.5, max_range=3.0))
    assert vm.integrate(wall_frame(4.0)) == 0  # beyond max_range
    assert vm.integrate(wall_frame(0.3)) == 0  # closer than min_range
    f = wall_frame(2.0)
    f.depth[0, :] = np.nan
    f.depth[1, :] = 0.0
    assert vm.integrate(f) == K.width * (K.height - 2)


def test_label_votes_majority_and_ties() -> None:
    vm = VoxelMap()
    vm.integrate(wall_frame(2.0, ids=5, index=0))
    vm.integrate(wall_frame(2.0, ids=9, index=1))
    _, lab, _ = vm.voxels()
    assert set(vm.label_ids()[lab].tolist()) == {5}  # tie: the lower label (seen first)
    vm.integrate(wall_frame(2.0, ids=9, index=2))
    _, lab, _ = vm.voxels()
    assert set(vm.label_ids()[lab].tolist()) == {9}  # majority


def test_observation_keeps_closest_viewpoint_and_point_counts() -> None:
    world = BoxWorld((Box((3.0, 0.0, 0.5), (0.4, 0.4, 1.0), 3),), floor_instance=1)
    vm = VoxelMap(VoxelConfig(min_points=5))
    far = make_frame(world, 0.0, 0.0, 0.0, K, index=0, height=0.8)
    near = make_frame(world, 1.5, 0.0, 0.0, K, index=1, height=0.8)
    vm.integrate(far)
    vm.integrate(near)
    vm.integrate(far)
    obs = vm.observation(3)
    assert obs is not None
    assert obs.frames == 3
    assert obs.viewpoint == pytest.approx((1.5, 0.0))
    assert obs.max_points == int((near.ids == 3).sum()) > int((far.ids == 3).sum())
    assert obs.total_points == int((near.ids == 3).sum() + 2 * (far.ids == 3).sum())
    # the centroid of its voxels lies on the box (front face seen: x ~ 2.8)
    assert obs.centroid is not None
    assert 2.75 <= obs.centroid[0] <= 3.2 and abs(obs.centroid[1]) < 0.2
    assert vm.observation(99) is None


def test_forget_instance_removes_its_votes_only() -> None:
    vm = VoxelMap()
    vm.integrate(wall_frame(2.0, ids=5))
    f = wall_frame(3.0, ids=6)
    vm.integrate(f)
    before = len(vm)
    removed = vm.forget_instance(5)
    assert removed > 0 and len(vm) == before - removed
    _, lab, _ = vm.voxels()
    assert set(vm.label_ids()[lab].tolist()) == {6}
    assert vm.observation(5).voxels == 0  # type: ignore[union-attr]
    assert vm.removals == 1


def test_merge_batching_does_not_change_the_map() -> None:
    world = BoxWorld((Box((2.5, 0.5, 0.5), (0.5, 2.0, 1.0), 2),
                      Box((3.5, -1.0, 1.0), (0.3, 0.3, 2.0), 3)), floor_instance=1)
    frames = [make_frame(world, 0.2 * i, 0.1 * i, 0.3 * i - 0.5, K, index=i) for i in range(8)]
    a, b = VoxelMap(VoxelConfig(flush_keys=1)), VoxelMap(VoxelConfig(flush_keys=10**9))
    for f in frames:
        a.integrate(f)
        b.integrate(f)
    ka, ca = a.entries()
    kb, cb = b.entries()
    np.testing.assert_array_equal(ka, kb)
    np.testing.assert_array_equal(ca, cb)
    assert a.observation(3) == b.observation(3)
    la, ha = a.level_histogram()
    lb, hb = b.level_histogram()
    assert la == lb and np.array_equal(ha, hb)
    # new keys drained once: every entry exactly once
    drained = np.sort(a.drain_new_keys())
    np.testing.assert_array_equal(drained, ka)
    assert a.drain_new_keys().size == 0


def test_frames_without_ids_build_geometry() -> None:
    vm = VoxelMap()
    vm.integrate(wall_frame(2.0, ids=None))
    ijk, lab, _ = vm.voxels()
    assert len(ijk) > 0 and set(lab.tolist()) == {0}
    assert vm.observed_instances() == []


def _points(n: int, x: float, y: float = 0.0, z: float = 0.5) -> np.ndarray:
    """``n`` world points inside the voxel holding (x, y, z) (5 cm voxels)."""
    return np.tile([[x, y, z]], (n, 1)) + np.linspace(0.0, 0.01, n)[:, None]


def test_frames_count_each_frame_once_per_entry() -> None:
    vm = VoxelMap(VoxelConfig(flush_keys=10**9))  # every frame pending until one flush
    door, sofa = (int(v) for v in vm.labels_of(np.array([7, 8])))
    vm.integrate_points(_points(40, 1.02), np.full(40, door), (0.0, 0.0), 0)  # one close frame
    for i in range(1, 4):  # three far frames, 3 points each
        vm.integrate_points(_points(3, 1.02), np.full(3, sofa), (0.0, 0.0), i)
    keys, counts = vm.entries()
    assert counts.tolist() == [40, 9]  # points: the door's one frame wins
    np.testing.assert_array_equal(vm.frame_counts(keys[::-1]), [3, 1])  # any order
    assert (keys & 4095).tolist() == [door, sofa]
    with pytest.raises(ValueError):
        vm.frame_counts(keys[-1:] + 1)  # a key not in the map (the next label)


def test_frame_counts_survive_batching_and_removal() -> None:
    world = BoxWorld((Box((2.5, 0.5, 0.5), (0.5, 2.0, 1.0), 2),
                      Box((3.5, -1.0, 1.0), (0.3, 0.3, 2.0), 3)), floor_instance=1)
    frames = [make_frame(world, 0.2 * i, 0.1 * i, 0.3 * i - 0.5, K, index=i) for i in range(8)]
    a, b = VoxelMap(VoxelConfig(flush_keys=1)), VoxelMap(VoxelConfig(flush_keys=10**9))
    for f in frames:
        a.integrate(f)
        b.integrate(f)
    ka, _ = a.entries()
    fa = a.frame_counts(ka)
    np.testing.assert_array_equal(fa, b.frame_counts(ka))
    assert fa.min() >= 1 and fa.max() <= len(frames)
    a.forget_instance(3)  # the frame counts of the entries left are unchanged
    kept, _ = a.entries()
    np.testing.assert_array_equal(a.frame_counts(kept), fa[np.isin(ka, kept)])
