"""What a replay reads off a log's first frames before it maps them.

A recording made without sgtool's live map says nothing about how far its depth can be
trusted; a noisy camera's far floor then fills the map with phantom obstacles
(:mod:`sgtool.mapping.depth_noise`). :func:`first_frames` reads the first :data:`FRAMES`
frames of the log once and returns

- ``noise``: the vertical noise of the floor against depth and the depth at which it
  reaches the bird's-eye map's floor tolerance (None when nothing could be measured);
- ``up_note``: a line when the camera's image "down" axis is not downward in the world in
  most of those frames (median world z of that axis above :data:`UPRIGHT`) and no floor
  is found at height 0 (a camera looking straight down is upright): sgtool maps heights
  along z, so a world written y-up maps side-on without any other sign;
- ``tilt_note``: a line when the floor, found at height 0, rises or falls more than
  :data:`TILT_NOTE` degrees ahead of (or beside) the camera in the median of those frames
  (:mod:`sgtool.mapping.floor_tilt`): the camera's pitch in the poses is off, or the
  world's floor is not level, and the far floor maps as obstacle or nothing.

The same log gives the same answer: the frames read and the pixels sampled are fixed.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass

import numpy as np

from sgtool.log.reader import LogReader
from sgtool.mapping.bev import BevConfig
from sgtool.mapping.depth_noise import DepthNoise, estimate, floor_height, frame_points
from sgtool.mapping.floor_tilt import floor_slopes, tilt_degrees

FRAMES = 60  # the first frames of the log that are measured
PIXELS = 20_000  # about this many pixels of each frame are measured (a fixed stride)
UPRIGHT = -0.3  # median world z of the camera's image-down axis above this: not z-up
UPSIDE_DOWN = 0.5  # above this: the world's z points down (not a y-up world's side-on)
TILT_NOTE = 1.0  # degrees of floor tilt ahead of or beside the camera that are said


@dataclass(frozen=True)
class FirstFrames:
    """What :func:`first_frames` found (module doc)."""

    noise: DepthNoise | None
    up_note: str | None
    tilt_note: str | None = None


def first_frames(reader: LogReader, ceiling: float, tf_time: str = "log",
                 tolerance: float | None = None, max_frames: int | None = None
                 ) -> FirstFrames:
    """The depth noise of the log's first :data:`FRAMES` frames, or of its first
    ``max_frames`` when fewer (a replay cut short reads no frame it would not map;
    :func:`estimate`, with the default bird's-eye ``floor_tolerance`` unless ``tolerance``
    is given; ``max_depth`` None when the log can be mapped to ``ceiling``), the z-up
    check and the floor-tilt check."""
    tol = BevConfig().floor_tolerance if tolerance is None else tolerance
    samples, down_z, slopes = [], [], []
    count = FRAMES if max_frames is None else min(FRAMES, max_frames)
    for fr in itertools.islice(reader.frames(tf_time=tf_time), count):
        k = fr.intrinsics
        stride = max(1, round(math.sqrt(k.width * k.height / PIXELS)))
        samples.append(frame_points(fr.depth, fr.pose, k.fx, k.fy, k.cx, k.cy, stride))
        down_z.append(float(np.asarray(fr.pose)[2, 1]))
        slopes.append(floor_slopes(fr.depth, fr.pose, k.fx, k.fy, k.cx, k.cy, 0.0, stride))
    note = None
    # a camera looking straight down has its image "down" level; a floor found at height
    # 0 shows the world is z-up all the same
    floor = floor_height(np.concatenate([fp.h for fp in samples])) if samples else None
    if down_z and (d := float(np.median(down_z))) > UPRIGHT and floor is None:
        how = ("upside down: the world's z points down" if d > UPSIDE_DOWN else
               "side-on (a world written y-up maps so)")
        note = (f"the camera's image 'down' axis points {d:+.2f} along the world's z in the "
                "median of the first frames: sgtool maps heights along z (z up), so this map "
                f"is {how}; check the poses' convention (an import's --up)")
    tilt = tilt_degrees(slopes) if floor is not None else None
    return FirstFrames(estimate(samples, tol, ceiling=ceiling), note,
                       None if tilt is None else tilt_note(*tilt))


def tilt_note(ahead: float, left: float) -> str | None:
    """The line for a floor rising ``ahead`` degrees ahead of the camera and ``left``
    degrees to its left (:func:`~sgtool.mapping.floor_tilt.tilt_degrees`), or None within
    :data:`TILT_NOTE` degrees."""
    if math.hypot(ahead, left) <= TILT_NOTE:
        return None
    what = "pitch" if abs(ahead) >= abs(left) else "roll"
    return (f"the floor {'rises' if ahead > 0 else 'falls'} {abs(ahead):.1f} degrees ahead of "
            f"the camera and {'rises' if left > 0 else 'falls'} {abs(left):.1f} to its left "
            "in the median of the first frames: the camera's "
            f"{what} in the poses is likely off by about that much (check the base-to-camera "
            "transform), or the world's floor is not level; the far floor then maps as "
            "obstacle or nothing")
