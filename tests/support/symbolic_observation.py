"""The observed graph of a symbolic episode built from scratch from the environment's state.

This is the rule of :mod:`sgtool.recorders.symbolic_environment.environment` written the
plain way (every node rebuilt at every step), as the environment computed it before its
observation became incremental: the oracle the incremental
:class:`~sgtool.recorders.symbolic_environment.observation.ObservedGraph` is tested against.
"""

from __future__ import annotations

import math

from sgtool.recorders.symbolic_environment import SymbolicEnv
from sgtool.scenegraph.graph import DoorNode, RegionNode, RobotState, RoomNode, SceneGraph


def scratch_graph(env: SymbolicEnv) -> SceneGraph:
    h, spec = env.house, env.spec
    dist = h.distances_from(env.place, frozenset(env.open_doors))
    distances: dict[str, float] = {}

    def put(node_id: str, place: int) -> None:
        d = float(dist[place])
        if math.isfinite(d):
            distances[node_id] = d

    rooms = []
    for ri in sorted(env.known_rooms):
        rid = h.room_ids[ri]
        explored = ri in env.explored_rooms
        cx, cy = spec.rooms[ri].centroid
        neighbours = tuple(sorted({h.room_ids[o] for o, door in h.links[ri]
                                   if o in env.known_rooms})) if explored else ()
        rooms.append(RoomNode(
            id=rid, category=h.room_names[ri] if explored else "unknown",
            position=(float(cx), float(cy)), explored=explored,
            category_scores=((h.room_names[ri], 1.0),) if explored else (),
            neighbours=neighbours,
        ))
        regs = h.room_regions[ri]
        put(rid, min((h.regions[r].place for r in regs), key=lambda p: (dist[p], p)))
    regions = []
    for ri in sorted(env.explored_rooms):
        for reg in h.room_regions[ri]:
            r = h.regions[reg]
            revealed = reg in env.revealed_regions
            regions.append(RegionNode(
                id=r.id, room=h.room_ids[ri], position=r.center,
                kind="region" if revealed else "frontier",
                frontier_type=None if revealed else "unexplored area",
            ))
            put(r.id, r.place)
    objects = []
    furniture = sorted(f for reg in env.revealed_regions for f in h.regions[reg].furniture)
    for f in furniture:
        objects.append(h.furniture_node(f, env.furn_state[f], f in env.furn_explored))
        put(h.furn_node_id(f), h.furn_place[f])
    for j in sorted(env.seen_objects):
        o = spec.objects[j]
        objects.append(h.object_node(j, env.obj_state[j],
                                     bool(o.affordances) and j in env.obj_explored))
        put(h.obj_node_id(j), h.furn_place[h.obj_furn[j]])
    doors = []
    for di in sorted(env.visible_doors):
        d = spec.doors[di]
        doors.append(DoorNode(
            id=f"door:{di}", position=(float(d.center[0]), float(d.center[1])),
            state="open" if di in env.open_doors else "closed",
            rooms=tuple(h.room_ids[h.room_index[r]] for r in d.rooms), instance=-1,
        ))
        a, b = h.door_sides[di]
        put(f"door:{di}", a if (dist[a], a) <= (dist[b], b) else b)
    here = env.place
    region = next((r.id for r in h.regions if r.place == here), None)
    robot = RobotState(position=h.places[here], room=h.room_ids[h.place_room[here]],
                       region=region)
    return SceneGraph(robot=robot, rooms=tuple(rooms), regions=tuple(regions),
                      objects=tuple(objects), doors=tuple(doors), distances=distances)
