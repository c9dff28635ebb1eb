"""Placeholder poses where tracking was lost (an identity matrix among a walk's poses) are
found and refused, naming the frames; a trajectory that jumps and stays (a time gap, a
relocalisation) or walks on is not (sgtool.recorders.importers.pose_jumps)."""

from __future__ import annotations

import numpy as np
import pytest
from support.rgbd_scenes import look_at, make_scene_folder, room

from sgtool.errors import SgtoolError
from sgtool.log import LogReader
from sgtool.recorders.importers.pose_jumps import placeholder_runs
from sgtool.recorders.importers.rgbd import RgbdOptions, import_rgbd
from sgtool.recorders.importers.textformats import PinholeParams

K = PinholeParams(60.0, 60.0, 39.5, 29.5)


def _walk(n: int, step: float = 0.05) -> np.ndarray:
    """Positions of a camera walking ``step`` m a frame from (1, 2, 1.4)."""
    return np.array([[1.0 + step * i, 2.0 + 0.3 * step * i, 1.4] for i in range(n)])


def test_runs_of_placeholders_are_found() -> None:
    p = _walk(60)
    p[10] = p[11] = 0.0  # two frames at the origin: an identity pose each
    p[40:43] = p[5]  # three frames given an earlier frame's pose
    assert placeholder_runs(p) == [(10, 11), (40, 42)]


@pytest.mark.parametrize("case", ["gap", "walk", "short", "long run"])
def test_jumps_that_do_not_come_back_are_no_placeholders(case: str) -> None:
    p = _walk(60)
    if case == "gap":  # the recording paused and went on elsewhere
        p[30:] += [3.0, 0.0, 0.0]
    if case == "long run":  # a third of the frames elsewhere: a segment, not placeholders
        p[20:40] = 0.0
    if case == "short":
        p = p[:4]
        p[2] = 0.0
    assert placeholder_runs(p) == []


def test_an_identity_pose_among_a_walks_is_refused(tmp_path) -> None:
    """Depth rendered from the walk, two ground-truth lines an identity: exit 0 and a map
    with a second copy of the room before; now one line naming the frames."""
    poses = [look_at((-1.0 + 0.03 * i, -0.5 + 0.01 * i, 1.4), (2.5, 1.0 - 0.03 * i, 0.5))
             for i in range(20)]
    root = make_scene_folder(tmp_path / "f", room(), poses)
    lines = (root / "groundtruth.txt").read_text().splitlines()
    for i in (8, 9):  # the header is line 0
        lines[i + 1] = f"{lines[i + 1].split()[0]} 0 0 0 0 0 0 1"
    (root / "groundtruth.txt").write_text("\n".join(lines) + "\n")
    with pytest.raises(SgtoolError, match=r"the poses \(ground truth\) of 2 frames jump away and "
                       r"come back \(.* to .*; up to \d\.\d\d m from the frame before"):
        import_rgbd(root, tmp_path / "a.mcap", RgbdOptions(intrinsics=K, progress=False))
    assert not (tmp_path / "a.mcap").exists()
    rep = import_rgbd(root, tmp_path / "b.mcap", RgbdOptions(intrinsics=K, progress=False,
                                                            estimate_poses=True))
    assert rep.frames == 20
    # the poses as they are, the two placeholder frames left out (no flag did that before:
    # --allow-drop named frames without a pose only)
    rep = import_rgbd(root, tmp_path / "c.mcap", RgbdOptions(intrinsics=K, progress=False,
                                                            allow_drop=True))
    assert rep.frames == 18 and rep.pose_source == "ground truth of the dataset"
    assert "2 frame(s) whose poses jump away and come back (placeholders) left out " \
        "(--allow-drop)" in rep.notes
    times = [f.time_ns for f in LogReader(tmp_path / "c.mcap").frames()]
    assert len(times) == 18
