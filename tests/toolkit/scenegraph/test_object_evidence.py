"""An object needs enough evidence before it exists and loses it when contradicted: a
label one frame gave makes no object, an object seen in many frames survives a few frames
that gave its pixels another id, an object whose voxels are seen empty disappears."""

from __future__ import annotations

import numpy as np
from support.synthetic_world import camera_pose

from sgtool.log.frame import CameraIntrinsics, Frame
from sgtool.mapping.free_space import FreeSpaceConfig, View
from sgtool.mapping.voxel_keys import VOXEL_SHIFT, pack
from sgtool.mapping.voxels import VoxelMap, unpack
from sgtool.scenegraph.instances import InstanceInfo
from sgtool.scenegraph.object_evidence import EvidenceRule, is_object, won_voxels
from sgtool.scenegraph.object_placement import seen_instances

K = CameraIntrinsics.from_fov(40, 30, 60)
POSE = camera_pose(0.0, 0.0, 0.0, height=1.0)  # at the origin, 1 m high, facing +x
WALL, CUP, BOWL = 5, 7, 9
INSTANCES = {i: InstanceInfo(i, c, kind=k) for i, c, k in
             ((WALL, "wall", "structure"), (CUP, "cup", "object"), (BOWL, "bowl", "object"))}
RULE = EvidenceRule(min_frames=2, min_voxels=1)


def frame(index: int, label: int) -> Frame:
    """A wall 3 m ahead; the centre pixel (one point) sees a thing 1.5 m ahead, id
    ``label``."""
    depth = np.full((K.height, K.width), 3.0, dtype=np.float32)
    ids = np.full((K.height, K.width), WALL, dtype=np.int32)
    depth[K.height // 2, K.width // 2] = 1.5
    ids[K.height // 2, K.width // 2] = label
    return Frame(index, index, None, depth, ids, POSE, K)


def objects(vm: VoxelMap, rule: EvidenceRule | None = RULE) -> list[int]:
    return [info.id for info, _, _ in seen_instances(vm, INSTANCES, ("object",), 1, rule)]


def test_won_voxels_count_the_winners_and_their_centroid() -> None:
    """Voxels (0,0,0) and (2,2,0) won by label 1, (4,0,0) by label 2, (6,0,0) by a label
    past ``n_labels`` (not counted)."""
    vk = pack(np.array([0, 2, 4, 6]), np.array([0, 2, 0, 0]), np.zeros(4, np.int64), 0)
    won = won_voxels(vk >> VOXEL_SHIFT, np.array([1, 1, 2, 5]), 3)
    assert won.count.tolist() == [0, 2, 1]
    assert np.allclose(won.centroid(1, 0.1), (0.15, 0.15, 0.05))  # centres 0.05 and 0.25
    assert np.allclose(won.centroid(2, 0.1), (0.45, 0.05, 0.05))
    assert won.centroid(0, 0.1) is None and won.centroid(5, 0.1) is None
    assert is_object(2, 1, RULE) and not is_object(1, 5, RULE) and not is_object(9, 0, RULE)


def test_a_label_in_one_frame_makes_no_object() -> None:
    vm = VoxelMap()
    for i in range(6):
        vm.integrate(frame(i, BOWL if i == 3 else CUP))  # one frame calls the cup a bowl
    assert objects(vm, None) == [CUP, BOWL]  # one frame with points was enough before
    assert objects(vm) == [CUP]


def test_an_object_seen_in_many_frames_survives_a_few_contradicting_ones() -> None:
    vm = VoxelMap()
    for i in range(10):
        vm.integrate(frame(i, BOWL if i in (2, 5, 8) else CUP))  # three frames swap
    # both have two frames or more; the cup wins the voxel 7 votes to 3: only it stands,
    # at that voxel's centre
    assert objects(vm) == [CUP]
    got = seen_instances(vm, INSTANCES, ("object",), 1, RULE)[0][1]
    keys, _ = vm.entries()
    ix, iy, iz, _ = unpack(keys[(keys & 0xFFF) == int(vm.labels_of(np.array([CUP]))[0])])
    assert len(ix) == 1
    assert np.allclose(got, ((ix[0] + 0.5) * 0.05, (iy[0] + 0.5) * 0.05, (iz[0] + 0.5) * 0.05))


def test_an_object_whose_voxels_are_seen_empty_disappears() -> None:
    vm = VoxelMap()
    vm.integrate(frame(0, CUP))
    vm.integrate(frame(1, CUP))  # two votes
    assert objects(vm) == [CUP]
    _, _, iz, _ = unpack(vm.entries()[0])
    band = (int(iz.min()), int(iz.max()))
    empty = View.of(POSE, K, np.full((K.height, K.width), 3.0, dtype=np.float32), 0.1)
    cfg = FreeSpaceConfig(weak_votes=4)
    vm.clear_seen_through([empty], *band, config=cfg)  # one miss of two: it stays
    assert objects(vm) == [CUP]
    vm.clear_seen_through([empty], *band, config=cfg)  # two misses: its voxel goes
    assert objects(vm) == []
