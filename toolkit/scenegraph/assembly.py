"""The last stage of a refresh: the layers computed by the earlier stages
(:class:`GraphParts`) become the nodes of a :class:`~sgtool.scenegraph.graph.SceneGraph`."""

from __future__ import annotations

import math
from collections.abc import Mapping
from collections.abc import Set as AbstractSet
from dataclasses import dataclass

from sgtool.mapping.voronoi import VoronoiGraph
from sgtool.scenegraph.door_evidence import DoorObservation
from sgtool.scenegraph.examined import EXAMINE, examinable
from sgtool.scenegraph.frontiers import Frontier
from sgtool.scenegraph.graph import (
    DoorNode,
    ObjectNode,
    RegionNode,
    RobotState,
    RoomNode,
    SceneGraph,
)
from sgtool.scenegraph.instances import InstanceInfo
from sgtool.scenegraph.object_placement import PlacedObject
from sgtool.scenegraph.room_nodes import Regions
from sgtool.scenegraph.room_segmentation import RoomSegmentation


@dataclass(frozen=True, eq=False)
class GraphParts:
    """What the stages of one refresh found, in the order the graph lists it."""

    seg: RoomSegmentation
    room_ids: list[str]  # per segmented room
    regions: Regions
    node_region: dict[int, str]  # Voronoi node -> its region id
    objects: list[PlacedObject]
    doors: list[DoorObservation]
    frontiers: list[Frontier]
    frontier_ids: list[str]
    frontier_nodes: list[int]  # nearest visible room node per frontier (-1: none)
    rooms: list[RoomNode]


def robot_state(robot: tuple[float, float, float] | None, robot_nodes: tuple[int, ...],
                vg: VoronoiGraph, parts: GraphParts) -> RobotState:
    """The robot's pose with the room and region of its nearest entry node in a room."""
    if robot is None:
        return RobotState(position=(0.0, 0.0))
    node_room = parts.seg.labels
    rroom = rreg = None
    lab = [e for e in robot_nodes if node_room[e] >= 0]
    if lab:
        best = min(lab, key=lambda e: (math.hypot(vg.positions[e, 0] - robot[0],
                                                  vg.positions[e, 1] - robot[1]), e))
        rroom = parts.room_ids[int(node_room[best])]
        rreg = parts.node_region.get(best)
    return RobotState(position=(robot[0], robot[1]), yaw=robot[2], room=rroom, region=rreg)


def assemble_graph(parts: GraphParts, robot: RobotState, instances: Mapping[int, InstanceInfo],
                   distances: dict[str, float], time_ns: int,
                   examined: AbstractSet[int] = frozenset()) -> SceneGraph:
    """The graph of one refresh; an examinable piece (a container or supporter) is
    ``explored`` once ``examined`` holds it and it is not closed
    (:mod:`sgtool.scenegraph.examined`), any other object once it is not closed."""
    node_room = parts.seg.labels
    region_nodes = [RegionNode(id=rid, room=room, position=pos)
                    for rid, (room, _n, pos) in parts.regions.items()]
    for fid, f, node in zip(parts.frontier_ids, parts.frontiers, parts.frontier_nodes,
                            strict=True):
        room = parts.room_ids[int(node_room[node])] if node >= 0 else None
        if room is None:
            continue
        region_nodes.append(RegionNode(id=fid, room=room, position=f.medoid,
                                       kind="frontier", frontier_type=f.type,
                                       size=f.size))
    object_nodes = []
    for o in parts.objects:
        if o.room is None:
            continue
        info = instances[o.instance]
        affs = set(info.affordances)
        looked = True
        if examinable(affs, info.kind == "object"):  # :mod:`sgtool.scenegraph.examined`
            affs.add(EXAMINE)
            looked = o.instance in examined
        object_nodes.append(ObjectNode(
            id=f"obj:{o.instance}", category=info.category,
            parent=o.parent, room=o.room, position=o.position, instance=o.instance,
            relation=info.relation if o.parent.startswith("obj:") else None,
            state=info.state, affordances=tuple(sorted(affs)),
            explored=info.state != "closed" and looked,
        ))
    door_nodes = [DoorNode(
        id=f"door:{d.instance}", position=d.position, state=d.state,
        rooms=tuple(sorted(d.rooms + ((d.unexplored_room,) if d.unexplored_room else ()))),
        instance=d.instance) for d in parts.doors]
    return SceneGraph(robot=robot, rooms=tuple(parts.rooms), regions=tuple(region_nodes),
                      objects=tuple(object_nodes), doors=tuple(door_nodes),
                      distances=distances, time_ns=time_ns)
