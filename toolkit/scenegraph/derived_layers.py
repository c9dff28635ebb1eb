"""The derived layers of a refresh as log messages (pure functions, no I/O).

- ``/map/occupancy``: the BEV occupancy grid as a Foxglove ``Grid`` (int8: -1 unknown,
  0 free, 100 occupied; :func:`sgtool.log.codec.encode_grid`);
- ``/map/voronoi``: the Voronoi graph as a ``SceneUpdate`` with one ``LINE_LIST`` whose
  edges are coloured by room (grey: cut at a door or in no room), and the nodes as small
  spheres in the same colours;
- ``/map/rooms``: per explored room its outline (the convex hull of its nodes, grown by
  their clearance-free margin of ``ROOM_MARGIN``) as a ``LINE_LOOP`` and a text label
  "room:3 kitchen"; every update first deletes all earlier entities, so rooms that merged
  or vanished disappear;
- ``/sgtool/scene_graph``: the canonical JSON of the graph.

Colours come from :func:`sgtool.colors.color_for`, so a room has the same
colour in Foxglove and in ``sgtool view``. Everything is a deterministic function of the
refresh.
"""

from __future__ import annotations

import functools

import numpy as np
from foxglove_schemas_protobuf.Color_pb2 import Color
from foxglove_schemas_protobuf.Grid_pb2 import Grid
from foxglove_schemas_protobuf.LinePrimitive_pb2 import LinePrimitive
from foxglove_schemas_protobuf.Point3_pb2 import Point3
from foxglove_schemas_protobuf.Pose_pb2 import Pose
from foxglove_schemas_protobuf.Quaternion_pb2 import Quaternion
from foxglove_schemas_protobuf.SceneEntity_pb2 import SceneEntity
from foxglove_schemas_protobuf.SceneEntityDeletion_pb2 import SceneEntityDeletion
from foxglove_schemas_protobuf.SceneUpdate_pb2 import SceneUpdate
from foxglove_schemas_protobuf.TextPrimitive_pb2 import TextPrimitive
from scipy.spatial import ConvexHull, QhullError

from sgtool.colors import color_for
from sgtool.log import codec
from sgtool.log import schemas as S
from sgtool.log.records import SceneGraphRecord
from sgtool.log.writer import LogWriter
from sgtool.scenegraph import scene_wire as sw
from sgtool.scenegraph.graph_scene import graph_scene_update
from sgtool.scenegraph.stream import Refresh

GRAPH_Z = 0.05  # m: height of the drawn graph above the floor
LABEL_Z = 1.5  # m: height of room labels
ROOM_MARGIN = 0.3  # m: room outlines grow this far beyond their nodes
NO_ROOM = (0.55, 0.55, 0.55)
DERIVED_TOPICS = (S.OCCUPANCY, S.VORONOI, S.ROOMS, S.RECORDS["scene_graph"].topic)


def _rgba(key: str | None, alpha: float = 1.0) -> tuple[float, float, float, float]:
    if key is None:
        r, g, b = NO_ROOM
    else:
        r, g, b = (c / 255.0 for c in color_for(key))
    return r, g, b, alpha


def room_color(key: str | None, alpha: float = 1.0) -> Color:
    """The Foxglove colour of room ``key`` (:func:`sgtool.colors.color_for`, channels 0 to
    1), grey (``NO_ROOM``) for None; opacity ``alpha``."""
    r, g, b, a = _rgba(key, alpha)
    return Color(r=r, g=g, b=b, a=a)


# LinePrimitive.points / .colors and SceneEntity.spheres records (sgtool.scenegraph.scene_wire)
_LINE_POINT = sw.field(5, sw.POINT3)
_LINE_COLOR = sw.field(7, sw.COLOR)
_SPHERE = sw.field(9, [*sw.field(1, [*sw.field(1, sw.POINT3), *sw.field(2, [b"\x21", "w"])]),
                       *sw.field(2, sw.doubles(("sx", "sy", "sz"))), *sw.field(3, sw.COLOR)])


def occupancy_message(refresh: Refresh) -> Grid | None:
    if refresh.layers is None:
        return None
    occ = refresh.layers.occupancy
    return codec.encode_grid(refresh.time_ns, occ.grid, occ.origin, occ.resolution)


def voronoi_message(refresh: Refresh) -> SceneUpdate | None:
    """The Voronoi graph, edges and nodes coloured by room (module doc). The points,
    colours and spheres are parsed from wire bytes built at once
    (:mod:`sgtool.scenegraph.scene_wire`): the same message as built one by one."""
    if refresh.layers is None:
        return None
    lay = refresh.layers
    vg = lay.voronoi
    ent = SceneEntity(timestamp=codec.timestamp(refresh.time_ns), frame_id=S.WORLD_FRAME,
                      id="voronoi")
    palette: dict[str | None, int] = {None: 0}
    code = np.asarray([palette.setdefault(r, len(palette)) for r in lay.node_rooms],
                      dtype=np.int64)
    rgba = np.asarray([_rgba(k) for k in palette], dtype=np.float64)  # in code order
    xy = np.asarray(vg.positions, dtype=np.float64).reshape(-1, 2)
    edges = np.asarray(vg.edges, dtype=np.int64).reshape(-1, 2)
    if len(edges):
        cu, cv = code[edges[:, 0]], code[edges[:, 1]]
        ends = xy[edges.reshape(-1)]  # u, v of every edge
        col = rgba[np.repeat(np.where(cu == cv, cu, 0), 2)]
        m = len(ends)
        line = LinePrimitive(type=LinePrimitive.LINE_LIST, pose=_identity(), thickness=0.03,
                             color=room_color(None))
        line.MergeFromString(
            sw.records(_LINE_POINT, {"x": ends[:, 0], "y": ends[:, 1], "z": GRAPH_Z}, m)
            + sw.records(_LINE_COLOR, {"r": col[:, 0], "g": col[:, 1], "b": col[:, 2],
                                       "a": col[:, 3]}, m))
        ent.lines.append(line)
    if len(xy):
        col = rgba[code]
        ent.MergeFromString(sw.records(_SPHERE, {
            "x": xy[:, 0], "y": xy[:, 1], "z": GRAPH_Z, "w": 1.0, "sx": 0.08, "sy": 0.08,
            "sz": 0.08, "r": col[:, 0], "g": col[:, 1], "b": col[:, 2], "a": col[:, 3]},
            len(xy)))
    return SceneUpdate(deletions=[SceneEntityDeletion(
        timestamp=codec.timestamp(refresh.time_ns), type=SceneEntityDeletion.ALL)],
        entities=[ent])


def room_hull(points: np.ndarray, margin: float) -> np.ndarray:
    """Convex hull, as (k, 2) vertices (counter-clockwise, from its lowest-x then lowest-y
    vertex), of the discs of radius ``margin`` (m) around ``points`` ((n, 2), m),
    approximated by 8 points per disc; collinear points are not vertices. Qhull
    (``scipy.spatial.ConvexHull``) finds it; a cloud that spans no area (fewer than 3
    points, or all on one line) is returned as its sorted distinct points when it has fewer
    than 3, else as its two extreme points."""
    ang = np.arange(8) * (np.pi / 4)
    ring = np.stack([np.cos(ang), np.sin(ang)], axis=1) * margin
    cloud = (points[:, None, :] + ring[None, :, :]).reshape(-1, 2)
    cloud = np.round(cloud, 6)
    cloud = cloud[np.lexsort((cloud[:, 1], cloud[:, 0]))]  # sorted: cloud[0] is the start
    keep = np.ones(len(cloud), dtype=bool)
    keep[1:] = np.any(cloud[1:] != cloud[:-1], axis=1)
    cloud = cloud[keep]
    if len(cloud) < 3:
        return cloud
    try:
        hull = ConvexHull(cloud)
    except QhullError:  # all points on one line: its two ends
        return cloud[[0, -1]]
    vertices = hull.vertices  # counter-clockwise in 2-D
    start = int(np.argmin(vertices))  # the smallest index is the lexicographic minimum
    return cloud[np.roll(vertices, -start)]


@functools.lru_cache(maxsize=1024)
def room_hull_of(points: bytes, margin: float) -> np.ndarray:
    """:func:`room_hull` of the float64 (x, y) pairs in ``points``, remembered: most rooms
    keep their nodes from one refresh to the next (the result is read-only)."""
    hull = room_hull(np.frombuffer(points, dtype=np.float64).reshape(-1, 2), margin)
    hull.setflags(write=False)
    return hull


def rooms_message(refresh: Refresh) -> SceneUpdate | None:
    """Room outlines and labels (module doc)."""
    if refresh.layers is None:
        return None
    lay = refresh.layers
    vg = lay.voronoi
    stamp = codec.timestamp(refresh.time_ns)
    upd = SceneUpdate(deletions=[SceneEntityDeletion(timestamp=stamp,
                                                     type=SceneEntityDeletion.ALL)])
    by_room: dict[str, list[int]] = {}
    for n, r in enumerate(lay.node_rooms):
        if r is not None:
            by_room.setdefault(r, []).append(n)
    categories = {r.id: r.category for r in refresh.graph.rooms}
    for rid in sorted(by_room, key=lambda s: (len(s), s)):
        nodes = np.asarray(by_room[rid])
        hull = room_hull_of(
            np.ascontiguousarray(vg.positions[nodes], dtype=np.float64).tobytes(), ROOM_MARGIN)
        ent = SceneEntity(timestamp=stamp, frame_id=S.WORLD_FRAME, id=rid)
        ent.lines.append(LinePrimitive(
            type=LinePrimitive.LINE_LOOP, pose=_identity(), thickness=0.05,
            color=room_color(rid),
            points=[Point3(x=float(x), y=float(y), z=GRAPH_Z) for x, y in hull.tolist()]))
        cx, cy = (float(v) for v in vg.positions[nodes].mean(axis=0))
        room = refresh.graph.room(rid)
        if room is not None:
            cx, cy = room.position
        t = TextPrimitive(billboard=True, font_size=14.0, scale_invariant=True,
                          color=room_color(rid),
                          text=f"{rid} {categories.get(rid, 'unknown')}")
        t.pose.position.x, t.pose.position.y, t.pose.position.z = cx, cy, LABEL_Z
        t.pose.orientation.w = 1.0
        ent.texts.append(t)
        upd.entities.append(ent)
    return upd


def _identity() -> Pose:
    """The pose of a primitive given in world coordinates (a pose left out is a zero
    quaternion on the wire, which a viewer may not read as no rotation)."""
    return Pose(orientation=Quaternion(w=1.0))


def write_refresh(writer: LogWriter, refresh: Refresh) -> None:
    """Write the derived channels of ``refresh`` at its time: occupancy, Voronoi graph,
    rooms (when map layers exist), the scene graph and its ``SceneUpdate`` (``/map/graph``,
    :mod:`sgtool.scenegraph.graph_scene`)."""
    t = refresh.time_ns
    for topic, make in ((S.OCCUPANCY, occupancy_message), (S.VORONOI, voronoi_message),
                        (S.ROOMS, rooms_message)):
        msg = make(refresh)
        if msg is not None:
            writer.write_proto(topic, t, msg)
    writer.write_record(SceneGraphRecord.of_graph(refresh.graph), t)
    writer.write_proto(S.GRAPH_SCENE, t, graph_scene_update(t, refresh.graph.to_dict()))
