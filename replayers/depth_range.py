"""The depth a replay maps to when neither the user nor the log chose one.

A recording made without sgtool's live map says nothing about how far its depth can be
trusted; a noisy camera's far floor then fills the map with phantom obstacles
(:mod:`sgtool.mapping.depth_noise`). :func:`measured_depth` reads the first
:data:`FRAMES` frames of the log, measures the vertical noise of the floor against depth
and returns the depth at which it reaches the bird's-eye map's floor tolerance, or None
when the default is fine (or nothing could be measured). The same log gives the same
answer: the frames read and the pixels sampled are fixed.
"""

from __future__ import annotations

import itertools

from sgtool.log.reader import LogReader
from sgtool.mapping.bev import BevConfig
from sgtool.mapping.depth_noise import DepthNoise, estimate, frame_heights

FRAMES = 60  # the first frames of the log that are measured
STRIDE = 2  # every STRIDE-th pixel in each direction


def measured_depth(reader: LogReader, ceiling: float, tf_time: str = "log",
                   tolerance: float | None = None) -> DepthNoise | None:
    """The depth noise of the log's first :data:`FRAMES` frames (:func:`estimate`, with
    the default bird's-eye ``floor_tolerance`` unless ``tolerance`` is given);
    ``max_depth`` None when the log can be mapped to ``ceiling``."""
    tol = BevConfig().floor_tolerance if tolerance is None else tolerance
    samples = []
    for fr in itertools.islice(reader.frames(tf_time=tf_time), FRAMES):
        k = fr.intrinsics
        samples.append(frame_heights(fr.depth, fr.pose, k.fx, k.fy, k.cx, k.cy, STRIDE))
    return estimate(samples, tol, ceiling=ceiling)
