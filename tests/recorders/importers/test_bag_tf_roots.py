"""`sgtool import bag` of tf trees stored from the camera out (legal tf, and common in
drivers that publish camera_link -> world), of images in the world frame, and of a camera
with no world at all: each is one line naming the --tf-frames pair to give (or
--estimate-poses), --list suggests the same pair, and with it the poses come through the
inverted links. Before, every frame got one constant pose and the import succeeded."""

from __future__ import annotations

import numpy as np
import pytest
from click.testing import CliRunner
from support.bag_export import BagWriter
from support.logfixtures import synthetic_frame

from sgtool.cli import cli
from sgtool.errors import SgtoolError
from sgtool.log import LogReader
from sgtool.log.frame import Frame
from sgtool.recorders.importers.bag import BagOptions, import_bag
from sgtool.recorders.importers.textformats import PinholeParams

DEPTH = "/camera/depth/image_raw"
KEEP_WORLD = dict(up=np.array([0.0, 0.0, 1.0]), floor_auto=False, progress=False)

# name: (the links of a frame's pose P as (parent, child, transform), the images' frame)
CASES = {
    "camera at the root": (lambda P: [("cam", "world", np.linalg.inv(P))], "cam"),
    "camera under a root link": (lambda P: [("cam_link", "world", np.linalg.inv(P)),
                                            ("cam_link", "cam", np.eye(4))], "cam"),
    "images in the world frame": (lambda P: [("world", "cam", P)], "world"),
}


def frames_of(n: int) -> list[Frame]:
    out = []
    for i in range(n):
        k, rgb, depth, ids, pose, base = synthetic_frame(i)
        out.append(Frame(i, i * 100_000_000, rgb, depth, ids, pose, k, base))
    return out


def write_bag(path, frames, links, image_frame: str, static: bool = False) -> None:
    """A ROS 2 bag of depth images in ``image_frame`` and, per frame (``static``: once, on
    /tf_static), the tf ``links`` of its pose."""
    with BagWriter(path, "ros2-sqlite3") as w:
        for i, f in enumerate(frames):
            t = f.time_ns
            if not static or i == 0:
                w.write("/tf_static" if static else "/tf", "tf2_msgs/msg/TFMessage", t,
                        w.tf(t, [w.transform_stamped(t, a, b, T) for a, b, T in links(f.pose)]))
            w.write(DEPTH, "sensor_msgs/msg/Image", t,
                    w.image(t, image_frame, (f.depth * 1000).round().astype(np.uint16),
                            "16UC1"))


def options(frames: list[Frame], **kw) -> BagOptions:
    k = frames[0].intrinsics
    return BagOptions(depth=DEPTH, intrinsics=PinholeParams(k.fx, k.fy, k.cx, k.cy),
                      **KEEP_WORLD, **kw)


@pytest.mark.parametrize("case", sorted(CASES))
def test_a_tree_stored_from_the_camera_out_is_refused_naming_the_pair(tmp_path, case):
    links, image_frame = CASES[case]
    frames = frames_of(6)
    bag = tmp_path / "b"
    write_bag(bag, frames, links, image_frame)
    out = tmp_path / "o.mcap"
    with pytest.raises(SgtoolError, match=r"--tf-frames (WORLD:CAMERA with the camera's "
                       r"frame, e.g. --tf-frames )?world:cam$"):
        import_bag(bag, out, options(frames))
    assert not out.exists()
    r = CliRunner().invoke(cli, ["import", "bag", str(bag), "--list"])
    line = next(x for x in r.output.splitlines() if x.startswith("camera / trajectory"))
    assert "--tf-frames world:cam" in line.split(": ", 1)[1].split(" | "), r.output
    assert import_bag(bag, out, options(frames, tf_frames=("world", "cam"))).frames == 6
    with LogReader(out) as log:
        for got, f in zip([g.pose for g in log.frames()], frames, strict=True):
            assert np.allclose(got, f.pose, atol=1e-6)


def test_a_camera_with_no_world_in_its_tree_is_told_to_estimate_poses(tmp_path):
    """Only a static link from the camera to another sensor: no trajectory in the bag."""
    frames = frames_of(4)
    write_bag(tmp_path / "b", frames, lambda P: [("cam", "imu", np.eye(4))], "cam",
              static=True)
    with pytest.raises(SgtoolError, match="no frame named like a world .* the bag holds no "
                       "camera trajectory; give --tf-frames WORLD:CAMERA, or --estimate-poses"):
        import_bag(tmp_path / "b", tmp_path / "o.mcap", options(frames))


def test_a_tree_of_static_links_only_is_refused_not_posed_once(tmp_path):
    """A camera driver's mounts alone (map -> camera_link -> cam on /tf_static, nothing on
    /tf): every frame got the one static pose, exit 0. Now one line naming the ways out;
    with --estimate-poses the bag's tree is no reference and the frames are estimated; with
    the pair named by --tf-frames the static pose is taken as asked."""
    frames = frames_of(4)
    write_bag(tmp_path / "b", frames, lambda P: [("map", "camera_link", frames[0].pose),
                                                 ("camera_link", "cam", np.eye(4))], "cam",
              static=True)
    out = tmp_path / "o.mcap"
    with pytest.raises(SgtoolError, match=r"static links only \(/tf_static\): every frame "
                       r"would get the same pose; give --tf-frames WORLD:CAMERA through a "
                       r"moving /tf link, --pose TOPIC, or --estimate-poses$"):
        import_bag(tmp_path / "b", out, options(frames))
    assert not out.exists()
    assert import_bag(tmp_path / "b", out, options(frames, estimate_poses=True)).frames == 4
    # the pair named (a camera on a tripod): its one pose is what was asked for
    rep = import_bag(tmp_path / "b", tmp_path / "t.mcap",
                     options(frames, tf_frames=("map", "cam")))
    assert rep.frames == 4
    # estimated while naming it: a constant pose is no reference to measure drift against
    rep = import_bag(tmp_path / "b", tmp_path / "e.mcap",
                     options(frames, tf_frames=("map", "cam"), estimate_poses=True))
    assert rep.drift is None
