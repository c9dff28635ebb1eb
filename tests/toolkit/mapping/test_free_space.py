"""Projective free-space evidence: a weak voxel that later views see through is dropped."""

from __future__ import annotations

import numpy as np
import pytest
from support.free_space_reference import near_depth
from support.synthetic_world import camera_pose

from sgtool.log.frame import CameraIntrinsics, Frame
from sgtool.mapping.free_space import RADII, FreeSpaceConfig, View, seen_through
from sgtool.mapping.voxels import VoxelMap, unpack

K = CameraIntrinsics.from_fov(40, 30, 60)
POSE = camera_pose(0.0, 0.0, 0.0, height=1.0)  # at the origin, 1 m high, facing +x


def view_of(distance: float) -> View:
    depth = np.full((K.height, K.width), distance, dtype=np.float32)
    return View.of(POSE, K, depth, 0.1)


def test_near_depth_takes_the_nearest_neighbour_and_holes_spread() -> None:
    d = np.full((5, 6), 4.0, dtype=np.float32)
    d[2, 2] = 1.0  # a thin thing
    d[0, 5] = 0.0  # a hole
    assert RADII[0] == 1
    got = View.of(POSE, K, d, 0.1).levels[0]
    assert (got[1:4, 1:4] == 1.0).all()  # the thin thing's pixel and its neighbours
    assert got[0, 4] == 0.0 and got[1, 5] == 0.0  # next to the hole: no evidence
    assert got[4, 0] == 4.0


@pytest.mark.parametrize("seed", range(6))
def test_view_levels_are_the_near_depth_at_every_radius(seed: int) -> None:
    rng = np.random.default_rng(seed)
    h, w = int(rng.integers(1, 40)), int(rng.integers(1, 40))
    d = rng.uniform(0.0, 6.0, (h, w)).astype(np.float32)  # below 0.3 m: invalid
    d[rng.random((h, w)) < 0.02] = np.nan
    d[rng.random((h, w)) < 0.02] = np.inf
    levels = View.of(POSE, K, d, 0.3).levels
    assert levels.shape == (len(RADII), h, w) and levels.dtype == np.float32
    for level, radius in zip(levels, RADII, strict=True):
        assert np.array_equal(level, near_depth(d, 0.3, radius))


def test_a_point_in_front_of_the_seen_surface_is_seen_through() -> None:
    v = view_of(3.0)  # a wall 3 m ahead
    pts = np.array([[1.0, 0.0, 1.0],  # 2 m in front of the wall: seen through
                    [2.9, 0.0, 1.0],  # within the margin: not
                    [3.5, 0.0, 1.0],  # behind the wall: not
                    [-1.0, 0.0, 1.0],  # behind the camera: not
                    [1.0, 5.0, 1.0]])  # outside the image: not
    assert seen_through(pts, v, 0.15, 0.1, 5.0, 0.05).tolist() == [True, False, False,
                                                                   False, False]
    holes = View.of(POSE, K, np.zeros((K.height, K.width), dtype=np.float32), 0.1)
    assert not seen_through(pts, holes, 0.15, 0.1, 5.0, 0.05).any()  # no depth: none


def test_a_thin_thing_inside_the_voxel_image_keeps_it() -> None:
    """A ray grazing a thin thing 2 pixels beside the voxel centre's pixel: the voxel is
    not seen through (its image covers that pixel); 12 pixels away it is."""
    depth = np.full((K.height, K.width), 3.0, dtype=np.float32)
    r, c = K.height // 2, K.width // 2
    pt = np.array([[1.0, 0.0, 1.0]])  # projects to (r, c); 1 m away: a 2-3 pixel voxel
    depth[r, c + 2] = 1.0
    assert not seen_through(pt, View.of(POSE, K, depth, 0.1), 0.15, 0.1, 5.0, 0.05)[0]
    depth[r, c + 2] = 3.0
    depth[r, c + 12] = 1.0
    assert seen_through(pt, View.of(POSE, K, depth, 0.1), 0.15, 0.1, 5.0, 0.05)[0]


def stray_frame(index: int) -> Frame:
    """One pixel of depth noise 1.5 m ahead, the rest on a wall 3 m ahead."""
    depth = np.full((K.height, K.width), 3.0, dtype=np.float32)
    depth[K.height // 2, K.width // 2] = 1.5
    return Frame(index, index, None, depth, None, POSE, K)


def test_a_stray_voxel_goes_after_as_many_misses_as_votes_and_the_wall_stays() -> None:
    vm = VoxelMap()
    vm.integrate(stray_frame(0))
    ix, _, iz, _ = unpack(vm.entries()[0])
    assert (ix == 30).sum() == 1  # the stray voxel, x = 1.5 m
    band = (int(iz.min()), int(iz.max()))
    walls = int((ix == 60).sum())
    cfg = FreeSpaceConfig(margin=0.15, weak_votes=4)
    assert vm.clear_seen_through([], *band, config=cfg) == 0  # watched, no view yet
    removals = vm.removals
    assert vm.clear_seen_through([view_of(3.0)], *band, config=cfg) == 1  # 1 vote, 1 miss
    ix, _, _, _ = unpack(vm.entries()[0])
    assert (ix == 30).sum() == 0 and int((ix == 60).sum()) == walls
    assert vm.removals == removals + 1 and len(vm.drain_removed_keys()) == 1


def test_a_voxel_with_more_votes_than_weak_is_kept() -> None:
    vm = VoxelMap()
    for i in range(5):  # the same stray point in 5 frames: 5 votes
        vm.integrate(stray_frame(i))
    _, _, iz, _ = unpack(vm.entries()[0])
    band = (int(iz.min()), int(iz.max()))
    views = [view_of(3.0)] * 10
    assert vm.clear_seen_through(views, *band, config=FreeSpaceConfig(weak_votes=4)) == 0
    vm2 = VoxelMap()
    for i in range(3):  # 3 votes: 3 misses clear it, 2 do not
        vm2.integrate(stray_frame(i))
    cfg = FreeSpaceConfig(weak_votes=4)
    assert vm2.clear_seen_through([view_of(3.0)] * 2, *band, config=cfg) == 0
    assert vm2.clear_seen_through([view_of(3.0)], *band, config=cfg) == 1


def test_voxels_outside_the_band_are_not_watched() -> None:
    vm = VoxelMap()
    vm.integrate(stray_frame(0))
    _, _, iz, _ = unpack(vm.entries()[0])
    below = (int(iz.min()) - 10, int(iz.min()) - 1)
    assert vm.clear_seen_through([view_of(3.0)], *below) == 0
