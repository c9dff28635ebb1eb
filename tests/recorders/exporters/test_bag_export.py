"""`sgtool export bag`: a derived log as ROS 1 and ROS 2 bags, read back by rosbags'
AnyReader: every message written is read back on its topic, the occupancy grids hold the
derived log's cells, the markers the graph's lines, rooms close their outlines, and an
existing output is refused without --force."""

from __future__ import annotations

import json
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
from support.logfixtures import DT, synthetic_frame

from sgtool.cli import cli
from sgtool.errors import SgtoolError
from sgtool.log import LogReader, LogWriter, codec
from sgtool.log import schemas as S
from sgtool.recorders.exporters.bag_export import export_bag
from sgtool.recorders.exporters.ros_maps import DELETEALL, LINE_LIST, LINE_STRIP, TEXT

GOLDEN = Path(__file__).resolve().parents[2] / "golden" / "house6-tour.mcap"


def read_bag(path: Path) -> dict[str, list[tuple[int, object]]]:
    from rosbags.highlevel import AnyReader
    from rosbags.typesys import Stores, get_typestore

    out: dict[str, list[tuple[int, object]]] = {}
    with AnyReader([path], default_typestore=get_typestore(Stores.LATEST)) as r:
        for c, t, raw in r.messages():
            out.setdefault(c.topic, []).append((t, r.deserialize(raw, c.msgtype)))
    return out


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
        w.write_record("scene_graph", t, {"version": "1.0", "rooms": [], "objects": [
            {"id": "obj:3", "category": "cabinet", "parent": "region:0", "room": "room:1",
             "position": [1.0, 2.0, 0.5]},
            {"id": "obj:4", "category": "apple", "parent": "obj:3", "room": "room:1",
             "position": [1.1, 2.0, 0.9]}]})
    return path


@pytest.mark.parametrize("fmt", ["ros1", "ros2"])
def test_every_channel_round_trips_through_rosbags(tmp_path, fmt):
    log = log_with_rooms(tmp_path / "d.mcap")
    out = tmp_path / ("o.bag" if fmt == "ros1" else "o")
    rep = export_bag(log, out, fmt)
    got = read_bag(out)
    assert {t: len(v) for t, v in got.items()} == {t: n for t, _, n in rep.counts}
    assert {t for t, _, _ in rep.counts} == {
        "/camera/depth/image_raw", "/camera/rgb/image_raw", "/camera/instances/image_raw",
        "/camera/camera_info", "/tf", "/map/occupancy", "/map/voronoi", "/map/rooms",
        "/map/objects", "/sgtool/scene_graph"}
    with LogReader(log) as r:
        grid_msg = next(iter(r.messages([S.OCCUPANCY]))).message
        depth0 = codec.decode_image(next(iter(r.messages([S.DEPTH]))).message)
        n_tf = r.message_count(S.TF)
    cells, origin, res = codec.decode_grid(grid_msg)
    _, grid = got["/map/occupancy"][0]
    assert (grid.info.width, grid.info.height) == (5, 4)
    assert grid.info.resolution == pytest.approx(res)
    assert (grid.info.origin.position.x, grid.info.origin.position.y) == origin
    assert np.array_equal(np.asarray(grid.data, np.int8).reshape(4, 5), cells)
    _, img = got["/camera/depth/image_raw"][0]
    assert img.encoding == "16UC1"
    assert np.array_equal(np.frombuffer(bytes(img.data), "<u2").reshape(depth0.shape), depth0)
    assert len(got["/tf"]) == n_tf
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
        assert t == tb
        assert np.array_equal(np.asarray(msg.data, np.int8).reshape(cells.shape), cells)
    assert f"/map/occupancy               nav_msgs/msg/OccupancyGrid  {len(grids)}" in r.output
    # an existing output is refused, replaced with --force
    r = CliRunner().invoke(cli, ["export", "bag", str(derived), "-o", str(out)])
    assert r.exit_code == 2 and "exists; not overwriting it (use --force)" in r.output
    r = CliRunner().invoke(cli, ["export", "bag", str(derived), "-o", str(out), "--force"])
    assert r.exit_code == 0 and len(read_bag(out)["/map/occupancy"]) == len(grids)
    assert not [p for p in tmp_path.iterdir() if p.name.endswith(".partial")]
    assert sorted(p.name for p in out.iterdir()) == ["bag.mcap", "metadata.yaml"]


def test_not_an_sgtool_log_and_bad_format(tmp_path):
    log = log_with_rooms(tmp_path / "d.mcap")
    with pytest.raises(SgtoolError, match="--format 'ros3': give ros1 or ros2"):
        export_bag(log, tmp_path / "o", "ros3")
    with pytest.raises(SgtoolError, match="no such file"):
        export_bag(tmp_path / "nope.mcap", tmp_path / "o")
    with pytest.raises(SgtoolError, match=r"folder .*missing does not exist"):
        export_bag(log, tmp_path / "missing" / "o")
