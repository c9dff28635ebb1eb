"""`sgtool import bag`: round trips through ROS 1 / ROS 2 sqlite3 / ROS 2 MCAP bags, camera
poses from tf checked against the TUM RGB-D ground truth, the real evo and Nav2 bags, and
the messages for bags and flags that are not what they claim."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner
from mcap.writer import IndexType, Writer
from support.bag_export import BagWriter, write_frames_bag, write_log_as_bag
from support.logfixtures import synthetic_frame

from sgtool.cli import cli
from sgtool.errors import SgtoolError
from sgtool.log import LogReader, LogWriter
from sgtool.log.frame import Frame
from sgtool.log.poses import pose_difference, pose_from_tq
from sgtool.recorders.importers.bag import BagOptions, import_bag, read_trajectory
from sgtool.recorders.importers.sink import IMPORT_METADATA
from sgtool.recorders.importers.textformats import read_tum_trajectory, seconds_to_ns

FORMATS = ["ros1", "ros2-sqlite3", "ros2-mcap"]
TOPICS = dict(depth="/camera/depth/image_raw", rgb="/camera/rgb/image_raw",
              ids="/camera/instances/image_raw", info="/camera/depth/camera_info")
KEEP_WORLD = dict(up=np.array([0.0, 0.0, 1.0]), floor_auto=False, progress=False)


def bag_path(tmp: Path, fmt: str, name: str = "b") -> Path:
    return tmp / (f"{name}.bag" if fmt == "ros1" else f"{name}_{fmt}")


def write_sgtool_log(path: Path, n: int = 8) -> Path:
    with LogWriter(path, seed=1) as w:
        for i in range(n):
            k, rgb, depth, ids, pose, _ = synthetic_frame(i)
            w.write_frame(1_700_000_000_000_000_000 + i * 33_333_333, depth=depth, pose=pose,
                          intrinsics=k, rgb=rgb, ids=ids)
    return path


# ----- round trip ------------------------------------------------------------------------------
@pytest.mark.parametrize("fmt", FORMATS)
def test_round_trip_sgtool_log_through_a_bag(tmp_path, fmt):
    src = write_sgtool_log(tmp_path / "src.mcap")
    bag = bag_path(tmp_path, fmt)
    assert write_log_as_bag(src, bag, fmt) == 8
    out = tmp_path / "back.mcap"
    rep = import_bag(bag, out, BagOptions(**TOPICS, **KEEP_WORLD))
    assert rep.frames == 8 and rep.has_rgb and rep.has_ids
    with LogReader(src) as a, LogReader(out) as b:
        fa, fb = list(a.frames()), list(b.frames())
        assert len(fa) == len(fb) == 8
        for x, y in zip(fa, fb, strict=True):
            assert x.time_ns == y.time_ns  # header stamps kept, to the nanosecond
            assert np.array_equal(x.depth, y.depth)  # millimetres, bit-exact
            assert np.array_equal(x.rgb, y.rgb) and np.array_equal(x.ids, y.ids)
            assert x.intrinsics == y.intrinsics
            dt, dr = pose_difference(x.pose, y.pose)
            assert dt < 1e-9 and dr < 1e-6
        meta = b.metadata[IMPORT_METADATA]
        assert meta["source_kind"] == ("bag/ros1" if fmt == "ros1" else "bag/ros2")
        assert meta["instance_ids"] == "present"
        assert b.last_record("episode")["kind"] == "import"


def test_a_ros1_bag_by_another_name_is_read(tmp_path):
    """ROS 1 bags are known by their first bytes, not their name (export bag -o NAME
    --format ros1 writes one without .bag)."""
    src = write_sgtool_log(tmp_path / "src.mcap", n=3)
    bag = bag_path(tmp_path, "ros1")
    assert write_log_as_bag(src, bag, "ros1") == 3
    renamed = bag.rename(tmp_path / "recording")
    rep = import_bag(renamed, tmp_path / "back.mcap", BagOptions(**TOPICS, **KEEP_WORLD))
    assert rep.frames == 3
    with LogReader(tmp_path / "back.mcap") as r:
        assert r.metadata[IMPORT_METADATA]["source_kind"] == "bag/ros1"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["back.mcap", "recording", "src.mcap"]


def test_round_trip_with_png_colour_and_automatic_world(tmp_path):
    """CompressedImage colour decodes losslessly (PNG); the automatic alignment of the
    synthetic scene (camera 1.2 m above a floor at z = 0, world already z-up) is the
    identity to within a degree and a centimetre."""
    src = write_sgtool_log(tmp_path / "src.mcap", n=6)
    bag = bag_path(tmp_path, "ros2-mcap")
    write_log_as_bag(src, bag, "ros2-mcap", rgb_format="png")
    out = tmp_path / "back.mcap"
    rep = import_bag(bag, out, BagOptions(depth=TOPICS["depth"], rgb=TOPICS["rgb"],
                                          info=TOPICS["info"], progress=False))
    assert not rep.has_ids
    a = rep.alignment
    assert np.degrees(np.arccos(a.up[2])) < 1.0 and abs(a.floor) < 0.01
    with LogReader(src) as r1, LogReader(out) as r2:
        for x, y in zip(r1.frames(), r2.frames(), strict=True):
            assert np.array_equal(x.rgb, y.rgb) and y.ids is None
            assert pose_difference(x.pose, y.pose)[0] < 0.01


# ----- TUM ground truth through tf --------------------------------------------------------------
OPTICAL_IN_BODY = pose_from_tq((0.02, -0.045, 0.01), (0.5, -0.5, 0.5, -0.5))  # a camera mount


def write_tum_bag(evo: Path, path: Path, fmt: str) -> tuple[list[int], list]:
    """A bag as a Kinect + motion capture recording of TUM fr1_xyz would be: /tf
    world -> kinect_body at the ground-truth times (100 Hz), /tf_static kinect_body ->
    optical frame, and 16UC1 depth images with CameraInfo at the real camera times (those of
    the RGBDSLAM estimate). The ground truth is the optical frame's pose, so the body's pose
    is gt @ inv(mount)."""
    gt = read_tum_trajectory(evo / "freiburg1_xyz-groundtruth.txt")
    cam_times = [seconds_to_ns(line.split()[0]) for line in
                 (evo / "freiburg1_xyz-rgbdslam.txt").read_text().splitlines()
                 if line and not line.startswith("#")]
    inv_mount = np.linalg.inv(OPTICAL_IN_BODY)
    events = [(t, 0, T) for t, T in gt] + [(t, 1, None) for t in cam_times]  # noqa: N806
    events.sort(key=lambda e: (e[0], e[1]))
    depth = np.full((6, 8), 1500, np.uint16)
    with BagWriter(path, fmt) as w:
        w.write("/tf_static", "tf2_msgs/msg/TFMessage", events[0][0], w.tf(0, [
            w.transform_stamped(events[0][0], "kinect_body", "openni_rgb_optical_frame",
                                OPTICAL_IN_BODY)]))
        Info = w.T("sensor_msgs/msg/CameraInfo")  # noqa: N806
        for t, kind, T in events:  # noqa: N806
            if kind == 0:
                w.write("/tf", "tf2_msgs/msg/TFMessage", t,
                        w.tf(t, [w.transform_stamped(t, "world", "kinect_body", T @ inv_mount)]))
            else:
                w.write("/camera/depth/image", "sensor_msgs/msg/Image", t,
                        w.image(t, "openni_rgb_optical_frame", depth, "16UC1"))
                k = np.array([5.0, 0, 3.5, 0, 5.0, 2.5, 0, 0, 1])
                names = [n for n, _ in w.ts.fielddefs["sensor_msgs/msg/CameraInfo"][1]]
                up = "K" in names
                kw = {("K" if up else "k"): k, ("D" if up else "d"): np.zeros(0),
                      ("R" if up else "r"): np.eye(3).ravel(),
                      ("P" if up else "p"): np.zeros(12)}
                roi = w.T("sensor_msgs/msg/RegionOfInterest")(
                    x_offset=0, y_offset=0, height=0, width=0, do_rectify=False)
                w.write("/camera/depth/camera_info", "sensor_msgs/msg/CameraInfo", t, Info(
                    header=w.header(t, "openni_rgb_optical_frame"), height=6, width=8,
                    distortion_model="plumb_bob", binning_x=0, binning_y=0, roi=roi, **kw))
    return cam_times, gt


def gt_at(gt: list, t: int) -> tuple[np.ndarray, float]:
    """Independent check value: the ground truth position linearly interpolated per axis,
    and the rotation angle between the two bracketing samples (a bound)."""
    times = np.array([s for s, _ in gt], dtype=np.float64)
    pos = np.array([T[:3, 3] for _, T in gt])
    p = np.array([np.interp(float(t), times, pos[:, i]) for i in range(3)])
    j = int(np.searchsorted(times, t))
    return p, pose_difference(gt[j - 1][1], gt[j][1])[1]


@pytest.mark.parametrize("fmt", FORMATS)
def test_tf_poses_against_tum_ground_truth(shared_data_dir, tmp_path, fmt):
    evo = shared_data_dir / "logs" / "evo"
    bag = bag_path(tmp_path, fmt, "fr1_xyz")
    cam_times, gt = write_tum_bag(evo, bag, fmt)
    out = tmp_path / "fr1_xyz.mcap"
    rep = import_bag(bag, out, BagOptions(depth="/camera/depth/image",
                                          info="/camera/depth/camera_info", **KEEP_WORLD))
    # every camera frame of fr1_xyz lies inside the ground truth's span
    assert len(cam_times) == 788 and gt[0][0] < cam_times[0] and cam_times[-1] < gt[-1][0]
    assert rep.frames == 788 and rep.pose_source == "tf world -> openni_rgb_optical_frame"
    with LogReader(out) as r:
        times = r.frame_times()
        assert times == sorted(cam_times)
        for i in (0, 100, 401, 787):
            fr = r.frame_at(times[i])
            p, bracket_deg = gt_at(gt, fr.time_ns)
            assert np.linalg.norm(fr.pose[:3, 3] - p) < 1e-6
            j = int(np.searchsorted([s for s, _ in gt], fr.time_ns))
            ang0 = pose_difference(gt[j - 1][1], fr.pose)[1]
            ang1 = pose_difference(gt[j][1], fr.pose)[1]
            assert ang0 <= bracket_deg + 1e-6 and ang1 <= bracket_deg + 1e-6
            assert fr.intrinsics.fx == 5.0 and fr.depth[0, 0] == pytest.approx(1.5)


# ----- the real bags of evo and Nav2 -----------------------------------------------------------
FIRST_ODOM = (1714741164177519307, (1.1603796887148006, -2.942426888388735, 0.0),
              (0.0, 0.0, 0.6808039454578293, 0.7324656905610344))


@pytest.mark.parametrize("name", ["tf_example.bag", "tf_example", "tf_example/tf_example.db3"])
def test_evo_tf_bags_ros1_and_ros2(shared_data_dir, tmp_path, name):
    """The same TurtleBot run as a ROS 1 bag, a ROS 2 sqlite3 bag folder and its bare .db3:
    517 odom -> base_footprint samples (+ a static base_link), so 517 poses of base_link,
    the first equal to the first /tf message."""
    bag = shared_data_dir / "logs" / "evo" / name
    out = tmp_path / "traj.mcap"
    rep = import_bag(bag, out, BagOptions(tf_frames=("odom", "base_link"), progress=False))
    assert rep.frames == 0 and rep.poses == 517
    traj = read_trajectory(out)
    assert len(traj) == 517
    t0, T0 = traj[0]  # noqa: N806
    assert t0 == FIRST_ODOM[0]
    dt, dr = pose_difference(T0, pose_from_tq(FIRST_ODOM[1], FIRST_ODOM[2]))
    assert dt < 1e-12 and dr < 1e-6
    assert all(abs(T[2, 3]) < 1e-9 for _, T in traj)  # a ground robot


def test_evo_ros1_and_ros2_bags_give_the_same_trajectory(shared_data_dir, tmp_path):
    evo = shared_data_dir / "logs" / "evo"
    trajs = []
    for name in ("tf_example.bag", "tf_example"):
        out = tmp_path / f"{name.replace('.', '_')}.mcap"
        import_bag(evo / name, out, BagOptions(tf_frames=("odom", "base_link"), progress=False))
        trajs.append(read_trajectory(out))
    assert [t for t, _ in trajs[0]] == [t for t, _ in trajs[1]]
    assert max(pose_difference(a, b)[0] for (_, a), (_, b) in zip(*trajs, strict=True)) < 1e-12


def test_evo_pose_topic_trajectory(shared_data_dir, tmp_path):
    bag = shared_data_dir / "logs" / "evo" / "ROS_example.bag"
    out = tmp_path / "gt.mcap"
    rep = import_bag(bag, out, BagOptions(pose="groundtruth", progress=False))
    assert rep.poses == 12765
    traj = read_trajectory(out)
    assert len(traj) == 12765 and traj[0][0] == 1502792570283404827
    assert np.allclose(traj[0][1][:3, 3], [-0.004899939787714927, -0.01775981455685227,
                                           -0.013755318406774505], atol=1e-12)


def test_nav2_bare_ros2_mcap_through_a_tf_chain(shared_data_dir, tmp_path):
    """A bare ROS 2 MCAP file (no metadata.yaml): map -> odom (AMCL) -> base_link (odometry)
    -> base_footprint (static): a planar robot path of plausible speed."""
    bag = shared_data_dir / "logs" / "rosbag2-mcap" / "evo_nav2_turtlebot.mcap"
    out = tmp_path / "nav2.mcap"
    rep = import_bag(bag, out, BagOptions(tf_frames=("map", "base_footprint"), progress=False))
    traj = read_trajectory(out)
    assert rep.poses == len(traj) > 1000
    xyz = np.array([T[:3, 3] for _, T in traj])
    t = np.array([s for s, _ in traj]) / 1e9
    assert np.all(np.abs(xyz[:, 2]) < 0.05)
    speed = np.linalg.norm(np.diff(xyz[:, :2], axis=0), axis=1) / np.maximum(np.diff(t), 1e-3)
    assert np.percentile(speed, 99) < 1.0  # a TurtleBot 4 drives < 0.5 m/s (+ AMCL jumps)


# ----- messages for foreign files and wrong flags ------------------------------------------------
def run(args: list[str]):  # type: ignore[no-untyped-def]
    return CliRunner().invoke(cli, args)


def test_missing_flags_list_topics_and_suggest(shared_data_dir, tmp_path):
    bag = shared_data_dir / "logs" / "evo" / "tf_example.bag"
    r = run(["import", "bag", str(bag), "-o", str(tmp_path / "o.mcap")])
    assert r.exit_code == 2 and "Traceback" not in r.output
    assert "/tf_static  tf2_msgs/msg/TFMessage" in r.output
    assert "suggested flags: --tf-frames odom:base_link" in r.output
    assert not (tmp_path / "o.mcap").exists()
    r = run(["import", "bag", str(shared_data_dir / "logs" / "evo" / "ROS_example.bag"),
             "--list"])
    assert r.exit_code == 0 and "--pose groundtruth" in r.output


def test_wrong_topic_types_name_topic_and_type(tmp_path):
    src = write_sgtool_log(tmp_path / "src.mcap", n=3)
    bag = bag_path(tmp_path, "ros1")
    write_log_as_bag(src, bag, "ros1")
    out = tmp_path / "o.mcap"
    base = ["import", "bag", str(bag), "-o", str(out)]
    r = run(base + ["--depth", TOPICS["info"], "--info", TOPICS["info"]])
    assert r.exit_code == 2
    assert ("--depth /camera/depth/camera_info is a sensor_msgs/msg/CameraInfo topic"
            in r.output)
    r = run(base + ["--depth", TOPICS["rgb"], "--info", TOPICS["info"]])
    assert r.exit_code == 2
    assert ("--depth /camera/rgb/image_raw carries 'rgb8' images; --depth needs a depth "
            "encoding" in r.output)
    assert "suggested flags: --depth /camera/depth/image_raw --rgb /camera/rgb/image_raw" \
        in r.output
    r = run(base + ["--depth", TOPICS["depth"], "--rgb", TOPICS["depth"]])
    assert "--rgb /camera/depth/image_raw carries '16UC1' images; --rgb needs a colour" \
        in r.output
    r = run(base + ["--depth", TOPICS["depth"], "--info", TOPICS["depth"]])
    assert "--info /camera/depth/image_raw is a sensor_msgs/msg/Image topic" in r.output
    r = run(base + ["--depth", "/nope", "--info", TOPICS["info"]])
    assert "--depth /nope: no such topic" in r.output and "/camera/rgb/image_raw" in r.output
    r = run(base + ["--depth", TOPICS["depth"], "--ids", TOPICS["rgb"]])
    assert "--ids /camera/rgb/image_raw carries 'rgb8' images; --ids needs an integer" \
        in r.output
    r = run(base + ["--depth", TOPICS["depth"], "--info", TOPICS["info"],
                    "--tf-frames", "map:camera_optical_frame"])
    assert "frame 'map' is not in the tf tree" in r.output
    assert "world -> camera_optical_frame" in r.output
    assert r.output.count("\n") == 1  # one line, the links in it
    r = run(base + ["--depth", TOPICS["depth"], "--tf-frames", "map:map"])
    assert r.exit_code == 2 and "--tf-frames 'map:map': the world and the camera are one " \
        "frame" in r.output
    assert not out.exists() and not Path(str(out) + ".partial").exists()
    assert all("Traceback" not in x for x in [r.output])


def test_foreign_files_are_named(shared_data_dir, tmp_path):
    src = write_sgtool_log(tmp_path / "src.mcap", n=2)
    with pytest.raises(SgtoolError, match="profile 'sgtool'.*not a ROS 2 bag.*sgtool log"):
        import_bag(src, tmp_path / "o.mcap", BagOptions(depth="/camera/depth"))
    readme = shared_data_dir / "README.md"
    with pytest.raises(SgtoolError, match="README.md: not a ROS bag"):
        import_bag(readme, tmp_path / "o.mcap", BagOptions(depth="/d"))
    talker = shared_data_dir / "logs" / "rosbag2-mcap" / "talker.mcap"
    with pytest.raises(SgtoolError, match="--depth /topic is a std_msgs/msg/String topic"):
        import_bag(talker, tmp_path / "o.mcap", BagOptions(depth="/topic", info="/topic"))
    assert not (tmp_path / "o.mcap").exists()
    # a cut copy and an empty file: what they are, and the way to the readable part
    cut = tmp_path / "cut.mcap"
    cut.write_bytes(talker.read_bytes()[:-100])
    with pytest.raises(SgtoolError, match=r"cut\.mcap: the file ends without the MCAP footer "
                       r"\(truncated, or still being written\); `sgtool doctor .*--recover"):
        import_bag(cut, tmp_path / "o.mcap", BagOptions(depth="/topic"))
    empty = tmp_path / "empty.mcap"
    empty.write_bytes(b"")
    with pytest.raises(SgtoolError, match="empty.mcap: not an MCAP file"):
        import_bag(empty, tmp_path / "o.mcap", BagOptions(depth="/topic"))
    assert not (tmp_path / "o.mcap").exists()
    # bytes appended to a whole file are named so (it was called cut short), and a file
    # without a summary has messages the summary does not list (it said "no messages")
    appended = tmp_path / "appended.mcap"
    appended.write_bytes(talker.read_bytes() + b"x" * 50)
    with pytest.raises(SgtoolError, match=r"appended\.mcap: 50 bytes after the end of the MCAP"):
        import_bag(appended, tmp_path / "o.mcap", BagOptions(depth="/topic"))
    bare = tmp_path / "bare.mcap"
    with open(bare, "wb") as f:
        w = Writer(f, index_types=IndexType.NONE, repeat_channels=False, repeat_schemas=False,
                   use_statistics=False, use_summary_offsets=False)
        w.start(profile="sgtool", library="test")
        w.add_message(w.register_channel("/t", "json", 0), 1, b"{}", 1)
        w.finish()
    with pytest.raises(SgtoolError, match="profile 'sgtool' and unlisted messages, not a ROS"):
        import_bag(bare, tmp_path / "o.mcap", BagOptions(depth="/topic"))
    assert not (tmp_path / "o.mcap").exists()


def test_cli_json_report_and_refusal_to_overwrite(tmp_path):
    src = write_sgtool_log(tmp_path / "src.mcap", n=3)
    bag = bag_path(tmp_path, "ros2-sqlite3")
    write_log_as_bag(src, bag, "ros2-sqlite3")
    out = tmp_path / "o.mcap"
    args = ["import", "bag", str(bag), "-o", str(out), "--depth", TOPICS["depth"],
            "--info", TOPICS["info"], "--up", "z", "--floor", "none", "--json", "--quiet"]
    r = run(args)
    assert r.exit_code == 0, r.output
    rep = json.loads(r.output)
    assert rep["frames"] == 3 and rep["instance_ids"] is False
    assert rep["alignment"]["up_method"] == "given"
    r = run(args)
    assert r.exit_code == 2 and "exists; not overwriting it (use --force)" in r.output
    assert run(args + ["--force"]).exit_code == 0


def test_pose_topic_instead_of_tf_with_every_and_limit(tmp_path):
    """Camera poses from a PoseStamped topic (no tf at all); --every 2 --limit 3."""
    src = write_sgtool_log(tmp_path / "src.mcap", n=8)
    bag = bag_path(tmp_path, "ros2-sqlite3")
    with LogReader(src) as r, BagWriter(bag, "ros2-sqlite3") as w:
        frames = list(r.frames())
        for f in frames:
            t = f.time_ns
            w.write("/camera/pose", "geometry_msgs/msg/PoseStamped", t,
                    w.pose_stamped(t, "map", f.pose))
            w.write(TOPICS["depth"], "sensor_msgs/msg/Image", t,
                    w.image(t, "cam", (f.depth * 1000).round().astype(np.uint16), "16UC1"))
    out = tmp_path / "o.mcap"
    k = frames[0].intrinsics
    from sgtool.recorders.importers.textformats import PinholeParams

    rep = import_bag(bag, out, BagOptions(depth=TOPICS["depth"], pose="/camera/pose",
                                          intrinsics=PinholeParams(k.fx, k.fy, k.cx, k.cy),
                                          every=2, limit=3, **KEEP_WORLD))
    assert rep.frames == 3 and rep.pose_source == "topic /camera/pose (8 poses)"
    with LogReader(out) as r:
        got = list(r.frames())
    for g, f in zip(got, frames[::2], strict=False):
        assert g.time_ns == f.time_ns and pose_difference(g.pose, f.pose)[0] < 1e-9
        assert np.array_equal(g.depth, f.depth)


def test_a_pose_topic_of_the_robot_base_is_carried_to_the_camera(tmp_path):
    """A robot's odometry (map -> base_link, TransformStamped) as --pose, the camera
    mounted on the base by /tf_static: the camera's pose is the base's times the mount,
    not the base's; without the mount in /tf the import refuses in one line."""
    src = write_sgtool_log(tmp_path / "src.mcap", n=6)
    mount = pose_from_tq(np.array([0.1, 0.0, 1.0]), np.array([-0.5, 0.5, -0.5, 0.5]))
    with LogReader(src) as r:
        frames = list(r.frames())
    k = frames[0].intrinsics
    from sgtool.recorders.importers.textformats import PinholeParams

    opts = dict(depth=TOPICS["depth"], pose="/odom",
                intrinsics=PinholeParams(k.fx, k.fy, k.cx, k.cy), **KEEP_WORLD)
    for static in (True, False):
        bag = bag_path(tmp_path, "ros2-sqlite3", f"b{static}")
        with BagWriter(bag, "ros2-sqlite3") as w:
            t0 = frames[0].time_ns
            if static:
                w.write("/tf_static", "tf2_msgs/msg/TFMessage", t0,
                        w.tf(t0, [w.transform_stamped(t0, "base_link", "cam", mount)]))
            for f in frames:
                t = f.time_ns
                w.write("/odom", "geometry_msgs/msg/TransformStamped", t,
                        w.transform_stamped(t, "map", "base_link",
                                            f.pose @ np.linalg.inv(mount)))
                w.write(TOPICS["depth"], "sensor_msgs/msg/Image", t,
                        w.image(t, "cam", (f.depth * 1000).round().astype(np.uint16), "16UC1"))
        out = tmp_path / f"o{static}.mcap"
        if not static:
            with pytest.raises(SgtoolError, match=r"--pose /odom gives the pose of frame "
                               r"'base_link', the depth images are in frame 'cam', and /tf "
                               r"does not link the two; give --tf-frames WORLD:cam"):
                import_bag(bag, out, BagOptions(**opts))
            assert not out.exists()
            continue
        rep = import_bag(bag, out, BagOptions(**opts))
        assert rep.pose_source == "topic /odom (6 poses), of base_link -> cam by /tf"
        with LogReader(out) as r:
            got = list(r.frames())
        assert len(got) == 6
        for g, f in zip(got, frames, strict=True):
            assert pose_difference(g.pose, f.pose)[0] < 1e-6


def test_bag_poses_estimated_by_odometry(shared_data_dir, tmp_path):
    """Six real ICL-NUIM frames as a ROS 2 bag: with tf and --estimate-poses the drift
    against the bag's tf is reported; without tf (a camera recorded alone) the poses are
    estimated from the images and start at the identity."""
    from support.bag_export import write_frames_bag

    from sgtool.recorders.importers.rgbd import RgbdOptions, import_rgbd

    icl = tmp_path / "icl.mcap"
    import_rgbd(shared_data_dir / "rgbd" / "icl-livingroom1-micro", icl,
                RgbdOptions(limit=6, progress=False))
    with_tf, no_tf = tmp_path / "with_tf", tmp_path / "no_tf"
    with LogReader(icl) as r:
        frames = list(r.frames())
    write_frames_bag(frames, with_tf, "ros2-mcap")
    write_frames_bag(frames, no_tf, "ros2-mcap", tf=False)
    flags = dict(depth=TOPICS["depth"], rgb=TOPICS["rgb"], info=TOPICS["info"], odometry="icp")
    rep = import_bag(with_tf, tmp_path / "a.mcap",
                     BagOptions(estimate_poses=True, **flags, **KEEP_WORLD))
    assert rep.frames == 6 and rep.drift is not None and rep.odometry_failures == 0
    assert rep.pose_source == ("estimated by icp odometry (tf world -> camera_optical_frame "
                               "kept for the drift)")
    # the reference is the bag's tf, not ground truth
    assert ("drift against the bag's poses (tf world -> camera_optical_frame): 6 frames"
            in "\n".join(rep.lines()))
    assert 0 < rep.drift.ate_rmse_m < 0.01
    rep = import_bag(no_tf, tmp_path / "b.mcap", BagOptions(**flags, **KEEP_WORLD))
    assert rep.frames == 6 and rep.drift is None
    assert rep.pose_source == "estimated by icp odometry"
    with LogReader(tmp_path / "b.mcap") as r:
        est = [f.pose for f in r.frames()]
    assert np.allclose(est[0], np.eye(4))
    # relative motion agrees with the reference trajectory to a centimetre
    rel = [np.linalg.inv(frames[0].pose) @ f.pose for f in frames]
    assert max(np.linalg.norm(a[:3, 3] - b[:3, 3]) for a, b in zip(est, rel, strict=True)) < 0.01


# ----- audit regressions: trajectory-only bags, --estimate-poses, --depth-scale ----------------
NAV2 = ("logs", "rosbag2-mcap", "evo_nav2_turtlebot.mcap")


def test_trajectory_bag_suggests_pose_topics_and_tf(shared_data_dir, tmp_path):
    """The Nav2 recording has /odom and /amcl_pose besides /tf: the suggestions list them
    as alternatives to --tf-frames (only --tf-frames was suggested)."""
    bag = shared_data_dir.joinpath(*NAV2)
    r = run(["import", "bag", str(bag), "-o", str(tmp_path / "o.mcap")])
    assert r.exit_code == 2 and "Traceback" not in r.output
    *table, line = r.output.splitlines()  # the topic table, then the one line
    assert line.startswith(f"sgtool: error: {bag}: say which topics to import")
    assert any(t.startswith("  /amcl_pose") for t in table)
    sugg = line[line.index("suggested flags:"):]
    assert "--tf-frames map:oakd_rgb_camera_optical_frame" in sugg
    assert "| --pose /amcl_pose | --pose /odom" in sugg
    assert "WORLD:FRAME" not in sugg
    r = run(["import", "bag", str(bag), "--list"])
    assert r.exit_code == 0 and "suggested flags: --pose /amcl_pose | --pose /odom" in r.output
    assert not (tmp_path / "o.mcap").exists()


@pytest.mark.parametrize("extra", [[], ["--tf-frames", "map:base_footprint"],
                                   ["--pose", "/odom"]])
def test_estimate_poses_without_images_is_an_error(shared_data_dir, tmp_path, extra):
    """--estimate-poses on a bag of trajectories alone was ignored (a trajectory was
    written); it is an error that says why and suggests the trajectory flags."""
    out = tmp_path / "o.mcap"
    r = run(["import", "bag", str(shared_data_dir.joinpath(*NAV2)), "-o", str(out),
             "--estimate-poses", *extra])
    assert r.exit_code == 2 and "Traceback" not in r.output, r.output
    assert ("--estimate-poses estimates camera poses from depth images, and the bag has no "
            "image topic") in r.output
    assert "--pose /amcl_pose" in r.output and "--tf-frames map:" in r.output
    assert not out.exists() and not Path(str(out) + ".partial").exists()


def test_estimate_poses_needs_depth_when_the_bag_has_images(tmp_path):
    src = write_sgtool_log(tmp_path / "src.mcap", n=2)
    bag = bag_path(tmp_path, "ros2-mcap")
    write_log_as_bag(src, bag, "ros2-mcap")
    with pytest.raises(SgtoolError, match=r"--estimate-poses .* it needs --depth"):
        import_bag(bag, tmp_path / "o.mcap", BagOptions(tf_frames=("world", "camera"),
                                                        estimate_poses=True, progress=False))


@pytest.mark.parametrize("scale", [-1000.0, 0.0, float("nan"), float("inf")])
def test_bag_depth_scale_must_be_positive(tmp_path, scale):
    src = write_sgtool_log(tmp_path / "src.mcap", n=2)
    bag = bag_path(tmp_path, "ros1")
    write_log_as_bag(src, bag, "ros1")
    out = tmp_path / "o.mcap"
    with pytest.raises(SgtoolError, match=r"--depth-scale .*: give the raw depth units per "
                                          r"metre, a positive number"):
        import_bag(bag, out, BagOptions(**TOPICS, depth_scale=scale, **KEEP_WORLD))
    r = run(["import", "bag", str(bag), "-o", str(out), f"--depth-scale={scale}"])
    assert r.exit_code == 2 and "Traceback" not in r.output
    assert "give the raw depth units per metre" in r.output, r.output
    assert not out.exists()


def test_float_depth_in_millimetres_is_refused_and_scaled(tmp_path):
    """32FC1 depth is metres in ROS; a bag whose floats are millimetres is refused with the
    scale that fits (as 16-bit depth of a wrong scale is), and --depth-scale 1000 reads it
    as the millimetres of the source, bit for bit: never a log of zeroed depth."""
    src = write_sgtool_log(tmp_path / "src.mcap")
    mm = bag_path(tmp_path, "ros2-mcap")
    write_log_as_bag(src, mm, "ros2-mcap", depth_units=1000.0)
    out = tmp_path / "mm.mcap"
    with pytest.raises(SgtoolError, match=r"32FC1 depth is metres\) looks wrong.*"
                                          r"--depth-scale 1000 fits"):
        import_bag(mm, out, BagOptions(**TOPICS, **KEEP_WORLD))
    assert not out.exists()
    rep = import_bag(mm, out, BagOptions(**TOPICS, **KEEP_WORLD, depth_scale=1000.0))
    assert rep.frames == 8
    metres = bag_path(tmp_path, "ros2-mcap", "m")
    write_log_as_bag(src, metres, "ros2-mcap", depth_units=1.0)  # 32FC1 in metres: as is
    back = tmp_path / "m.mcap"
    import_bag(metres, back, BagOptions(**TOPICS, **KEEP_WORLD))
    with LogReader(src) as a, LogReader(out) as b, LogReader(back) as c:
        for x, y, z in zip(a.frames(), b.frames(), c.frames(), strict=True):
            assert np.array_equal(x.depth, y.depth) and np.array_equal(x.depth, z.depth)
            assert np.count_nonzero(y.depth) > 0


def test_a_simulator_clock_starting_at_zero_keeps_its_first_frame(tmp_path):
    """Header stamps from a clock that starts at 0 (a simulation) in a bag recorded on the
    wall clock: the first image's stamp of 0 is a time, not an unset stamp, so its pose is
    found and every frame is imported at its header time."""
    frames = []
    for i in range(5):
        k, rgb, depth, ids, pose, _ = synthetic_frame(i)
        frames.append(Frame(index=i, time_ns=i * 33_000_000, rgb=rgb, depth=depth, ids=ids,
                            pose=pose, intrinsics=k))
    bag = tmp_path / "sim"
    write_frames_bag(frames, bag, "ros2-mcap", record_offset_ns=1_733_000_000 * 10**9)
    out = tmp_path / "o.mcap"
    rep = import_bag(bag, out, BagOptions(**TOPICS, **KEEP_WORLD))
    assert rep.frames == 5 and not any("zero header stamp" in n for n in rep.notes)
    with LogReader(out) as r:
        assert [f.time_ns for f in r.frames()] == [f.time_ns for f in frames]


def test_transforms_never_stamped_are_put_at_bag_time(tmp_path):
    """A tf broadcaster that leaves its header stamps at 0 beside stamped images (wall
    clock): the transforms are put at the bag's record times, said in a note, and every
    frame gets its pose; a simulator's clock at 0 (the test above) keeps its stamps."""
    frames = []
    for i in range(5):
        k, rgb, depth, ids, pose, _ = synthetic_frame(i)
        frames.append(Frame(index=i, time_ns=1_733_000_000 * 10**9 + i * 33_000_000, rgb=rgb,
                            depth=depth, ids=ids, pose=pose, intrinsics=k))
    bag = tmp_path / "unstamped"
    write_frames_bag(frames, bag, "ros2-mcap", tf_stamped=False)
    out = tmp_path / "o.mcap"
    rep = import_bag(bag, out, BagOptions(**TOPICS, **KEEP_WORLD))
    assert rep.frames == 5
    assert any(n.startswith("5 /tf transforms had a zero header stamp") for n in rep.notes)
    with LogReader(out) as r:
        for got, want in zip(r.frames(), frames, strict=True):
            assert got.time_ns == want.time_ns
            assert np.allclose(got.pose, want.pose, atol=1e-9)


def test_a_camera_info_that_changes_part_way_is_followed(tmp_path):
    """A CameraInfo whose focal length changes at the fourth image (a zoom): each imported
    frame has the intrinsics in effect at its time, and the note counts one change."""
    import dataclasses

    frames = []
    for i in range(6):
        k, rgb, depth, ids, pose, _ = synthetic_frame(i)
        if i >= 3:
            k = dataclasses.replace(k, fx=k.fx * 1.02, fy=k.fy * 1.02)
        frames.append(Frame(index=i, time_ns=10**9 + i * 33_000_000, rgb=rgb, depth=depth,
                            ids=ids, pose=pose, intrinsics=k))
    bag = tmp_path / "zoom"
    write_frames_bag(frames, bag, "ros2-mcap")
    out = tmp_path / "o.mcap"
    rep = import_bag(bag, out, BagOptions(**TOPICS, **KEEP_WORLD))
    assert [n for n in rep.notes if "camera info changed" in n] == [
        "the camera info changed 1 time(s); each image has the one in effect at its time "
        "(the world alignment and checks use the first)"]
    with LogReader(out) as r:
        got = [f.intrinsics.fx for f in r.frames()]
    assert got == pytest.approx([f.intrinsics.fx for f in frames], abs=1e-9)
    # the same on a simulator's clock (stamps from 0) in a wall-clock bag
    sim = [dataclasses.replace(f, time_ns=f.time_ns - 10**9) for f in frames]
    write_frames_bag(sim, tmp_path / "zoom_sim", "ros2-mcap",
                     record_offset_ns=1_733_000_000 * 10**9)
    import_bag(tmp_path / "zoom_sim", tmp_path / "o2.mcap", BagOptions(**TOPICS, **KEEP_WORLD))
    with LogReader(tmp_path / "o2.mcap") as r:
        got = [f.intrinsics.fx for f in r.frames()]
    assert got == pytest.approx([f.intrinsics.fx for f in frames], abs=1e-9)
    # and with CameraInfo never stamped: a change takes effect at the next image recorded
    write_frames_bag(sim, tmp_path / "zoom_unstamped", "ros2-mcap",
                     record_offset_ns=1_733_000_000 * 10**9, info_stamped=False)
    import_bag(tmp_path / "zoom_unstamped", tmp_path / "o3.mcap",
               BagOptions(**TOPICS, **KEEP_WORLD))
    with LogReader(tmp_path / "o3.mcap") as r:
        got = [f.intrinsics.fx for f in r.frames()]
    assert got == pytest.approx([f.intrinsics.fx for f in frames], abs=1e-9)
    # a CameraInfo for another image size part-way is refused in one line
    sized = [dataclasses.replace(f, intrinsics=dataclasses.replace(
        f.intrinsics, width=2 * f.intrinsics.width)) if f.index >= 3 else f for f in frames]
    write_frames_bag(sized, tmp_path / "sized", "ros2-mcap")
    with pytest.raises(SgtoolError, match="changes to .* images .* part-way through"):
        import_bag(tmp_path / "sized", tmp_path / "s.mcap", BagOptions(**TOPICS, **KEEP_WORLD))
    assert not (tmp_path / "s.mcap").exists()


def test_a_bag_folder_with_damaged_metadata_is_one_line(tmp_path):
    """A ROS 2 bag folder whose metadata.yaml does not parse: the YAML parser's
    multi-line message is cut to its first line."""
    bag = tmp_path / "bag"
    bag.mkdir()
    (bag / "metadata.yaml").write_text("garbage: [\n")
    r = CliRunner().invoke(cli, ["import", "bag", str(bag), "--list"])
    assert r.exit_code == 2, r.output
    assert r.output.startswith(f"sgtool: error: {bag}: not a readable ROS bag")
    assert r.output.count("\n") == 1 and "Traceback" not in r.output


def test_a_cut_ros2_mcap_points_to_doctor(tmp_path):
    """A ROS 2 bag whose .mcap was cut short (a recorder killed): the one line says how to
    copy what is readable."""
    bag = bag_path(tmp_path, "ros2-mcap")
    write_log_as_bag(write_sgtool_log(tmp_path / "src.mcap"), bag, "ros2-mcap")
    (part,) = sorted(bag.glob("*.mcap"))
    part.write_bytes(part.read_bytes()[: part.stat().st_size // 2])
    r = CliRunner().invoke(cli, ["import", "bag", str(bag), "--list"])
    assert r.exit_code == 2 and r.output.count("\n") == 1, r.output
    assert f"`sgtool doctor {part} --recover OUT.mcap` copies what is readable" in r.output


@pytest.mark.parametrize("fmt", ["ros2-sqlite3", "ros2-mcap"])
def test_a_ros2_bag_folder_named_dot_bag_is_read_as_ros2(tmp_path, fmt):
    """`ros2 bag record -o run.bag` makes a folder named run.bag, which the bag reader took
    for a ROS 1 file (and, for MCAP storage, suggested recovering an undamaged file)."""
    src = write_sgtool_log(tmp_path / "src.mcap", n=4)
    bag = tmp_path / "run.bag"
    write_log_as_bag(src, bag, fmt)
    assert bag.is_dir()
    r = CliRunner().invoke(cli, ["import", "bag", str(bag), "--list"])
    assert r.exit_code == 0 and r.output.startswith(f"{bag} (ros2): topics"), r.output
    (storage,) = [p for p in bag.iterdir() if p.suffix in (".mcap", ".db3")]
    r = CliRunner().invoke(cli, ["import", "bag", str(storage), "--list"])  # its file
    assert r.exit_code == 0 and "(ros2): topics" in r.output, r.output
    out = tmp_path / "o.mcap"
    r = CliRunner().invoke(cli, ["import", "bag", str(bag), "-o", str(out), "--quiet",
                                 "--depth", TOPICS["depth"], "--info", TOPICS["info"],
                                 "--up", "z", "--floor", "none"])
    assert r.exit_code == 0, r.output
    with LogReader(out) as log:
        assert sum(1 for _ in log.frames()) == 4


def test_poses_of_float_depth_are_checked_against_it_too(shared_data_dir, tmp_path):
    """Depth in metres (32FC1) has no scale to check, but its poses still must move as it
    does: world-to-camera poses were imported, exit 0, when the depth was float (the
    motion check rode on the 16-bit scale fit); right poses pass with the check shown."""
    import dataclasses

    from support.bag_export import write_frames_bag

    from sgtool.recorders.importers.rgbd import RgbdOptions, import_rgbd

    icl = tmp_path / "icl.mcap"
    import_rgbd(shared_data_dir / "rgbd" / "icl-livingroom1-micro", icl,
                RgbdOptions(every=3, limit=20, progress=False))
    with LogReader(icl) as r:
        frames = list(r.frames())
    inverted = [dataclasses.replace(f, pose=np.linalg.inv(f.pose)) for f in frames]
    good, bad = tmp_path / "good", tmp_path / "bad"
    write_frames_bag(frames, good, "ros2-mcap", depth_units=1.0)
    write_frames_bag(inverted, bad, "ros2-mcap", depth_units=1.0)
    flags = dict(depth=TOPICS["depth"], rgb=TOPICS["rgb"], info=TOPICS["info"], **KEEP_WORLD)
    with pytest.raises(SgtoolError, match=r"look world-to-camera: .* 1\.0\dx as far as "
                                          r"their inverses"):
        import_bag(bad, tmp_path / "b.mcap", BagOptions(**flags))
    assert not (tmp_path / "b.mcap").exists()
    rep = import_bag(good, tmp_path / "g.mcap", BagOptions(**flags))
    assert rep.frames == 20
    assert dict(rep.checks)["depth scale against the poses"].startswith("depth moves 1.0")


def test_a_tree_that_ends_at_the_body_frame_imports_with_camera_axes(shared_data_dir,
                                                                     tmp_path):
    """A tf tree whose camera frame is ROS's camera_link (x forward, z up) with no static
    link to an optical frame: the refusal names --camera-axes body, with which the frames
    are posed as the optical frame's poses were."""
    import dataclasses

    from sgtool.recorders.importers.pose_axes import BODY_T_OPTICAL
    from sgtool.recorders.importers.rgbd import RgbdOptions, import_rgbd

    icl = tmp_path / "icl.mcap"
    import_rgbd(shared_data_dir / "rgbd" / "icl-livingroom1-micro", icl,
                RgbdOptions(every=3, limit=20, progress=False))
    with LogReader(icl) as r:
        frames = list(r.frames())
    body = [dataclasses.replace(f, pose=f.pose @ np.linalg.inv(BODY_T_OPTICAL))
            for f in frames]
    bag = tmp_path / "body"
    write_frames_bag(body, bag, "ros2-mcap")
    flags = dict(depth=TOPICS["depth"], rgb=TOPICS["rgb"], info=TOPICS["info"], **KEEP_WORLD)
    with pytest.raises(SgtoolError, match=r"camera frame with body axes .* give --camera-axes "
                       r"body to read them so, or --tf-frames WORLD:CAMERA_OPTICAL_FRAME"):
        import_bag(bag, tmp_path / "b.mcap", BagOptions(**flags))
    rep = import_bag(bag, tmp_path / "b.mcap", BagOptions(**flags, camera_axes="body"))
    assert rep.frames == 20
    with LogReader(tmp_path / "b.mcap") as r:
        for want, got in zip(frames, r.frames(), strict=True):
            assert np.allclose(want.pose, got.pose, atol=1e-5)
    res = CliRunner().invoke(cli, ["import", "bag", str(bag), "-o", str(tmp_path / "c.mcap"),
                                   "--camera-axes", "sideways"])
    assert res.exit_code == 2 and "'sideways' is not one of 'optical', 'opengl', 'body'" \
        in res.output


def test_camera_axes_where_no_camera_pose_is_read_is_refused(shared_data_dir, tmp_path):
    """--camera-axes turns the depth camera's poses: a trajectory import (no --depth) keeps
    its frame's poses, so it is refused there (before, it turned them and kept the frame's
    name, which an export published rotated)."""
    bag = shared_data_dir / "logs" / "evo" / "tf_example.bag"
    r = CliRunner().invoke(cli, ["import", "bag", str(bag), "--tf-frames", "odom:base_link",
                                 "--camera-axes", "body", "-o", str(tmp_path / "t.mcap")])
    assert r.exit_code == 2 and r.output.strip().endswith(
        "--camera-axes body reads the depth camera's poses (give --depth); a trajectory "
        "import keeps its frame's poses as they are"), r.output
    assert not (tmp_path / "t.mcap").exists()


@pytest.mark.parametrize("t0_s", [0, 100])
@pytest.mark.parametrize("together", [True, False])
def test_a_link_never_stamped_beside_a_simulator_clock_is_on_that_clock(tmp_path, t0_s,
                                                                          together):
    """A broadcaster that leaves one link's stamps at 0 beside /tf stamped on a simulator's
    clock (started 0 s or 100 s before the recording, on the wall clock): the link is put
    on the simulator's clock (its record time less the other transforms' delay), in the
    same TFMessage as a stamped transform or in its own, and every frame gets its pose."""
    from sgtool.log.codec import depth_to_mm

    wall = 1_733_000_000 * 10**9
    bag, poses = tmp_path / "sim", []
    with BagWriter(bag, "ros2-mcap") as w:
        for i in range(5):
            k, rgb, depth, _, pose, _ = synthetic_frame(i)
            poses.append(pose)
            t = t0_s * 10**9 + i * 33_000_000
            moved = w.transform_stamped(t, "world", "base", pose)
            fixed = w.transform_stamped(0, "base", "camera_optical_frame", np.eye(4))
            for part in ([moved, fixed],) if together else ([moved], [fixed]):
                w.write("/tf", "tf2_msgs/msg/TFMessage", t + wall, w.tf(t, part))
            w.write(TOPICS["info"], "sensor_msgs/msg/CameraInfo", t + wall,
                    w.camera_info(t, "camera_optical_frame", k))
            w.write(TOPICS["depth"], "sensor_msgs/msg/Image", t + wall,
                    w.image(t, "camera_optical_frame", depth_to_mm(depth), "16UC1"))
    out = tmp_path / "o.mcap"
    rep = import_bag(bag, out, BagOptions(depth=TOPICS["depth"], info=TOPICS["info"],
                                          **KEEP_WORLD))
    assert rep.frames == 5
    with LogReader(out) as r:
        for got, want in zip(r.frames(), poses, strict=True):
            assert np.allclose(got.pose, want, atol=1e-9)
