"""A folder of ``color/``, ``depth/``, ``pose/NAME.txt`` and ``intrinsic/intrinsic_depth.txt``
(a ScanNet export, or a lab's own reconstruction) imports with its own poses and
intrinsics: it was read as an Open3D folder without a trajectory, so its poses were
estimated by odometry and its intrinsics taken as PrimeSense's, silently other ones."""

from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np
import pytest
from click.testing import CliRunner
from support.rgbd_folders import SMALL_K, level_camera, room_depth

from sgtool.cli import cli
from sgtool.log import LogReader
from sgtool.recorders.importers.layouts import read_sequence

K4 = np.array([[SMALL_K.fx, 0, SMALL_K.cx, 0], [0, SMALL_K.fy, SMALL_K.cy, 0],
               [0, 0, 1, 0], [0, 0, 0, 1]], dtype=float)


def scannet_folder(root: Path, n: int = 8, lost: tuple[int, ...] = ()) -> list[np.ndarray]:
    """``n`` frames of a camera 1.4 m above a floor, 2 cm apart, named 0..n-1 without zero
    padding as ScanNet's exporter names them; the poses of ``lost`` are -inf (ScanNet's
    mark of a frame its reconstruction lost)."""
    for d in ("color", "depth", "pose", "intrinsic"):
        (root / d).mkdir(parents=True)
    raw = np.round(room_depth(SMALL_K, 1.4, 25.0) * 1000).clip(0, 65535).astype(np.uint16)
    colour = np.full((SMALL_K.height, SMALL_K.width, 3), 90, np.uint8)
    poses = []
    for i in range(n):
        cv2.imwrite(str(root / "color" / f"{i}.jpg"), colour)
        cv2.imwrite(str(root / "depth" / f"{i}.png"), raw)
        pose = level_camera(0.02 * i, 1.4, 25.0)
        poses.append(pose)
        np.savetxt(root / "pose" / f"{i}.txt", np.full((4, 4), -np.inf) if i in lost else pose)
    np.savetxt(root / "intrinsic" / "intrinsic_depth.txt", K4)
    return poses


def imported(root: Path, out: Path, *extra: str):  # noqa: ANN201
    return CliRunner().invoke(cli, ["import", "rgbd", str(root), "--up", "z", "--floor",
                                    "none", "--fps", "10", "--quiet", *extra, "-o", str(out)])


def test_the_folders_own_poses_and_intrinsics_are_taken(tmp_path):
    poses = scannet_folder(tmp_path / "scene", n=12, lost=(3,))
    r = imported(tmp_path / "scene", tmp_path / "s.mcap")
    assert r.exit_code == 0, r.output
    assert "file intrinsic/intrinsic_depth.txt" in r.output
    assert "poses from pose/ (11 files)" in r.output
    assert "1 of 12 frames have no finite pose in pose/ (first: 3.png): left out" in r.output
    assert "odometry" not in r.output
    with LogReader(tmp_path / "s.mcap") as log:
        frames = list(log.frames())
    assert len(frames) == 11
    assert frames[0].intrinsics.fx == SMALL_K.fx and frames[0].intrinsics.cx == SMALL_K.cx
    kept = [p for i, p in enumerate(poses) if i != 3]
    for fr, pose in zip(frames, kept, strict=True):
        assert np.allclose(fr.pose, pose, atol=1e-9)


def test_more_than_a_tenth_without_poses_is_refused_saying_why(tmp_path):
    scannet_folder(tmp_path / "scene", n=8, lost=(3,))
    r = imported(tmp_path / "scene", tmp_path / "s.mcap")
    assert r.exit_code == 2 and "they have no pose file, or one of non-finite" in r.output
    assert "--allow-drop" in r.output and not (tmp_path / "s.mcap").exists()


def test_a_three_by_four_pose_and_a_three_by_three_matrix_are_read(tmp_path):
    root = tmp_path / "scene"
    poses = scannet_folder(root, n=3)
    np.savetxt(root / "pose" / "1.txt", poses[1][:3])
    np.savetxt(root / "intrinsic" / "intrinsic_depth.txt", K4[:3, :3])
    seq = read_sequence(root)
    assert seq.pose_source == "trajectory" and len(seq.frames) == 3
    assert np.allclose(seq.frames[1].pose, poses[1])
    assert (seq.intrinsics.fx, seq.intrinsics.cy) == (SMALL_K.fx, SMALL_K.cy)


@pytest.mark.parametrize(("write", "says"), [
    (lambda p: p.write_text("1 0 0\n0 1 0\n"), "expected a 4x4 camera-to-world matrix"),
    (lambda p: np.savetxt(p, np.diag([2.0, 1.0, 1.0, 1.0])), "not a rigid camera-to-world"),
    (lambda p: p.write_text("a b c d\n"), "expected a 4x4 camera-to-world matrix"),
])
def test_a_bad_pose_file_is_one_line_and_no_output(tmp_path, write, says):
    root = tmp_path / "scene"
    scannet_folder(root, n=3)
    write(root / "pose" / "2.txt")
    r = imported(root, tmp_path / "s.mcap")
    assert r.exit_code != 0 and says in r.output and "2.txt" in r.output
    assert "Traceback" not in r.output and not (tmp_path / "s.mcap").exists()


def test_a_log_trajectory_comes_first(tmp_path):
    """A folder with both a *.log trajectory and pose files takes the trajectory, as
    before (the Open3D layout's own)."""
    root = tmp_path / "scene"
    poses = scannet_folder(root, n=3)
    moved = [p.copy() for p in poses]
    for p in moved:
        p[0, 3] += 5.0
    lines = []
    for i, p in enumerate(moved):
        lines += [f"{i} {i} {i + 1}", *(" ".join(f"{v:.9f}" for v in row) for row in p)]
    (root / "trajectory.log").write_text("\n".join(lines) + "\n")
    seq = read_sequence(root)
    assert np.allclose(seq.frames[2].pose, moved[2])


def test_a_frame_left_out_keeps_the_times_of_the_frames_after_it(tmp_path):
    """Frame i of the folder is at i/fps whether or not frames before it have a pose (as
    7-Scenes frame n is at n/fps): leaving out a lost frame does not pull the later ones
    earlier."""
    scannet_folder(tmp_path / "scene", n=12, lost=(3,))
    seq = read_sequence(tmp_path / "scene", fps=10.0)
    assert [round(f.time_ns / 1e8) for f in seq.frames] == [0, 1, 2, *range(4, 12)]


def test_zero_padded_pose_names_pair_with_plain_depth_names(tmp_path):
    root = tmp_path / "scene"
    poses = scannet_folder(root, n=3)
    for i in range(3):
        (root / "pose" / f"{i}.txt").rename(root / "pose" / f"{i:06d}.txt")
    seq = read_sequence(root)
    assert len(seq.frames) == 3 and np.allclose(seq.frames[2].pose, poses[2])
    for i in range(3):
        (root / "pose" / f"{i:06d}.txt").rename(root / "pose" / f"frame-{i}.txt")
    r = imported(root, tmp_path / "s.mcap")
    assert r.exit_code == 2 and "none of its 3 pose files is named for a depth image" in r.output


def test_only_the_colour_cameras_intrinsics_are_no_primesense_default(tmp_path):
    """A ScanNet export with intrinsic_color.txt but no intrinsic_depth.txt: the colour
    camera's matrix is not the depth images', and PrimeSense's default is no ScanNet
    camera's: a refusal naming --intrinsics, not a map 10 % off with a warning blaming the
    poses."""
    root = tmp_path / "scene"
    scannet_folder(root, n=3)
    (root / "intrinsic" / "intrinsic_depth.txt").rename(root / "intrinsic" / "intrinsic_color.txt")
    r = imported(root, tmp_path / "s.mcap")
    assert r.exit_code == 2 and "only intrinsic_color.txt" in r.output
    assert "--intrinsics" in r.output and not (tmp_path / "s.mcap").exists()
    k = SMALL_K
    r = imported(root, tmp_path / "s.mcap", "--intrinsics", f"{k.fx},{k.fy},{k.cx},{k.cy}")
    assert r.exit_code == 0, r.output
    assert "intrinsic/intrinsic_color.txt not read" in r.output
