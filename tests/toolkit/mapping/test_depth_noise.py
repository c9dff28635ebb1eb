"""The depth a noisy log can be mapped to, from its points below the floor.

Frames of the two-room house from the numpy ray-caster, a camera 1.2 m up pitched down,
with depth noise sigma_d = c z^2 added (seeded). A floor point at depth z moves along its
ray when its depth errs by e: its height changes by H e / z (H the camera's height above
the floor), so the vertical noise is sigma_v(z) = H c z, and 4 sigma_v reaches the 0.1 m
floor tolerance at z = 0.1 / (4 H c): 3.47 m for c = 0.006, 2.08 m for c = 0.01, 1.39 m
for c = 0.015.
"""

from __future__ import annotations

import math

import numpy as np
from support.synthetic_world import make_frame, two_room_house, world_of_house

from sgtool.log.frame import CameraIntrinsics
from sgtool.mapping.depth_noise import (
    BIN,
    MIN_DEPTH,
    estimate,
    floor_height,
    frame_points,
    sensor_max_depth,
)

K = CameraIntrinsics.from_fov(160, 120, 60)
H = 1.2


def samples(c: float, seed: int = 0, floor: float = 0.0):
    """The frames looking around the kitchen and the bedroom, with noise ``c z^2``, in a
    world whose floor is at height ``floor``."""
    hw = world_of_house(two_room_house())
    rng = np.random.default_rng(seed)
    out = []
    for x, y in ((2.0, 1.5), (6.0, 1.5)):
        for i in range(12):
            f = make_frame(hw.world, x, y, 2 * math.pi * i / 12, K, height=H, pitch=0.5)
            d = f.depth.astype(np.float64)
            d = d + c * d * d * rng.standard_normal(d.shape)
            pose = f.pose.copy()
            pose[2, 3] += floor
            out.append(frame_points(d, pose, K.fx, K.fy, K.cx, K.cy))
    return out


def test_a_clean_log_keeps_its_depth():
    est = estimate(samples(0.0), 0.1)
    assert est is not None and abs(est.floor) < 0.005
    assert est.max_depth is None and max(est.sigma) < 0.005


def test_noisy_depth_is_cut_where_four_sigma_reach_the_floor_tolerance():
    for c in (0.006, 0.01, 0.015):
        est = estimate(samples(c), 0.1)
        cut = 0.1 / (4 * H * c)  # module doc
        assert est is not None and abs(est.floor) < 0.01
        # the bin the cut falls in, or the next (the measurement's noise near the cut)
        assert cut - BIN <= est.max_depth <= cut + BIN, (c, est)
        # the measured noise follows H c z within a quarter up to a metre past the cut
        for z, s in zip(est.depths, est.sigma, strict=True):
            if z < est.max_depth + 1.0:
                assert abs(s / (H * c * (z + BIN / 2)) - 1) < 0.25, (c, z, s)


def test_a_cut_beyond_the_ceiling_changes_nothing():
    est = estimate(samples(0.004), 0.1, ceiling=4.0)  # cut near 5.2 m
    assert est is not None and est.max_depth is None


def test_very_noisy_depth_keeps_what_surrounds_the_robot():
    # noise 0.05 z^2: 4 sigma_v is past the tolerance where the floor is seen nearest
    est = estimate(samples(0.05), 0.1)
    assert est is not None and est.max_depth == MIN_DEPTH


def test_no_estimate_without_a_floor_at_height_zero():
    # a world written with the floor elsewhere (walls cross height 0 there): not measured
    for floor in (-1.2, -2.0, 0.8):
        assert estimate(samples(0.01, floor=floor), 0.1) is None, floor
    assert estimate([], 0.1) is None
    assert floor_height(np.zeros(100)) is None  # too few points to find a floor
    assert floor_height(np.full(10_000, 0.7)) is None  # no floor at height 0


def test_a_stray_point_far_away_costs_nothing():
    """A pose error that puts one frame's points 500 km up: the floor search looks near
    height 0 only (no histogram over the distance), and the rest is measured as before."""
    frames = samples(0.01)
    far = frames[0]
    frames[0] = type(far)(far.h + 5e8, far.slope, far.camera_z + 5e8)
    est = estimate(frames, 0.1)
    assert est is not None and est.max_depth == estimate(samples(0.01), 0.1).max_depth


def test_a_sensor_model_is_cut_where_the_measurement_cuts_it():
    # sigma_v(z) = H c z (module doc of the test): the model cuts in the bin the cut
    # falls in, the measurement there or one bin either side (its noise near the cut)
    for c in (0.006, 0.01, 0.015):
        est = estimate(samples(c), 0.1)
        model = sensor_max_depth(c, H, 0.1)
        assert est is not None and est.max_depth is not None and model is not None
        cut = 0.1 / (4 * H * c)
        assert cut - BIN <= model <= cut, c
        assert abs(est.max_depth - model) <= BIN, (c, model, est.max_depth)
    assert sensor_max_depth(0.01, H, 0.1) == 2.0  # 0.1 / (4 x 1.2 x 0.01) = 2.08: bin 2.0
    assert sensor_max_depth(0.0, H, 0.1) is None  # no noise: nothing to cut
    assert sensor_max_depth(0.05, H, 0.1) == MIN_DEPTH  # the robot keeps its surroundings
    assert sensor_max_depth(0.004, H, 0.1, ceiling=5.0) is None  # the cut lies at 5.0 m
    # a camera mounted higher sees the floor's noise larger: cut nearer
    assert sensor_max_depth(0.01, 2 * H, 0.1) == 1.0


def test_a_sunken_floor_is_no_noise():
    """A fifth of the floor seen between 1 and 3 m lies 0.15 m lower (a sunken area, a step
    down): points below the floor that are no noise. (N1) takes the median, so a minority
    of them does not read as noise (their RMS would: 0.15 m x sqrt(0.2 / 0.6) is 0.087 m,
    4 sigma 0.35 m), and (N3) leaves out depths where they are all there is: a good
    sensor's log is not cut; a noisy one's is, more conservatively (the sunken points are
    a third of those below the floor there)."""
    from sgtool.mapping.depth_noise import FramePoints

    def sunken(fp: FramePoints, every: int = 5) -> FramePoints:
        zf = fp.floor_depths(0.0)
        floor = np.flatnonzero((np.abs(fp.h) < 0.2) & (zf > 1.0) & (zf < 3.0))
        h = fp.h.copy()
        h[floor[::every]] -= 0.15
        return FramePoints(h, fp.slope, fp.camera_z)

    # a good sensor (0.002 z^2: 4 sigma reach the tolerance at 10 m): nothing cut
    clean = estimate([sunken(fp) for fp in samples(0.002)], 0.1, ceiling=5.0)
    assert clean is not None and clean.max_depth is None
    # no noise at all and a twentieth of the floor lower: the points below the floor are
    # the sunken ones (and a few a rounding error below), far fewer than half the
    # floor's there ((N3)): nothing cut either
    exact = estimate([sunken(fp, 20) for fp in samples(0.0)], 0.1)
    assert exact is None or exact.max_depth is None
    noisy = estimate([sunken(fp) for fp in samples(0.01)], 0.1)
    assert noisy is not None and noisy.max_depth is not None
    assert noisy.max_depth <= 2.0  # cut, at 2 m without the sunken area, nearer with it
