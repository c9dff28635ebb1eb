"""Importer building blocks on inputs built here: text formats, pose interpolation, the tf
tree, the z-up world alignment, ROS image decoding."""

from __future__ import annotations

import struct
from pathlib import Path

import cv2
import numpy as np
import pytest
from support.bag_export import typestore_for
from support.rgbd_folders import room_depth
from support.trajectory_files import (
    ns_to_seconds_text,
    write_open3d_log,
    write_tum_trajectory,
)

from sgtool.errors import SgtoolError
from sgtool.log.frame import CameraIntrinsics
from sgtool.log.poses import (
    PoseTrack,
    interpolate,
    pose_difference,
    rotation_angle_deg,
)
from sgtool.recorders.importers import images, textformats
from sgtool.recorders.importers.tftree import TfTree
from sgtool.recorders.importers.upright import (
    DepthSample,
    estimate_alignment,
    parse_up,
    rotation_to_z,
)


def rot_z(deg: float) -> np.ndarray:
    a = np.radians(deg)
    R = np.eye(4)  # noqa: N806
    R[:2, :2] = [[np.cos(a), -np.sin(a)], [np.sin(a), np.cos(a)]]
    return R


def trans(x: float, y: float, z: float) -> np.ndarray:
    T = np.eye(4)  # noqa: N806
    T[:3, 3] = (x, y, z)
    return T


# ----- text formats ----------------------------------------------------------------------------
def test_seconds_to_ns_is_exact():
    assert textformats.seconds_to_ns("1305031102.160407") == 1305031102160407000
    assert textformats.seconds_to_ns("0.000000001") == 1
    assert ns_to_seconds_text(1305031102160407000) == "1305031102.160407"


def test_tum_trajectory_round_trip(tmp_path: Path):
    poses = [(1_000_000_000 + i * 10_000_000, trans(i, 2 * i, 0.5) @ rot_z(10 * i))
             for i in range(5)]
    p = tmp_path / "gt.txt"
    write_tum_trajectory(p, poses)
    back = textformats.read_tum_trajectory(p)
    assert [t for t, _ in back] == [t for t, _ in poses]
    for (_, a), (_, b) in zip(poses, back, strict=True):
        dt, dr = pose_difference(a, b)
        assert dt < 1e-8 and dr < 1e-6


def test_tum_trajectory_errors_name_the_line(tmp_path: Path):
    p = tmp_path / "gt.txt"
    p.write_text("# header\n1.0 0 0 0 0 0 0 1\n2.0 0 0 0 0 0 1\n")
    with pytest.raises(SgtoolError, match=r"gt\.txt:3: .*8 numbers.* 7"):
        textformats.read_tum_trajectory(p)


def test_open3d_log_round_trip_and_bad_block(tmp_path: Path):
    poses = [trans(0.1 * i, 0, 0) @ rot_z(5 * i) for i in range(3)]
    p = tmp_path / "traj.log"
    write_open3d_log(p, poses)
    back = textformats.read_open3d_log(p)
    assert len(back) == 3 and all(np.allclose(a, b, atol=1e-8) for a, b in zip(poses, back,
                                                                              strict=True))
    p.write_text("0 0 1\n1 0 0 0\n0 1 0 0\n0 0 1 0\n")
    with pytest.raises(SgtoolError, match="5 lines per pose"):
        textformats.read_open3d_log(p)


def test_intrinsics_from_json_matrix_and_text(tmp_path: Path):
    j = tmp_path / "cam.json"
    # Open3D stores the matrix column major
    j.write_text('{"width": 640, "height": 480, "intrinsic_matrix": '
                 '[525.0, 0, 0, 0, 520.0, 0, 319.5, 239.5, 1]}')
    p = textformats.read_intrinsics_file(j)
    assert (p.fx, p.fy, p.cx, p.cy, p.width, p.height) == (525.0, 520.0, 319.5, 239.5, 640, 480)
    m = tmp_path / "camera-intrinsics.txt"
    m.write_text("585 0 320\n0 586 240\n0 0 1\n")
    p = textformats.read_intrinsics_file(m)
    assert (p.fx, p.fy, p.cx, p.cy) == (585, 586, 320, 240)
    p = textformats.parse_intrinsics("500, 501, 320.5, 240")
    assert (p.fx, p.fy, p.cx, p.cy) == (500, 501, 320.5, 240)
    # the same four numbers in a file (an outside lab's intrinsics.txt), as the flag takes
    for text in ("500 501 320.5 240\n", "500,501,320.5,240\n", "# fx fy cx cy\n500 501 320.5 240"):
        four = tmp_path / "four.txt"
        four.write_text(text)
        p = textformats.read_intrinsics_file(four)
        assert (p.fx, p.fy, p.cx, p.cy, p.source) == (500, 501, 320.5, 240, "four.txt")
    four.write_text("500 501 320.5\n")
    with pytest.raises(SgtoolError, match=r"four\.txt: expected a 3x3 camera matrix .*, the four "
                       r"numbers fx fy cx cy, or Open3D intrinsics JSON"):
        textformats.read_intrinsics_file(four)
    with pytest.raises(SgtoolError, match="fx,fy,cx,cy"):
        textformats.parse_intrinsics("500,501")


def test_transposed_matrices_are_named_and_commas_and_byte_order_marks_read(tmp_path: Path):
    """A K written transposed, or an Open3D matrix listed row by row, read as cx = cy = 0
    and was blamed on "intrinsics of 8x8 images"; a K with commas was refused as not three
    rows of three numbers; a list file saved with a byte-order mark failed on its first
    line."""
    t = tmp_path / "K.txt"
    t.write_text("525 0 0\n0 525 0\n319.5 239.5 1\n")
    with pytest.raises(SgtoolError, match=r"K.txt: a 3x3 camera matrix .* written transposed"):
        textformats.read_intrinsics_file(t)
    j = tmp_path / "cam.json"
    j.write_text('{"width": 640, "height": 480, "intrinsic_matrix": '
                 '[525.0, 0, 319.5, 0, 525.0, 239.5, 0, 0, 1]}')
    with pytest.raises(SgtoolError, match=r"only transposed: Open3D lists it column by "
                       r"column .* this one is row by row"):
        textformats.read_intrinsics_file(j)
    t.write_text("585, 0, 320\n0, 586, 240\n0, 0, 1\n")
    p = textformats.read_intrinsics_file(t)
    assert (p.fx, p.fy, p.cx, p.cy) == (585, 586, 320, 240)
    t.write_text("# K (fx, fy, cx, cy in pixels)\n585 0 320\n0 586 240\n0 0 1\n")
    p = textformats.read_intrinsics_file(t)  # a comma in a comment is no delimiter
    assert (p.fx, p.fy, p.cx, p.cy) == (585, 586, 320, 240)
    j.write_text('\ufeff{"width": 640, "height": 480, "intrinsic_matrix": '
                 '[525.0, 0, 0, 0, 520.0, 0, 319.5, 239.5, 1]}', encoding="utf-8")
    assert textformats.read_intrinsics_file(j).fy == 520.0
    lst = tmp_path / "rgb.txt"
    lst.write_text("\ufeff# rgb\n1305031102.175304 rgb/1305031102.175304.png\n",
                   encoding="utf-8")
    assert textformats.read_tum_list(lst) == [(1305031102175304000, "rgb/1305031102.175304.png")]


# ----- poses ------------------------------------------------------------------------------------
def test_interpolation_halfway_in_rotation_and_translation():
    a = np.eye(4)
    b = trans(2, 0, 0) @ rot_z(90)
    m = interpolate(a, b, 0.5)
    assert np.allclose(m[:3, 3], [1, 0, 0])
    assert rotation_angle_deg(m) == pytest.approx(45.0, abs=1e-9)
    assert np.allclose(m[:3, :3], rot_z(45)[:3, :3], atol=1e-12)


def test_pose_track_gaps_and_tolerance():
    ms = 1_000_000
    track = PoseTrack.from_samples(
        [(0, trans(0, 0, 0)), (100 * ms, trans(1, 0, 0)), (2000 * ms, trans(5, 0, 0))],
        max_gap_ns=500 * ms, tolerance_ns=20 * ms,
    )
    assert np.allclose(track.at(25 * ms)[:3, 3], [0.25, 0, 0])  # interpolated
    assert np.allclose(track.at(110 * ms)[:3, 3], [1, 0, 0])  # within tolerance of a sample
    assert track.at(1000 * ms) is None  # in a 1.9 s dropout
    assert track.at(-30 * ms) is None  # before the track
    assert np.allclose(track.at(2015 * ms)[:3, 3], [5, 0, 0])  # just after the last


def test_tf_tree_composes_static_and_dynamic_links_through_a_common_ancestor():
    ms = 1_000_000
    tree = TfTree(tolerance_ns=10 * ms)
    for t, x in ((0, 0.0), (100 * ms, 1.0)):
        tree.add("/odom", "base", t, trans(x, 0, 0) @ rot_z(90 * x), static=False)
    tree.add("base", "camera", 0, trans(0, 0, 1.5), static=True)
    tree.add("odom", "landmark", 0, trans(3, 0, 0), static=True)
    tree.freeze()
    assert tree.roots() == ["odom"]
    T = tree.lookup("odom", "camera", 50 * ms)  # noqa: N806
    assert np.allclose(T[:3, 3], [0.5, 0, 1.5]) and rotation_angle_deg(T) == pytest.approx(45)
    # camera in the landmark frame: through the common ancestor odom
    L = tree.lookup("landmark", "camera", 0)  # noqa: N806
    assert np.allclose(L[:3, 3], [-3, 0, 1.5])
    assert tree.lookup("odom", "camera", 500 * ms) is None  # beyond the samples
    assert tree.lookup("odom", "nowhere", 0) is None
    assert tree.sample_times("odom", "camera") == [0, 100 * ms]


# ----- world alignment -------------------------------------------------------------------------
@pytest.mark.parametrize("axis", ["x", "-x", "y", "-y", "z", "-z"])
def test_rotation_to_z_maps_each_axis_up(axis):
    u = parse_up(axis)
    R = rotation_to_z(u)  # noqa: N806
    assert np.allclose(R @ u, [0, 0, 1]) and np.allclose(R @ R.T, np.eye(3))
    assert np.linalg.det(R) == pytest.approx(1.0)


def test_alignment_recovers_a_tilted_world_and_the_floor():
    """A world whose up is a tilted vector and whose floor is 0.7 m below its origin; the
    camera is pitched down 25 degrees (so the camera-up guess alone is 25 degrees off)."""
    k = CameraIntrinsics(80, 60, 60.0, 60.0, 39.5, 29.5)
    up_src = np.array([0.2, -0.9, 0.3])
    up_src /= np.linalg.norm(up_src)
    R_src = rotation_to_z(up_src).T  # noqa: N806  (z-up world -> source world)
    pitch = 25.0
    samples, poses = [], []
    for i in range(4):
        # camera in the z-up world: optical axis forward along a yawed heading, pitched down
        yaw = np.radians(40 * i)
        p = np.radians(pitch)
        fwd = np.array([np.cos(yaw) * np.cos(p), np.sin(yaw) * np.cos(p), -np.sin(p)])
        right = np.array([np.sin(yaw), -np.cos(yaw), 0.0])
        down = np.cross(fwd, right)
        cam = np.eye(4)
        cam[:3, :3] = np.stack([right, down, fwd], axis=1)
        cam[:3, 3] = (0.3 * i, 0.1 * i, 1.4 - 0.7)  # 1.4 m above a floor at z = -0.7
        src = np.eye(4)
        src[:3, :3] = R_src
        pose = src @ cam
        poses.append(pose)
        samples.append(DepthSample(room_depth(k, 1.4, pitch), k, pose))
    a = estimate_alignment(poses, samples)
    assert a.up_method == "horizontal-normals"
    assert np.degrees(np.arccos(np.clip(np.dot(a.up, up_src), -1, 1))) < 0.5
    assert a.floor == pytest.approx(-0.7, abs=0.01)
    for pose in poses:  # every camera ends up 1.4 m above z = 0
        assert a.apply(pose)[2, 3] == pytest.approx(1.4, abs=0.01)
    given = estimate_alignment(poses, samples, up=up_src, floor=None, floor_auto=False)
    assert given.up_method == "given" and given.floor == 0.0


def test_parse_up_rejects_nonsense():
    assert parse_up("auto") is None
    assert np.allclose(parse_up("0,0,2"), [0, 0, 1])
    with pytest.raises(SgtoolError, match="--up"):
        parse_up("sideways")


# ----- ROS image messages -------------------------------------------------------------------
def test_compressed_depth_16bit_and_inverse_32bit():
    ts = typestore_for("ros2-mcap")
    Header = ts.types["std_msgs/msg/Header"]  # noqa: N806
    Time = ts.types["builtin_interfaces/msg/Time"]  # noqa: N806
    CI = ts.types["sensor_msgs/msg/CompressedImage"]  # noqa: N806
    hdr = Header(stamp=Time(sec=1, nanosec=0), frame_id="cam")
    mm = (np.arange(48, dtype=np.uint16).reshape(6, 8) * 50 + 400)
    mm[0, 0] = 0
    png = cv2.imencode(".png", mm)[1].tobytes()
    msg = CI(header=hdr, format="16UC1; compressedDepth png",
             data=np.frombuffer(struct.pack("<iff", 0, 0.0, 0.0) + png, np.uint8))
    raw, scale = images.decode_depth_message(msg, "sensor_msgs/msg/CompressedImage", "/d")
    assert scale == 1000.0 and np.array_equal(raw, mm)
    # 32FC1: quantised inverse depth, depth = A / (v - B)
    qa, qb = 100.0, -10.0
    depth_m = np.linspace(0.5, 4.0, 48, dtype=np.float32).reshape(6, 8)
    v = np.rint(qa / depth_m + qb).astype(np.uint16)
    png = cv2.imencode(".png", v)[1].tobytes()
    msg = CI(header=hdr, format="32FC1; compressedDepth png",
             data=np.frombuffer(struct.pack("<iff", 0, qa, qb) + png, np.uint8))
    raw, scale = images.decode_depth_message(msg, "sensor_msgs/msg/CompressedImage", "/d")
    assert scale == 1.0
    assert np.allclose(raw, depth_m, rtol=0.02)


def test_raw_image_with_row_padding_and_bgr():
    ts = typestore_for("ros1")
    Header = ts.types["std_msgs/msg/Header"]  # noqa: N806
    Time = ts.types["builtin_interfaces/msg/Time"]  # noqa: N806
    Image = ts.types["sensor_msgs/msg/Image"]  # noqa: N806
    rgb = np.arange(4 * 5 * 3, dtype=np.uint8).reshape(4, 5, 3)
    padded = np.zeros((4, 16), np.uint8)  # step 16 > 15 bytes per row
    padded[:, :15] = rgb[..., ::-1].reshape(4, 15)
    msg = Image(header=Header(seq=0, stamp=Time(sec=0, nanosec=0), frame_id="c"), height=4,
                width=5, encoding="bgr8", is_bigendian=0, step=16, data=padded.ravel())
    out = images.decode_color_message(msg, "sensor_msgs/msg/Image", "/rgb")
    assert np.array_equal(out, rgb)
    msg = Image(header=Header(seq=0, stamp=Time(sec=0, nanosec=0), frame_id="c"), height=4,
                width=5, encoding="yuv422", is_bigendian=0, step=10,
                data=np.zeros(40, np.uint8))
    with pytest.raises(SgtoolError, match=r"topic /rgb: a yuv422 image needs an even width"):
        images.decode_color_message(msg, "sensor_msgs/msg/Image", "/rgb")
    msg = Image(header=Header(seq=0, stamp=Time(sec=0, nanosec=0), frame_id="c"), height=4,
                width=5, encoding="nv21", is_bigendian=0, step=10,
                data=np.zeros(40, np.uint8))
    with pytest.raises(SgtoolError, match=r"topic /rgb: image encoding 'nv21'"):
        images.decode_color_message(msg, "sensor_msgs/msg/Image", "/rgb")


def test_depth_for_log_keeps_millimetres_and_clears_65535():
    raw = np.array([[0, 1234, 65535]], np.uint16)
    out = images.depth_for_log(raw, 1000.0)
    assert out.dtype == np.uint16 and out.tolist() == [[0, 1234, 0]]
    tum = images.depth_for_log(np.array([[5000, 0]], np.uint16), 5000.0)
    assert tum.dtype == np.float32 and tum.tolist() == [[1.0, 0.0]]


def test_open3d_log_blocks_go_to_the_frames_their_headers_name(tmp_path: Path):
    """Each block's header 'i j n' names its frame: blocks written out of order are put in
    order, a frame given twice is refused, and headers that all say the same keep the
    file's order."""
    poses = [trans(0.1 * i, 0, 0) for i in range(4)]
    p = tmp_path / "traj.log"

    def write(ids: list[int], order: list[int]) -> None:
        blocks = []
        for i, k in zip(ids, order, strict=True):
            rows = "\n".join(" ".join(f"{v:.6f}" for v in r) for r in poses[k])
            blocks.append(f"{i} {i} {i + 1}\n{rows}\n")
        p.write_text("".join(blocks))

    write([2, 0, 3, 1], [2, 0, 3, 1])  # reversed and shuffled, each with its own id
    assert [float(m[0, 3]) for m in textformats.read_open3d_log(p)] == \
        pytest.approx([0.0, 0.1, 0.2, 0.3])
    write([0, 1, 1, 3], [0, 1, 2, 3])
    with pytest.raises(SgtoolError, match=r"traj\.log:11: frame id 1 is given twice "
                                          r"\(first on line 6\)"):
        textformats.read_open3d_log(p)
    write([0, 1, 2, 7], [0, 1, 2, 3])  # a pose for frame 7 where the fourth is 3
    with pytest.raises(SgtoolError, match=r"traj\.log: the frame ids of its pose blocks jump "
                                          r"from 2 to 7"):
        textformats.read_open3d_log(p)
    write([0, 0, 0, 0], [0, 1, 2, 3])  # ids that say nothing: the file's order
    assert [float(m[0, 3]) for m in textformats.read_open3d_log(p)] == \
        pytest.approx([0.0, 0.1, 0.2, 0.3])
    p.write_text("a b c\n" + "1 0 0 0\n0 1 0 0\n0 0 1 0\n0 0 0 1\n")
    with pytest.raises(SgtoolError, match=r"traj\.log:1: expected the block header 'i j n' "
                                          r"\(numbers\)"):
        textformats.read_open3d_log(p)
