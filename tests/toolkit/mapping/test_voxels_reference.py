"""The integration (issue 20: one sort per frame, point counts from the distinct keys,
contiguous coordinates) against the plain reference it replaced, on the frames of a
recorded golden log: the same (voxel, label) keys with the same votes, the same
per-instance statistics, hence the same occupancy."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from sgtool.log import LogReader
from sgtool.mapping.mixed_pixels import mixed_pixels
from sgtool.mapping.voxels import OFFSET, VoxelConfig, VoxelMap, pack

GOLDEN = Path(__file__).resolve().parents[2] / "golden" / "house6-tour.mcap"


def reference(frames: list, cfg: VoxelConfig) -> tuple[dict[int, int], dict[int, int]]:
    """Votes per packed key and points per instance id, computed the obvious way."""
    votes: dict[int, int] = {}
    points: dict[int, int] = {}
    labels: dict[int, int] = {0: 0}
    for fr in frames:
        h, w = fr.depth.shape
        v, u = np.mgrid[0:h, 0:w]
        z = fr.depth.astype(np.float64).ravel()
        ok = (z >= cfg.min_range) & (z < cfg.max_range) & ~mixed_pixels(fr.depth).ravel()
        k = fr.intrinsics
        xc = (u.ravel()[ok] - k.cx) / k.fx * z[ok]
        yc = (v.ravel()[ok] - k.cy) / k.fy * z[ok]
        cam = np.stack([xc, yc, z[ok], np.ones(ok.sum())])
        world = fr.pose @ cam
        ids = fr.ids.ravel()[ok]
        for i in np.unique(ids).tolist():  # label indices in order of first appearance
            labels.setdefault(int(i), len(labels))
        lab = np.asarray([labels[int(i)] for i in ids.tolist()], dtype=np.int64)
        vox = np.floor(world[:3] / cfg.resolution).astype(np.int64)
        assert (np.abs(vox) < OFFSET - 1).all()
        keys, counts = np.unique(pack(vox[0], vox[1], vox[2], lab), return_counts=True)
        for key, c in zip(keys.tolist(), counts.tolist(), strict=True):
            votes[key] = votes.get(key, 0) + c
        for i, c in zip(*np.unique(ids, return_counts=True), strict=True):
            points[int(i)] = points.get(int(i), 0) + int(c)
    return votes, points


def test_integration_equals_the_plain_reference_on_a_recorded_log():
    with LogReader(GOLDEN) as r:
        frames = [f for _, f in zip(range(40), r.frames(), strict=False)]
    cfg = VoxelConfig()
    vm = VoxelMap(cfg)
    for f in frames:
        vm.integrate(f)
    keys, counts = vm.entries()
    votes, points = reference(frames, cfg)
    assert len(keys) > 1000
    assert dict(zip(keys.tolist(), counts.tolist(), strict=True)) == votes
    for iid, n in points.items():
        if iid == 0:
            continue
        obs = vm.observation(iid)
        assert obs is not None and obs.total_points == n
