"""Points beyond the voxel keys' range (17 bits per axis: +-3276.7 m at 5 cm) are refused
with one line naming the frame, the camera position, the range and the fix, never dropped
silently; frames whose points all fit are mapped whole, even next to the edge."""

from __future__ import annotations

import numpy as np
import pytest
from support.frames_log import frames_log

from sgtool.cli import main
from sgtool.log.frame import CameraIntrinsics, Frame
from sgtool.mapping.backproject import MapRangeError
from sgtool.mapping.voxels import OFFSET, VoxelConfig, VoxelMap

K4 = CameraIntrinsics(4, 4, 2.0, 2.0, 1.5, 1.5)  # rays up to 0.75 off the axis
EDGE = (OFFSET - 2) * 0.05  # metres: the far side of the last voxel that fits


def flat_frame(x: float, index: int = 0) -> Frame:
    """A camera at (x, 0, 0) looking along +z at a wall 2 m away (points x +- 1.5 m)."""
    pose = np.eye(4)
    pose[0, 3] = x
    return Frame(index, index * 100_000_000, None, np.full((4, 4), 2.0, np.float32), None,
                 pose, K4, None)


def test_a_frame_across_the_edge_of_the_packing_is_refused_not_dropped() -> None:
    vm = VoxelMap(VoxelConfig(resolution=0.05))
    with pytest.raises(MapRangeError) as e:
        vm.integrate(flat_frame(EDGE - 0.01, index=3))
    msg = str(e.value)
    assert "\n" not in msg
    assert msg.startswith("frame 3 at 0.300 s: the camera at (3276.7, 0.0, 0.0) m")
    assert "+-3276.7 m of the world origin" in msg and "recentre the trajectory" in msg
    assert len(vm) == 0 and vm.version == 0  # nothing half integrated


def test_a_frame_next_to_the_edge_whose_points_fit_is_mapped_whole() -> None:
    # the per-frame bound on the pose cannot vouch for it; the exact range does
    vm = VoxelMap(VoxelConfig(resolution=0.05))
    assert vm.integrate(flat_frame(EDGE - 1.6)) == 16
    assert vm.integrate(flat_frame(-EDGE + 1.6, index=1)) == 16
    ijk, _, total = vm.voxels()
    assert int(total.sum()) == 32 and int(np.abs(ijk[:, 0]).max()) >= OFFSET - 4


def test_a_pose_that_is_not_finite_is_refused() -> None:
    f = flat_frame(0.0)
    f.pose[1, 3] = np.nan
    with pytest.raises(MapRangeError, match="frame 0 at 0.000 s: the camera pose is not "
                                            "finite"):
        VoxelMap().integrate(f)


def test_a_frame_tf_does_not_pose_names_the_missing_chain() -> None:
    """A log reader poses a frame /tf has no chain for with NaN: the error says so."""
    f = flat_frame(0.0)
    f.pose[:] = np.nan
    with pytest.raises(MapRangeError, match="frame 0 at 0.000 s: no camera pose: /tf has no "
                                            "chain from the frame 'world'"):
        VoxelMap().integrate(f)


def test_world_points_beyond_the_packing_are_refused() -> None:
    vm = VoxelMap()
    pts = np.array([[0.0, 0.0, 0.0], [0.0, -5000.0, 1.0]])
    with pytest.raises(MapRangeError, match=r"^frame 7: world points \(or NaN\) reach "
                                            r"beyond \+-3276.7 m"):
        vm.integrate_points(pts, np.zeros(2, np.int64), (0.0, 0.0), frame_index=7)
    assert vm.integrate_points(pts[:1], np.zeros(1, np.int64), (0.0, 0.0)) == 1


def run(argv: list[str], capsys: pytest.CaptureFixture[str]) -> tuple[int, str]:
    """``sgtool ARGV`` as the console script runs it: (exit code, stderr)."""
    try:
        main(argv)
        code = 0
    except SystemExit as e:
        code = int(e.code or 0)
    return code, capsys.readouterr().err


def test_replay_of_a_log_far_from_the_origin_is_refused_in_one_line(tmp_path, capsys) -> None:
    far = frames_log(tmp_path / "far.mcap", shift=(5000.0, 0.0, 0.0))
    out = tmp_path / "far_d.mcap"
    code, err = run(["replay", str(far), "-o", str(out)], capsys)
    assert code == 2
    assert err.count("\n") == 1 and err.startswith("sgtool: error: frame 0 at 0.000 s: the "
                                                   "camera at (5000.0, ")
    assert "+-3276.7 m" in err and "Traceback" not in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["far.mcap"]  # no output at all
    # the same log 3 km out is within the range: replayed as usual
    near = frames_log(tmp_path / "near.mcap", shift=(3000.0, 0.0, 0.0))
    code, err = run(["replay", str(near), "-o", str(tmp_path / "near_d.mcap")], capsys)
    assert code == 0, err
    assert (tmp_path / "near_d.mcap").exists()
