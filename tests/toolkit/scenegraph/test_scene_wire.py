"""Voronoi layer messages parsed from wire bytes built with numpy
(:mod:`sgtool.scenegraph.scene_wire`) equal the messages built field by field, to the
serialised byte; room hulls are remembered, never changed."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest
from foxglove_schemas_protobuf.LinePrimitive_pb2 import LinePrimitive
from foxglove_schemas_protobuf.Point3_pb2 import Point3
from foxglove_schemas_protobuf.SceneEntity_pb2 import SceneEntity
from foxglove_schemas_protobuf.SceneEntityDeletion_pb2 import SceneEntityDeletion
from foxglove_schemas_protobuf.SceneUpdate_pb2 import SceneUpdate
from foxglove_schemas_protobuf.Vector3_pb2 import Vector3

from sgtool.log import codec
from sgtool.log import schemas as S
from sgtool.scenegraph import scene_wire as sw
from sgtool.scenegraph.derived_layers import (
    GRAPH_Z,
    room_color,
    room_hull,
    room_hull_of,
    voronoi_message,
)


def _one_by_one(refresh: SimpleNamespace) -> SceneUpdate:
    """The Voronoi message built through the protobuf API, field by field."""
    vg, rooms = refresh.layers.voronoi, refresh.layers.node_rooms
    ent = SceneEntity(timestamp=codec.timestamp(refresh.time_ns), frame_id=S.WORLD_FRAME,
                      id="voronoi")
    xy = vg.positions.tolist()
    points = [Point3(x=float(x), y=float(y), z=GRAPH_Z) for x, y in xy]
    if len(vg.edges):
        pts, cols = [], []
        for u, v in vg.edges.tolist():
            c = room_color(rooms[u] if rooms[u] == rooms[v] else None)
            pts += (points[u], points[v])
            cols += (c, c)
        line = LinePrimitive(type=LinePrimitive.LINE_LIST, thickness=0.03,
                             points=pts, colors=cols, color=room_color(None))
        line.pose.orientation.w = 1.0  # the world frame as it is, no zero quaternion
        ent.lines.append(line)
    for n, (x, y) in enumerate(xy):
        s = ent.spheres.add()
        s.pose.position.x, s.pose.position.y, s.pose.position.z = float(x), float(y), GRAPH_Z
        s.pose.orientation.w = 1.0
        s.size.x = s.size.y = s.size.z = 0.08
        s.color.CopyFrom(room_color(rooms[n]))
    return SceneUpdate(deletions=[SceneEntityDeletion(
        timestamp=codec.timestamp(refresh.time_ns), type=SceneEntityDeletion.ALL)],
        entities=[ent])


def _refresh(rng: np.random.Generator, n: int) -> SimpleNamespace:
    pos = rng.normal(size=(n, 2)) * 5.0
    if n >= 2:
        pos[0] = (0.0, -0.0)  # zeros: unset in the message, -0.0 kept
        pos[1] = (1e-300, -7.25)
    m = int(rng.integers(0, 3 * n + 1)) if n else 0
    edges = rng.integers(0, max(n, 1), size=(m, 2)) if n else np.zeros((0, 2), np.int64)
    rooms = [None if rng.random() < 0.3 else f"room:{int(rng.integers(0, 6))}"
             for _ in range(n)]
    graph = SimpleNamespace(positions=pos, edges=edges)
    return SimpleNamespace(time_ns=int(rng.integers(0, 1 << 50)),
                           layers=SimpleNamespace(voronoi=graph, node_rooms=rooms))


@pytest.mark.parametrize("seed", range(25))
def test_voronoi_message_equals_the_one_built_field_by_field(seed: int) -> None:
    rng = np.random.default_rng(seed)
    r = _refresh(rng, int(rng.integers(0, 80)) if seed else 0)
    got, ref = voronoi_message(r), _one_by_one(r)
    assert got == ref
    assert got.SerializeToString(deterministic=True) == ref.SerializeToString(deterministic=True)
    n = len(r.layers.voronoi.positions)
    assert len(got.entities[0].spheres) == n
    if n >= 2:
        assert got.entities[0].spheres[1].pose.position.x == 1e-300


def test_voronoi_message_without_layers() -> None:
    assert voronoi_message(SimpleNamespace(time_ns=0, layers=None)) is None


def test_records_are_the_protobuf_wire_format() -> None:
    data = sw.records(sw.field(1, sw.POINT3), {"x": np.array([1.5, -2.0]), "y": 0.0,
                                               "z": np.array([3.0, 4.0])}, 2)
    assert len(data) == 2 * 29  # tag, length, 3 x (tag, double)
    assert data[:2] == bytes([0x0A, 27])
    v = Vector3()
    v.MergeFromString(data[2:29])
    assert (v.x, v.y, v.z) == (1.5, 0.0, 3.0)
    with pytest.raises(ValueError):
        sw.field(3, ["a"] * 16)  # 128 bytes: needs a two-byte length


def test_hull_memo_is_the_hull_and_read_only() -> None:
    rng = np.random.default_rng(3)
    for _ in range(5):
        pts = rng.normal(size=(int(rng.integers(1, 12)), 2))
        got = room_hull_of(np.ascontiguousarray(pts).tobytes(), 0.3)
        np.testing.assert_array_equal(got, room_hull(pts, 0.3))
        assert not got.flags.writeable
        again = room_hull_of(np.ascontiguousarray(pts).tobytes(), 0.3)
        assert again is got  # remembered
