"""The scene graph of a refresh as a Foxglove ``SceneUpdate`` (``/map/graph``), so a
Foxglove user sees what the JSON channel holds (a pure function, no I/O).

The update first deletes every earlier entity, then has one entity per node and one for
the edges, all in the world frame:

- an object (``obj:N``): a cube of :data:`OBJECT_SIZE` at its position, coloured by its
  room, and a label "obj:N category (state)";
- a door (``door:N``): a cylinder at floor level, green when open, red when closed, and a
  label;
- a frontier (``frontier:N``): a sphere at :data:`GRAPH_Z`, cyan when it leads out,
  yellow otherwise;
- ``edges``: one ``LINE_LIST`` of the graph's edges: object -> parent (object or region),
  frontier -> room, door -> each of its rooms (rooms at :data:`ROOM_Z`).

Every node entity carries ``metadata`` key/value pairs (id, category or kind, room, state,
parent, ...; lists joined with commas) that Foxglove shows when the entity is selected.
Colours come from :func:`sgtool.colors.color_for`, as in ``sgtool view``.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

from foxglove_schemas_protobuf.Color_pb2 import Color
from foxglove_schemas_protobuf.CubePrimitive_pb2 import CubePrimitive
from foxglove_schemas_protobuf.CylinderPrimitive_pb2 import CylinderPrimitive
from foxglove_schemas_protobuf.KeyValuePair_pb2 import KeyValuePair
from foxglove_schemas_protobuf.LinePrimitive_pb2 import LinePrimitive
from foxglove_schemas_protobuf.Point3_pb2 import Point3
from foxglove_schemas_protobuf.Pose_pb2 import Pose
from foxglove_schemas_protobuf.Quaternion_pb2 import Quaternion
from foxglove_schemas_protobuf.SceneEntity_pb2 import SceneEntity
from foxglove_schemas_protobuf.SceneEntityDeletion_pb2 import SceneEntityDeletion
from foxglove_schemas_protobuf.SceneUpdate_pb2 import SceneUpdate
from foxglove_schemas_protobuf.SpherePrimitive_pb2 import SpherePrimitive
from foxglove_schemas_protobuf.TextPrimitive_pb2 import TextPrimitive
from foxglove_schemas_protobuf.Vector3_pb2 import Vector3
from google.protobuf.timestamp_pb2 import Timestamp

from sgtool.colors import color_for
from sgtool.log import schemas as S

GRAPH_Z = 0.05  # m: height of 2D nodes (regions, frontiers, doors) above the floor
ROOM_Z = 1.5  # m: height of the room nodes edges end at
OBJECT_SIZE = 0.15  # m: edge of an object's cube
FRONTIER_SIZE = 0.2  # m
DOOR_SIZE = (0.3, 0.3, 0.1)  # m: a door's cylinder (diameter x, y; height)
OPEN, CLOSED = (0.2, 0.8, 0.2), (0.85, 0.2, 0.2)
LEADING_OUT, FRONTIER = (0.16, 0.78, 1.0), (1.0, 0.78, 0.16)
EDGE = (0.6, 0.6, 0.6)


def _color(rgb: tuple[float, float, float], a: float = 1.0) -> Color:
    return Color(r=rgb[0], g=rgb[1], b=rgb[2], a=a)


def _keyed(key: str | None) -> tuple[float, float, float]:
    if key is None:
        return EDGE
    r, g, b = color_for(key)
    return r / 255.0, g / 255.0, b / 255.0


def _point(pos: Sequence[float], z: float = GRAPH_Z) -> Point3:
    return Point3(x=float(pos[0]), y=float(pos[1]), z=float(pos[2]) if len(pos) > 2 else z)


def _pose(p: Point3) -> Pose:
    return Pose(position=Vector3(x=p.x, y=p.y, z=p.z), orientation=Quaternion(w=1.0))


def _meta(node: Mapping[str, Any], keys: Sequence[str]) -> list[KeyValuePair]:
    out = []
    for k in keys:
        v = node.get(k)
        if v is None:
            continue
        text = ",".join(str(x) for x in v) if isinstance(v, list) else str(v)
        out.append(KeyValuePair(key=k, value=text))
    return out


def _entity(stamp: Timestamp, eid: str, label: str, at: Point3, meta: list[KeyValuePair],
            color: Color) -> SceneEntity:
    text = TextPrimitive(pose=_pose(Point3(x=at.x, y=at.y, z=at.z + 0.25)), billboard=True,
                         font_size=12.0, scale_invariant=True, color=color, text=label)
    return SceneEntity(timestamp=stamp, frame_id=S.WORLD_FRAME, id=eid, metadata=meta,
                       texts=[text])


def graph_scene_update(t_ns: int, graph: Mapping[str, Any]) -> SceneUpdate:
    """The scene graph record ``graph`` (its JSON form) at ``t_ns`` as a SceneUpdate
    (module doc)."""
    stamp = Timestamp(seconds=t_ns // 1_000_000_000, nanos=t_ns % 1_000_000_000)
    entities: list[SceneEntity] = []
    where: dict[str, Point3] = {}
    for room in graph.get("rooms") or ():
        where[room["id"]] = _point(room["position"][:2], ROOM_Z)
    for reg in graph.get("regions") or ():
        where[reg["id"]] = _point(reg["position"][:2])
    for obj in graph.get("objects") or ():
        where[obj["id"]] = _point(obj["position"])
    for obj in graph.get("objects") or ():
        at = where[obj["id"]]
        col = _color(_keyed(obj.get("room")))
        state = f" ({obj['state']})" if obj.get("state") else ""
        ent = _entity(stamp, obj["id"], f"{obj['id']} {obj['category']}{state}", at,
                      _meta(obj, ("id", "category", "room", "state", "parent", "relation",
                                  "affordances", "explored")), col)
        ent.cubes.append(CubePrimitive(pose=_pose(at), color=col, size=Vector3(
            x=OBJECT_SIZE, y=OBJECT_SIZE, z=OBJECT_SIZE)))
        entities.append(ent)
    for door in graph.get("doors") or ():
        at = _point(door["position"][:2])
        col = _color(OPEN if door.get("state") == "open" else CLOSED)
        meta = [KeyValuePair(key="category", value="door"),
                *_meta(door, ("id", "state", "rooms", "instance"))]
        ent = _entity(stamp, door["id"], f"{door['id']} {door.get('state') or ''}".strip(),
                      at, meta, col)
        ent.cylinders.append(CylinderPrimitive(pose=_pose(at), color=col, bottom_scale=1.0,
                                               top_scale=1.0, size=Vector3(
            x=DOOR_SIZE[0], y=DOOR_SIZE[1], z=DOOR_SIZE[2])))
        entities.append(ent)
    for reg in graph.get("regions") or ():
        if reg.get("kind") != "frontier":
            continue
        at = where[reg["id"]]
        leads_out = reg.get("frontier_type") == "leading out"
        col = _color(LEADING_OUT if leads_out else FRONTIER)
        ent = _entity(stamp, reg["id"], reg.get("frontier_type") or "frontier", at,
                      _meta(reg, ("id", "kind", "frontier_type", "room", "size")), col)
        ent.spheres.append(SpherePrimitive(pose=_pose(at), color=col, size=Vector3(
            x=FRONTIER_SIZE, y=FRONTIER_SIZE, z=FRONTIER_SIZE)))
        entities.append(ent)
    entities.append(SceneEntity(timestamp=stamp, frame_id=S.WORLD_FRAME, id="edges",
                                lines=[_edges(graph, where)]))
    return SceneUpdate(deletions=[SceneEntityDeletion(
        timestamp=stamp, type=SceneEntityDeletion.ALL)], entities=entities)


def _edges(graph: Mapping[str, Any], where: Mapping[str, Point3]) -> LinePrimitive:
    """The graph's edges (module doc) as one LINE_LIST; an edge to a node the graph does
    not place is left out."""
    pairs: list[tuple[str, str]] = []
    for obj in graph.get("objects") or ():
        if obj.get("parent"):
            pairs.append((obj["id"], obj["parent"]))
    for reg in graph.get("regions") or ():
        if reg.get("kind") == "frontier" and reg.get("room"):
            pairs.append((reg["id"], reg["room"]))
    door_at = {d["id"]: _point(d["position"][:2]) for d in graph.get("doors") or ()}
    pts: list[Point3] = []
    for a, b in pairs:
        if a in where and b in where:
            pts.extend((where[a], where[b]))
    for door in graph.get("doors") or ():
        for room in door.get("rooms") or ():
            if room in where:
                pts.extend((door_at[door["id"]], where[room]))
    return LinePrimitive(type=LinePrimitive.LINE_LIST, pose=_pose(Point3()), thickness=0.01,
                         scale_invariant=False, color=_color(EDGE, 0.8), points=pts)
