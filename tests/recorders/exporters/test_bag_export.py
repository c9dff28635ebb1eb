"""`sgtool export bag`: a derived log as ROS 1 and ROS 2 bags, read back by rosbags'
AnyReader: every message written is read back on its topic with its type, the occupancy
grids hold the derived log's cells, the markers the graph's lines, rooms close their
outlines, each image has a CameraInfo of the same stamp and frame, fixed transforms are on
/tf_static once, no stamp is 0, frames follow REP-105, maps are latched, bags are
compressed, and an existing output is refused without --force and replaced only where
sgtool wrote it."""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner
from foxglove_schemas_protobuf.Color_pb2 import Color
from foxglove_schemas_protobuf.LinePrimitive_pb2 import LinePrimitive
from foxglove_schemas_protobuf.Point3_pb2 import Point3
from foxglove_schemas_protobuf.SceneEntity_pb2 import SceneEntity
from foxglove_schemas_protobuf.SceneEntityDeletion_pb2 import SceneEntityDeletion
from foxglove_schemas_protobuf.SceneUpdate_pb2 import SceneUpdate
from foxglove_schemas_protobuf.TextPrimitive_pb2 import TextPrimitive
from support.bag_read import read_bag, stamp_ns
from support.logfixtures import DT, synthetic_frame

from sgtool.cli import cli
from sgtool.errors import SgtoolError
from sgtool.log import LogReader, LogWriter, codec
from sgtool.log import schemas as S
from sgtool.recorders.exporters.bag_export import REP105, export_bag, trajectory_frames
from sgtool.recorders.exporters.ros_maps import (
    CUBE,
    CYLINDER,
    DELETEALL,
    LINE_LIST,
    LINE_STRIP,
    SPHERE_LIST,
    TEXT,
)
from sgtool.scenegraph.graph_scene import DOOR_SIZE, graph_scene_update

GOLDEN = Path(__file__).resolve().parents[2] / "golden" / "house6-tour.mcap"


def log_with_rooms(path: Path, n: int = 4) -> Path:
    """Frames, an occupancy grid, a Voronoi line list, a rooms update (an outline loop and a
    label) and a scene graph with two objects."""
    with LogWriter(path, seed=7) as w:
        for i in range(n):
            k, rgb, depth, ids, pose, base = synthetic_frame(i)
            w.write_frame(i * DT, rgb=rgb, depth=depth, ids=ids, pose=pose, intrinsics=k,
                          base_pose=base)
        t = n * DT
        grid = np.full((4, 5), -1, np.int8)
        grid[1:3, 1:4] = 0
        grid[0, 0] = 100
        w.write_proto(S.OCCUPANCY, t, codec.encode_grid(t, grid, (1.5, -2.0), 0.05))
        w.write_proto(S.VORONOI, t, SceneUpdate(entities=[SceneEntity(
            id="voronoi", frame_id="world", lines=[LinePrimitive(
                type=LinePrimitive.LINE_LIST, thickness=0.02, color=Color(r=1, a=1),
                points=[Point3(x=0, y=0, z=0), Point3(x=1, y=2, z=0)])])]))
        ent = SceneEntity(id="room:1", frame_id="world", lines=[LinePrimitive(
            type=LinePrimitive.LINE_LOOP, thickness=0.05, color=Color(r=0, g=1, b=0, a=1),
            points=[Point3(x=0, y=0), Point3(x=2, y=0), Point3(x=2, y=3)])])
        ent.texts.append(TextPrimitive(text="room:1 kitchen", color=Color(a=1)))
        w.write_proto(S.ROOMS, t, SceneUpdate(deletions=[SceneEntityDeletion(
            type=SceneEntityDeletion.ALL)], entities=[ent]))
        graph = {"version": "1.0", "rooms": [{"id": "room:1", "position": [1.0, 1.0]}],
                 "objects": [
            {"id": "obj:3", "category": "cabinet", "parent": "region:0", "room": "room:1",
             "position": [1.0, 2.0, 0.5]},
            {"id": "obj:4", "category": "apple", "parent": "obj:3", "room": "room:1",
             "position": [1.1, 2.0, 0.9]}],
                 "doors": [{"id": "door:1", "position": [2.0, 0.5], "state": "closed",
                            "rooms": ["room:1"]}],
                 "regions": [{"id": "frontier:0", "kind": "frontier", "room": "room:1",
                              "frontier_type": "leading out", "position": [3.0, 3.0]}]}
        w.write_record("scene_graph", t, graph)
        w.write_proto(S.GRAPH_SCENE, t, graph_scene_update(t, graph))
    return path


ALL_TOPICS = {
    "/camera/depth/image_raw", "/camera/rgb/image_raw", "/camera/instances/image_raw",
    "/camera/depth/camera_info", "/camera/rgb/camera_info", "/camera/instances/camera_info",
    "/tf", "/tf_static", "/map/occupancy", "/map/voronoi", "/map/rooms", "/map/objects",
    "/map/graph", "/sgtool/scene_graph"}


@pytest.mark.parametrize("fmt", ["ros1", "ros2"])
def test_every_channel_round_trips_through_rosbags(tmp_path, fmt):
    log = log_with_rooms(tmp_path / "d.mcap")
    out = tmp_path / ("o.bag" if fmt == "ros1" else "o")
    rep = export_bag(log, out)  # the format from the name
    assert rep.fmt == fmt
    types: dict[str, str] = {}
    got = read_bag(out, types)
    assert {t: len(v) for t, v in got.items()} == {t: n for t, _, n in rep.counts}
    assert {t: ty for t, ty, _ in rep.counts} == types
    assert set(types) == ALL_TOPICS
    with LogReader(log) as r:
        grid_msg = next(iter(r.messages([S.OCCUPANCY]))).message
        depth0 = codec.decode_image(next(iter(r.messages([S.DEPTH]))).message)
    cells, origin, res = codec.decode_grid(grid_msg)
    _, grid = got["/map/occupancy"][0]
    assert (grid.info.width, grid.info.height) == (5, 4)
    assert grid.info.resolution == pytest.approx(res)
    assert (grid.info.origin.position.x, grid.info.origin.position.y) == origin
    assert np.array_equal(np.asarray(grid.data, np.int8).reshape(4, 5), cells)
    assert grid.header.frame_id == "map"
    _, img = got["/camera/depth/image_raw"][0]
    assert img.encoding == "16UC1" and img.header.frame_id == "camera_optical_frame"
    assert np.array_equal(np.frombuffer(bytes(img.data), "<u2").reshape(depth0.shape), depth0)
    # world -> base moves (one /tf per frame), base -> camera is fixed (one /tf_static)
    assert len(got["/tf"]) == 4
    assert all(m.transforms[0].child_frame_id == "base_link" for _, m in got["/tf"])
    (t_static, static), = got["/tf_static"]
    assert [(x.header.frame_id, x.child_frame_id) for x in static.transforms] == [
        ("base_link", "camera_optical_frame")]
    assert t_static == 1_000_000_000 == stamp_ns(static.transforms[0])
    # a CameraInfo with every image: same stamp, same frame; nothing at stamp 0
    for ns in ("depth", "rgb", "instances"):
        imgs, infos = got[f"/camera/{ns}/image_raw"], got[f"/camera/{ns}/camera_info"]
        assert len(imgs) == len(infos) == 4
        for (ti, im), (tc, ci) in zip(imgs, infos, strict=True):
            assert ti == tc == stamp_ns(im) == stamp_ns(ci)
            assert im.header.frame_id == ci.header.frame_id
            assert (ci.width, ci.height) == (im.width, im.height)
    assert [t for t, _ in got["/camera/depth/image_raw"]] == [
        1_000_000_000 + i * DT for i in range(4)]
    assert min(t for msgs in got.values() for t, _ in msgs) == 1_000_000_000
    _, vor = got["/map/voronoi"][0]
    line = vor.markers[0]
    assert line.type == LINE_LIST and [(p.x, p.y) for p in line.points] == [(0, 0), (1, 2)]
    _, rooms = got["/map/rooms"][0]
    kinds = [m.type if m.action != DELETEALL else "deleteall" for m in rooms.markers]
    assert kinds == ["deleteall", LINE_STRIP, TEXT]
    loop = rooms.markers[1].points
    assert len(loop) == 4 and (loop[0].x, loop[0].y) == (loop[-1].x, loop[-1].y)  # closed
    assert rooms.markers[2].text == "room:1 kitchen"
    _, objs = got["/map/objects"][0]
    labels = [m.text for m in objs.markers if m.type == TEXT]
    assert labels == ["obj:3 cabinet", "obj:4 apple"]
    _, graph = got["/sgtool/scene_graph"][0]
    assert json.loads(graph.data)["objects"][1]["category"] == "apple"
    # /map/graph: a cube per object, a cylinder per door, the frontier, the edges
    _, scene = got["/map/graph"][0]
    shapes = [(m.ns, m.type) for m in scene.markers if m.type != TEXT and m.action != DELETEALL]
    assert shapes == [("obj:3", CUBE), ("obj:4", CUBE), ("door:1", CYLINDER),
                      ("frontier:0", SPHERE_LIST), ("edges", LINE_LIST)]
    door = next(m for m in scene.markers if m.type == CYLINDER)
    assert (door.pose.position.x, door.pose.position.y, door.pose.orientation.w) == (2, 0.5, 1)
    assert (door.scale.x, door.scale.y, door.scale.z) == DOOR_SIZE
    edges = next(m for m in scene.markers if m.ns == "edges").points
    assert len(edges) == 2 * 3  # obj:4 - obj:3, frontier - room, door - room
    assert "door:1 closed" in [m.text for m in scene.markers if m.type == TEXT]


def test_ros2_metadata_qos_distro_and_compression(tmp_path):
    """Maps and /tf_static offer transient-local QoS, images volatile; humble writes
    metadata version 5 with QoS as a YAML string, jazzy version 9 with its distro; the
    MCAP chunks are zstd."""
    import yaml
    from mcap.reader import make_reader

    log = log_with_rooms(tmp_path / "d.mcap")
    for distro, version in (("humble", 5), ("jazzy", 9)):
        out = tmp_path / distro
        export_bag(log, out, distro=distro)
        info = yaml.safe_load((out / "metadata.yaml").read_text())[
            "rosbag2_bagfile_information"]
        assert info["version"] == version
        assert info.get("ros_distro") == (None if distro == "humble" else "jazzy")
        qos = {}
        for tm in info["topics_with_message_count"]:
            prof = tm["topic_metadata"]["offered_qos_profiles"]
            assert isinstance(prof, str) == (distro == "humble")
            assert ("type_description_hash" in tm["topic_metadata"]) == (distro == "jazzy")
            prof = yaml.safe_load(prof) if isinstance(prof, str) else prof
            qos[tm["topic_metadata"]["name"]] = (prof[0]["durability"], prof[0]["depth"])
        # humble spells the policies as numbers, jazzy as names
        latched, volatile = ((1, 1), (2, 10)) if distro == "humble" else (
            ("transient_local", 1), ("volatile", 10))
        assert qos["/map/occupancy"] == qos["/tf_static"] == latched
        assert qos["/camera/depth/image_raw"] == volatile
        with open(out / f"{distro}.mcap", "rb") as fh:
            chunks = [c for c in make_reader(fh).get_summary().chunk_indexes]
        assert chunks and {c.compression for c in chunks} == {"zstd"}
        assert len(read_bag(out)["/map/occupancy"]) == 1


def test_topics_time_base_and_frame_names(tmp_path):
    log = log_with_rooms(tmp_path / "d.mcap")
    out = tmp_path / "o.bag"
    rep = export_bag(log, out, topics=["/camera/depth", "/map/occupancy"], time_base_s=5,
                     frames={"world": "odom"})
    got = read_bag(out)
    assert set(got) == {"/camera/depth/image_raw", "/camera/depth/camera_info",
                        "/map/occupancy"} == {t for t, _, _ in rep.counts}
    assert got["/map/occupancy"][0][1].header.frame_id == "odom"
    assert got["/camera/depth/image_raw"][0][1].header.frame_id == "camera"  # not renamed
    assert got["/camera/depth/image_raw"][0][0] == 5_000_000_000
    with pytest.raises(SgtoolError, match="--topics /nope: not a topic"):
        export_bag(log, tmp_path / "x", topics=["/nope"])
    with pytest.raises(SgtoolError, match="would be at stamp 0"):
        export_bag(log, tmp_path / "x", time_base_s=0)
    with pytest.raises(SgtoolError, match="a .bag name is a ROS 1 bag file"):
        export_bag(log, tmp_path / "x.bag", "ros2")
    with pytest.raises(SgtoolError, match="--compression zstd: a ros1 bag takes"):
        export_bag(log, tmp_path / "x.bag", compression="zstd")
    assert not list(tmp_path.glob("x*")) and not list(tmp_path.glob(".x*"))


def test_force_replaces_only_what_sgtool_wrote(tmp_path):
    log = log_with_rooms(tmp_path / "d.mcap")
    out = tmp_path / "o"
    out.mkdir()
    (out / "notes.txt").write_text("mine")
    with pytest.raises(SgtoolError, match="not empty"):
        export_bag(log, out)
    export_bag(log, out, force=True)
    export_bag(log, out, force=True)
    assert (out / "notes.txt").read_text() == "mine"
    assert {p.name for p in out.iterdir()} == {"notes.txt", "o.mcap", "metadata.yaml",
                                               ".sgtool-output"}
    assert "/tf_static" in read_bag(out)
    # a ROS 1 target that is not a bag is never replaced
    other = tmp_path / "other.bag"
    other.write_text("not a bag")
    with pytest.raises(SgtoolError, match="is not a ROS 1 bag"):
        export_bag(log, other, force=True)
    assert other.read_text() == "not a bag"


def test_a_replayed_log_round_trips_grid_for_grid(tmp_path):
    if not GOLDEN.is_file():
        pytest.skip("golden log absent")
    derived = tmp_path / "derived.mcap"
    r = CliRunner().invoke(cli, ["replay", str(GOLDEN), "-o", str(derived), "--max-frames",
                                 "40", "--no-progress"])
    assert r.exit_code == 0, r.output
    out = tmp_path / "bag"
    r = CliRunner().invoke(cli, ["export", "bag", str(derived), "-o", str(out)])
    assert r.exit_code == 0, r.output
    got = read_bag(out)
    with LogReader(derived) as rd:
        grids = [(d.log_time_ns, codec.decode_grid(d.message)[0])
                 for d in rd.messages([S.OCCUPANCY])]
        assert len(got["/sgtool/scene_graph"]) == rd.message_count("/sgtool/scene_graph")
    assert len(grids) >= 2 and len(got["/map/occupancy"]) == len(grids)
    for (t, cells), (tb, msg) in zip(grids, got["/map/occupancy"], strict=True):
        assert t + 1_000_000_000 == tb  # the default time base: log time + 1 s
        assert np.array_equal(np.asarray(msg.data, np.int8).reshape(cells.shape), cells)
    assert re.search(rf"/map/occupancy +nav_msgs/msg/OccupancyGrid +{len(grids)}\n", r.output)
    # an existing output is refused, replaced with --force
    r = CliRunner().invoke(cli, ["export", "bag", str(derived), "-o", str(out)])
    assert r.exit_code == 2 and "not empty" in r.output and "--force" in r.output
    r = CliRunner().invoke(cli, ["export", "bag", str(derived), "-o", str(out), "--force"])
    assert r.exit_code == 0 and len(read_bag(out)["/map/occupancy"]) == len(grids)
    assert not [p for p in tmp_path.iterdir() if p.name.endswith(".partial")]
    assert sorted(p.name for p in out.iterdir()) == [".sgtool-output", "bag.mcap",
                                                     "metadata.yaml"]


def test_not_an_sgtool_log_and_bad_format(tmp_path):
    log = log_with_rooms(tmp_path / "d.mcap")
    with pytest.raises(SgtoolError, match=r"--format \(fmt=\) 'ros3': give ros1 or ros2"):
        export_bag(log, tmp_path / "o", "ros3")
    with pytest.raises(SgtoolError, match="--distro 'iron'"):
        export_bag(log, tmp_path / "o", distro="iron")
    with pytest.raises(SgtoolError, match="no such file"):
        export_bag(tmp_path / "nope.mcap", tmp_path / "o")
    with pytest.raises(SgtoolError, match=r"folder .*missing does not exist"):
        export_bag(log, tmp_path / "missing" / "o")


def test_cli_options(tmp_path):
    log = log_with_rooms(tmp_path / "d.mcap")
    out = tmp_path / "o"
    r = CliRunner().invoke(cli, ["export", "bag", str(log), "-o", str(out), "--frames",
                                 "sgtool", "--frame", "camera=cam", "--topics",
                                 "/camera/depth, /tf", "--time-base", "2", "--no-progress"])
    assert r.exit_code == 0, r.output
    assert "(ros2, zstd)" in r.output and "log time + 2 s" in r.output
    got = read_bag(out)
    assert set(got) == {"/camera/depth/image_raw", "/camera/depth/camera_info", "/tf",
                        "/tf_static"}
    assert got["/camera/depth/image_raw"][0][1].header.frame_id == "cam"
    assert got["/tf"][0][1].transforms[0].header.frame_id == "world"
    for bad, says in ((["--frame", "camera"], "--frame 'camera': give OLD=NEW"),
                      (["--frame", "nope=x"], "'nope' is no frame of an sgtool log (those are "
                       "world (map), base (base_link), camera (camera_optical_frame))"),
                      (["--frame", "world=bad name"], "'bad name' is not a ROS frame name"),
                      (["--frame", "world=base_link"], "two frames would be named base_link"),
                      (["--frame", "map=odom", "--frame", "world=x"], "--frame 'world=x' and "
                       "--frame 'map=odom' rename the same frame (world); give one"),
                      (["-o", str(log / "out")], f"-o {log / 'out'}: {log} is a file, not a "
                       "folder"),
                      (["--topics", ","], "--topics: give at least one topic"),
                      (["--compression", "lz4"], "a ros2 bag takes none, zstd")):
        r = CliRunner().invoke(cli, ["export", "bag", str(log), "-o", str(tmp_path / "x"),
                                     *bad])
        assert r.exit_code == 2 and says in r.output, r.output
    # a frame by its REP-105 name (the default --frames): map is the world frame
    odom = tmp_path / "odom"
    r = CliRunner().invoke(cli, ["export", "bag", str(log), "-o", str(odom), "--frame",
                                 "map=odom", "--topics", "/tf", "--no-progress"])
    assert r.exit_code == 0, r.output
    assert read_bag(odom)["/tf"][0][1].transforms[0].header.frame_id == "odom"


def test_a_link_still_to_the_last_bits_is_static_and_foreign_channels_are_named(tmp_path):
    """A log of schema 1.0 composes base -> camera per frame, equal to the last bits: it
    goes once to /tf_static; channels sgtool does not know are not exported, and said so."""
    src = tmp_path / "jitter.mcap"
    with LogWriter(src, seed=7) as w:
        for i in range(4):
            k, _, depth, _, pose, base = synthetic_frame(i)
            if i == 0:
                w.write_calibration(0, k)
            w.write_transform(i * DT, S.WORLD_FRAME, S.BASE_FRAME, base)
            link = np.linalg.inv(base) @ pose
            link[0, 3] += i * 1e-16  # float noise of a composition
            w.write_transform(i * DT, S.BASE_FRAME, S.CAMERA_FRAME, link)
            w.write_depth(i * DT, depth)
        cid = w.copy_channel("/chatter", "", "", b"", "json")
        w.write_raw(cid, 0, b'{"data": "hi"}')
    rep = export_bag(src, tmp_path / "out")
    got = read_bag(tmp_path / "out")
    assert len(got["/tf_static"]) == 1
    (msg,) = (m for _, m in got["/tf_static"])
    assert [t.child_frame_id for t in msg.transforms] == ["camera_optical_frame"]
    assert {t.child_frame_id for _, m in got["/tf"] for t in m.transforms} == {"base_link"}
    assert rep.others == ("/chatter",)
    assert "note: not exported, channels sgtool does not know: /chatter" in rep.lines()


def test_a_recording_off_time_zero_keeps_its_stamps(tmp_path):
    """A log whose time starts at 900 s (a recording imported from a bag) exports at its
    own stamps, to play beside the original; one starting at 0 (simulation) is moved 1 s
    off stamp 0."""
    from support.crafted_logs import frame_messages

    log = tmp_path / "imported.mcap"
    with LogWriter(log, seed=1) as w:
        for topic, t, msg in frame_messages():
            w.write_proto(topic, t + 900_000_000_000, msg)
    rep = export_bag(log, tmp_path / "o.bag", topics=["/camera/depth"])
    stamps = [t for t, _ in read_bag(tmp_path / "o.bag")["/camera/depth/image_raw"]]
    assert stamps[0] == 900_000_000_000 and rep.time_base_s == 0.0
    at_zero = log_with_rooms(tmp_path / "d.mcap")
    rep = export_bag(at_zero, tmp_path / "z.bag", topics=["/camera/depth"])
    assert rep.time_base_s == 1.0


def test_a_tf_trajectory_keeps_its_frame_names_in_the_bag(shared_data_dir, tmp_path):
    """evo's odom -> base_link trajectory, imported and exported: the bag's /tf names the
    robot base base_link under odom, as the source did (not camera_optical_frame under
    map: a base's axes are not an optical frame's); --frames sgtool, names given to the
    API and --frame renames (by the name shown) still win."""
    from sgtool.recorders.importers.bag import import_bag
    from sgtool.recorders.importers.bag_options import BagOptions

    log = tmp_path / "traj.mcap"
    import_bag(shared_data_dir / "logs" / "evo" / "tf_example.bag", log,
               BagOptions(tf_frames=("odom", "base_link"), progress=False))
    export_bag(log, tmp_path / "b")
    tf = read_bag(tmp_path / "b")["/tf"]
    assert len(tf) == 517
    assert {(m.transforms[0].header.frame_id, m.transforms[0].child_frame_id)
            for _, m in tf} == {("odom", "base_link")}
    export_bag(log, tmp_path / "s", frames={})
    m = read_bag(tmp_path / "s")["/tf"][0][1]
    assert (m.transforms[0].header.frame_id, m.transforms[0].child_frame_id) == ("world", "camera")
    export_bag(log, tmp_path / "r", frames={**REP105, S.CAMERA_FRAME: "robot"})
    m = read_bag(tmp_path / "r")["/tf"][0][1]  # the names given are the names written
    assert (m.transforms[0].header.frame_id, m.transforms[0].child_frame_id) == ("map", "robot")
    # the CLI renames a frame by the name the bag shows for it (base_link here)
    r = CliRunner().invoke(cli, ["export", "bag", str(log), "-o", str(tmp_path / "c"),
                                 "--frame", "base_link=robot", "--no-progress"])
    assert r.exit_code == 0, r.output
    m = read_bag(tmp_path / "c")["/tf"][0][1]
    assert (m.transforms[0].header.frame_id, m.transforms[0].child_frame_id) == ("odom", "robot")


def test_trajectory_frames_leave_other_logs_alone():
    assert trajectory_frames({}, REP105) == REP105
    assert trajectory_frames({"content": "frames", "pose_frame": "x"}, REP105) == REP105
    got = trajectory_frames({"content": "trajectory", "pose_frame": "base_link"}, REP105)
    assert got == {S.WORLD_FRAME: "map", S.CAMERA_FRAME: "base_link"}  # no clash with base


def test_a_calibration_logged_after_the_images_of_its_time_still_gives_camera_info(
        tmp_path):
    """MCAP orders no messages of one log time; a log rewritten with the calibration after
    the images of the same time (as a ROS driver publishes camera_info after image) lost
    the first frame's CameraInfo of every camera, and gave the frame whose calibration
    changed the old one."""
    import dataclasses

    from support.mcap_variants import Variant, channel_ids, rewrite

    log = tmp_path / "d.mcap"
    with LogWriter(log, seed=7) as w:  # the camera's calibration changes at frame 2
        for i in range(4):
            k, rgb, depth, ids, pose, base = synthetic_frame(i)
            k = dataclasses.replace(k, fx=2 * k.fx) if i >= 2 else k
            w.write_frame(i * DT, rgb=rgb, depth=depth, ids=ids, pose=pose, intrinsics=k,
                          base_pose=base)
    calib = channel_ids(log, S.CALIBRATION)
    late = rewrite(log, tmp_path / "late.mcap", Variant(order=lambda ms: sorted(
        ms, key=lambda m: (m.log_time, m.channel_id in calib))))
    got = read_bag(export_bag(late, tmp_path / "o.bag").output)
    fx0 = synthetic_frame(0)[0].fx
    for ns in ("rgb", "depth", "instances"):
        images = [t for t, _ in got[f"/camera/{ns}/image_raw"]]
        infos = [t for t, _ in got[f"/camera/{ns}/camera_info"]]
        assert infos == images and len(images) == 4
        # each with the calibration of its own log time, logged after it
        assert [getattr(m, "k", getattr(m, "K", None))[0]
                for _, m in got[f"/camera/{ns}/camera_info"]] == pytest.approx(
            [fx0, fx0, 2 * fx0, 2 * fx0])


def test_a_log_without_calibration_says_why_there_is_no_camera_info(tmp_path):
    """Its images were exported without CameraInfo and nothing said so."""
    from support.mcap_variants import without

    log = log_with_rooms(tmp_path / "d.mcap")
    bare = without(log, tmp_path / "bare.mcap", S.CALIBRATION)
    rep = export_bag(bare, tmp_path / "o.bag")
    (note,) = [x for x in rep.lines() if "no CameraInfo" in x]
    assert note == ("note: no CameraInfo for /camera/depth, /camera/instances, /camera/rgb: "
                    "the log holds no camera calibration (/camera/calibration) to give its "
                    "images one")
    assert not [x for x in export_bag(log, tmp_path / "p.bag").lines() if "no CameraInfo" in x]
