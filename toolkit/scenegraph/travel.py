"""Travel distances from the robot to every node of the scene graph, over the Voronoi
graph before the room cuts: from the robot's entry nodes (the visible nodes within
``entry_radius``) to a node, plus the straight last leg to an object, door or frontier;
an unexplored room is reached through its door."""

from __future__ import annotations

import math

import numpy as np
from scipy.sparse import csr_matrix
from scipy.sparse.csgraph import dijkstra

from sgtool.mapping.voronoi import VoronoiGraph
from sgtool.scenegraph.assembly import GraphParts


def node_distances(vg: VoronoiGraph, graph: csr_matrix, robot_xy: tuple[float, float] | None,
                   entries: tuple[int, ...]) -> np.ndarray:
    """Per Voronoi node: the shortest path from ``robot_xy`` through one of its entry
    nodes (inf where unreachable, everywhere without entries)."""
    dist_node = np.full(len(vg.positions), np.inf)
    if robot_xy is None or not entries:
        return dist_node
    idx = np.asarray(entries, dtype=np.int64)
    off = np.hypot(*(vg.positions[idx] - np.asarray(robot_xy)).T)
    d = dijkstra(graph, directed=False, indices=idx)
    return np.min(d.reshape(len(idx), -1) + off[:, None], axis=0)


def travel_distances(vg: VoronoiGraph, dist_node: np.ndarray,
                     parts: GraphParts) -> dict[str, float]:
    """Node id -> travel distance (m) of every reachable room, region, object, door,
    frontier and unexplored room."""
    distances: dict[str, float] = {}

    def put(node_id: str, value: float) -> None:
        if math.isfinite(value):
            distances[node_id] = float(value)

    def leg(node: int, x: float, y: float) -> float:
        return math.hypot(x - vg.positions[node, 0], y - vg.positions[node, 1])

    for i, rid in enumerate(parts.room_ids):
        put(rid, dist_node[parts.seg.centres[i]])
    for reg_id, region in parts.regions.items():
        put(reg_id, dist_node[region[1]])
    obj_dist: dict[int, float] = {}
    for o in parts.objects:
        if o.node >= 0 and o.top == o.instance:
            obj_dist[o.instance] = float(dist_node[o.node] + leg(o.node, *o.position[:2]))
    for o in parts.objects:
        if o.room is not None and o.top in obj_dist:
            put(f"obj:{o.instance}", obj_dist[o.top])
    door_dist: dict[int, float] = {}
    for dr in parts.doors:
        if dr.node >= 0:
            door_dist[dr.instance] = float(dist_node[dr.node] + leg(dr.node, *dr.position))
            put(f"door:{dr.instance}", door_dist[dr.instance])
    for fid, f, node in zip(parts.frontier_ids, parts.frontiers, parts.frontier_nodes,
                            strict=True):
        if node >= 0:
            put(fid, dist_node[node] + leg(node, *f.medoid))
    for rn in parts.rooms:
        if not rn.explored:
            dr = next(d for d in parts.doors if d.unexplored_room == rn.id)
            if dr.instance in door_dist:
                put(rn.id, door_dist[dr.instance] + math.hypot(
                    rn.position[0] - dr.position[0], rn.position[1] - dr.position[1]))
    return distances
