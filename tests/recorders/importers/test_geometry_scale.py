"""The depth scale checked against metric poses: depth in 0.1 mm units read at TUM's 5000
units/m looks indoor by its statistics (2x too deep) but moves twice as far as the ground
truth between nearby frames; the error names --depth-scale 10000, which imports."""

from __future__ import annotations

import numpy as np
import pytest
from support.rgbd_scenes import look_at, make_scene_folder, room

from sgtool.errors import SgtoolError
from sgtool.recorders.importers.rgbd import RgbdOptions, import_rgbd
from sgtool.recorders.importers.scale_check import ScaleFit, geometric_scale_problem, snap_scale
from sgtool.recorders.importers.textformats import PinholeParams

K = PinholeParams(60.0, 60.0, 39.5, 29.5)
# 20 frames walking 2.2 cm a frame through a 5 x 4 m room while turning
POSES = [look_at((-1.0 + 0.02 * i, -0.5 + 0.01 * i, 1.4), (2.5, 1.0 - 0.03 * i, 0.5))
         for i in range(20)]


def test_tenth_millimetre_depth_names_the_scale_that_fits(tmp_path):
    root = make_scene_folder(tmp_path / "f", room(), POSES, units_per_m=10000.0)
    with pytest.raises(SgtoolError, match=r"depth scale 5000 units/m \(dataset default: tum "
                       r"layout\) disagrees with the ground truth: between 6 pairs .* moves "
                       r"2.0\dx as far as the poses.*--depth-scale 10000 fits"):
        import_rgbd(root, tmp_path / "a.mcap", RgbdOptions(intrinsics=K, progress=False))
    assert not (tmp_path / "a.mcap").exists()
    rep = import_rgbd(root, tmp_path / "b.mcap", RgbdOptions(intrinsics=K, progress=False,
                                                             depth_scale=10000.0))
    assert rep.frames == 20 and rep.warnings == ()
    assert abs(rep.alignment.floor) < 0.01  # the true room: the floor at 0, camera 1.4 m up


def test_the_right_scale_passes(tmp_path):
    root = make_scene_folder(tmp_path / "f", room(), POSES, units_per_m=5000.0)
    rep = import_rgbd(root, tmp_path / "a.mcap", RgbdOptions(intrinsics=K, progress=False))
    assert rep.frames == 20 and rep.warnings == ()
    assert dict(rep.checks)["depth scale against the poses"].startswith(
        "depth moves 1.00x as far as the poses over 6 frame pairs")


def test_depth_a_fifth_off_is_named_when_the_pairs_agree(tmp_path):
    """Depth in 1/4000 m (a RealSense L515) read at TUM's 5000: 0.8x, which passed as within
    20 % although every pair agreed within a few percent; the scene was 0.8x its size."""
    root = make_scene_folder(tmp_path / "f", room(), POSES, units_per_m=4000.0)
    with pytest.raises(SgtoolError, match=r"moves 0\.80x as far as the poses .*"
                       r"--depth-scale 4000 fits"):
        import_rgbd(root, tmp_path / "a.mcap", RgbdOptions(intrinsics=K, progress=False))


def test_quaternions_written_scalar_first_are_named(tmp_path):
    """The ground truth's quaternions written qw qx qy qz (read qx qy qz qw): the poses
    turn the wrong way; the import said the poses "may" be in another convention (a
    warning) and then blamed the floor, whose advised --floor imported a wrong map."""
    root = make_scene_folder(tmp_path / "f", room(), POSES)
    gt = root / "groundtruth.txt"
    lines = gt.read_text().splitlines()
    out = [lines[0]]
    for line in lines[1:]:
        t, x, y, z, qx, qy, qz, qw = line.split()
        out.append(" ".join((t, x, y, z, qw, qx, qy, qz)))
    gt.write_text("\n".join(out) + "\n")
    # the translations fit (0.91x, spread 0.31): the surfaces decide
    with pytest.raises(SgtoolError, match=r"the poses' quaternions \(ground truth\) look "
                       r"written w x y z: between 6 pairs of nearby frames the surfaces seen "
                       r"from both meet within 0\.\d mm with them read w x y z, \d+\.\d mm "
                       r"apart read x y z w; .*reorder the columns"):
        import_rgbd(root, tmp_path / "a.mcap", RgbdOptions(intrinsics=K, progress=False))


def test_no_verdict_without_a_clear_consistent_ratio():
    assert geometric_scale_problem(None, 1000.0, "x", "ground truth") is None
    # geometry that does not move (a static scene under moving poses): no verdict
    assert geometric_scale_problem(ScaleFit(0.02, 6, 0.1), 1000.0, "x", "gt") is None
    assert geometric_scale_problem(ScaleFit(2.0, 6, 0.9), 1000.0, "x", "gt") is None  # spread
    assert geometric_scale_problem(ScaleFit(1.1, 6, 0.1), 1000.0, "x", "gt") is None
    # a fifth off, the pairs agreeing closely: named; as loosely agreed, or on 3 pairs: not
    assert "--depth-scale 4000 fits" in str(
        geometric_scale_problem(ScaleFit(0.8, 6, 0.05), 5000.0, "x", "gt"))
    assert geometric_scale_problem(ScaleFit(0.8, 6, 0.2), 5000.0, "x", "gt") is None
    assert geometric_scale_problem(ScaleFit(0.8, 3, 0.05), 5000.0, "x", "gt") is None
    p = geometric_scale_problem(ScaleFit(0.2, 6, 0.1), 1000.0, "x", "gt")
    assert p is None  # at the bound: no verdict
    assert "--depth-scale 5000 fits" in str(
        geometric_scale_problem(ScaleFit(4.9, 6, 0.1), 1000.0, "x", "gt"))
    assert snap_scale(9700.0) == 10000.0 and snap_scale(2345.0) == 2300.0
    # a usual scale is named only within 5 %: 4350 named as 4000 left 9 % that then passed
    assert snap_scale(4350.0) == 4400.0 and snap_scale(4150.0) == 4000.0


def test_a_depth_scale_15_percent_off_is_not_blamed_on_the_poses(tmp_path):
    """Depth stored at 5750 units/m read at 5000 (1.15x, the pairs agreeing closely) on a
    camera that barely turns: the tight tolerance put the poses out, the loose one let
    their inverses or reordered quaternions in, and the remedy named was to invert or
    reorder correct poses."""
    root = make_scene_folder(tmp_path / "f", room(), POSES, units_per_m=5750.0)
    with pytest.raises(SgtoolError, match=r"depth scale 5000 units/m .* moves 1\.1\dx as far "
                       r"as the poses .*--depth-scale 5[78]00 fits"):
        import_rgbd(root, tmp_path / "a.mcap", RgbdOptions(intrinsics=K, progress=False))


def _scene_bag(bag, units_per_m, k=None):  # type: ignore[no-untyped-def]
    """A ROS 1 bag of the room seen from POSES: /tf map -> cam, /info (``k``, else the
    scene's camera), 16UC1 /depth at ``units_per_m``."""
    from support.bag_export import BagWriter
    from support.rgbd_scenes import K as SK
    from support.rgbd_scenes import render

    t0, dt = 1_700_000_000_000_000_000, 33_000_000
    with BagWriter(bag, "ros1") as w:
        for i, pose in enumerate(POSES):
            t = t0 + i * dt
            w.write("/tf", "tf2_msgs/msg/TFMessage", t,
                    w.tf(t, [w.transform_stamped(t, "map", "cam", pose)]))
            w.write("/info", "sensor_msgs/msg/CameraInfo", t,
                    w.camera_info(t, "cam", SK if k is None else k))
            raw = (render(room(), pose) * units_per_m).round().astype("uint16")
            w.write("/depth", "sensor_msgs/msg/Image", t, w.image(t, "cam", raw, "16UC1"))
    return bag


def test_bag_depth_at_half_millimetres_names_the_scale_that_fits(tmp_path):
    """16UC1 depth in 0.5 mm units (ROS says millimetres): 2x too deep, still indoor by its
    statistics; the /tf poses say otherwise."""
    from sgtool.recorders.importers.bag import BagOptions, import_bag

    bag = _scene_bag(tmp_path / "b.bag", 2000.0)
    opts = dict(depth="/depth", info="/info", progress=False)
    with pytest.raises(SgtoolError, match=r"depth scale 1000 units/m \(the image encoding.*\) "
                       r"disagrees with the tf map -> cam: .* moves 2.0\dx as far.*"
                       r"--depth-scale 2000 fits"):
        import_bag(bag, tmp_path / "a.mcap", BagOptions(**opts))
    rep = import_bag(bag, tmp_path / "b.mcap", BagOptions(depth_scale=2000.0, **opts))
    assert rep.frames == 20 and rep.warnings == ()


def test_real_icl_pixels_in_tenth_millimetres_name_10000(shared_data_dir, tmp_path):
    """ICL-NUIM livingroom frames (mm) re-written in 0.1 mm units as a TUM folder with their
    trajectory as ground truth: read at TUM's 5000 they look indoor (2x deep), and the
    geometry names --depth-scale 10000."""
    import cv2
    import numpy as np

    from sgtool.log.poses import tq_from_pose
    from sgtool.recorders.importers.textformats import read_open3d_log

    icl = shared_data_dir / "rgbd" / "icl-livingroom1-micro"
    poses = read_open3d_log(icl / "open3d_estimated_trajectory.log")[:40]
    root = tmp_path / "icl_tum"
    (root / "depth").mkdir(parents=True)
    (root / "rgb").mkdir()
    rgb_l, depth_l, gt = [], [], []
    for i, pose in enumerate(poses):
        t = 100.0 + i / 30
        mm = cv2.imread(str(icl / "depth" / f"{i:05d}.png"), cv2.IMREAD_UNCHANGED)
        cv2.imwrite(str(root / "depth" / f"{i:05d}.png"),
                    (mm.astype(np.uint32) * 10).clip(0, 65535).astype(np.uint16))
        (root / "rgb" / f"{i:05d}.jpg").write_bytes((icl / "image" / f"{i:05d}.jpg").read_bytes())
        rgb_l.append(f"{t:.6f} rgb/{i:05d}.jpg")
        depth_l.append(f"{t:.6f} depth/{i:05d}.png")
        tr, q = tq_from_pose(pose)
        gt.append(f"{t:.6f} " + " ".join(f"{v:.9f}" for v in (*tr, *q)))
    for name, lines in (("rgb.txt", rgb_l), ("depth.txt", depth_l), ("groundtruth.txt", gt)):
        (root / name).write_text("\n".join(lines) + "\n")
    k = PinholeParams(525.0, 525.0, 319.5, 239.5)
    with pytest.raises(SgtoolError, match=r"depth scale 5000 units/m .* disagrees with the "
                       r"ground truth.*--depth-scale 10000 fits"):
        import_rgbd(root, tmp_path / "a.mcap", RgbdOptions(intrinsics=k, progress=False))
    rep = import_rgbd(root, tmp_path / "b.mcap", RgbdOptions(intrinsics=k, progress=False,
                                                             depth_scale=10000.0))
    assert rep.frames == 40 and rep.warnings == ()


def _rewrite_ground_truth(root, change):
    lines = (root / "groundtruth.txt").read_text().splitlines()
    out = [lines[0]]
    for line in lines[1:]:
        t, *v = line.split()
        out.append(" ".join([t, *change([float(x) for x in v])]))
    (root / "groundtruth.txt").write_text("\n".join(out) + "\n")


def test_poses_in_another_convention_are_caught(tmp_path):
    """A ground truth written world-to-camera: between nearby frames the depth moves
    against the poses (the scale check's fit is negative), so the import refuses in one
    line naming the usual causes; with --estimate-poses (the ground truth only measures
    the drift) it is a warning."""
    import numpy as np
    from scipy.spatial.transform import Rotation

    def inverted(v):
        m = np.eye(4)
        m[:3, :3] = Rotation.from_quat(v[3:]).as_matrix()
        m[:3, 3] = v[:3]
        inv = np.linalg.inv(m)
        return [f"{x:.9f}" for x in (*inv[:3, 3], *Rotation.from_matrix(inv[:3, :3]).as_quat())]

    root = make_scene_folder(tmp_path / "inv", room(), POSES, units_per_m=5000.0)
    _rewrite_ground_truth(root, inverted)
    with pytest.raises(SgtoolError, match=r"the poses \(ground truth\) look world-to-camera: "
                       r"between 6 pairs .* moves -1\.\d\dx on average, the pairs "
                       r"disagreeing, as far as the poses, and 1\.0\dx as far as their "
                       r"inverses; .*give --world-to-camera to invert them, or --estimate-poses"):
        import_rgbd(root, tmp_path / "a.mcap", RgbdOptions(intrinsics=K, progress=False))
    assert not (tmp_path / "a.mcap").exists()
    rep = import_rgbd(root, tmp_path / "est.mcap",
                      RgbdOptions(intrinsics=K, progress=False, estimate_poses=True))
    assert rep.frames == 20 and any("do not move as the depth does" in w for w in rep.warnings)


def test_pose_motion_problem_needs_a_clear_disagreement():
    from sgtool.recorders.importers.scale_check import pose_motion_problem

    assert pose_motion_problem(None, "gt") is None
    assert pose_motion_problem(ScaleFit(1.0, 6, 0.05), "gt") is None  # they agree
    assert pose_motion_problem(ScaleFit(-0.4, 1, float("inf")), "gt") is None  # one pair
    assert pose_motion_problem(ScaleFit(2.0, 6, 0.1), "gt") is None  # the scale's problem
    assert pose_motion_problem(ScaleFit(40.0, 6, 0.1), "gt") is None  # the scale's, too
    text, clear = pose_motion_problem(ScaleFit(-0.4, 5, float("inf")), "gt")
    assert clear and "-0.40x" in text
    text, clear = pose_motion_problem(ScaleFit(1.07, 5, 0.65), "gt")
    assert not clear and "up to 65% apart" in text
    # depth standing still while the poses move, the pairs disagreeing (world-to-camera
    # poses of a real sequence: 0.14x, spread 9.17): clear over 3 pairs, likely over 2
    text, clear = pose_motion_problem(ScaleFit(0.14, 6, 9.17, step_m=0.066), "gt")
    assert clear and "hardly moves (0.14x as far as the poses)" in text
    assert pose_motion_problem(ScaleFit(0.05, 2, 84.0, step_m=0.066), "gt")[1] is False  # type: ignore[index]
    # a camera panning on a tripod (2.5 cm a pair, hidden by depth noise): likely only
    assert pose_motion_problem(ScaleFit(-0.04, 5, 37.0, step_m=0.025), "gt")[1] is False  # type: ignore[index]
    assert pose_motion_problem(ScaleFit(0.1, 6, 0.2), "gt") is None  # a scale: the pairs agree


def test_a_five_hertz_ground_truth_is_interpolated(tmp_path):
    """A ground truth at 5 Hz (a SLAM system's, not a motion-capture system's 100 Hz) was
    refused as not covering the frames' time: the folder reader interpolated over gaps of
    0.1 s only. Gaps of 2.5 of the trajectory's steps are bridged (to 0.5 s)."""
    from sgtool.log import LogReader

    root = make_scene_folder(tmp_path / "f", room(), POSES)  # 30 fps, ground truth per frame
    gt = root / "groundtruth.txt"
    lines = gt.read_text().splitlines()
    gt.write_text("\n".join([lines[0], *lines[1::6]]) + "\n")  # every 6th pose: 5 Hz
    rep = import_rgbd(root, tmp_path / "a.mcap", RgbdOptions(intrinsics=K, progress=False))
    assert rep.frames == 19  # frames 0 to 18 lie within the trajectory's span (0 to 18)
    with LogReader(tmp_path / "a.mcap") as r:
        first = next(iter(r.frames()))
    assert first.pose is not None


def test_an_uncalibrated_camera_info_names_the_flag_that_helps(tmp_path):
    """A CameraInfo whose K is all zeros (a driver that was never calibrated): refused
    without a word of --intrinsics, which imports it."""
    import dataclasses

    from support.rgbd_scenes import K as SK

    from sgtool.recorders.importers.bag import BagOptions, import_bag

    zero = dataclasses.replace(SK, fx=0.0, fy=0.0, cx=0.0, cy=0.0)
    bag = _scene_bag(tmp_path / "b.bag", 1000.0, zero)
    with pytest.raises(SgtoolError, match=r"no usable focal length .*give its intrinsics "
                       r"with --intrinsics fx,fy,cx,cy"):
        import_bag(bag, tmp_path / "a.mcap", BagOptions(depth="/depth", info="/info",
                                                        progress=False))


def test_an_openexr_depth_image_is_named(tmp_path):
    from sgtool.recorders.importers.images import read_depth_file

    f = tmp_path / "d.exr"
    f.write_bytes(b"\x76\x2f\x31\x01" + bytes(60))
    with pytest.raises(SgtoolError, match=r"OpenEXR, which this OpenCV build does not "
                       r"decode\): store depth as 16-bit PNG"):
        read_depth_file(f)


def test_poses_of_the_cameras_body_frame_are_named(tmp_path):
    """A ROS user whose tf has only camera_link (x forward, z up): its poses were blamed on
    "another convention" in a warning, then the floor error's --floor wrote a wrong map."""
    import numpy as np

    from sgtool.recorders.importers.pose_axes import BODY_T_OPTICAL

    body = [p @ np.linalg.inv(BODY_T_OPTICAL) for p in POSES]
    root = make_scene_folder(tmp_path / "f", room(), POSES)
    gt = root / "groundtruth.txt"
    from scipy.spatial.transform import Rotation

    lines = gt.read_text().splitlines()
    out = [lines[0]]
    for line, pose in zip(lines[1:], body, strict=True):
        q = Rotation.from_matrix(pose[:3, :3]).as_quat()
        out.append(" ".join([line.split()[0], *(f"{x:.9f}" for x in pose[:3, 3]),
                             *(f"{x:.9f}" for x in q)]))
    gt.write_text("\n".join(out) + "\n")
    with pytest.raises(SgtoolError, match=r"look like those of a camera frame with body axes "
                       r"\(x forward, y left, z up: ROS's camera_link\).* and 1\.0\dx as far "
                       r"as the optical frame they imply; give --camera-axes body"):
        import_rgbd(root, tmp_path / "a.mcap", RgbdOptions(intrinsics=K, progress=False))
    rep = import_rgbd(root, tmp_path / "b.mcap", RgbdOptions(intrinsics=K, progress=False,
                                                            camera_axes="body"))
    assert rep.frames == len(POSES)
    assert dict(rep.checks)["depth scale against the poses"].startswith("depth moves 1.0")


def _posed_as(root, convert) -> None:
    """The folder's ground truth rewritten with each pose turned by ``convert``."""
    import numpy as np
    from scipy.spatial.transform import Rotation

    def turned(v):
        m = np.eye(4)
        m[:3, :3] = Rotation.from_quat(v[3:]).as_matrix()
        m[:3, 3] = v[:3]
        c = convert(m)
        return [f"{x:.9f}" for x in (*c[:3, 3], *Rotation.from_matrix(c[:3, :3]).as_quat())]

    _rewrite_ground_truth(root, turned)


GL = np.diag([1.0, -1.0, -1.0, 1.0])  # NeRF's and Blender's camera: y up, looking along -z


@pytest.mark.parametrize(("convert", "flags", "named"), [
    (lambda m: m @ GL, dict(camera_axes="opengl"), "give --camera-axes opengl to read them so"),
    (np.linalg.inv, dict(world_to_camera=True), "give --world-to-camera to invert them"),
    (lambda m: np.linalg.inv(m @ GL), dict(world_to_camera=True, camera_axes="opengl"),
     "give --camera-axes opengl --world-to-camera to read them so"),
], ids=["opengl", "world-to-camera", "both"])
def test_poses_of_another_convention_import_with_the_flag_named(tmp_path, convert, flags,
                                                                named):
    """Poses written in another camera frame's axes, world-to-camera, or both: the refusal
    names the flags that read them, and with them the frames are posed as the ground
    truth is."""
    from sgtool.log.reader import LogReader

    plain = make_scene_folder(tmp_path / "plain", room(), POSES)
    import_rgbd(plain, tmp_path / "plain.mcap", RgbdOptions(intrinsics=K, progress=False))
    root = make_scene_folder(tmp_path / "f", room(), POSES)
    _posed_as(root, convert)
    with pytest.raises(SgtoolError, match=named):
        import_rgbd(root, tmp_path / "a.mcap", RgbdOptions(intrinsics=K, progress=False))
    rep = import_rgbd(root, tmp_path / "b.mcap", RgbdOptions(intrinsics=K, progress=False,
                                                            **flags))
    assert any(n.startswith("poses read as given: ") for n in rep.notes)
    with LogReader(tmp_path / "plain.mcap") as a, LogReader(tmp_path / "b.mcap") as b:
        for fa, fb in zip(a.frames(), b.frames(), strict=True):
            assert np.allclose(fa.pose, fb.pose, atol=1e-6)


def test_a_floor_error_after_doubted_poses_says_to_fix_the_poses_first():
    from sgtool.recorders.importers.provenance import Findings

    f = Findings()
    text = "the floor is not clear ...; give the floor's height with --floor"
    assert f.floor_doubt(text) == text and f.floor_doubt(None) is None
    f.warning("the poses (ground truth) do not move as the depth does: ...")
    assert f.floor_doubt(text).endswith(
        "; but the poses were doubted above: wrong poses misplace the floor too, so fix "
        "them (or give --estimate-poses) before giving --floor")


@pytest.mark.parametrize(("flags", "advice"), [
    (dict(camera_axes="opengl"), "read them with neither --camera-axes nor --world-to-camera "
                                 "instead of --camera-axes opengl"),
    (dict(world_to_camera=True), "read them with neither --camera-axes nor --world-to-camera "
                                 "instead of --world-to-camera"),
])
def test_a_convention_flag_given_wrongly_is_named_as_given(tmp_path, flags, advice) -> None:
    """Poses in sgtool's convention read with a convention flag they do not need: the
    refusal names the flags that read them, not the flag already given (following that
    advice went round in a circle)."""
    root = make_scene_folder(tmp_path / "f", room(), POSES)
    with pytest.raises(SgtoolError) as e:
        import_rgbd(root, tmp_path / "a.mcap", RgbdOptions(intrinsics=K, progress=False,
                                                          **flags))
    assert advice in str(e.value), str(e.value)


def test_convention_flags_for_a_folder_without_poses_are_refused(tmp_path) -> None:
    """A folder without poses has them estimated: --camera-axes/--world-to-camera would be
    ignored (and the report said the poses were read so): one line."""
    root = make_scene_folder(tmp_path / "f", room(), POSES)
    (root / "groundtruth.txt").unlink()
    with pytest.raises(SgtoolError, match=r"^--camera-axes and --world-to-camera: .* has no "
                       r"poses to read \(they are estimated from the depth\); leave them out$"):
        import_rgbd(root, tmp_path / "a.mcap", RgbdOptions(
            intrinsics=K, progress=False, camera_axes="opengl", world_to_camera=True))


def test_a_wrong_axes_flag_over_other_axes_is_named(shared_data_dir, tmp_path) -> None:
    """Real 7-Scenes poses rewritten as ROS camera_link's, read with --camera-axes opengl:
    no single turn on top of that reading is one of the named axes, so the check said only
    "do not move as the depth does"; the poses as written are tried now, and the advice
    names the flag to give instead of the one given."""
    import shutil

    from sgtool.recorders.importers.pose_axes import BODY_T_OPTICAL

    root = tmp_path / "kitchen"
    shutil.copytree(shared_data_dir / "rgbd" / "7scenes-redkitchen-every10", root)
    for f in sorted(root.glob("frame-*.pose.txt")):
        np.savetxt(f, np.loadtxt(f) @ np.linalg.inv(BODY_T_OPTICAL))
    with pytest.raises(SgtoolError, match=r"look like those of a camera frame with body axes "
                       r".*, not of the opengl axes --camera-axes opengl reads: .* read them "
                       r"with --camera-axes body instead of --camera-axes opengl"):
        import_rgbd(root, tmp_path / "a.mcap", RgbdOptions(progress=False, limit=50,
                                                          camera_axes="opengl"))
