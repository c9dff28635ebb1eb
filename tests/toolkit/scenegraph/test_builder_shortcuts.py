"""Shortcuts of the builder's orchestration equal the plain computation: after a container
(not a door) changed state, the door voxels are kept and extended with the new keys rather
than rebuilt from every key, and still equal the voxel map's scan; a refresh after any
state change equals a from-scratch refresh."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from support.synthetic_world import look_around, make_frame, two_room_house, walk, world_of_house

from sgtool.log.frame import CameraIntrinsics
from sgtool.mapping.voxels import VoxelConfig
from sgtool.scenegraph.builder import BuilderConfig, SceneGraphBuilder
from sgtool.scenegraph.door_voxels import DoorVoxels


def as_set(ijk: np.ndarray) -> set[tuple[int, int, int]]:
    return {tuple(int(v) for v in row) for row in ijk}


@pytest.mark.parametrize("changed", ["refrigerator", "countertop", "door"])
def test_door_voxels_after_a_state_change_equal_the_scan(
        changed: str, monkeypatch: pytest.MonkeyPatch) -> None:
    hw = world_of_house(two_room_house("open"))
    k = CameraIntrinsics.from_fov(80, 60, 60)
    poses = look_around(2.0, 1.5, 0.0, 8) + walk([(2.0, 1.5), (6.0, 1.5)], 0.5)
    b = SceneGraphBuilder(hw.instances, None,
                          BuilderConfig(voxels=VoxelConfig(min_points=5), refresh_every=3))
    resets = []
    plain_reset = DoorVoxels.reset
    monkeypatch.setattr(DoorVoxels, "reset",
                        lambda self, *a: (resets.append(1), plain_reset(self, *a))[1])
    doors = [i for i, v in hw.instances.items() if v.kind == "door"]
    target = next(i for i, v in hw.instances.items() if v.category == changed)
    half = len(poses) // 2
    for i, (x, y, yaw) in enumerate(poses):
        if i == half:  # the instance changes state: its voxels are dropped
            info = hw.instances[target]
            state = "closed" if info.state == "open" else "open"
            table = dict(hw.instances)
            table[target] = dataclasses.replace(info, state=state)
            assert b.set_instances(table) == [target]
            resets.clear()
        b.integrate(make_frame(hw.world, x, y, yaw, k, index=i, pitch=0.3))
        if b.due():
            graph = b.refresh(i)
            kept, scan = b._door_voxels.of(doors), b.voxels.voxels_of(doors)
            assert kept.keys() == scan.keys()
            for d in doors:
                assert as_set(kept[d]) == as_set(scan[d]) and len(kept[d]) == len(scan[d])
    assert b.voxels.removals == 1  # the change dropped voxels
    # a door's voxels gone: rebuilt from every key; a container's: kept
    assert (len(resets) > 0) == (changed == "door")
    graph = b.refresh(len(poses))
    assert b.refresh(len(poses), from_scratch=True) == graph
