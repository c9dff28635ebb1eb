"""A door's evidence is the voxels it wins near their median: a blob a swapped label left
elsewhere in the house is dropped."""

from __future__ import annotations

import numpy as np

from sgtool.scenegraph.door_voxels import near_median


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
