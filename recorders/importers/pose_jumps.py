"""Poses that jump away and come back: placeholders a dataset wrote where its tracking was
lost (an identity matrix, the last good pose of another segment), which ScanNet marks
with ``-inf`` and other exporters do not. Each such frame would be integrated at the wrong
place, and the map would hold a second copy of what it saw, with exit 0.

A *jump* is a step between consecutive frames longer than :data:`JUMP_MIN_M` and
:data:`JUMP_STEPS` times the median step; a run of at most :data:`MAX_RUN_SHARE` of the
frames that starts with a jump, ends with one and comes back to within half the shorter
of the two jumps of where it left is a run of placeholders. A real trajectory does not do that: a
camera that moved far in one step (a time gap, a relocalisation) does not come back in
the next.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

JUMP_MIN_M = 0.3  # m: a step shorter than this is no jump, whatever the median step
JUMP_STEPS = 8.0  # times the median step between consecutive frames
MAX_RUN_SHARE = 0.1  # a run of placeholders is at most this share of the frames (and >= 3)


def placeholder_runs(positions: np.ndarray) -> list[tuple[int, int]]:
    """The runs ``(first, last)`` (frame indices, inclusive) of poses that jump away from
    the frame before and come back after (module doc), in order; ``positions`` is the
    (n, 3) array of the camera positions in frame order."""
    p = np.asarray(positions, float)
    n = len(p)
    if n < 5:
        return []
    steps = np.linalg.norm(np.diff(p, axis=0), axis=1)  # steps[i]: frame i -> i + 1
    jump = max(JUMP_MIN_M, JUMP_STEPS * float(np.median(steps)))
    longest = max(3, int(MAX_RUN_SHARE * n))
    runs: list[tuple[int, int]] = []
    i = 1
    while i < n - 1:
        if steps[i - 1] <= jump:
            i += 1
            continue
        back = next((j for j in range(i, min(n - 1, i + longest))
                     if steps[j] > jump and np.linalg.norm(p[j + 1] - p[i - 1])
                     <= min(steps[i - 1], steps[j]) / 2), None)
        if back is None:
            i += 1
            continue
        runs.append((i, back))
        i = back + 1
    return runs


def placeholder_poses_problem(poses: Sequence[np.ndarray], names: Sequence[str],
                              pose_source: str) -> str | None:
    """The problem of the ``poses`` (camera-to-world, in frame order; ``names`` the frames'
    files) that :func:`placeholder_runs` finds, naming the frames; None when none."""
    positions = np.array([np.asarray(q, float)[:3, 3] for q in poses]) if poses else \
        np.zeros((0, 3))
    runs = placeholder_runs(positions)
    if not runs:
        return None
    frames = sum(b - a + 1 for a, b in runs)
    shown = [names[a] if a == b else f"{names[a]} to {names[b]}" for a, b in runs[:4]]
    more = f" and {len(runs) - 4} more runs" if len(runs) > 4 else ""
    far = max(float(np.linalg.norm(positions[a] - positions[a - 1])) for a, _ in runs)
    return (f"the poses ({pose_source}) of {frames} frames jump away and come back "
            f"({', '.join(shown)}{more}; up to {far:.2f} m from the frame before, which the "
            "frame after them is near again): placeholder poses where tracking was lost (an "
            "identity matrix, where ScanNet writes -inf) are the usual cause, and each "
            "would be mapped at the wrong place; give those frames no pose where the "
            "layout has a way to (a pose/NAME.txt of -inf, as ScanNet writes, or none), "
            "--allow-drop to import the other frames only, or --estimate-poses to estimate "
            "the poses from the depth")
