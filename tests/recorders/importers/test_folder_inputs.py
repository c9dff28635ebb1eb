"""Bad RGB-D folder inputs and import options: each is refused in one line naming the file,
the line or the flag (or, where the data can be used, imported with a note), and no log is
written. Folders are built here from tiny synthetic images."""

from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np
import pytest
from click.testing import CliRunner
from support.trajectory_files import write_open3d_log

from sgtool.cli import cli
from sgtool.errors import SgtoolError
from sgtool.log.frame import CameraIntrinsics
from sgtool.recorders.importers.checks import check_floor, seconds_option_ns
from sgtool.recorders.importers.image_files import natural_key
from sgtool.recorders.importers.images import read_color_file_kind, resize_to
from sgtool.recorders.importers.layouts import FolderSequence, read_sequence
from sgtool.recorders.importers.odometry import FailedStep, OdometryResult
from sgtool.recorders.importers.provenance import FLOOR_ORIGINS, Findings
from sgtool.recorders.importers.rgbd import RgbdOptions, camera_for, import_rgbd
from sgtool.recorders.importers.sanity import time_range_problem
from sgtool.recorders.importers.textformats import (
    PinholeParams,
    parse_intrinsics,
    read_intrinsics_file,
    read_open3d_log,
    read_pose_file,
)
from sgtool.recorders.importers.upright import DepthSample, estimate_alignment

W, H = 32, 24


def _pose(x: float) -> np.ndarray:
    T = np.eye(4)  # noqa: N806
    T[0, 3] = x
    return T


def _depth(path: Path, value: int = 2000) -> None:
    cv2.imwrite(str(path), np.full((H, W), value, np.uint16))


def _colour(path: Path, w: int = W, h: int = H) -> None:
    cv2.imwrite(str(path), np.full((h, w, 3), 128, np.uint8))


def open3d_folder(root: Path, names: list[str]) -> Path:
    """depth/NAME.png, image/NAME.jpg and traj.log whose pose i has x = i, in list order."""
    (root / "depth").mkdir(parents=True)
    (root / "image").mkdir()
    for n in names:
        _depth(root / "depth" / f"{n}.png")
        _colour(root / "image" / f"{n}.jpg")
    write_open3d_log(root / "traj.log", [_pose(float(i)) for i in range(len(names))])
    return root


def seven_folder(root: Path, n: int = 3, depth_value: int = 2000) -> Path:
    root.mkdir(parents=True)
    for i in range(n):
        _depth(root / f"frame-{i:06d}.depth.png", depth_value)
        _colour(root / f"frame-{i:06d}.color.png")
        np.savetxt(root / f"frame-{i:06d}.pose.txt", _pose(0.1 * i))
    return root


# ----- item 1: frame order ---------------------------------------------------------------------
def test_unpadded_names_sort_by_number_and_keep_their_poses(tmp_path):
    seq = read_sequence(open3d_folder(tmp_path / "f", [str(i) for i in range(12)]))
    assert [f.depth_path.stem for f in seq.frames] == [str(i) for i in range(12)]
    assert [f.color_path.stem for f in seq.frames] == [str(i) for i in range(12)]
    assert [f.pose[0, 3] for f in seq.frames] == [float(i) for i in range(12)]
    assert sorted(["10.png", "2.png", "frame-1.png"], key=natural_key) == \
        ["2.png", "10.png", "frame-1.png"]


def test_a_tum_ground_truth_in_an_open3d_folder_is_said_to_be_unread(tmp_path):
    """A TUM folder without rgb.txt and depth.txt reads as the open3d layout: its
    groundtruth.txt was ignored without a word (the poses then estimated, the times lost)."""
    root = open3d_folder(tmp_path / "f", ["0", "1", "2"])
    (root / "traj.log").unlink()
    (root / "groundtruth.txt").write_text("".join(f"{t}.0 0 0 0 0 0 0 1\n" for t in range(5)))
    notes = read_sequence(root).notes
    assert any(n.startswith("groundtruth.txt not read: a folder of depth/ and colour folders "
                            "is read as the open3d layout") for n in notes), notes
    # given as --trajectory, its lines are taken in order: a count that differs says so
    with pytest.raises(SgtoolError, match=r"has 5 poses for 3 frames; this layout takes a "
                       r"TUM trajectory's lines one per frame, in order, its times unused"):
        read_sequence(root, trajectory=root / "groundtruth.txt")


def test_names_whose_numbers_tie_are_refused(tmp_path):
    root = open3d_folder(tmp_path / "f", ["0", "1", "2"])
    _depth(root / "depth" / "01.png")
    with pytest.raises(SgtoolError, match=r"01.png and 1.png have the same number; the frame "
                       "order is ambiguous"):
        read_sequence(root)


# ----- items 4 and 12: rigid poses, named lines --------------------------------------------------
LOG = "0 0 1\n1 0 0 0\n0 1 0 0\n0 0 1 0\n0 0 0 1\n"


@pytest.mark.parametrize(("block", "match"), [
    ("0 0 1\n2 0 0 0\n0 2 0 0\n0 0 2 0\n0 0 0 1\n", r"traj.log:7: the rotation is not "
     r"orthonormal with det \+1 \(\|R\^T R - I\| = 3, det 8\)"),
    ("0 0 1\n1 0.5 0 0\n0 1 0 0\n0 0 1 0\n0 0 0 1\n", r"traj.log:7: the rotation is not "
     "orthonormal"),
    ("0 0 1\n-1 0 0 0\n0 1 0 0\n0 0 1 0\n0 0 0 1\n", r"traj.log:7: .*det -1"),
    ("0 0 1\n1 0 0 0\n0 1 0 0\n0 0 1 0\n0.1 0 0 1\n", "traj.log:10: the last row is 0.1 0 0 1, "
     "not 0 0 0 1"),
    ("0 0 1\n1 0 0 0\n0 1 0 0\nnan 0 1 0\n0 0 0 1\n", "traj.log:9: a pose matrix row that is "
     "not finite"),
    ("0 0 1\n1 0 0 0\n0 1 0\n0 0 1 0\n0 0 0 1\n", "traj.log:8: expected a matrix row of four "
     "numbers, this one has 3"),
])
def test_open3d_log_poses_must_be_rigid(tmp_path, block, match):
    p = tmp_path / "traj.log"
    p.write_text(LOG + block)
    with pytest.raises(SgtoolError, match=match):
        read_open3d_log(p)


def test_nearly_orthonormal_float_text_is_accepted(tmp_path):
    p = tmp_path / "traj.log"
    p.write_text(LOG + "0 0 1\n1.0004 0 0 0\n0 0.9997 0 0\n0 0 1 0\n0 0 0 1\n")
    assert len(read_open3d_log(p)) == 2


def test_seven_scenes_pose_files_must_be_rigid(tmp_path):
    p = tmp_path / "frame-000030.pose.txt"
    p.write_text("1.5 0 0 0\n0 1.5 0 0\n0 0 1.5 0\n0 0 0 1\n")
    with pytest.raises(SgtoolError, match="frame-000030.pose.txt:1: the rotation is not"):
        read_pose_file(p)
    p.write_text("1 0 0 0\nnan 1 0 0\n0 0 1 0\n0 0 0 1\n")
    with pytest.raises(SgtoolError, match="pose.txt:2: a pose matrix row that is not finite"):
        read_pose_file(p)
    root = seven_folder(tmp_path / "s")
    (root / "frame-000001.pose.txt").write_text("1 0 0 0\n0 1 0 0\n0 0 1 0\n0.1 0 0 1\n")
    with pytest.raises(SgtoolError, match="frame-000001.pose.txt:4: the last row"):
        read_sequence(root)


def test_open3d_images_pair_by_number_whatever_their_zero_padding(tmp_path):
    """Colour 00007.jpg pairs with depth 7.png (as pose/000007.txt poses it): one image
    missing on each side never pairs the frames between by position (they took the next
    frame's colour)."""
    root = open3d_folder(tmp_path / "f", [str(i) for i in range(6)])
    for i in range(6):
        (root / "image" / f"{i}.jpg").rename(root / "image" / f"{i:05d}.jpg")
    (root / "image" / "00001.jpg").unlink()
    (root / "depth" / "4.png").unlink()
    write_open3d_log(root / "traj.log", [_pose(float(i)) for i in range(5)])
    frames = read_sequence(root).frames
    assert [(f.depth_path.stem, f.color_path and f.color_path.stem) for f in frames] == [
        ("0", "00000"), ("1", None), ("2", "00002"), ("3", "00003"), ("5", "00005")]


def test_open3d_frames_keep_their_numbers_times_past_a_missing_frame(tmp_path):
    """Frame 3 missing from the folder (no depth: colour only; or no image at all) leaves
    frames 4 and 5 at 4/fps and 5/fps (they were at 3/fps and 4/fps, one frame early), with
    a note; a folder of every fifth frame stays 1/fps apart; names that are not plain
    numbers keep their list positions."""
    def times(root: Path) -> list[float]:
        return [f.time_ns / 1e8 for f in read_sequence(root, fps=10.0).frames]

    root = open3d_folder(tmp_path / "a", [str(i) for i in range(6)])
    (root / "traj.log").unlink()
    (root / "depth" / "3.png").unlink()
    assert times(root) == [0.0, 1.0, 2.0, 4.0, 5.0]
    assert "1 gap(s) in the numbers of the depth images (first: after depth/2.png)" in \
        read_sequence(root).notes[-1]
    (root / "image" / "3.jpg").unlink()
    assert times(root) == [0.0, 1.0, 2.0, 4.0, 5.0]
    sparse = open3d_folder(tmp_path / "b", [f"{5 * i:06d}" for i in range(4)])
    assert times(sparse) == [0.0, 1.0, 2.0, 3.0]
    named = open3d_folder(tmp_path / "c", ["a0", "a1", "a3"])
    assert times(named) == [0.0, 1.0, 2.0]
    # names that are time stamps (33 or 34 ms apart) are no frame numbers: list positions
    stamps = open3d_folder(tmp_path / "d", [str(1_000_000 + 33 * i + i // 2) for i in range(4)])
    assert times(stamps) == [0.0, 1.0, 2.0, 3.0]
    # colour numbered otherwise (paired in order): the depth images' numbers alone
    other = open3d_folder(tmp_path / "e", [str(1000 + i) for i in range(3)])
    for i in range(3):
        (other / "image" / f"{1000 + i}.jpg").rename(other / "image" / f"{i}.jpg")
    assert times(other) == [0.0, 1.0, 2.0]


def test_open3d_takes_no_tum_trajectory_short_of_the_frames(tmp_path):
    """A TUM --trajectory (its lines taken in order, times unused) with fewer lines than the
    frames may lack any frame (tracking lost mid-way): refused, never the first frames'
    poses (frame 1 took frame 2's)."""
    root = open3d_folder(tmp_path / "f", ["0", "1", "2"])
    (root / "traj.log").unlink()
    tum = tmp_path / "slam.txt"
    tum.write_text("0.0 0 0 0 0 0 0 1\n0.0667 2 0 0 0 0 0 1\n")  # frame 1 lost
    with pytest.raises(SgtoolError, match="slam.txt has 2 poses for 3 frames; this layout"):
        read_sequence(root, trajectory=tum)


def test_open3d_missing_depth_is_named(tmp_path):
    root = open3d_folder(tmp_path / "f", ["00000", "00010", "00020"])
    (root / "depth" / "00010.png").unlink()
    with pytest.raises(SgtoolError, match=r"traj.log has 3 poses for 2 frames \(1 colour images "
                       r"have no depth image; first: depth/00010\.\* for image/00010.jpg; "
                       r"--skip-missing leaves them out with their poses\)"):
        read_sequence(root)
    write_open3d_log(root / "traj.log", [_pose(0.0), _pose(2.0)])  # a pose per depth image
    assert [f.pose[0, 3] for f in read_sequence(root).frames] == [0.0, 2.0]


def test_trajectory_log_for_a_tum_folder_goes_in_listed_order(tmp_path):
    root = tmp_path / "tum"
    root.mkdir()
    lines = []
    for i in range(3):
        _depth(root / f"d{i}.png")
        lines.append(f"{10 + i / 30:.6f} d{i}.png")
    (root / "depth.txt").write_text("\n".join(lines) + "\n")
    (root / "rgb.txt").write_text("")
    write_open3d_log(tmp_path / "t.log", [_pose(float(i)) for i in range(3)])
    seq = read_sequence(root, trajectory=tmp_path / "t.log")
    assert seq.pose_source == "trajectory"
    assert [f.pose[0, 3] for f in seq.frames] == [0.0, 1.0, 2.0]
    # a matrix a line (NICE-SLAM's traj.txt) has no times either: the same order
    (tmp_path / "traj.txt").write_text("".join(
        " ".join(f"{x:g}" for x in _pose(float(i)).ravel()) + "\n" for i in range(3)))
    seq = read_sequence(root, trajectory=tmp_path / "traj.txt")
    assert [f.pose[0, 3] for f in seq.frames] == [0.0, 1.0, 2.0]


# ----- item 6: intrinsics ----------------------------------------------------------------------
def test_a_malformed_intrinsics_json_is_an_error(tmp_path):
    root = open3d_folder(tmp_path / "f", ["0", "1"])
    (root / "camera.json").write_text('{"intrinsic_matrix": [600, 0, 0, 0, 600, 0, 320, 240]}')
    with pytest.raises(SgtoolError, match=r"camera.json: expected Open3D intrinsics JSON"):
        read_sequence(root)
    (root / "camera.json").write_text('{"width": 640,')  # cut short: no default instead
    with pytest.raises(SgtoolError, match=r"camera.json: expected Open3D intrinsics JSON"):
        read_sequence(root)
    (root / "camera.json").write_text('{"other": 1}')  # not an intrinsics file: ignored
    assert read_sequence(root).intrinsics.source.startswith("dataset default")
    seq = read_sequence(root, timestamps="index", skip_missing=True)  # TUM's options
    assert any("--timestamps index: not used by the Open3D" in n  # (--skip-missing is)
               for n in seq.notes)


@pytest.mark.parametrize("text", ["nan,525,319.5,239.5", "inf,525,319.5,239.5",
                                  "525,525,nan,239.5", "525,525,-5000,239.5", "0,525,1,1"])
def test_intrinsics_must_be_finite_and_positive(text):
    with pytest.raises(SgtoolError, match=r"--intrinsics .*(not finite|must be positive)"):
        parse_intrinsics(text)


def test_intrinsics_files_are_checked(tmp_path):
    p = tmp_path / "k.txt"
    p.write_text("nan 0 320\n0 525 240\n0 0 1\n")
    with pytest.raises(SgtoolError, match="k.txt: intrinsics .* not finite"):
        read_intrinsics_file(p)


def _seq(intr: PinholeParams) -> FolderSequence:
    return FolderSequence("open3d", Path("f"), (), intr, 1000.0, "none")


def test_principal_point_of_another_resolution():
    small = PinholeParams(262.5, 262.5, 159.75, 119.75, source="file cam.json")
    with pytest.raises(SgtoolError, match=r"principal point \(159.75, 119.75\) is far from the "
                       r"centre \(320, 240\) of the 640x480 .* look like intrinsics of 320x240"):
        camera_for(_seq(small), RgbdOptions(), 640, 480, Findings())
    found = Findings()  # given with the flag: a warning
    k = camera_for(_seq(small), RgbdOptions(intrinsics=small), 640, 480, found)
    assert k.cx == 159.75 and "far from the centre" in found.warnings[0]
    with pytest.raises(SgtoolError, match=r"principal point \(700, 240\) is outside the 640x480"):
        camera_for(_seq(PinholeParams(525, 525, 700, 240)), RgbdOptions(), 640, 480)
    assert camera_for(_seq(PinholeParams(525, 525, 319.5, 239.5)), RgbdOptions(), 640, 480,
                      Findings()).fx == 525


# ----- items 7 and 8: numeric options and time stamps ------------------------------------------
@pytest.mark.parametrize(("opts", "match"), [
    (dict(fps=1e-12), r"--fps 1e-12: must be a number from 0.1 to 1000"),
    (dict(fps=1e12), r"--fps 1e\+12: must be a number from 0.1 to 1000"),
    (dict(fps=float("nan")), r"--fps nan"),
    (dict(floor=float("nan")), r"--floor nan: must be a number"),
    (dict(floor=1e300), r"--floor 1e\+300: must be a number from -10000 to 10000"),
])
def test_options_are_checked_before_anything_is_read(tmp_path, opts, match):
    with pytest.raises(SgtoolError, match=match):
        import_rgbd(tmp_path / "nowhere", tmp_path / "x.mcap", RgbdOptions(**opts))
    assert not (tmp_path / "x.mcap").exists()


@pytest.mark.parametrize("value", [float("nan"), float("inf"), 1e300, -1.0])
def test_duration_flags(value):
    with pytest.raises(SgtoolError, match="--max-dt .*must be a number from 0 to 60"):
        seconds_option_ns(value, "--max-dt", 60.0)
    assert seconds_option_ns(0.02, "--max-dt", 60.0) == 20_000_000
    assert check_floor(None) is None and check_floor(-0.5) == -0.5


@pytest.mark.parametrize("args", [["--max-dt", "nan"], ["--max-dt", "1e300"],
                                  ["--floor", "nan"], ["--floor", "inf"], ["--fps", "1e-12"]])
def test_cli_numeric_flags_give_one_line(tmp_path, args):
    root = open3d_folder(tmp_path / "f", ["0", "1"])
    r = CliRunner().invoke(cli, ["import", "rgbd", str(root), "-o", str(tmp_path / "x.mcap"),
                                 *args])
    assert r.exit_code == 2 and "Traceback" not in r.output, r.output
    assert f"error: {args[0]} " in r.output and not (tmp_path / "x.mcap").exists()


def test_cli_tf_tolerance_gives_one_line(tmp_path):
    r = CliRunner().invoke(cli, ["import", "bag", str(tmp_path), "--depth", "/d",
                                 "--tf-tolerance", "nan", "-o", str(tmp_path / "x.mcap")])
    assert r.exit_code == 2 and "--tf-tolerance nan: must be a number" in r.output, r.output


def _tum(root: Path, stamps: list[str]) -> Path:
    root.mkdir()
    for i in range(len(stamps)):
        _depth(root / f"d{i}.png")
    (root / "depth.txt").write_text("".join(f"{t} d{i}.png\n" for i, t in enumerate(stamps)))
    (root / "rgb.txt").write_text("")
    return root


def test_tum_times_a_log_cannot_hold(tmp_path):
    ms = _tum(tmp_path / "ms", ["1305031102160.407", "1305031102193.740"])
    with pytest.raises(SgtoolError, match="depth.txt: time stamps up to 1.305e\\+12 s are "
                       "beyond year 2262: they look like milliseconds"):
        read_sequence(ms)
    neg = _tum(tmp_path / "neg", ["-0.5", "-0.466"])
    with pytest.raises(SgtoolError, match=r"depth.txt: negative time stamps \(from -0.5 s\)"):
        read_sequence(neg)
    assert len(read_sequence(neg, timestamps="index").frames) == 2
    assert time_range_problem([0, 10**9], "x") is None


def _log_of_frames(path: Path, frames: list[int]) -> None:
    """An Open3D .log with one block per frame id given, frame k's pose at x = k."""
    lines = []
    for k in frames:
        lines.append(f"{k} {k} {k + 1}")
        lines.extend(" ".join(f"{v:.8f}" for v in row) for row in _pose(float(k)))
    path.write_text("\n".join(lines) + "\n")


@pytest.mark.parametrize(("names", "blocks"), [
    ([str(i) for i in range(2, 8)], [2, 3, 4]),  # a clip named as its recording's frames
    ([str(i) for i in range(6)], [2, 3, 4, 5, 6]),  # ids past the last frame
])
def test_pose_blocks_that_do_not_name_the_frames_plainly_are_refused(tmp_path, names, blocks):
    """A .log whose first block is not frame 0 poses the frames from that position (a
    reconstruction that started late) only when the images are numbered from 0 and the
    blocks end within them; otherwise which frames they pose is unclear (a clip numbered
    2..7 had file 4 posed with frame 2's pose), and the import says so."""
    root = open3d_folder(tmp_path / "o3d", names)
    _log_of_frames(root / "traj.log", blocks)
    with pytest.raises(SgtoolError, match="which frames they pose is unclear"):
        read_sequence(root)
    late = open3d_folder(tmp_path / "late", [str(i) for i in range(6)])
    _log_of_frames(late / "traj.log", [2, 3, 4])
    seq = read_sequence(late)
    assert [(f.depth_path.stem, f.pose[0, 3]) for f in seq.frames] == [
        ("2", 2.0), ("3", 3.0), ("4", 4.0)]
    negative = open3d_folder(tmp_path / "negative", [str(i) for i in range(6)])
    _log_of_frames(negative / "traj.log", [-2, -1, 0])  # ids that say nothing: in order
    assert [f.pose[0, 3] for f in read_sequence(negative).frames] == [-2.0, -1.0, 0.0]
    # both notes count the folder's 6 frames (the second counted the 4 left after the first)
    assert [n.split(" frames")[0] for n in seq.notes if " frames come " in n] == [
        "2 of 6", "1 of 6"], seq.notes


def test_ground_truth_on_another_clock_names_both_time_spans(tmp_path):
    """Ground truth timed from 0 beside images in Unix time: the refusal shows both spans
    (it said only that no image was within the ground truth's)."""
    root = _tum(tmp_path / "rel", ["1305031102.175", "1305031102.211"])
    (root / "groundtruth.txt").write_text("0.07 0 0 0 0 0 0 1\n1.97 0 0 0 0 0 0 1\n")
    with pytest.raises(SgtoolError, match=r"time span of groundtruth.txt \(depth "
                       r"1305031102.175-1305031102.211 s, poses 0.070-1.970 s\)"):
        read_sequence(root)


# ----- item 9: no valid depth ------------------------------------------------------------------
def test_all_invalid_depth_is_refused(tmp_path):
    root = seven_folder(tmp_path / "s", depth_value=65535)
    with pytest.raises(SgtoolError, match="none of the 3 sampled depth images has a valid pixel"):
        import_rgbd(root, tmp_path / "x.mcap", RgbdOptions(progress=False))
    assert not (tmp_path / "x.mcap").exists()


def test_floor_not_estimated_for_want_of_depth_says_so():
    k = CameraIntrinsics(W, H, 30.0, 30.0, W / 2, H / 2)
    empty = [DepthSample(np.zeros((H, W), np.float32), k, np.eye(4))]
    a = estimate_alignment([np.eye(4)], empty)
    assert a.floor_method == "no-depth" and "no valid depth" in FLOOR_ORIGINS[a.floor_method]
    assert estimate_alignment([np.eye(4)], empty, floor_auto=False).floor_method == "none"
    assert estimate_alignment([np.eye(4)], []).floor_method == "none"


# ----- item 10: odometry note ------------------------------------------------------------------
def test_odometry_note_points_at_the_frame_spacing():
    poses = tuple(np.eye(4) for _ in range(8))
    failed = tuple(FailedStep(i, "motion", "", 1 / 30, 0.17, 0.1) for i in range(1, 8))
    note = OdometryResult(poses, "rgbd+icp", failed).warning()
    assert "odometry failed on 100% of the steps" in note
    assert "0.0333 s apart in the log (30 fps)" in note and "0.170 m per step" in note
    assert "--fps 10 or less" in note
    other = OdometryResult(poses, "icp", tuple(FailedStep(i, "matches") for i in range(1, 8)))
    assert other.warning().endswith("(give the poses, or try another --odometry)")


# ----- item 11: 7-Scenes frames without depth or colour ----------------------------------------
@pytest.mark.parametrize("kind", ["depth", "color"])
def test_seven_scenes_frame_without_an_image(tmp_path, kind):
    root = seven_folder(tmp_path / "s")
    (root / f"frame-000001.{kind}.png").unlink()
    with pytest.raises(SgtoolError, match=rf"1 of 3 frames lack a depth or colour image \(first: "
                       rf"frame-000001\.{kind}\.png is missing\); give --skip-missing"):
        read_sequence(root)
    seq = read_sequence(root, skip_missing=True)
    assert len(seq.frames) == 2 and "skipped 1 frames" in seq.notes[0]


# ----- items 13 and 14: colour images ----------------------------------------------------------
def test_colour_of_another_aspect_ratio_is_refused():
    with pytest.raises(SgtoolError, match="c.jpg: 640x360 pixels, another aspect ratio than the "
                       "640x480 depth images"):
        resize_to(np.zeros((360, 640, 3), np.uint8), 640, 480, "c.jpg")
    assert resize_to(np.zeros((240, 320, 3), np.uint8), 640, 480).shape == (480, 640, 3)


def test_a_truncated_jpeg_is_named(tmp_path):
    p = tmp_path / "c.jpg"
    cv2.imwrite(str(p), np.random.default_rng(0).integers(0, 255, (48, 64, 3), np.uint8))
    assert read_color_file_kind(p)[0].shape == (48, 64, 3)
    p.write_bytes(p.read_bytes()[:-200])
    with pytest.raises(SgtoolError, match="c.jpg: truncated JPEG"):
        read_color_file_kind(p)


@pytest.mark.parametrize("value", [1e300, 1e-300, 0.5])
def test_depth_scale_out_of_range(tmp_path, value):
    with pytest.raises(SgtoolError, match=r"--depth-scale .*: give the raw depth units per "
                       r"metre, a positive number .* from 1 to 1e\+06"):
        import_rgbd(tmp_path, tmp_path / "x.mcap", RgbdOptions(depth_scale=value))


def test_file_names_with_superscripts_sort_as_text() -> None:
    from sgtool.recorders.importers.image_files import natural_key as file_key

    names = ["²1.png", "10.png", "2.png"]  # "²" alone: isdigit() but not int()
    assert sorted(names, key=file_key) == ["2.png", "10.png", "²1.png"]


def test_time_stamp_names_with_fractions_sort_in_time() -> None:
    """A number with a fraction is one decimal number: "X.05" before "X.1" (time order),
    and fixed-width TUM names keep their order; only equal values tie."""
    from sgtool.recorders.importers.image_files import natural_key as file_key

    names = ["1305031103.1.png", "1305031103.05.png", "1305031102.175304.png", "10.png"]
    assert sorted(names, key=file_key) == ["10.png", "1305031102.175304.png",
                                           "1305031103.05.png", "1305031103.1.png"]
    assert file_key("2.5.png") == file_key("2.50.png")
    assert file_key("1305031103.5.png") != file_key("1305031103.05.png")


def test_huge_pose_entries_and_intrinsics_sizes_are_one_line(tmp_path, recwarn) -> None:
    """Finite but huge numbers: no numpy overflow warning before the one-line refusal, no
    OverflowError traceback."""
    import numpy as np
    import pytest

    from sgtool.errors import SgtoolError
    from sgtool.log.codec import rigid_problem
    from sgtool.recorders.importers.textformats import read_intrinsics_file

    m = np.eye(4)
    m[0, 0] = 1e200
    row, why = rigid_problem(m)
    assert row == 0 and "not orthonormal with det +1 (an entry of magnitude 1e+200)" in why
    f = tmp_path / "camera.json"
    f.write_text('{"width": 1e999, "height": 480, "intrinsic_matrix": '
                 '[525, 0, 0, 0, 525, 0, 319.5, 239.5, 1]}')
    with pytest.raises(SgtoolError, match="expected Open3D intrinsics JSON"):
        read_intrinsics_file(f)
    assert not [w for w in recwarn if issubclass(w.category, RuntimeWarning)]


def test_a_trajectory_file_is_read_by_its_content_not_only_its_suffix(tmp_path) -> None:
    """An Open3D .log (any case of the suffix) starts with three frame ids; a TUM
    trajectory that happens to end in .log (eight numbers a line) is read as TUM."""
    from sgtool.recorders.importers.textformats import is_open3d_log

    o3d = tmp_path / "traj.LOG"
    o3d.write_text("0 0 1\n1 0 0 0\n0 1 0 0\n0 0 1 0\n0 0 0 1\n")
    tum = tmp_path / "groundtruth.log"
    tum.write_text("# timestamp tx ty tz qx qy qz qw\n1.0 0 0 0 0 0 0 1\n")
    assert is_open3d_log(o3d) and not is_open3d_log(tum)
    assert not is_open3d_log(tmp_path / "traj.txt") and not is_open3d_log(tmp_path / "x.log")


def test_open3d_pairs_by_name_when_one_name_has_no_partner(tmp_path):
    """A lab that dropped bad frames: depth 00020 and colour 00040 gone; each depth image
    keeps the colour image of its name (not its neighbour's by list position), the one
    without a colour image is said."""
    names = [f"{i:05d}" for i in range(0, 60, 10)]
    root = open3d_folder(tmp_path / "f", names)
    (root / "depth" / "00020.png").unlink()
    (root / "image" / "00040.jpg").unlink()
    write_open3d_log(root / "traj.log", [_pose(float(i)) for i in range(5)])
    seq = read_sequence(root)
    assert [(f.depth_path.stem, f.color_path.stem if f.color_path else None)
            for f in seq.frames] == [("00000", "00000"), ("00010", "00010"),
                                     ("00030", "00030"), ("00040", None), ("00050", "00050")]
    assert "1 depth images have no colour image of their name (first: depth/00040.png)" \
        in seq.notes
    # names of two schemes: paired in order, and said
    root = open3d_folder(tmp_path / "g", ["00000", "00001"])
    for i, p in enumerate(sorted((root / "image").iterdir())):
        p.rename(root / "image" / f"rgb_{i}.jpg")
    seq = read_sequence(root)
    assert [f.color_path.name for f in seq.frames] == ["rgb_0.jpg", "rgb_1.jpg"]
    assert "depth and colour images paired in order (their names differ)" in seq.notes


def test_stray_and_hidden_files_in_depth_are_no_frames(tmp_path):
    """A preview.jpg beside the PNG depth images and macOS's ._00000.png files: no frames
    (the trajectory's 5 poses fit the 5 depth images), the stray file named in a note."""
    names = [f"{i:05d}" for i in range(5)]
    root = open3d_folder(tmp_path / "f", names)
    write_open3d_log(root / "traj.log", [_pose(float(i)) for i in range(5)])
    (root / "depth" / "preview.jpg").write_bytes((root / "image" / "00000.jpg").read_bytes())
    (root / "depth" / "._00000.png").write_bytes(b"\0\5\x16\x07")
    seq = read_sequence(root)
    assert [f.depth_path.name for f in seq.frames] == [f"{n}.png" for n in names]
    assert any("1 file(s) in depth/ are not .png images" in n and "preview.jpg" in n
               for n in seq.notes)
    # a JPEG preview beside every PNG (a tie): the PNGs are the depth, JPEG holds none
    for n in names:
        (root / "depth" / f"{n}.jpg").write_bytes(b"")
    assert [f.depth_path.name for f in read_sequence(root).frames] == \
        [f"{n}.png" for n in names]
    # .tif and .tiff are one type
    tif = open3d_folder(tmp_path / "t", names)
    write_open3d_log(tif / "traj.log", [_pose(float(i)) for i in range(5)])
    for i, n in enumerate(names):
        (tif / "depth" / f"{n}.png").rename(tif / "depth" / f"{n}.{'tif' if i % 2 else 'tiff'}")
    assert len(read_sequence(tif).frames) == 5


def test_seven_scenes_frames_without_a_pose_are_named_and_dropped_or_estimated(tmp_path):
    root = seven_folder(tmp_path / "s", n=4)
    (root / "frame-000002.pose.txt").unlink()
    seq = read_sequence(root)
    assert [f.depth_path.name[:12] for f in seq.frames] == [
        "frame-000000", "frame-000001", "frame-000003"]
    assert seq.dropped == 1 and "1 of 4 frames have no pose.txt, or one of non-finite " \
        "numbers (untracked) (first: frame-000002.depth.png): left out" in seq.notes
    kept = read_sequence(root, keep_unposed=True)  # --estimate-poses
    assert len(kept.frames) == 4 and kept.dropped == 0 and kept.frames[2].pose is None


def test_a_seven_scenes_pose_of_non_finite_numbers_is_an_untracked_frame(tmp_path):
    """ScanNet-style -inf rows mark a frame the tracker lost: it has no pose (left out, or
    estimated with --estimate-poses), rather than stopping the import."""
    root = seven_folder(tmp_path / "s", n=4)
    (root / "frame-000001.pose.txt").write_text("-inf -inf -inf -inf\n" * 4)
    seq = read_sequence(root)
    assert [f.depth_path.name[:12] for f in seq.frames] == [
        "frame-000000", "frame-000002", "frame-000003"]
    assert seq.dropped == 1
    kept = read_sequence(root, keep_unposed=True)
    assert len(kept.frames) == 4 and kept.frames[1].pose is None
    (root / "frame-000001.pose.txt").write_text("# lost\n" + "-inf,-inf,-inf,-inf\n" * 4)
    assert read_sequence(root).dropped == 1  # commas and comments, as read_pose_file reads
    for damaged in ("1 0 0 x\n" * 4, "1 0 0 0\n0 1 0 inf\n", "nan\n"):  # still errors
        (root / "frame-000002.pose.txt").write_text(damaged)
        with pytest.raises(SgtoolError, match="frame-000002.pose.txt"):
            read_sequence(root)


def test_float_depth_files_say_how_to_convert_them(tmp_path):
    from sgtool.recorders.importers.images import read_depth_file

    p = tmp_path / "d.tiff"
    cv2.imwrite(str(p), np.full((H, W), 1.5, np.float32))
    with pytest.raises(SgtoolError, match=r"float32 \(depth in metres\?\); write it as 16-bit "
                       r"millimetres .* --depth-scale 1000"):
        read_depth_file(p)


def test_a_trajectory_without_poses_says_so(tmp_path) -> None:
    from support.rgbd_folders import make_tum_folder

    root = make_tum_folder(tmp_path / "tum", [1.0, 1.1, 1.2])
    (root / "groundtruth.txt").write_text("# timestamp tx ty tz qx qy qz qw\n")
    with pytest.raises(SgtoolError, match=r"groundtruth.txt: holds no poses \(TUM lines"):
        read_sequence(root)
    # poses to be estimated: the frames are kept, as without the file
    assert len(read_sequence(root, keep_unposed=True).frames) == 3


def test_a_problem_of_a_value_given_keeps_it_and_says_so() -> None:
    told: list[str] = []
    findings = Findings(warn=told.append)
    text = ("depth scale 1 units/m (flag --depth-scale) looks wrong: ...; --depth-scale 1000 "
            "fits (median 2.10 m); give it, or --depth-scale 1 to keep this one")
    findings.problem(text, given=True)
    assert told == ["depth scale 1 units/m (flag --depth-scale) looks wrong: ...; "
                    "--depth-scale 1000 fits (median 2.10 m); the value given is kept"]
    with pytest.raises(SgtoolError, match="to keep this one$"):
        findings.problem(text, given=False)


def test_odometry_options_without_estimated_poses_are_a_note(tmp_path) -> None:
    """--odometry and --depth-max shape estimated poses only: beside the dataset's own
    poses they did nothing, and a note says so (the import goes on)."""
    root = open3d_folder(tmp_path / "f", ["0", "1", "2"])
    args = ["import", "rgbd", str(root), "--quiet", "--up", "y", "--floor", "none",
            "--intrinsics", "30,30,15.5,11.5"]
    r = CliRunner().invoke(cli, [*args, "-o", str(tmp_path / "a.mcap"), "--odometry", "icp",
                                 "--depth-max", "3"])
    assert r.exit_code == 0, r.output
    assert "note: --odometry and --depth-max did nothing: no pose was estimated" in r.stderr
    r = CliRunner().invoke(cli, [*args, "-o", str(tmp_path / "b.mcap")])
    assert r.exit_code == 0 and "did nothing" not in r.stderr, r.output


def test_intrinsics_given_as_text_from_python_are_one_line(tmp_path) -> None:
    """RgbdOptions(intrinsics="fx,fy,cx,cy") from Python: a one-line error naming the
    parser, before anything is read (it was an AttributeError while frames were read)."""
    root = open3d_folder(tmp_path / "f", ["0", "1"])
    with pytest.raises(SgtoolError, match=r"^intrinsics: give a PinholeParams "
                       r"\(sgtool.parse_intrinsics reads 'fx,fy,cx,cy' or a file\), got a str$"):
        import_rgbd(root, tmp_path / "x.mcap", RgbdOptions(intrinsics="30,30,15.5,11.5"))
    assert not (tmp_path / "x.mcap").exists()


def test_a_tum_folder_missing_a_list_is_named_not_read_as_another_layout(tmp_path):
    """A TUM folder without rgb.txt (depth.txt and groundtruth.txt there, colour and depth
    folders beside them) was read as an Open3D folder: its time stamps and ground truth
    silently ignored. It is a TUM folder that lacks rgb.txt."""
    from support.rgbd_folders import make_tum_folder

    root = make_tum_folder(tmp_path / "tum", [0.0, 0.1, 0.2])
    (root / "rgb.txt").unlink()
    with pytest.raises(SgtoolError, match="not a TUM RGB-D folder .*: no rgb.txt"):
        read_sequence(root)
    other = make_tum_folder(tmp_path / "tum2", [0.0, 0.1, 0.2], ground_truth=False)
    (other / "depth.txt").unlink()  # rgb.txt alone (a validation sequence): TUM too
    with pytest.raises(SgtoolError, match="not a TUM RGB-D folder .*: no depth.txt"):
        read_sequence(other)


@pytest.mark.parametrize("text", ["600 0 16\n0 600 12\n0 0 1\n", "600,0,16\n0,600,12\n0,0,1\n"])
def test_an_intrinsics_text_file_in_an_open3d_folder_is_read(tmp_path: Path, text) -> None:
    """An intrinsics.txt beside the images (a 3x3 camera matrix) was passed over for
    the PrimeSense default; it is read as --intrinsics reads a file. A text file named for
    something else is not."""
    root = open3d_folder(tmp_path / "f", [str(i) for i in range(3)])
    (root / "notes.txt").write_text("recorded on a Tuesday\n")
    assert read_sequence(root).intrinsics.fx == 525.0  # the PrimeSense default
    (root / "intrinsics.txt").write_text(text)
    k = read_sequence(root).intrinsics
    assert (k.fx, k.fy, k.cx, k.cy, k.source) == (600.0, 600.0, 16.0, 12.0,
                                                 "file intrinsics.txt")


def test_an_open3d_folder_reads_the_depth_cameras_intrinsics_file(tmp_path: Path) -> None:
    """ScanNet-style intrinsic_color.txt and intrinsic_depth.txt beside each other: the
    depth camera's is read (the colour one sorts first); a text file that only has
    "intrinsic" in its name (a README) is not read as intrinsics."""
    root = open3d_folder(tmp_path / "f", [str(i) for i in range(3)])
    (root / "intrinsic_color.txt").write_text("1170 0 16\n0 1170 12\n0 0 1\n")
    (root / "intrinsic_depth.txt").write_text("577 0 16\n0 577 12\n0 0 1\n")
    (root / "intrinsics_README.txt").write_text("fx and fy in pixels\n")
    k = read_sequence(root).intrinsics
    assert (k.fx, k.source) == (577.0, "file intrinsic_depth.txt")


@pytest.mark.parametrize("name", ["camera-intrinsics.txt", "depth_intrinsics.txt",
                                  "Intrinsics.TXT"])
def test_other_names_of_an_intrinsics_file_are_read(tmp_path: Path, name: str) -> None:
    """7-Scenes' and tsdf-fusion's camera-intrinsics.txt, a depth_intrinsics.txt, a name in
    capitals (a Windows tool's): read as the folder's intrinsics (not passed over for the
    PrimeSense default)."""
    root = open3d_folder(tmp_path / "f", [str(i) for i in range(3)])
    (root / name).write_text("600 0 16\n0 600 12\n0 0 1\n")
    assert read_sequence(root).intrinsics.fx == 600.0


def test_a_broken_intrinsics_file_is_not_read_when_the_intrinsics_are_given(
        tmp_path: Path) -> None:
    """--intrinsics overrides what the folder says: a folder whose intrinsics file does not
    read was refused all the same (an outside lab's 7-Scenes copy)."""
    root = open3d_folder(tmp_path / "f", [str(i) for i in range(3)])
    (root / "camera-intrinsics.txt").write_text("600 0 16\n0 600\n")  # a row cut short
    with pytest.raises(SgtoolError, match=r"camera-intrinsics\.txt"):
        read_sequence(root)
    assert read_sequence(root, intrinsics_given=True).frames


@pytest.mark.parametrize("numbers", [16, 12])
def test_a_trajectory_of_a_matrix_a_line_poses_the_frames(tmp_path, numbers: int) -> None:
    """NICE-SLAM's Replica renders keep their poses as traj.txt, a 4x4 matrix a line (KITTI
    a 3x4): beside color/ and depth/ it was passed over without a note (the poses
    estimated) and as --trajectory it was read as TUM ("8 numbers, this one has 16"). It
    poses the frames in order, found by itself or given; a TUM folder takes it as it takes
    a .log, in depth.txt's order."""
    root = open3d_folder(tmp_path / "f", [str(i) for i in range(4)])
    (root / "traj.log").unlink()
    rows = [" ".join(f"{x:g}" for x in _pose(0.5 * i)[: numbers // 4].ravel())
            for i in range(4)]
    (root / "traj.txt").write_text("\n".join(rows) + "\n")
    seq = read_sequence(root)
    assert seq.pose_source == "trajectory" and "poses from traj.txt" in seq.notes
    assert [f.pose[0, 3] for f in seq.frames] == [0.0, 0.5, 1.0, 1.5]
    given = read_sequence(open3d_folder(tmp_path / "g", [str(i) for i in range(4)]),
                          trajectory=root / "traj.txt")
    assert [f.pose[0, 3] for f in given.frames] == [0.0, 0.5, 1.0, 1.5]
    # a line short (a placeholder's line removed): no frame ids say which, refused
    (root / "traj.txt").write_text("\n".join(rows[:2] + rows[3:]) + "\n")
    with pytest.raises(SgtoolError, match=r"traj\.txt has 3 poses for 4 frames; a matrix a "
                       r"line names no frame: one line per frame, in order"):
        read_sequence(root)
    (root / "traj.txt").write_text(rows[0] + "\n" + rows[1] + " 7\n")
    with pytest.raises(SgtoolError, match=r"traj\.txt:2: a line of this trajectory is a pose "
                       r"matrix of 12 or 16 numbers .* this one has " + str(numbers + 1)):
        read_sequence(root)


def test_pose_blocks_removed_with_their_frames_pair_by_their_ids(tmp_path: Path) -> None:
    """A lab removed bad frames 10-14 with their pose blocks: images 0-9 and 15-19, a .log
    whose block ids are the same numbers. Refused ("the frame ids jump from 9 to 15") with
    nothing to do about it; each image takes the block of its number. A block missing for
    an image there is still refused."""
    names = [f"{i:05d}" for i in (*range(10), *range(15, 20))]
    root = open3d_folder(tmp_path / "f", names)
    blocks = []
    for i in (*range(10), *range(15, 20)):
        blocks.append(f"{i} {i} {i + 1}")
        blocks.extend(" ".join(f"{v:.8f}" for v in row) for row in _pose(float(i)))
    (root / "traj.log").write_text("\n".join(blocks) + "\n")
    seq = read_sequence(root)
    assert [f.pose[0, 3] for f in seq.frames] == [float(i) for i in (*range(10),
                                                                     *range(15, 20))]
    assert any("paired with the images by its block ids" in n for n in seq.notes)
    (root / "depth" / "00016.png").rename(root / "depth" / "00012.png")  # no block 12
    (root / "image" / "00016.jpg").rename(root / "image" / "00012.jpg")
    with pytest.raises(SgtoolError, match=r"the frame ids of its pose blocks jump from 9 to 15"):
        read_sequence(root)
