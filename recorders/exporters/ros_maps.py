"""The derived layers of an sgtool log as ROS messages (built with a
:class:`~sgtool.recorders.exporters.bagwriter.BagWriter`'s type store):

- occupancy (Foxglove ``Grid``, int8 -1/0/100, rows along +y) -> ``nav_msgs/OccupancyGrid``
  with the same cells, origin and resolution (the ROS convention is the same);
- Voronoi graph, rooms and the scene graph's scene (Foxglove ``SceneUpdate``: objects,
  doors, frontiers, edges) -> ``visualization_msgs/MarkerArray``: a ``DELETEALL`` marker
  when the update deletes everything, then per entity its lines (``LINE_LIST``;
  ``LINE_LOOP`` as a closed ``LINE_STRIP``), its spheres as one ``SPHERE_LIST``, each cube
  as a ``CUBE`` and each cylinder as a ``CYLINDER`` (pose and size kept), and its texts as
  ``TEXT_VIEW_FACING``; colours per vertex kept;
- objects of the scene graph -> ``MarkerArray`` of a sphere and a label per object,
  coloured by room as ``sgtool view`` does;
- the scene graph record -> ``std_msgs/String`` holding its canonical JSON.
"""

from __future__ import annotations

import json
from collections.abc import Mapping
from typing import Any

import numpy as np

from sgtool.colors import color_for
from sgtool.log import codec
from sgtool.log import schemas as S
from sgtool.recorders.exporters.bagwriter import BagWriter

MARKER = "visualization_msgs/msg/Marker"
# visualization_msgs/Marker types and actions
LINE_STRIP, LINE_LIST, SPHERE_LIST, SPHERE, TEXT, CUBE, CYLINDER = 4, 5, 7, 2, 9, 1, 3
DELETEALL = 3
TEXT_HEIGHT = 0.3  # m: Foxglove texts are sized in pixels; RViz's in metres
OBJECT_SIZE = 0.15  # m


def _t(t_ns: int) -> tuple[int, int]:
    return int(t_ns // 1_000_000_000), int(t_ns % 1_000_000_000)


def _pose(w: BagWriter, x: float = 0.0, y: float = 0.0, z: float = 0.0) -> Any:
    g = "geometry_msgs/msg/"
    return w.make(g + "Pose", position=w.make(g + "Point", x=float(x), y=float(y), z=float(z)),
                  orientation=w.make(g + "Quaternion", w=1.0))


def _colour(w: BagWriter, c: Any) -> Any:
    return w.make("std_msgs/msg/ColorRGBA", r=float(c.r), g=float(c.g), b=float(c.b),
                  a=float(c.a))


def _rgba(w: BagWriter, rgb: tuple[int, int, int], a: float = 1.0) -> Any:
    return w.make("std_msgs/msg/ColorRGBA", r=rgb[0] / 255.0, g=rgb[1] / 255.0,
                  b=rgb[2] / 255.0, a=a)


def _solid_pose(w: BagWriter, pose: Any) -> Any:
    """A Foxglove ``Pose`` (position and orientation) as ``geometry_msgs/Pose``; an unset
    orientation (all zero) is the identity."""
    g, q = "geometry_msgs/msg/", pose.orientation
    quat = (q.x, q.y, q.z, q.w) if (q.x, q.y, q.z, q.w) != (0, 0, 0, 0) else (0, 0, 0, 1)
    return w.make(g + "Pose", position=_point(w, pose.position),
                  orientation=w.make(g + "Quaternion", x=float(quat[0]), y=float(quat[1]),
                                     z=float(quat[2]), w=float(quat[3])))


def _point(w: BagWriter, p: Any) -> Any:
    return w.make("geometry_msgs/msg/Point", x=float(p.x), y=float(p.y), z=float(p.z))


def occupancy_grid(w: BagWriter, t_ns: int, grid: Any) -> Any:
    """A Foxglove ``Grid`` of sgtool's occupancy as ``nav_msgs/OccupancyGrid``."""
    cells, (ox, oy), res = codec.decode_grid(grid)
    sec, nsec = _t(t_ns)
    info = w.make("nav_msgs/msg/MapMetaData",
                  map_load_time=w.make("builtin_interfaces/msg/Time", sec=sec, nanosec=nsec),
                  resolution=float(res), width=int(cells.shape[1]), height=int(cells.shape[0]),
                  origin=_pose(w, ox, oy, float(grid.pose.position.z)))
    return w.make("nav_msgs/msg/OccupancyGrid", header=w.header(t_ns, grid.frame_id),
                  info=info, data=np.ascontiguousarray(cells, np.int8).ravel())


def _marker(w: BagWriter, t_ns: int, frame: str, ns: str, mid: int, **kw: Any) -> Any:
    return w.make(MARKER, header=w.header(t_ns, frame), ns=ns, id=mid,
                  pose=kw.pop("pose", None) or _pose(w), **kw)


def marker_array(w: BagWriter, t_ns: int, update: Any) -> Any:
    """A Foxglove ``SceneUpdate`` as ``visualization_msgs/MarkerArray`` (module doc)."""
    markers = []
    if len(update.deletions):
        markers.append(w.make(MARKER, header=w.header(t_ns, S.WORLD_FRAME), action=DELETEALL))
    g = "geometry_msgs/msg/Vector3"
    for ent in update.entities:
        frame, ns = ent.frame_id or S.WORLD_FRAME, ent.id
        for line in ent.lines:
            pts = [_point(w, p) for p in line.points]
            cols = [_colour(w, c) for c in line.colors]
            kind = LINE_LIST if line.type == line.LINE_LIST else LINE_STRIP
            if line.type == line.LINE_LOOP and pts:
                pts.append(pts[0])
                cols = cols + cols[:1] if cols else cols
            markers.append(_marker(w, t_ns, frame, ns, len(markers), type=kind, points=pts,
                                   colors=cols, color=_colour(w, line.color),
                                   scale=w.make(g, x=float(line.thickness))))
        if len(ent.spheres):
            s0 = ent.spheres[0]
            markers.append(_marker(
                w, t_ns, frame, ns, len(markers), type=SPHERE_LIST,
                points=[_point(w, s.pose.position) for s in ent.spheres],
                colors=[_colour(w, s.color) for s in ent.spheres], color=_colour(w, s0.color),
                scale=w.make(g, x=float(s0.size.x), y=float(s0.size.y), z=float(s0.size.z))))
        for kind, solids in ((CUBE, ent.cubes), (CYLINDER, ent.cylinders)):
            for solid in solids:
                markers.append(_marker(w, t_ns, frame, ns, len(markers), type=kind,
                                       pose=_solid_pose(w, solid.pose),
                                       color=_colour(w, solid.color),
                                       scale=w.make(g, x=float(solid.size.x),
                                                    y=float(solid.size.y),
                                                    z=float(solid.size.z))))
        for text in ent.texts:
            p = text.pose.position
            markers.append(_marker(w, t_ns, frame, ns, len(markers), type=TEXT,
                                   pose=_pose(w, p.x, p.y, p.z), text=text.text,
                                   color=_colour(w, text.color),
                                   scale=w.make(g, z=TEXT_HEIGHT)))
    return w.make("visualization_msgs/msg/MarkerArray", markers=markers)


def object_markers(w: BagWriter, t_ns: int, graph: Mapping[str, Any]) -> Any:
    """The objects of a scene graph record: a sphere and a "id category" label each."""
    markers = [w.make(MARKER, header=w.header(t_ns, S.WORLD_FRAME), action=DELETEALL)]
    g = "geometry_msgs/msg/Vector3"
    for obj in graph.get("objects") or ():
        x, y, z = (float(v) for v in obj["position"])
        col = _rgba(w, color_for(obj.get("room") or obj["id"]))
        markers.append(_marker(w, t_ns, S.WORLD_FRAME, "objects", len(markers), type=SPHERE,
                               pose=_pose(w, x, y, z), color=col,
                               scale=w.make(g, x=OBJECT_SIZE, y=OBJECT_SIZE, z=OBJECT_SIZE)))
        markers.append(_marker(w, t_ns, S.WORLD_FRAME, "object_labels", len(markers),
                               type=TEXT, pose=_pose(w, x, y, z + 0.2), color=col,
                               text=f"{obj['id']} {obj['category']}",
                               scale=w.make(g, z=TEXT_HEIGHT / 2)))
    return w.make("visualization_msgs/msg/MarkerArray", markers=markers)


def graph_string(w: BagWriter, graph: Mapping[str, Any]) -> Any:
    """The scene graph record as ``std_msgs/String`` of its canonical JSON."""
    return w.make("std_msgs/msg/String",
                  data=json.dumps(graph, sort_keys=True, separators=(",", ":")))
