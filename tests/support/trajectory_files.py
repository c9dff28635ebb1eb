"""Time stamps and trajectory files as the importers read them, for building test folders.

Each writes what :mod:`sgtool.recorders.importers.textformats` reads back: a TUM
trajectory (``timestamp tx ty tz qx qy qz qw``, seconds, metres, quaternion x y z w) and an
Open3D ``.log`` (per pose a ``i i i+1`` header and the 4x4 camera-to-world matrix)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from sgtool.log.poses import tq_from_pose


def ns_to_seconds_text(t_ns: int) -> str:
    """Integer nanoseconds -> "seconds.microseconds" as TUM files write them."""
    return f"{t_ns // 1_000_000_000}.{(t_ns % 1_000_000_000) // 1000:06d}"


def write_tum_trajectory(path: Path, poses: list[tuple[int, np.ndarray]]) -> None:
    """(time in ns, 4x4 pose) pairs as a TUM trajectory file."""
    lines = ["# timestamp tx ty tz qx qy qz qw"]
    for t, pose in poses:
        tr, q = tq_from_pose(pose)
        vals = " ".join(f"{v:.9f}" for v in (*tr, *q))
        lines.append(f"{ns_to_seconds_text(t)} {vals}")
    path.write_text("\n".join(lines) + "\n")


def write_open3d_log(path: Path, poses: list[np.ndarray]) -> None:
    """4x4 poses as an Open3D ``.log`` trajectory, one block per pose."""
    lines = []
    for i, pose in enumerate(poses):
        lines.append(f"{i} {i} {i + 1}")
        lines.extend(" ".join(f"{v:.8f}" for v in row) for row in np.asarray(pose))
    path.write_text("\n".join(lines) + "\n")
