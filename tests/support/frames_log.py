"""A small log of camera frames only (no derived channels, so replay copies its chunks as
they are), optionally moved far from the world origin or carrying a block of random
bytes (incompressible: zstd stores them as they are, so a byte of them can be changed in
the file without breaking the decompression, only the chunk's CRC)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from support.logfixtures import DT, synthetic_frame

from sgtool.log import LogWriter

NOISE_TOPIC = "/noise"


def frames_log(path: Path, n: int = 4, shift: tuple[float, float, float] = (0.0, 0.0, 0.0),
               noise: bytes = b"") -> Path:
    """``n`` synthetic frames (:func:`~support.logfixtures.synthetic_frame`) with every
    pose moved by ``shift`` (m); ``noise`` as one raw message at log time 0."""
    move = np.eye(4)
    move[:3, 3] = shift
    with LogWriter(path, seed=3) as w:
        if noise:
            w.write_raw(w.copy_channel(NOISE_TOPIC, "", "", b"", "raw"), 0, noise)
        for i in range(n):
            k, rgb, depth, ids, pose, base = synthetic_frame(i)
            w.write_frame(i * DT, rgb=rgb, depth=depth, ids=ids, pose=move @ pose,
                          intrinsics=k, base_pose=move @ base)
    return path
