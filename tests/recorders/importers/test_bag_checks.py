"""`sgtool import bag` on bags whose poses or calibration are not what a pinhole camera with
rigid poses needs: a /tf or pose-topic sample that is not finite or whose quaternion is zero
is refused in one line naming the topic, the time and the field (not turned into the
identity); a CameraInfo with lens distortion gets a note or a warning (sgtool does not
undistort); --tf-frames with --pose (where it would be ignored) is refused."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from click.testing import CliRunner
from support.bag_export import BagWriter
from support.logfixtures import synthetic_frame

from sgtool.cli import cli
from sgtool.errors import SgtoolError
from sgtool.log import LogReader
from sgtool.log.frame import CameraIntrinsics
from sgtool.log.poses import pose_difference
from sgtool.recorders.importers.bag import BagOptions, check_options, import_bag
from sgtool.recorders.importers.distortion import distortion_finding, distortion_shift_px

T0 = 1_700_000_000_000_000_000
DT = 100_000_000
DEPTH, INFO, POSE = "/camera/depth/image_raw", "/camera/depth/camera_info", "/camera/pose"
KEEP_WORLD = dict(up=np.array([0.0, 0.0, 1.0]), floor_auto=False, progress=False)
Edit = Callable[[int, Any], None]  # (frame index, message) -> change the message in place


def write_bag(path: Path, n: int = 5, *, tf_edit: Edit | None = None,
              pose_edit: Edit | None = None, info_edit: Edit | None = None,
              no_return: bool = False, depth_edit: Edit | None = None) -> Path:
    """``n`` synthetic frames as a ROS 1 bag: /tf world -> cam, a PoseStamped topic with the
    same poses, CameraInfo and 16UC1 depth (all 0 with ``no_return``); each ``*_edit`` may
    spoil a message."""
    with BagWriter(path, "ros1") as w:
        for i in range(n):
            k, _, depth, _, pose, _ = synthetic_frame(i)
            t = T0 + i * DT
            tr = w.transform_stamped(t, "world", "cam", pose)
            if tf_edit is not None:
                tf_edit(i, tr)
            w.write("/tf", "tf2_msgs/msg/TFMessage", t, w.tf(t, [tr]))
            ps = w.pose_stamped(t, "world", pose)
            if pose_edit is not None:
                pose_edit(i, ps)
            w.write(POSE, "geometry_msgs/msg/PoseStamped", t, ps)
            info = w.camera_info(t, "cam", k)
            if info_edit is not None:
                info_edit(i, info)
            w.write(INFO, "sensor_msgs/msg/CameraInfo", t, info)
            img = w.image(t, "cam", (depth * 1000 * (not no_return)).round().astype(np.uint16),
                          "16UC1")
            if depth_edit is not None:
                depth_edit(i, img)
            w.write(DEPTH, "sensor_msgs/msg/Image", t, img)
    return path


def _zero_quaternion(q: Any) -> None:
    q.x = q.y = q.z = q.w = 0.0


# ----- poses that are not rigid transforms ---------------------------------------------------
@pytest.mark.parametrize("edit, field", [
    (lambda tr: _zero_quaternion(tr.transform.rotation),
     "field transforms[0].transform.rotation: quaternion (x, y, z, w) = (0.0, 0.0, 0.0, 0.0) "
     "cannot be normalised"),
    (lambda tr: setattr(tr.transform.rotation, "w", float("nan")),
     "field transforms[0].transform.rotation"),
    (lambda tr: setattr(tr.transform.translation, "x", float("nan")),
     "field transforms[0].transform.translation: (nan, "),
    (lambda tr: setattr(tr.transform.translation, "z", float("inf")),
     "field transforms[0].transform.translation"),
])
def test_tf_sample_that_is_not_a_pose_is_refused(tmp_path, edit, field):
    bag = write_bag(tmp_path / "b.bag", tf_edit=lambda i, tr: edit(tr) if i == 3 else None)
    out = tmp_path / "o.mcap"
    with pytest.raises(SgtoolError) as e:
        import_bag(bag, out, BagOptions(depth=DEPTH, info=INFO, **KEEP_WORLD))
    msg = str(e.value)
    assert msg.startswith(f"/tf message at {T0 + 3 * DT} ns (header stamp), transform "
                          "world -> cam: ")
    assert field in msg and "\n" not in msg
    assert not out.exists() and list(tmp_path.iterdir()) == [bag]


def test_pose_topic_sample_with_a_zero_quaternion_is_refused(tmp_path):
    bag = write_bag(tmp_path / "b.bag",
                    pose_edit=lambda i, ps: _zero_quaternion(ps.pose.orientation) if i == 2
                    else None)
    with pytest.raises(SgtoolError, match=(
            rf"^{POSE} message at {T0 + 2 * DT} ns \(header stamp\): field pose.orientation: "
            r"quaternion .* cannot be normalised")):
        import_bag(bag, tmp_path / "o.mcap", BagOptions(depth=DEPTH, info=INFO, pose=POSE,
                                                        **KEEP_WORLD))


def test_zero_quaternion_refused_on_the_command_line_in_one_line(tmp_path):
    bag = write_bag(tmp_path / "b.bag",
                    tf_edit=lambda i, tr: _zero_quaternion(tr.transform.rotation) if i == 1
                    else None)
    out = tmp_path / "o.mcap"
    r = CliRunner().invoke(cli, ["import", "bag", str(bag), "--depth", DEPTH, "--info", INFO,
                                 "-o", str(out), "--quiet"])
    assert r.exit_code == 2
    lines = r.output.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("sgtool: error: /tf message at ")
    assert "cannot be normalised" in lines[0] and not out.exists()


def test_a_quaternion_that_is_not_unit_length_is_normalised(tmp_path):
    """Scaled quaternions (x3) give the same poses as the unit ones."""
    def scale(i: int, tr: Any) -> None:
        q = tr.transform.rotation
        q.x, q.y, q.z, q.w = 3 * q.x, 3 * q.y, 3 * q.z, 3 * q.w

    a = write_bag(tmp_path / "a.bag")
    b = write_bag(tmp_path / "b.bag", tf_edit=scale)
    opts = BagOptions(depth=DEPTH, info=INFO, **KEEP_WORLD)
    import_bag(a, tmp_path / "a.mcap", opts)
    import_bag(b, tmp_path / "b.mcap", opts)
    with LogReader(tmp_path / "a.mcap") as ra, LogReader(tmp_path / "b.mcap") as rb:
        for x, y in zip(ra.frames(), rb.frames(), strict=True):
            dt, dr = pose_difference(x.pose, y.pose)
            assert dt < 1e-12 and dr < 1e-6


# ----- --tf-frames with --pose ----------------------------------------------------------------
def test_tf_frames_with_a_pose_topic_is_refused_before_the_bag_is_read(tmp_path):
    with pytest.raises(SgtoolError, match=r"--tf-frames a:b applies only to camera poses from "
                       r"the tf tree \(without --pose\); --pose /groundtruth"):
        check_options(BagOptions(pose="/groundtruth", tf_frames=("a", "b")))
    bag = write_bag(tmp_path / "b.bag", n=2)
    r = CliRunner().invoke(cli, ["import", "bag", str(bag), "--pose", POSE, "--tf-frames",
                                 "world:cam", "-o", str(tmp_path / "o.mcap")])
    assert r.exit_code == 2 and len(r.output.strip().splitlines()) == 1
    assert "--tf-frames world:cam applies only" in r.output
    assert not (tmp_path / "o.mcap").exists()


# ----- lens distortion ------------------------------------------------------------------------
def _set_d(coeffs: list[float]) -> Edit:
    def edit(i: int, info: Any) -> None:
        setattr(info, "D" if hasattr(info, "D") else "d", np.array(coeffs, dtype=np.float64))
    return edit


def test_distortion_shift_of_known_models():
    k = CameraIntrinsics(640, 480, 500.0, 500.0, 319.5, 239.5)
    assert distortion_shift_px("plumb_bob", (0.0,) * 5, k) == 0.0
    # k1 alone at the corner (r = 0.8 in normalised coordinates): r^3 * k1 * f pixels
    corner = np.hypot(319.5, 239.5) / 500.0
    assert distortion_shift_px("plumb_bob", (0.1, 0, 0, 0, 0), k) == pytest.approx(
        0.1 * corner**3 * 500.0, rel=1e-9)
    # fisheye: theta = atan(r) with k = 0 still differs from the pinhole r
    assert distortion_shift_px("equidistant", (0, 0, 0, 0), k) == pytest.approx(
        (corner - np.arctan(corner)) * 500.0, rel=1e-9)
    assert distortion_shift_px("mystery", (0.1,), k) is None
    assert distortion_finding(("plumb_bob", (0.0,) * 5), "/info", k) is None
    assert distortion_finding(None, "/info", k) is None
    small = distortion_finding(("plumb_bob", (0.001, 0, 0, 0, 0)), "/info", k)
    assert small is not None and not small[1] and "does not undistort" in small[0]


def test_implausible_distortion_is_a_warning_without_numpy_warnings(recwarn):
    k = CameraIntrinsics(640, 480, 500.0, 500.0, 319.5, 239.5)
    assert distortion_shift_px("plumb_bob", (1e300, 1e300, 0, 0, 1e300), k) > 1e4
    text, warn = distortion_finding(("plumb_bob", (1e300, 0, 0, 0, 0)), "/info", k)
    assert warn and "more than 10,000 px (implausible coefficients)" in text
    assert not [w for w in recwarn if issubclass(w.category, RuntimeWarning)]


def test_camera_info_with_distortion_is_reported(tmp_path):
    """A noticeable distortion is a warning (shown at once and kept in the log metadata),
    a slight one a note; zero coefficients say nothing."""
    shown: list[str] = []
    opts = BagOptions(depth=DEPTH, info=INFO, warn=shown.append, **KEEP_WORLD)
    strong = write_bag(tmp_path / "s.bag", info_edit=_set_d([0.5, -0.1, 0.001, 0.002, 0.0]))
    rep = import_bag(strong, tmp_path / "s.mcap", opts)
    assert rep.frames == 5 and len(rep.warnings) == 1 and shown == list(rep.warnings)
    w = rep.warnings[0]
    assert w.startswith(f"--info {INFO} has plumb_bob lens distortion (D=0.5,-0.1,0.001,"
                        "0.002,0) and sgtool does not undistort: it moves pixels by up to ")
    weak = write_bag(tmp_path / "w.bag", info_edit=_set_d([1e-4, 0, 0, 0, 0]))
    rep = import_bag(weak, tmp_path / "w.mcap", opts)
    assert not rep.warnings and any("lens distortion (D=0.0001,0,0,0,0)" in n
                                    for n in rep.notes)
    clean = write_bag(tmp_path / "c.bag")
    rep = import_bag(clean, tmp_path / "c.mcap", opts)
    assert not rep.warnings and not any("distortion" in n for n in rep.notes)


def test_depth_without_a_return_is_refused_as_the_folder_importer_does(tmp_path):
    """A bag whose depth images hold no valid pixel imported with exit 0 into a log of no
    map (the RGB-D folder importer refused it): one line naming the bag and the topic."""
    bag = write_bag(tmp_path / "b.bag", no_return=True)
    out = tmp_path / "o.mcap"
    with pytest.raises(SgtoolError, match=rf"b\.bag: --depth {DEPTH}: none of the 5 sampled "
                                          "depth images has a valid pixel"):
        import_bag(bag, out, BagOptions(depth=DEPTH, info=INFO, **KEEP_WORLD))
    assert not out.exists()


def test_a_trajectory_far_from_the_origin_is_refused_at_import(tmp_path):
    """A camera 1e6 m from the origin imported with exit 0 into a log that replay then
    refused: the import refuses it, with replay's advice, and writes nothing."""
    def far(i, tr):
        tr.transform.translation.x += 1e6

    bag = write_bag(tmp_path / "b.bag", tf_edit=far)
    out = tmp_path / "o.mcap"
    with pytest.raises(SgtoolError, match=r"^frame 0 .*: the camera at \(1000000.*\) m is "
                                          r"beyond .* recentre the trajectory"):
        import_bag(bag, out, BagOptions(depth=DEPTH, info=INFO, **KEEP_WORLD))
    assert not out.exists()


def test_images_stamped_out_of_their_recording_order_are_told(tmp_path):
    """Two depth images whose header stamps run backwards against the bag's order: the
    import says so (each is posed at its own stamp; --timestamps bag takes the order)."""
    def swap(i, msg):
        if i in (2, 3):
            t = T0 + (5 - i) * DT
            msg.header.stamp.sec, msg.header.stamp.nanosec = t // 10**9, t % 10**9

    bag = tmp_path / "b.bag"
    write_bag(bag, depth_edit=swap)
    warned: list[str] = []
    import_bag(bag, tmp_path / "o.mcap", BagOptions(depth=DEPTH, info=INFO, warn=warned.append,
                                                    **KEEP_WORLD))
    assert any("1 image(s) stamped earlier than the image recorded before" in w
               for w in warned), warned
