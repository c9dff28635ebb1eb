"""One-line refusals of imports that used to be silently wrong: a colour frame of another bit
depth or channel count than the folder's first, intrinsics whose principal point belongs to
another resolution (whatever size they claim), a PNG payload labelled RVL, topic
suggestions that preferred the first name over the native encoding and the camera's aligned
pair, resizes missing from the report, and more than 10 % of the frames dropped for want of
a pose."""

from __future__ import annotations

import dataclasses
import json
import struct
from pathlib import Path
from types import SimpleNamespace

import cv2
import numpy as np
import pytest
from click.testing import CliRunner
from support.bag_export import BagWriter
from support.logfixtures import synthetic_frame
from support.rgbd_folders import make_tum_folder

from sgtool.cli import cli
from sgtool.errors import SgtoolError
from sgtool.recorders.importers.bag import BagOptions, import_bag
from sgtool.recorders.importers.bag_topics import suggest_flags
from sgtool.recorders.importers.bagfiles import TopicInfo
from sgtool.recorders.importers.images import decode_depth_message, header_kind
from sgtool.recorders.importers.layouts import FolderSequence
from sgtool.recorders.importers.provenance import Findings
from sgtool.recorders.importers.rgbd import RgbdOptions, camera_for, import_rgbd
from sgtool.recorders.importers.textformats import PinholeParams

K = PinholeParams(60.0, 60.0, 39.5, 29.5)
TIMES = [100.0 + i / 30 for i in range(12)]


def opts(**kw) -> RgbdOptions:  # type: ignore[no-untyped-def]
    return RgbdOptions(intrinsics=kw.pop("intrinsics", K), progress=False, **kw)


# ----- colour frames of another kind ---------------------------------------------------------
def test_a_16_bit_grey_png_among_colour_frames_is_refused(tmp_path):
    root = make_tum_folder(tmp_path / "f", TIMES)
    grey16 = np.full((60, 80), 2000, np.uint16)  # what a depth image in rgb/ looks like
    cv2.imwrite(str(root / "rgb" / "0005.png"), grey16)
    assert header_kind(root / "rgb" / "0005.png") == "16-bit 1-channel"
    assert header_kind(root / "rgb" / "0004.png") == "8-bit 3-channel"
    with pytest.raises(SgtoolError, match=r"0005.png: a 16-bit 1-channel image among colour "
                       r"frames that are 8-bit 3-channel \(the first, 0000.png\)"):
        import_rgbd(root, tmp_path / "a.mcap", opts())
    assert not (tmp_path / "a.mcap").exists()


def test_a_grey_jpeg_among_colour_jpegs_is_refused_when_decoded(tmp_path):
    """JPEG headers are not read up front; the frame is refused when it is decoded (before
    anything is written)."""
    root = make_tum_folder(tmp_path / "f", TIMES)
    rgb_txt = (root / "rgb.txt").read_text().replace(".png", ".jpg")
    (root / "rgb.txt").write_text(rgb_txt)
    for i in range(len(TIMES)):
        img = np.full((60, 80, 3), 90, np.uint8) if i != 7 else np.full((60, 80), 90, np.uint8)
        cv2.imwrite(str(root / "rgb" / f"{i:04d}.jpg"), img)
    with pytest.raises(SgtoolError, match=r"0007.jpg: a 8-bit 1-channel image among colour "
                       "frames that are 8-bit 3-channel"):
        import_rgbd(root, tmp_path / "a.mcap", opts())
    assert not (tmp_path / "a.mcap").exists()


# ----- intrinsics of another resolution --------------------------------------------------------
def _seq(intr: PinholeParams) -> FolderSequence:
    return FolderSequence("open3d", Path("f"), (), intr, 1000.0, "none")


def test_intrinsics_that_claim_the_image_size_are_still_checked():
    """A file that says 640x480 but holds the numbers of 320x240 images (principal point at
    a quarter of the image) is refused; given with the flag, a warning."""
    half = PinholeParams(262.5, 262.5, 159.75, 119.75, width=640, height=480,
                         source="file cam.json")
    with pytest.raises(SgtoolError, match=r"principal point \(159.75, 119.75\) is far from the "
                       r"centre \(320, 240\).* intrinsics of 320x240"):
        camera_for(_seq(half), RgbdOptions(), 640, 480, Findings())
    found = Findings()
    camera_for(_seq(half), RgbdOptions(intrinsics=half), 640, 480, found)
    assert len(found.warnings) == 1 and "far from the centre" in found.warnings[0]
    # 640x480 numbers for 1280x960 images: a quarter off, no longer let through
    with pytest.raises(SgtoolError, match="intrinsics of 640x480"):
        camera_for(_seq(PinholeParams(525, 525, 319.5, 239.5)), RgbdOptions(), 1280, 960,
                   Findings())


T0 = 1_700_000_000_000_000_000
DT = 100_000_000
DEPTH, INFO, RGB = "/camera/depth/image_raw", "/camera/depth/camera_info", "/camera/rgb/image"


def write_bag(path: Path, n: int = 5, *, k_edit=None, tf_every: int = 1,  # type: ignore[no-untyped-def]
              rgb_size: tuple[int, int] | None = None) -> Path:
    """``n`` synthetic frames (64x48) as a ROS 1 bag: /tf world -> cam (every ``tf_every``-th
    frame), CameraInfo (K changed by ``k_edit``), 16UC1 depth and bgr8 colour (of
    ``rgb_size`` when given)."""
    with BagWriter(path, "ros1") as w:
        for i in range(n):
            k, rgb, depth, _, pose, _ = synthetic_frame(i)
            t = T0 + i * DT
            if i % tf_every == 0:
                w.write("/tf", "tf2_msgs/msg/TFMessage", t,
                        w.tf(t, [w.transform_stamped(t, "world", "cam", pose)]))
            info = w.camera_info(t, "cam", k)
            if k_edit is not None:
                k_edit(info)
            w.write(INFO, "sensor_msgs/msg/CameraInfo", t, info)
            w.write(DEPTH, "sensor_msgs/msg/Image", t,
                    w.image(t, "cam", (depth * 1000).round().astype(np.uint16), "16UC1"))
            if rgb_size is not None:
                big = cv2.resize(rgb, rgb_size, interpolation=cv2.INTER_NEAREST)
                w.write(RGB, "sensor_msgs/msg/Image", t, w.image(t, "cam", big[..., ::-1], "bgr8"))
    return path


KEEP_WORLD = dict(up=np.array([0.0, 0.0, 1.0]), floor_auto=False, progress=False)


def _quarter_k(info) -> None:  # type: ignore[no-untyped-def]
    k = info.K if hasattr(info, "K") else info.k
    k[2], k[5] = 16.0, 12.0  # the principal point of 32x24 images


def test_camera_info_of_another_resolution_is_refused(tmp_path):
    bag = write_bag(tmp_path / "b.bag", k_edit=_quarter_k)
    with pytest.raises(SgtoolError, match=rf"topic {INFO}\): the principal point \(16, 12\) is "
                       r"far from the centre \(32, 24\) of the 64x48 depth images"):
        import_bag(bag, tmp_path / "o.mcap", BagOptions(depth=DEPTH, info=INFO, **KEEP_WORLD))
    assert not (tmp_path / "o.mcap").exists()
    given = PinholeParams(55.4, 55.4, 16.0, 12.0)
    rep = import_bag(bag, tmp_path / "g.mcap", BagOptions(depth=DEPTH, intrinsics=given,
                                                          **KEEP_WORLD))
    assert "flag --intrinsics" in rep.warnings[0]
    # its off-centre principal point tilts the floor seen against the up given: said too
    assert len(rep.warnings) == 2 and "degrees off the horizontal surfaces" in rep.warnings[1]


# ----- a PNG payload labelled RVL ---------------------------------------------------------------
def test_png_payload_labelled_rvl_is_decoded_as_png():
    depth = (np.arange(48 * 64).reshape(48, 64) % 4000 + 300).astype(np.uint16)
    ok, png = cv2.imencode(".png", depth)
    assert ok
    msg = SimpleNamespace(format="16UC1; compressedDepth rvl",
                          data=np.frombuffer(struct.pack("<iff", 0, 0.0, 0.0) + png.tobytes(),
                                             np.uint8))
    a, scale = decode_depth_message(msg, "sensor_msgs/msg/CompressedImage", "/d")
    assert scale == 1000.0 and np.array_equal(a, depth)
    # a payload that is neither is named by what it starts with
    bad = SimpleNamespace(format="16UC1; compressedDepth png",
                          data=np.frombuffer(struct.pack("<iff", 0, 0.0, 0.0) + b"GIF89a..",
                                             np.uint8))
    with pytest.raises(SgtoolError, match=r"the payload after the 12-byte header is not a PNG "
                       r"\(it starts with 4749463839612e2e\)"):
        decode_depth_message(bad, "sensor_msgs/msg/CompressedImage", "/d")


# ----- topic suggestions -------------------------------------------------------------------------
def test_suggestions_prefer_native_encodings():
    image = "sensor_msgs/msg/Image"
    topics = [TopicInfo("/camera/depth/image", image, 5),  # 32FC1, first by name
              TopicInfo("/camera/depth/image_raw", image, 5),  # 16UC1
              TopicInfo("/camera/rgb/image_bayer", image, 5),  # bayer, first by name
              TopicInfo("/camera/rgb/image_color", image, 5),  # bgr8
              TopicInfo("/camera/depth/camera_info", "sensor_msgs/msg/CameraInfo", 5)]
    enc = {"/camera/depth/image": "32FC1", "/camera/depth/image_raw": "16UC1",
           "/camera/rgb/image_bayer": "bayer_grbg8", "/camera/rgb/image_color": "bgr8"}
    assert suggest_flags(topics, encodings=enc) == [
        "--depth /camera/depth/image_raw", "--rgb /camera/rgb/image_color",
        "--info /camera/depth/camera_info"]


def test_suggestions_prefer_the_cameras_aligned_pair():
    """realsense-ros with two cameras: the aligned depth of the first and its colour stream,
    and the aligned depth's camera info (not the first colour topic or info by name)."""
    image, info = "sensor_msgs/msg/Image", "sensor_msgs/msg/CameraInfo"
    topics = [TopicInfo("/a_cam/color/image_raw", image, 5),
              TopicInfo("/d435/aligned_depth_to_color/camera_info", info, 5),
              TopicInfo("/d435/aligned_depth_to_color/image_raw", image, 5),
              TopicInfo("/d435/color/camera_info", info, 5),
              TopicInfo("/d435/color/image_raw", image, 5),
              TopicInfo("/d435/depth/camera_info", info, 5),
              TopicInfo("/d435/depth/image_rect_raw", image, 5)]
    enc = {t.topic: ("16UC1" if "depth" in t.topic else "rgb8") for t in topics
           if t.msgtype == image}
    assert suggest_flags(topics, encodings=enc) == [
        "--depth /d435/aligned_depth_to_color/image_raw", "--rgb /d435/color/image_raw",
        "--info /d435/aligned_depth_to_color/camera_info"]


# ----- resizes in the report ---------------------------------------------------------------------
def test_every_resize_is_in_the_report_and_json(tmp_path):
    root = make_tum_folder(tmp_path / "f", TIMES)
    for p in (root / "rgb").iterdir():
        cv2.imwrite(str(p), np.full((120, 160, 3), 90, np.uint8))
    rep = import_rgbd(root, tmp_path / "a.mcap", opts())
    assert rep.resizes == ("colour resized from 160x120 to the 80x60 depth images (12 frames)",)
    assert "resized: colour resized from 160x120 to the 80x60 depth images (12 frames)" \
        in rep.lines()
    r = CliRunner().invoke(cli, ["import", "rgbd", str(root), "-o", str(tmp_path / "b.mcap"),
                                 "--intrinsics", "60,60,39.5,29.5", "--json", "--quiet"])
    assert r.exit_code == 0, r.output
    d = json.loads(r.stdout)
    assert d["resizes"] == [{"stream": "colour", "from": [160, 120], "to": [80, 60],
                             "frames": 12}]


def test_bag_colour_resize_is_reported(tmp_path):
    bag = write_bag(tmp_path / "b.bag", rgb_size=(128, 96))
    rep = import_bag(bag, tmp_path / "o.mcap", BagOptions(depth=DEPTH, info=INFO, rgb=RGB,
                                                          **KEEP_WORLD))
    assert rep.resizes == ("colour resized from 128x96 to the 64x48 depth images (5 frames)",)


# ----- frames dropped for want of a pose ---------------------------------------------------------
def test_ground_truth_covering_half_the_frames_is_an_error(tmp_path):
    root = make_tum_folder(tmp_path / "f", TIMES)
    gt = (root / "groundtruth.txt").read_text().splitlines()
    (root / "groundtruth.txt").write_text("\n".join(gt[: 1 + 3 * 6]) + "\n")  # 6 of 12
    with pytest.raises(SgtoolError, match=r"6 of 12 frames \(50 %, more than 10 %\) would be "
                       r"dropped.*--estimate-poses.*--allow-drop"):
        import_rgbd(root, tmp_path / "a.mcap", opts())
    rep = import_rgbd(root, tmp_path / "b.mcap", opts(allow_drop=True))
    assert rep.frames == 6


def test_tf_at_a_low_rate_dropping_frames_is_an_error_naming_the_flags(tmp_path):
    # /tf at 2 Hz (0 and 0.5 s), images at 10 Hz for 1 s: the last 4 have no pose
    bag = write_bag(tmp_path / "b.bag", n=10, tf_every=5)
    with pytest.raises(SgtoolError, match=r"4 of 10 frames \(40 %.*--tf-tolerance S.*"
                       r"--estimate-poses.*--allow-drop"):
        import_bag(bag, tmp_path / "o.mcap", BagOptions(depth=DEPTH, info=INFO, **KEEP_WORLD))
    rep = import_bag(bag, tmp_path / "p.mcap", BagOptions(depth=DEPTH, info=INFO,
                                                          allow_drop=True, **KEEP_WORLD))
    assert rep.frames == 6
    r = CliRunner().invoke(cli, ["import", "bag", str(bag), "--depth", DEPTH, "--info", INFO,
                                 "-o", str(tmp_path / "q.mcap"), "--quiet", "--floor", "none",
                                 "--up", "z"])
    assert r.exit_code == 2 and len(r.output.strip().splitlines()) == 1
    assert "--allow-drop" in r.output


def test_warnings_shown_above_are_counted_not_repeated(tmp_path):
    """On a terminal each warning is on stderr as it is found; the report then counts them
    instead of printing them again (a redirected report keeps them)."""
    rep = import_rgbd(make_tum_folder(tmp_path / "f", TIMES), tmp_path / "a.mcap", opts())
    rep = dataclasses.replace(rep, warnings=("first thing", "second thing"))
    assert rep.lines()[-2:] == ["warning: first thing", "warning: second thing"]
    shown = rep.lines(warnings_shown=True)
    assert shown[-1] == "2 warnings, shown above"
    assert not any("thing" in line for line in shown)
    assert rep.lines(warnings_shown=True)[:-1] == rep.lines()[:-2]
