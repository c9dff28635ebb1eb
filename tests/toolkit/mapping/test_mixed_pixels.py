"""Mixed ("flying") depth pixels: the pixels between two surfaces are found, every pixel of
a surface is kept (a plane at a grazing angle, an occlusion edge, a one-pixel strip),
and the voxel map leaves them out.

The depth images are rendered by hand: a floor seen from a camera 1.2 m up, a box in
front of a wall, so every pixel's true surface is known."""

from __future__ import annotations

import numpy as np

from sgtool.log.frame import CameraIntrinsics, Frame
from sgtool.mapping.mixed_pixels import mixed_pixels
from sgtool.mapping.voxels import VoxelConfig, VoxelMap
from sgtool.recorders.sim.noise import mixed_edges

H, W = 96, 128
K = CameraIntrinsics.from_fov(W, H, 70.0)


def _floor(pitch: float = 0.25, height: float = 1.2) -> np.ndarray:
    """Depth (z along the optical axis) of a level floor ``height`` below a camera looking
    down by ``pitch`` rad; rows above the horizon read 0 (no return)."""
    v = (np.arange(H, dtype=np.float64) - K.cy) / K.fy  # ray: (u, v, 1) in the camera
    down = v * np.cos(pitch) + np.sin(pitch)  # the ray's downward part per unit of z
    z = np.where(down > 1e-3, height / np.maximum(down, 1e-3), 0.0)
    return np.repeat(z[:, None], W, axis=1).astype(np.float32)


def _box_before_wall() -> np.ndarray:
    d = np.full((H, W), 4.0, np.float32)  # a wall 4 m away
    d[30:70, 40:90] = 2.0  # a box face 2 m away
    return d


def test_surfaces_have_no_mixed_pixels() -> None:
    # a floor at grazing angles (depth steps of more than 10 % between rows far away)
    floor = _floor()
    assert np.nanmax(np.abs(np.diff(1 / floor[floor > 0]))) > 0  # it slopes
    assert not mixed_pixels(floor).any()
    assert not mixed_pixels(_box_before_wall()).any()  # occlusion edges, each side a plane
    tilted = _box_before_wall() + np.linspace(0.0, 0.8, W, dtype=np.float32)[None, :]
    assert not mixed_pixels(tilted).any()


def test_pixels_between_the_two_sides_of_an_edge_are_mixed() -> None:
    d = _box_before_wall()
    d[30:70, 89] = np.resize([2.5, 3.0, 3.5], 40)  # a column of mixed pixels on the box's
    d[40:50, 39] = [2.3, 3.6, 2.9, 3.4, 2.5, 3.7, 2.7, 3.2, 2.4, 3.5]  # right edge, ten on
    m = mixed_pixels(d)  # its left: each its own mix
    assert m[30:70, 89].all() and m[40:50, 39].all()
    assert m.sum() == 50  # and nothing else
    same = _box_before_wall()
    same[30:70, 89] = 3.0  # mixed pixels of one depth down the edge read as a strip (M4),
    same[30:70, 39] = 1 / np.linspace(1 / 2.2, 1 / 3.8, 40)  # as do ones that run evenly
    assert not mixed_pixels(same).any()
    two = _box_before_wall()  # a run of two across the edge, in either order
    two[30:70:2, 90], two[30:70:2, 91] = 2.6, 3.4
    two[31:70:2, 90], two[31:70:2, 91] = 3.4, 2.6
    found = mixed_pixels(two)[32:68, 90:92]
    assert found.mean() > 0.9


def test_a_one_pixel_strip_between_two_surfaces_is_kept() -> None:
    """A thin thing seen across (a cloth on a shelf's edge) continues itself along its
    length; its depth is no mix of the surfaces above and below it."""
    d = np.full((H, W), 1.05, np.float32)  # a shelf's back, 1.05 m
    d[50:, :] = 0.45  # the shelf's front edge below, 0.45 m
    d[49, 20:60] = 0.95  # the cloth: one row, 40 pixels
    assert not mixed_pixels(d).any()


def test_a_side_face_seen_nearly_edge_on_is_kept() -> None:
    """A box's side face two pixels wide between its front face (2 m) and the wall behind
    (4 m): in the row the two pixels sit between the surfaces and continue neither
    (M1)-(M3); down the column each continues its surface, whose depth changes by 4 % a
    row (more than a level step of (M4)) evenly (inverse depth nearly affine)."""
    d = _box_before_wall()
    grow = 1.04 ** np.arange(13, dtype=np.float32)
    d[30:43, 90] = 1 / (0.30 * grow)  # 3.3 m, and nearer by 4 % a row
    d[30:43, 91] = 1 / (0.27 * grow)  # 3.7 m ...
    assert not mixed_pixels(d).any()


def test_pixels_without_depth_take_no_part() -> None:
    d = _box_before_wall()
    d[:, 88:90] = 0.0  # no return along the box's right edge
    d[10, 10] = np.nan
    d[20, 20] = np.inf
    assert not mixed_pixels(d).any()  # a hole is no side of an edge
    d[30:70, 39] = np.resize([2.5, 3.0, 3.5], 40)  # a mixed column on the left edge
    d[45, 38] = 0.0  # a hole beside one of them
    m = mixed_pixels(d)
    assert m[30:70, 39].sum() >= 39 and m.sum() == m[30:70, 39].sum()


def test_simulated_flying_pixels_are_found() -> None:
    """`--noise flying=1.0` mixes every edge pixel (both sides of each edge); the ones
    found hold nearly all of those off both surfaces by more than the tolerance."""
    d = _box_before_wall()
    noisy = mixed_edges(d, 1.0, np.random.default_rng(3))
    off = (np.abs(noisy - 2.0) > 0.1) & (np.abs(noisy - 4.0) > 0.2)  # on neither face
    m = mixed_pixels(noisy)
    assert off.sum() > 100
    assert (m & off).sum() >= 0.9 * off.sum()
    assert not (m & (noisy == d)).any()  # no pixel left as it was


def _frame(depth: np.ndarray) -> Frame:
    pose = np.eye(4)  # camera at the origin, optical axes as the world's
    return Frame(0, 0, None, depth, np.full(depth.shape, 7, np.int32), pose, K, None)


def test_the_voxel_map_leaves_mixed_pixels_out() -> None:
    d = _box_before_wall()
    d[30:70, 89] = np.resize([2.6, 3.3, 2.9, 3.1], 40)  # points 1 m behind the box's face
    for on, floating in ((True, 0), (False, 38)):
        vm = VoxelMap(VoxelConfig(mixed_pixels=on))
        vm.integrate(_frame(d))
        keys, _ = vm.entries()
        ijk, _, _ = vm.voxels()
        z = (ijk[:, 2] + 0.5) * vm.resolution
        assert int(np.count_nonzero((z > 2.5) & (z < 3.5))) >= floating
        if on:
            assert not np.any((z > 2.5) & (z < 3.5))
