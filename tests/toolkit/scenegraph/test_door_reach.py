"""A door's evidence is the voxels it wins near their median: a blob a swapped label left
elsewhere in the house is dropped; a door wins a voxel by points and by frames, and only
where enough frames gave it the door's label."""

from __future__ import annotations

import numpy as np

from sgtool.mapping.voxels import VoxelConfig, VoxelMap
from sgtool.scenegraph.builder import DOOR_MIN_FRAMES
from sgtool.scenegraph.door_voxels import DoorVoxels, near_median


def test_a_far_blob_of_a_few_frames_is_dropped() -> None:
    panel = np.stack([np.full(40, 10), np.arange(40), np.zeros(40)], axis=1)  # 2 m panel
    blob = np.stack([np.full(15, 90), np.arange(15), np.zeros(15)], axis=1)  # 4 m away
    ijk = np.concatenate([panel, blob]).astype(np.int64)
    kept = near_median(ijk, 30.0)
    assert np.array_equal(kept, panel)


def test_a_door_alone_is_kept_whole() -> None:
    # an opened door: the panel swung 90 degrees and the opening under the lintel
    panel = np.stack([np.full(18, 0), np.arange(18), np.full(18, 10)], axis=1)
    opening = np.stack([np.arange(18), np.zeros(18), np.full(18, 44)], axis=1)
    ijk = np.concatenate([panel, opening]).astype(np.int64)
    assert near_median(ijk, 30.0) is ijk
    empty = np.zeros((0, 3), np.int64)
    assert near_median(empty, 30.0) is empty


def _points(n: int, x: float, y: float = 0.02, z: float = 0.52) -> np.ndarray:
    """``n`` world points inside the 5 cm voxel holding (x, y, z)."""
    return np.tile([[x, y, z]], (n, 1)) + np.linspace(0.0, 0.01, n)[:, None]


def _door_map(door_frames: int) -> VoxelMap:
    """A door (id 7) seen in ``door_frames`` frames: five voxels of its panel at x = 1.0 m
    (voxel column 20), and one more voxel above the first that only the last of those
    frames saw (depth noise). Then one frame swapped a sofa (id 8) at x = 2.0-2.15 m to the
    door's id, seen from close (40 points a voxel): the sofa's own three far frames put 3
    points in two of those voxels (the door still wins them by points), the third voxel
    only the swapped frame saw."""
    vm = VoxelMap(VoxelConfig(flush_keys=10**9))
    door, sofa = (int(v) for v in vm.labels_of(np.array([7, 8])))
    for i in range(door_frames):
        pts = np.concatenate([_points(5, 1.02, 0.02 + 0.05 * k) for k in range(5)])
        if i == door_frames - 1:
            pts = np.concatenate([pts, _points(5, 1.02, 0.02, 0.57)])
        vm.integrate_points(pts, np.full(len(pts), door), (0.0, 0.0), i)
    swapped = np.concatenate([_points(40, x) for x in (2.02, 2.07, 2.12)])
    vm.integrate_points(swapped, np.full(len(swapped), door), (0.0, 0.0), 10)
    for i in range(11, 14):
        far = np.concatenate([_points(3, x) for x in (2.02, 2.07)])
        vm.integrate_points(far, np.full(len(far), sofa), (0.0, 0.0), i)
    return vm


def _won(vm: VoxelMap, with_frames: bool) -> list[tuple[int, int, int]]:
    dv = DoorVoxels()
    dv.reset(vm.entries()[0], vm.label_ids(), [7])
    args = (vm.frame_counts, DOOR_MIN_FRAMES) if with_frames else ()
    return sorted(map(tuple, dv.won([7], vm.winning_labels, *args)[7].tolist()))


def test_a_door_column_needs_a_voxel_several_frames_gave_it() -> None:
    vm = _door_map(door_frames=4)
    panel = [(20, k, 10) for k in range(5)] + [(20, 0, 11)]
    # by points alone the door also wins the sofa's voxels the swapped frame saw up close
    assert _won(vm, with_frames=False) == sorted(panel + [(40, 0, 10), (41, 0, 10),
                                                          (42, 0, 10)])
    # their columns hold door voxels one frame each gave; the voxel above the panel that
    # one frame gave stays: its column holds voxels four frames gave
    assert _won(vm, with_frames=True) == sorted(panel)


def test_a_door_seen_in_one_frame_keeps_its_voxels() -> None:
    vm = _door_map(door_frames=1)  # most of the door's voxels: one frame each
    assert _won(vm, with_frames=True) == _won(vm, with_frames=False)
