"""`sgtool import rgbd` on the real RGB-D folders (7-Scenes, ICL-NUIM via Open3D, Open3D test
data) and on a TUM RGB-D folder assembled from a real TUM frame and the real fr1_xyz
ground truth: layout detection, association by time stamp, poses against ground truth,
the z-up world, odometry drift, and the messages for folders that are not what they
claim."""

from __future__ import annotations

import json
import os
import shutil
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner
from support.trajectory_files import ns_to_seconds_text

from sgtool.cli import cli
from sgtool.errors import SgtoolError
from sgtool.log import LogReader
from sgtool.log.poses import pose_difference
from sgtool.recorders.importers.layouts import detect_layout, read_sequence
from sgtool.recorders.importers.odometry import drift_against
from sgtool.recorders.importers.rgbd import RgbdOptions, import_rgbd
from sgtool.recorders.importers.sink import IMPORT_METADATA
from sgtool.recorders.importers.textformats import (
    PinholeParams,
    parse_intrinsics,
    read_open3d_log,
    read_tum_trajectory,
    seconds_to_ns,
)

QUIET = dict(progress=False)


def alignment_of(reader: LogReader) -> np.ndarray:
    meta = reader.metadata[IMPORT_METADATA]
    return np.array([float(v) for v in meta["world_alignment"].split()]).reshape(4, 4)


@pytest.fixture
def rgbd_data(shared_data_dir: Path) -> Path:
    return shared_data_dir / "rgbd"


def test_layouts_are_detected(rgbd_data, tmp_path):
    assert detect_layout(rgbd_data / "7scenes-redkitchen-every10") == "7scenes"
    assert detect_layout(rgbd_data / "icl-livingroom1-micro") == "open3d"
    assert detect_layout(rgbd_data / "open3d-testdata") == "open3d"
    seq = read_sequence(rgbd_data / "open3d-testdata")
    assert len(seq.frames) == 5 and seq.notes == ("poses from trajectory.log",)
    (tmp_path / "seq-01").mkdir()
    with pytest.raises(SgtoolError, match="no known RGB-D layout.*seq-01: import one"):
        detect_layout(tmp_path)


# ----- TUM RGB-D --------------------------------------------------------------------------------
def make_tum_folder(data: Path, root: Path, n: int = 30) -> tuple[list[int], list[int]]:
    """A TUM folder: the real TUM frame of the Open3D test data at the first ``n`` camera
    times of fr1_xyz (from the RGBDSLAM estimate), depth 8 ms after colour except the last
    frame (45 ms: no colour within 20 ms), and the real fr1_xyz ground truth."""
    evo = data / "logs" / "evo"
    other = data / "rgbd" / "open3d-testdata" / "other_formats"
    root.mkdir()
    (root / "rgb").mkdir()
    (root / "depth").mkdir()
    cam = [seconds_to_ns(line.split()[0]) for line in
           (evo / "freiburg1_xyz-rgbdslam.txt").read_text().splitlines()
           if line and not line.startswith("#")][:n]
    rgb_lines, depth_lines, depth_t = ["# color images"], ["# depth maps"], []
    for i, t in enumerate(cam):
        td = t + (45_000_000 if i == n - 1 else 8_000_000)
        depth_t.append(td)
        rgb_name, depth_name = f"rgb/{ns_to_seconds_text(t)}.png", \
            f"depth/{ns_to_seconds_text(td)}.png"
        os.symlink(other / "TUM_color.png", root / rgb_name)
        os.symlink(other / "TUM_depth.png", root / depth_name)
        rgb_lines.append(f"{ns_to_seconds_text(t)} {rgb_name}")
        depth_lines.append(f"{ns_to_seconds_text(td)} {depth_name}")
    (root / "rgb.txt").write_text("\n".join(rgb_lines) + "\n")
    (root / "depth.txt").write_text("\n".join(depth_lines) + "\n")
    shutil.copy(evo / "freiburg1_xyz-groundtruth.txt", root / "groundtruth.txt")
    return cam, depth_t


def test_tum_folder_association_and_ground_truth(shared_data_dir, tmp_path):
    root = tmp_path / "rgbd_dataset_freiburg1_xyz"
    _, depth_t = make_tum_folder(shared_data_dir, root)
    out = tmp_path / "tum.mcap"
    rep = import_rgbd(root, out, RgbdOptions(**QUIET))
    assert rep.kind == "rgbd/tum" and rep.frames == 30
    assert rep.notes == ("1 depth images had no colour image within 20 ms",)
    gt = read_tum_trajectory(root / "groundtruth.txt")
    gtt = np.array([t for t, _ in gt], dtype=np.float64)
    gtp = np.array([T[:3, 3] for _, T in gt])
    import cv2

    raw = cv2.imread(str(shared_data_dir / "rgbd" / "open3d-testdata" / "other_formats" /
                         "TUM_depth.png"), cv2.IMREAD_UNCHANGED)
    with LogReader(out) as r:
        A_inv = np.linalg.inv(alignment_of(r))  # noqa: N806
        frames = list(r.frames())
        assert [f.time_ns for f in frames] == depth_t  # the depth stamps, kept
        assert frames[-1].rgb is None and all(f.rgb is not None for f in frames[:-1])
        k = frames[0].intrinsics  # TUM's published freiburg1 calibration
        assert (k.fx, k.fy, k.cx, k.cy) == (517.3, 516.5, 318.6, 255.3)
        # depth in 1/5000 m, stored to the millimetre
        assert np.allclose(frames[0].depth, np.rint(raw / 5.0) / 1000.0, atol=1e-6)
        for f in frames[::7]:
            src = A_inv @ f.pose
            expect = [np.interp(float(f.time_ns), gtt, gtp[:, i]) for i in range(3)]
            assert np.linalg.norm(src[:3, 3] - expect) < 1e-5
        meta = r.metadata[IMPORT_METADATA]
        assert meta["layout"] == "tum" and meta["pose_source"] == "ground truth of the dataset"
        assert meta["depth_scale"] == "5000" and meta["instance_ids"] == "absent"


def test_tum_without_calibration_asks_for_intrinsics(shared_data_dir, tmp_path):
    root = tmp_path / "my_recording"
    make_tum_folder(shared_data_dir, root, n=3)
    with pytest.raises(SgtoolError, match="--intrinsics fx,fy,cx,cy"):
        import_rgbd(root, tmp_path / "o.mcap", RgbdOptions(**QUIET))
    k = parse_intrinsics("525,525,319.5,239.5")
    rep = import_rgbd(root, tmp_path / "o.mcap", RgbdOptions(intrinsics=k, **QUIET))
    assert rep.frames == 3


# ----- 7-Scenes and ICL-NUIM --------------------------------------------------------------------
def test_7scenes_ground_truth_and_z_up_world(rgbd_data, tmp_path):
    folder = rgbd_data / "7scenes-redkitchen-every10"
    out = tmp_path / "kitchen.mcap"
    rep = import_rgbd(folder, out, RgbdOptions(**QUIET))
    assert rep.frames == 100 and rep.pose_source == "ground truth of the dataset"
    a = rep.alignment
    assert a.up_method == "horizontal-normals" and a.floor_method == "horizontal-plane"
    gt = [np.loadtxt(p) for p in sorted(folder.glob("frame-*.pose.txt"))]
    with LogReader(out) as r:
        A = alignment_of(r)  # noqa: N806
        assert np.allclose(A[:3, :3] @ np.array(a.up), [0, 0, 1])
        times = r.frame_times()
        # frame-000990 is the 100th file: Kinect frame n at n / 30 s, and the report says so
        assert times[0] == 0 and times[-1] == round(990 * 1e9 / 30)
        assert any(n.startswith("the frame numbers advance by 10") and "33 s" in n
                   for n in rep.notes), rep.notes
        heights = []
        for i in (0, 33, 99):
            f = r.frame_at(times[i])
            # the dataset's rotations are orthonormal to ~1e-4 only; the log's are exact
            assert np.abs(f.pose - A @ gt[i]).max() < 5e-4
            assert f.intrinsics.fx == 585.0 and f.rgb is not None and f.ids is None
            heights.append(f.pose[2, 3])
            # the camera's optical axis is never pointing up at the ceiling in this sequence
            assert f.pose[2, 2] < 0.2
        # a hand-held Kinect, 1.2-1.7 m above the floor
        assert all(1.1 < h < 1.8 for h in heights), heights
        f = r.frame_at(times[0])
        # points of frame 0 in the z-up world: the lowest surface is the floor at z ~ 0
        k = f.intrinsics
        v, u = np.nonzero(f.depth > 0)
        z = f.depth[v, u]
        pc = np.stack([(u - k.cx) / k.fx * z, (v - k.cy) / k.fy * z, z], 1)
        pw = pc @ f.pose[:3, :3].T + f.pose[:3, 3]
        assert -0.05 < np.percentile(pw[:, 2], 1) < 0.1


def test_icl_livingroom_import(rgbd_data, tmp_path):
    folder = rgbd_data / "icl-livingroom1-micro"
    out = tmp_path / "icl.mcap"
    rep = import_rgbd(folder, out, RgbdOptions(every=3, **QUIET))
    assert rep.frames == 71 and rep.kind == "rgbd/open3d"
    traj = read_open3d_log(folder / "open3d_estimated_trajectory.log")
    with LogReader(out) as r:
        A = alignment_of(r)  # noqa: N806
        frames = list(r.frames())
        assert [f.time_ns for f in frames[:3]] == [0, 100_000_000, 200_000_000]  # 3 / 30 s
        assert pose_difference(frames[5].pose, A @ traj[15])[0] < 1e-6
        assert frames[0].intrinsics.fx == 525.0  # from camera_primesense.json
        # ICL's first camera is level: the world up is its -y, within 3 degrees
        up = np.array(rep.alignment.up)
        assert np.degrees(np.arccos(-up[1])) < 3.0
        assert all(0.2 < f.pose[2, 3] < 1.5 for f in frames)


# ----- odometry --------------------------------------------------------------------------------
def test_odometry_drift_on_7scenes(rgbd_data, tmp_path):
    """Six real Kinect frames (every 10th: 0.17 m of path) by RGB-D odometry + ICP, against
    the 7-Scenes ground truth (measured: ATE 0.8 cm, RPE 0.6 cm / 0.15 deg per frame)."""
    rep = import_rgbd(rgbd_data / "7scenes-redkitchen-every10", tmp_path / "o.mcap",
                      RgbdOptions(estimate_poses=True, limit=6, **QUIET))
    d = rep.drift
    assert d is not None and d.frames == 6 and rep.odometry_failures == 0
    assert 1e-4 < d.ate_rmse_m < 0.03 and d.rpe_translation_m < 0.02
    assert d.rpe_rotation_deg < 1.0
    assert rep.pose_source.startswith("estimated by rgbd+icp odometry")
    assert rep.drift_reference == "ground truth"
    assert any(line.startswith("drift against ground truth: ") for line in rep.lines())
    assert "odometry: 0 of 5 steps failed" in "\n".join(rep.lines())
    with LogReader(tmp_path / "o.mcap") as r:
        meta = r.metadata[IMPORT_METADATA]
        drift = json.loads(meta["odometry_drift"])
        assert drift["ate_rmse_m"] == pytest.approx(d.ate_rmse_m, abs=1e-6)
        assert meta["odometry_drift_reference"] == "ground truth"
        assert json.loads(meta["odometry_failures"])["failed"] == 0


def test_folder_without_poses_is_estimated(rgbd_data, tmp_path):
    """An Open3D layout without a trajectory: poses come from odometry alone (ICP here);
    checked afterwards against the ICL trajectory the folder came with."""
    icl = rgbd_data / "icl-livingroom1-micro"
    root = tmp_path / "noposes"
    (root / "color").mkdir(parents=True)
    (root / "depth").mkdir()
    for i in range(8):
        os.symlink(icl / "image" / f"{i:05d}.jpg", root / "color" / f"{i:05d}.jpg")
        os.symlink(icl / "depth" / f"{i:05d}.png", root / "depth" / f"{i:05d}.png")
    shutil.copy(icl / "camera_primesense.json", root / "intrinsic.json")
    out = tmp_path / "o.mcap"
    rep = import_rgbd(root, out, RgbdOptions(odometry="icp", **QUIET))
    assert rep.frames == 8 and rep.drift is None
    assert rep.pose_source == "estimated by icp odometry"
    ref = read_open3d_log(icl / "open3d_estimated_trajectory.log")[:8]
    with LogReader(out) as r:
        A_inv = np.linalg.inv(alignment_of(r))  # noqa: N806
        est = [A_inv @ f.pose for f in r.frames()]
    assert np.allclose(est[0], np.eye(4), atol=1e-9)  # starts at the identity
    d = drift_against(est, ref)
    assert d.ate_rmse_m < 0.01 and d.final_rotation_deg < 0.5


# ----- messages --------------------------------------------------------------------------------
def test_corrupt_image_leaves_no_output(rgbd_data, tmp_path):
    icl = rgbd_data / "icl-livingroom1-micro"
    root = tmp_path / "broken"
    (root / "image").mkdir(parents=True)
    (root / "depth").mkdir()
    for i in range(4):
        os.symlink(icl / "image" / f"{i:05d}.jpg", root / "image" / f"{i:05d}.jpg")
        os.symlink(icl / "depth" / f"{i:05d}.png", root / "depth" / f"{i:05d}.png")
    (root / "depth" / "00002.png").unlink()
    (root / "depth" / "00002.png").write_bytes(b"not a png")
    shutil.copy(icl / "open3d_estimated_trajectory.log", root / "a.log")
    with pytest.raises(SgtoolError, match="a.log has 211 poses for 4 frames"):
        import_rgbd(root, tmp_path / "o.mcap", RgbdOptions(**QUIET))
    (root / "a.log").unlink()
    out = tmp_path / "o.mcap"
    with pytest.raises(SgtoolError, match=r"00002.png: OpenCV cannot read this image"):
        import_rgbd(root, out, RgbdOptions(odometry="icp", floor_auto=False,
                                           up=np.array([0.0, -1.0, 0.0]), **QUIET))
    assert not out.exists() and not Path(str(out) + ".partial").exists()


def test_cli_rgbd(rgbd_data, tmp_path):
    out = tmp_path / "o.mcap"
    r = CliRunner().invoke(cli, ["import", "rgbd", str(rgbd_data / "open3d-testdata"), "-o",
                                 str(out), "--json", "--quiet", "--up", "y"])
    assert r.exit_code == 0, r.output
    rep = json.loads(r.output)
    assert rep["frames"] == 5 and rep["alignment"]["up_method"] == "given"
    assert rep["kind"] == "rgbd/open3d" and rep["drift"] is None
    assert "poses from trajectory.log" in rep["notes"]
    # poses estimated: the trajectory only measures the drift, and the notes say so
    r = CliRunner().invoke(cli, ["import", "rgbd", str(rgbd_data / "open3d-testdata"), "-o",
                                 str(tmp_path / "e.mcap"), "--json", "--quiet", "--up", "y",
                                 "--estimate-poses"])
    assert r.exit_code == 0, r.output
    notes = json.loads(r.output)["notes"]
    assert "trajectory.log kept to measure the odometry's drift" in notes
    assert not any(n.startswith("poses from") for n in notes)
    r = CliRunner().invoke(cli, ["import", "rgbd", str(rgbd_data / "open3d-testdata"), "-o",
                                 str(tmp_path / "p.mcap"), "--layout", "7scenes"])
    assert r.exit_code == 2 and "not a 7-Scenes folder" in r.output
    assert "Traceback" not in r.output


def test_import_is_byte_identical(rgbd_data, tmp_path):
    """Same folder, same options -> the same bytes (no wall clock, stable order)."""
    outs = []
    for name in ("a.mcap", "b.mcap"):
        import_rgbd(rgbd_data / "7scenes-redkitchen-every10", tmp_path / name,
                    RgbdOptions(every=20, **QUIET))
        outs.append((tmp_path / name).read_bytes())
    assert outs[0] == outs[1]


# ----- audit regressions: layouts, options, the drift's reference -------------------------------
def one_line_error(args: list[str]) -> str:
    """Run the CLI; it must fail with exit code 2 and a one-line message, no traceback."""
    r = CliRunner().invoke(cli, args)
    assert r.exit_code == 2, r.output
    assert isinstance(r.exception, SystemExit) and "Traceback" not in r.output
    lines = r.output.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("sgtool: error: "), r.output
    return lines[0]


LAYOUT_OF = {"a 7-Scenes folder": "7scenes", "an Open3D/Redwood folder": "open3d"}
LAYOUT_MISMATCH = [
    # folder, --layout, what is missing, what the folder looks like
    ("7scenes-redkitchen-every10", "tum", "no rgb.txt and no depth.txt", "a 7-Scenes folder"),
    ("7scenes-redkitchen-every10", "open3d", "no depth/ folder", "a 7-Scenes folder"),
    ("icl-livingroom1-micro", "tum", "no rgb.txt and no depth.txt", "an Open3D/Redwood folder"),
    ("icl-livingroom1-micro", "7scenes", "no frame-XXXXXX.depth.png files",
     "an Open3D/Redwood folder"),
    ("open3d-testdata", "tum", "no rgb.txt and no depth.txt", "an Open3D/Redwood folder"),
    ("open3d-testdata", "7scenes", "no frame-XXXXXX.depth.png files",
     "an Open3D/Redwood folder"),
]


@pytest.mark.parametrize(("name", "layout", "missing", "seen"), LAYOUT_MISMATCH)
def test_folder_of_another_layout_is_a_one_line_error(rgbd_data, tmp_path, name, layout,
                                                      missing, seen):
    """Every layout against every other layout's real folder: a one-line SgtoolError that
    names what is missing and the layout the folder looks like; no output file (was a
    FileNotFoundError traceback for tum and open3d)."""
    out = tmp_path / "x.mcap"
    msg = one_line_error(["import", "rgbd", str(rgbd_data / name), "--layout", layout,
                          "-o", str(out), "--quiet"])
    assert missing in msg and f"it looks like {seen}" in msg, msg
    assert f"use --layout {LAYOUT_OF[seen]}, or --layout auto" in msg
    assert not out.exists() and not Path(str(out) + ".partial").exists()


@pytest.mark.parametrize("layout", ["auto", "tum", "7scenes", "open3d"])
def test_empty_and_half_made_folders(tmp_path, layout):
    """An empty folder in every layout; an Open3D folder whose depth/ is empty; a TUM
    folder without depth.txt; a folder that does not exist (Python API)."""
    empty = tmp_path / "empty"
    empty.mkdir()
    out = tmp_path / "x.mcap"
    msg = one_line_error(["import", "rgbd", str(empty), "--layout", layout, "-o", str(out)])
    assert "no known" in msg or "matches no known layout" in msg, msg
    half = tmp_path / "half"
    (half / "depth").mkdir(parents=True)
    (half / "color").mkdir()
    msg = one_line_error(["import", "rgbd", str(half), "--layout", layout, "-o", str(out)]
                         if layout != "auto" else ["import", "rgbd", str(half), "-o", str(out)])
    expect = {"tum": "no rgb.txt and no depth.txt; it looks like an Open3D/Redwood folder",
              "7scenes": "no frame-XXXXXX.depth.png files; it looks like an Open3D",
              "open3d": "not an Open3D/Redwood folder", "auto": "no images in depth/"}
    assert expect[layout] in msg, msg
    assert not out.exists()
    if layout == "auto":  # depth of another format: said, with what is read
        np.save(half / "depth" / "000000.npy", np.zeros((4, 4), np.float32))
        msg = one_line_error(["import", "rgbd", str(half), "-o", str(out)])
        assert "no images in depth/ (it holds .npy files; depth is read from 16-bit PNG or " \
            "TIFF images)" in msg, msg
        (half / "depth" / "000000.npy").unlink()
    (half / "rgb.txt").write_text("0.0 rgb/a.png\n")
    with pytest.raises(SgtoolError, match=r"not a TUM RGB-D folder .*: no depth.txt"):
        read_sequence(half, "tum")
    with pytest.raises(SgtoolError, match="no such folder"):
        import_rgbd(tmp_path / "nowhere", out, RgbdOptions(layout=layout if layout != "auto"
                                                             else None, **QUIET))


def test_tum_folder_read_in_another_layout(shared_data_dir, tmp_path):
    """A TUM folder (rgb/ and depth/ image folders too): as 7-Scenes an error that points
    at TUM; forced to Open3D it reads, with a note that it looks like TUM."""
    root = tmp_path / "tum"
    make_tum_folder(shared_data_dir, root, n=3)
    msg = one_line_error(["import", "rgbd", str(root), "--layout", "7scenes", "-o",
                          str(tmp_path / "x.mcap")])
    assert "it looks like a TUM RGB-D folder (rgb.txt + depth.txt): use --layout tum" in msg
    seq = read_sequence(root, "open3d")
    assert any("also looks like TUM RGB-D" in n for n in seq.notes)
    assert read_sequence(root).layout == "tum" and not any("looks like" in n for n in
                                                            read_sequence(root).notes)


@pytest.mark.parametrize(("flag", "value"), [
    ("--depth-scale", "-1000"), ("--depth-scale", "0"), ("--depth-scale", "nan"),
    ("--depth-scale", "inf"), ("--fps", "0"), ("--limit", "-1"), ("--max-dt", "-0.01"),
    ("--depth-max", "0"),
])
def test_bad_numeric_options_are_refused(rgbd_data, tmp_path, flag, value):
    """--depth-scale -1000 wrote an all-zero depth log and 0 fell back to the default;
    now both, and other non-positive / non-finite numbers, are one-line errors."""
    out = tmp_path / "x.mcap"
    msg = one_line_error(["import", "rgbd", str(rgbd_data / "open3d-testdata"), "-o",
                          str(out), f"{flag}={value}", "--quiet"])
    assert msg.startswith(f"sgtool: error: {flag} "), msg
    if flag == "--depth-scale":
        assert "a positive number (1000 for millimetres, 5000 for TUM RGB-D)" in msg
    assert not out.exists()


def test_given_depth_scale_is_used(rgbd_data, tmp_path):
    """A valid --depth-scale replaces the layout's: 2000 units per metre halve the depth."""
    depths = []
    for scale in (None, 2000.0):
        out = tmp_path / f"{scale}.mcap"
        import_rgbd(rgbd_data / "open3d-testdata", out,
                    RgbdOptions(depth_scale=scale, limit=1, up=np.array([0.0, -1.0, 0.0]),
                                floor_auto=False, **QUIET))
        with LogReader(out) as r:
            depths.append(next(iter(r.frames())).depth)
    ok = depths[0] > 0
    assert np.allclose(depths[1][ok], depths[0][ok] / 2, atol=1e-3)


def test_drift_against_a_reconstructed_reference_is_not_called_ground_truth(rgbd_data,
                                                                           tmp_path):
    """The Open3D layout's .log (ICL-NUIM's trajectory in the Open3D data) is Open3D's
    reconstruction: the report, JSON and metadata say so; 7-Scenes and TUM keep
    "ground truth" (test_odometry_drift_on_7scenes, test_tum_estimate_reports_ground_truth).
    (The Open3D test data's world has its up along +y: --up y, as auto finds.)"""
    out = tmp_path / "o.mcap"
    r = CliRunner().invoke(cli, ["import", "rgbd", str(rgbd_data / "open3d-testdata"), "-o",
                                 str(out), "--estimate-poses", "--odometry", "icp", "--quiet",
                                 "--up", "y", "--floor", "none"])
    assert r.exit_code == 0, r.output
    ref = "the reference trajectory (reconstructed, not ground truth)"
    assert f"drift against {ref}: 5 frames" in r.output
    assert "ground truth" not in r.output.replace(ref, "")
    with LogReader(out) as log:
        assert log.metadata[IMPORT_METADATA]["odometry_drift_reference"] == ref
    r = CliRunner().invoke(cli, ["import", "rgbd", str(rgbd_data / "open3d-testdata"), "-o",
                                 str(out), "--estimate-poses", "--odometry", "icp", "--quiet",
                                 "--up", "y", "--floor", "none", "--force", "--json"])
    rep = json.loads(r.output)
    assert rep["drift_reference"] == ref and rep["odometry_failures"] == 0
    assert rep["odometry_failure_reasons"] == {"reported": 0, "matches": 0, "motion": 0}


def test_tum_estimate_reports_ground_truth(shared_data_dir, tmp_path):
    root = tmp_path / "rgbd_dataset_freiburg1_xyz"
    make_tum_folder(shared_data_dir, root, n=3)
    rep = import_rgbd(root, tmp_path / "o.mcap",
                      RgbdOptions(estimate_poses=True, odometry="icp", floor_auto=False,
                                  up=np.array([0.0, 0.0, 1.0]), **QUIET))
    assert rep.drift is not None and rep.drift_reference == "ground truth"
    assert any(line.startswith("drift against ground truth: ") for line in rep.lines())


def test_7scenes_names_in_upper_case_are_read(rgbd_data, tmp_path):
    """frame-XXXXXX.depth.PNG (a camera's or another file system's spelling) is the same
    layout: detected, and each frame's files found whatever their case."""
    import shutil

    src = rgbd_data / "7scenes-redkitchen-every10"
    folder = tmp_path / "upper"
    folder.mkdir()
    shutil.copy(src / "camera-intrinsics.txt", folder)
    for n in range(0, 100, 10):
        for kind, ext in (("color", "jpg"), ("depth", "png"), ("pose", "txt")):
            name = f"frame-{n:06d}.{kind}.{ext}"
            shutil.copy(src / name, folder / (name.upper().replace("FRAME", "frame")
                                              if kind == "depth" else name))
    assert detect_layout(folder) == "7scenes"
    rep = import_rgbd(folder, tmp_path / "u.mcap", RgbdOptions(**QUIET))
    assert rep.frames == 10


def test_7scenes_broken_intrinsics_file_gives_way_to_the_flag(rgbd_data, tmp_path):
    """A 7-Scenes copy whose camera-intrinsics.txt does not read: refused (naming it) unless
    --intrinsics is given, which overrides what the folder says."""
    folder = tmp_path / "k"
    shutil.copytree(rgbd_data / "7scenes-redkitchen-every10", folder)
    (folder / "camera-intrinsics.txt").write_text("585 0 320\n")
    with pytest.raises(SgtoolError, match=r"camera-intrinsics\.txt"):
        import_rgbd(folder, tmp_path / "a.mcap", RgbdOptions(limit=3, **QUIET))
    rep = import_rgbd(folder, tmp_path / "b.mcap", RgbdOptions(
        limit=3, intrinsics=PinholeParams(585.0, 585.0, 320.0, 240.0), **QUIET))
    assert rep.frames == 3


def icl_with_poses(rgbd_data: Path, folder: Path, change) -> Path:
    """A copy of the ICL micro folder in ``folder`` whose trajectory's every pose is
    ``change(pose)`` (a convention or a unit another tool writes)."""
    src = rgbd_data / "icl-livingroom1-micro"
    shutil.copytree(src, folder)
    lines = (src / "open3d_estimated_trajectory.log").read_text().split("\n")
    out = []
    for i in range(0, len(lines) - 4, 5):
        if not lines[i].strip():
            break
        pose = np.array([[float(x) for x in lines[i + k].split()] for k in range(1, 5)])
        out += [lines[i], *(" ".join(f"{x:.8f}" for x in row) for row in change(pose))]
    (folder / "open3d_estimated_trajectory.log").write_text("\n".join(out) + "\n")
    return folder


def test_world_to_camera_poses_are_refused_for_what_they_are(rgbd_data, tmp_path):
    """The ICL sequence with its trajectory inverted (world-to-camera): the depth hardly
    moves while the poses do, over every pair checked. The import says the poses are
    wrong, before the floor they would misplace (it blamed the floor, whose advice gave a
    wrong map)."""
    folder = icl_with_poses(rgbd_data, tmp_path / "inverted", np.linalg.inv)
    with pytest.raises(SgtoolError, match=r"look world-to-camera: .* 1\.0\dx as far as "
                                          r"their inverses"):
        import_rgbd(folder, tmp_path / "i.mcap", RgbdOptions(**QUIET, every=3))
    assert not (tmp_path / "i.mcap").exists()
    # the first 10 frames (2.5 cm a pair, under a degree): the inverses' error fits a
    # consistent 0.4x, which was blamed on the depth scale (--depth-scale 420 "fits")
    with pytest.raises(SgtoolError, match=r"look world-to-camera: between \d pairs of nearby "
                                          r"frames the depth moves 0\.\d\dx as far as the "
                                          r"poses, and 1\.00x as far as their inverses"):
        import_rgbd(folder, tmp_path / "i.mcap", RgbdOptions(**QUIET, limit=10))


def test_one_pose_for_every_frame_is_refused_while_the_depth_moves(rgbd_data, tmp_path):
    """The ICL sequence with its first pose repeated for every frame (a trajectory that
    never moves): the depth changes over the sequence, so the import says the poses stand
    still (it imported every view at one place, exit 0); --estimate-poses takes it."""
    seen: list[np.ndarray] = []

    def first(pose: np.ndarray) -> np.ndarray:
        seen.append(pose)
        return seen[0]

    folder = icl_with_poses(rgbd_data, tmp_path / "frozen", first)
    with pytest.raises(SgtoolError, match=r"the poses \(trajectory\) stand still over all 71 "
                                          r"frames while the depth changes \(\d+% of the"):
        import_rgbd(folder, tmp_path / "f.mcap", RgbdOptions(**QUIET, every=3))
    assert not (tmp_path / "f.mcap").exists()
    rep = import_rgbd(folder, tmp_path / "e.mcap",
                      RgbdOptions(**QUIET, every=3, limit=12, estimate_poses=True))
    assert rep.frames == 12


def test_an_up_far_off_the_horizontal_surfaces_is_doubted(rgbd_data, tmp_path):
    """ICL's up is -y; a given up 27 degrees off it (a tilted world every height would
    follow) is kept with a warning naming the surfaces' up; -y itself passes quietly."""
    src = rgbd_data / "icl-livingroom1-micro"
    said: list[str] = []
    tilt = np.radians(27.0)
    off = np.array([0.0, -np.cos(tilt), np.sin(tilt)])
    rep = import_rgbd(src, tmp_path / "t.mcap",
                      RgbdOptions(**QUIET, every=10, up=off, floor=-0.45))
    (warn,) = [w for w in rep.warnings if "degrees off the horizontal" in w]
    assert warn.startswith("--up 0.000,-0.891,0.454 is 2")  # 27-29: the surfaces' own tilt
    assert "give --up -0.0" in warn
    rep = import_rgbd(src, tmp_path / "y.mcap",
                      RgbdOptions(**QUIET, every=10, up=np.array([0.0, -1.0, 0.0])))
    assert not [w for w in rep.warnings if "degrees off" in w or "upside down" in w]
    # +y: the surfaces agree (their normal is found along it), the cameras do not
    rep = import_rgbd(src, tmp_path / "f.mcap",
                      RgbdOptions(**QUIET, every=10, up=np.array([0.0, 1.0, 0.0]),
                                  floor=1.41))
    (warn,) = [w for w in rep.warnings if "upside down" in w]
    assert warn.startswith("--up 0.000,1.000,0.000 points the way the cameras' images point "
                           "down") and "give --up 0.000,-1.000,0.000 or --up auto" in warn
    # z, another axis: said so (it advised the normal of the walls near z as the up)
    with pytest.raises(SgtoolError):  # (the floor check then fails: no floor along z)
        import_rgbd(src, tmp_path / "z.mcap", RgbdOptions(
            every=10, up=np.array([0.0, 0.0, 1.0]), progress=False,
            warn=lambda w: said.append(w)))
    assert [w for w in said if "degrees from the cameras' image up" in w]
    assert not [w for w in said if "off the horizontal surfaces" in w]


@pytest.mark.parametrize(("factor", "unit"), [(100.0, "centimetres"), (1000.0, "millimetres")])
def test_poses_in_centimetres_are_named_so(rgbd_data, tmp_path, factor, unit):
    """A trajectory written in cm or mm: no frame pair matched at metres, so the check had
    no verdict and the floor was blamed (52 m under the camera; the --floor it advised
    gave a map of views 69 m apart, exit 0). The translations read in the unit fit."""
    def scaled(pose: np.ndarray) -> np.ndarray:
        out = pose.copy()
        out[:3, 3] *= factor
        return out

    folder = icl_with_poses(rgbd_data, tmp_path / "units", scaled)
    with pytest.raises(SgtoolError, match=rf"the poses' translations \(trajectory\) look in "
                                          rf"{unit}: .* 1\.0\dx as far as the poses read in"):
        import_rgbd(folder, tmp_path / "u.mcap", RgbdOptions(**QUIET, limit=60))


def test_a_colour_frame_without_depth_is_skipped_with_its_pose(rgbd_data, tmp_path):
    """An Open3D folder whose depth image 00005 is missing: the trajectory has a pose more
    than the frames (refused, naming --skip-missing); with --skip-missing the frame goes
    with its pose and every other frame keeps its own."""
    src = rgbd_data / "icl-livingroom1-micro"
    folder = tmp_path / "gap"
    (folder / "depth").mkdir(parents=True)
    (folder / "image").mkdir()
    for i in range(12):
        shutil.copy(src / "depth" / f"{i:05d}.png", folder / "depth")
        shutil.copy(src / "image" / f"{i:05d}.jpg", folder / "image")
    shutil.copy(src / "camera_primesense.json", folder)
    lines = (src / "open3d_estimated_trajectory.log").read_text().split("\n")
    (folder / "traj.log").write_text("\n".join(lines[:60]) + "\n")
    (folder / "depth" / "00005.png").unlink()
    with pytest.raises(SgtoolError, match=r"has 12 poses for 11 frames .*--skip-missing leaves "
                                          r"them out with their poses"):
        import_rgbd(folder, tmp_path / "a.mcap", RgbdOptions(**QUIET))
    rep = import_rgbd(folder, tmp_path / "b.mcap", RgbdOptions(**QUIET, skip_missing=True,
                                                               floor_auto=False))
    assert rep.frames == 11
    want = [np.array([[float(x) for x in lines[5 * i + k].split()] for k in range(1, 5)])
            for i in range(12) if i != 5]
    with LogReader(tmp_path / "b.mcap") as r:
        got = [f.pose for f in r.frames()]
    back = want[0] @ np.linalg.inv(got[0])  # undoes the import's world alignment (A @ pose)
    assert all(pose_difference(back @ g, w)[0] < 1e-5 for g, w in zip(got, want, strict=True))
    # a trajectory of one pose per RGB-D pair (as Open3D's reconstruction writes) is taken
    # as it is with the flag too (it was refused, the hint naming the flag given)
    kept = [i for i in range(12) if i != 5]
    (folder / "traj.log").write_text("\n".join(
        line for k, i in enumerate(kept)
        for line in (f"{k} {k} {k + 1}", *lines[5 * i + 1:5 * i + 5])) + "\n")
    rep = import_rgbd(folder, tmp_path / "c.mcap", RgbdOptions(**QUIET, skip_missing=True,
                                                               floor_auto=False))
    with LogReader(tmp_path / "c.mcap") as r:
        again = [f.pose for f in r.frames()]
    assert rep.frames == 11 and all(np.allclose(a, g) for a, g in zip(again, got, strict=True))


def test_a_trajectory_that_stops_early_leaves_the_later_frames_out(rgbd_data, tmp_path):
    """An Open3D .log shorter than the frames (a reconstruction that stopped early; it was
    refused, --allow-drop and --limit no way past): the frames after its last pose are
    dropped frames, up to a tenth with a note, more refused without --allow-drop."""
    src = rgbd_data / "icl-livingroom1-micro"
    folder = tmp_path / "short"
    shutil.copytree(src, folder)
    lines = (src / "open3d_estimated_trajectory.log").read_text().split("\n")
    log = folder / "open3d_estimated_trajectory.log"
    log.write_text("\n".join(lines[:5 * 150]) + "\n")
    with pytest.raises(SgtoolError, match=r"61 of 211 frames \(29 %.*--allow-drop"):
        import_rgbd(folder, tmp_path / "a.mcap", RgbdOptions(**QUIET))
    rep = import_rgbd(folder, tmp_path / "b.mcap", RgbdOptions(**QUIET, allow_drop=True,
                                                               every=10))
    assert rep.frames == 15  # frames 0, 10, ..., 140 of the 150 posed
    assert any("61 of 211 frames come after the last pose" in n for n in rep.notes)
    log.write_text("\n".join(lines[:5 * 200]) + "\n")  # 11 short: a note only
    rep = import_rgbd(folder, tmp_path / "c.mcap", RgbdOptions(**QUIET, every=10))
    assert rep.frames == 20 and any("11 of 211 frames come after" in n for n in rep.notes)
    # a frame missing from the numbering (its depth image, or both images): the blocks,
    # handed to the frames in order, posed every later frame with the block before its own
    (folder / "depth" / "00008.png").unlink()
    with pytest.raises(SgtoolError, match=r"200 poses for 210 frames with frames missing "
                       r"from the numbering \(no depth image for image/00008.jpg\): which "
                       r"frames its poses belong to is unclear; give one pose per frame$"):
        import_rgbd(folder, tmp_path / "d.mcap", RgbdOptions(**QUIET))
    (folder / "image" / "00008.jpg").unlink()
    with pytest.raises(SgtoolError, match=r"\(a gap after depth/00007.png\)"):
        import_rgbd(folder, tmp_path / "e.mcap", RgbdOptions(**QUIET))
    assert not (tmp_path / "d.mcap").exists() and not (tmp_path / "e.mcap").exists()


def test_a_trajectory_that_starts_late_poses_the_frames_it_names(rgbd_data, tmp_path):
    """An Open3D .log whose pose blocks start at frame 8 (a reconstruction that started
    late) poses frames 8.. with them, never frames 0.. (they were shifted by 8 frames, with
    a note that the last 8 frames were left out); the frames before are left out with a
    note and keep their times."""
    src = rgbd_data / "icl-livingroom1-micro"
    folder = tmp_path / "late"
    shutil.copytree(src, folder)
    lines = (src / "open3d_estimated_trajectory.log").read_text().split("\n")
    (folder / "open3d_estimated_trajectory.log").write_text(
        "\n".join(lines[5 * 8:5 * 211]) + "\n")
    rep = import_rgbd(folder, tmp_path / "a.mcap", RgbdOptions(**QUIET, limit=40))
    assert any("8 of 211 frames come before the first pose" in n for n in rep.notes)
    want = [np.array([[float(x) for x in lines[5 * i + k].split()] for k in range(1, 5)])
            for i in range(8, 48)]
    with LogReader(tmp_path / "a.mcap") as r:
        frames = list(r.frames())
    got = [f.pose for f in frames]
    assert frames[0].time_ns == round(8 * 1e9 / 30)
    back = want[0] @ np.linalg.inv(got[0])
    assert all(pose_difference(back @ g, w)[0] < 1e-5 for g, w in zip(got, want, strict=True))


def test_a_still_camera_is_not_taken_for_frozen_poses() -> None:
    """Poses that stand still over depth that hardly changes (a camera on a tripod, a
    person walking through a corner of the view) pass; so do poses that move."""
    from sgtool.recorders.importers.scale_check import frozen_poses_problem

    rng = np.random.default_rng(0)
    room = rng.uniform(1.0, 4.0, (48, 64))
    still = [room + rng.normal(0, 0.005, room.shape) for _ in range(5)]
    for k, d in enumerate(still):
        d[10:30, 5 * k:5 * k + 8] = 0.8  # someone walking: 5 % of the pixels
    eye = [np.eye(4)] * 5
    assert frozen_poses_problem(eye, still, "trajectory") is None
    moved = [np.roll(room, 7 * k, axis=1) for k in range(5)]
    text, clear = frozen_poses_problem(eye, moved, "trajectory")
    assert clear and "stand still over all 5 frames" in text
    steps = [np.eye(4) for _ in range(5)]
    for k, p in enumerate(steps):
        p[0, 3] = 0.1 * k
    assert frozen_poses_problem(steps, moved, "trajectory") is None


def test_depth_at_another_scale_is_named_by_the_poses(rgbd_data, tmp_path):
    """7-Scenes depth written at 5000 units/m (TUM's) instead of its 1000: the error names
    5000, which the metric poses fit, not the usual scale whose median depth is nearest
    2 m (4000, which imported with a map 21 % too large)."""
    import shutil

    import cv2

    src = rgbd_data / "7scenes-redkitchen-every10"
    folder = tmp_path / "k5000"
    folder.mkdir()
    shutil.copy(src / "camera-intrinsics.txt", folder)
    for n in range(0, 300, 10):
        for kind, ext in (("color", "jpg"), ("pose", "txt")):
            shutil.copy(src / f"frame-{n:06d}.{kind}.{ext}", folder)
        d = cv2.imread(str(src / f"frame-{n:06d}.depth.png"), cv2.IMREAD_UNCHANGED)
        d = np.where(d == 65535, 65535, np.minimum(d.astype(np.int64) * 5, 65534))
        cv2.imwrite(str(folder / f"frame-{n:06d}.depth.png"), d.astype(np.uint16))
    with pytest.raises(SgtoolError, match=r"--depth-scale 5000 fits"):
        import_rgbd(folder, tmp_path / "k.mcap", RgbdOptions(**QUIET))


def test_a_hand_held_camera_clears_no_body(rgbd_data, tmp_path):
    """An imported recording has a camera but no robot base: nothing stands below a
    hand-held camera, so no voxel is dropped around its path. 7-Scenes' camera passes over
    the kitchen island, which the robot-body rule carved away by an amount that depended
    on how often the graph refreshed (--every 1 against 100: 73 cells)."""
    from sgtool.replayers.derived_log import ReplayOptions, replay

    log = tmp_path / "k.mcap"
    import_rgbd(rgbd_data / "7scenes-redkitchen-every10", log, RgbdOptions(**QUIET))
    grids, cleared = [], []
    for every in (1, 100):
        rep = replay(log, None, ReplayOptions(every=every),
                     on_refresh=lambda r, s: cleared.append(s.builder.cleared_entries))
        grids.append(rep.last.layers.occupancy.grid.tobytes())
    assert cleared and not any(cleared) and grids[0] == grids[1]



def test_cameras_looking_down_keep_their_up_and_an_up_along_their_x_is_named() -> None:
    """A tabletop scan pitched 55 degrees down: the right up (z) is no 'other axis' (its
    image up is 55 degrees off it); an up along the cameras' level x axis is named so."""
    from scipy.spatial.transform import Rotation

    from sgtool.recorders.importers.upright import estimate_alignment, given_up_problem

    level = np.column_stack([[0, -1, 0], [0, 0, -1], [1, 0, 0]]).astype(float)  # looks +x
    pose = np.eye(4)
    pose[:3, :3] = Rotation.from_euler("y", 55, degrees=True).as_matrix() @ level
    pose[2, 3] = 1.2
    def said(up):
        return given_up_problem(estimate_alignment([pose] * 5, [], up=np.array(up)))
    assert said([0.0, 0.0, 1.0]) is None
    text = said([0.0, 1.0, 0.0])
    assert text is not None and "lies within 0 degrees of the cameras' image x axis" in text
