"""Frames with nearly every pixel valid are integrated in place, without gathers
(``VoxelMap._integrate_dense``): the map must be bit for bit the one of the gather path."""

from __future__ import annotations

import numpy as np
import pytest
from support.synthetic_world import Box, BoxWorld, make_frame

import sgtool.mapping.voxels as vx
from sgtool.log.frame import CameraIntrinsics, Frame
from sgtool.mapping.mixed_pixels import mixed_pixels
from sgtool.mapping.voxels import VoxelConfig, VoxelMap

K = CameraIntrinsics.from_fov(48, 36, 70)


def _frames(seed: int) -> list[Frame]:
    """Frames of a walled box world, with a few invalid pixels of every kind (NaN, inf,
    0, too near, too far) that carry instance ids seen nowhere else."""
    rng = np.random.default_rng(seed)
    boxes = [Box((float(rng.uniform(1.5, 3.0)), float(rng.uniform(-1.5, 1.5)), 0.5),
                 (0.4, 0.4, 1.0), 10 + i) for i in range(4)]
    walls = [Box((4.0, 0.0, 1.5), (0.2, 8.0, 3.0), 5), Box((0.0, 4.0, 1.5), (8.0, 0.2, 3.0), 6),
             Box((0.0, -4.0, 1.5), (8.0, 0.2, 3.0), 7), Box((-4.0, 0.0, 1.5), (0.2, 8.0, 3.0), 8)]
    world = BoxWorld(tuple(boxes + walls), floor_instance=1)
    out = []
    for i in range(6):
        f = make_frame(world, float(rng.uniform(-1, 1)), float(rng.uniform(-1, 1)),
                       float(rng.uniform(-np.pi, np.pi)), K, index=i, pitch=0.2)
        depth = f.depth.copy()
        ids = f.ids.copy()
        n_bad = int(rng.integers(0, depth.size // 10))
        bad = rng.choice(depth.size, size=n_bad, replace=False)
        depth.reshape(-1)[bad] = rng.choice(
            np.array([np.nan, np.inf, 0.0, 0.05, 6.0, -1.0], dtype=np.float32), size=n_bad)
        ids.reshape(-1)[bad] = 900 + rng.integers(0, 50, size=n_bad)  # ids only there
        out.append(Frame(f.index, f.time_ns, None, depth, ids, f.pose, K, f.base_pose))
    return out


def _state(vm: VoxelMap) -> list[np.ndarray]:
    keys, counts = vm.entries()
    st = vm._stats
    return [keys, counts, vm.label_ids(), st.points_max, st.points_total, st.frames,
            st.last_index, st.view_dist, st.view_xy, st.vox_n, st.vox_sum]


@pytest.mark.parametrize("seed", range(8))
def test_dense_path_gives_the_same_map(seed: int, monkeypatch: pytest.MonkeyPatch) -> None:
    frames = _frames(seed)
    cfg = VoxelConfig(max_range=5.0, min_points=20)
    dense, gather = VoxelMap(cfg), VoxelMap(cfg)
    calls = {"dense": 0}
    real = VoxelMap._integrate_dense

    def counted(self: VoxelMap, *a: object) -> None:
        calls["dense"] += 1
        real(self, *a)  # type: ignore[arg-type]

    monkeypatch.setattr(VoxelMap, "_integrate_dense", counted)
    used_a = [dense.integrate(f) for f in frames]
    n_dense = calls["dense"]
    monkeypatch.setattr(vx, "DENSE_SHARE", 2.0)  # never: every frame through the gathers
    used_b = [gather.integrate(f) for f in frames]
    assert calls["dense"] == n_dense
    assert n_dense >= 1  # the test covers the dense path
    assert used_a == used_b
    # the points used: the valid pixels (no NaN, inf, too near or too far, not mixed)
    for f, n in zip(frames, used_a, strict=True):
        d = f.depth
        with np.errstate(invalid="ignore"):
            ok = (d >= cfg.min_range) & (d < cfg.max_range) & ~mixed_pixels(d)
        assert n == int(ok.sum())
    for a, b in zip(_state(dense), _state(gather), strict=True):
        np.testing.assert_array_equal(a, b)  # bit for bit; NaNs in the same places
    # ids seen only on invalid pixels got no label
    assert not set(dense.label_ids().tolist()) & set(range(900, 950))


def test_frame_without_ids_through_the_dense_path() -> None:
    world = BoxWorld((Box((2.5, 0.0, 0.5), (0.5, 2.0, 1.0), 2),), floor_instance=1)
    f = make_frame(world, 0.0, 0.0, 0.0, K, index=0, with_ids=False)
    vm = VoxelMap()
    n = vm.integrate(f)
    with np.errstate(invalid="ignore"):
        assert n == int(((f.depth >= 0.1) & (f.depth < 5.0)).sum()) > 0
    _, lab, total = vm.voxels()
    assert set(lab.tolist()) == {0} and int(total.sum()) == n
