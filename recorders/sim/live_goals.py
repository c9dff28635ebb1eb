"""Where a skill of the robot goes: the goal of a scene-graph node on the robot's own map.

A :class:`Goal` names what to drive to; :meth:`sgtool.recorders.sim.live_skills.LiveSkills.select`
turns it into a cell of the map at every plan. An object or door node is a place to stand
within reach of (a container's: in front of its opening when the map shows one), a
frontier node its cluster's cells (the nearest reachable one), a room or region node a
point (the reachable cell nearest it).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from sgtool.mapping.live_paths import (
    front_goal,
    nearest_along_floor,
    open_fan,
    stand_goal,
    view_goal,
)
from sgtool.scenegraph.examined import carrier_kinds
from sgtool.scenegraph.graph import DoorNode, ObjectNode, RegionNode, RoomNode

if TYPE_CHECKING:
    from sgtool.mapping.occupancy import OccupancyMap
    from sgtool.scenegraph.builder import MapLayers


@dataclass(frozen=True, eq=False)
class Goal:
    """Where a skill goes: ``kind`` "stand" (within reach of ``points[0]``, facing it),
    "front" (a container at ``points[0]``: standing so, in front of its opening when the
    map shows one, :func:`~sgtool.mapping.live_paths.front_goal`), "view" (where a
    container at ``points[0]`` is seen whole, facing it:
    :func:`~sgtool.mapping.live_paths.view_goal`), "point" (the reachable cell nearest
    ``points[0]``) or "cells" (the nearest reachable of ``points``, a frontier's
    cluster). ``room``: the room of an object node (a stand at it is sought in that room
    first, :meth:`~sgtool.recorders.sim.live_skills.LiveSkills.select`), else None."""

    label: str
    kind: str
    points: np.ndarray = field(default_factory=lambda: np.zeros((0, 2)))
    room: str | None = None

    def face(self) -> tuple[float, float] | None:
        if self.kind not in ("stand", "front", "view"):
            return None
        return float(self.points[0, 0]), float(self.points[0, 1])


def frontier_points(layers: MapLayers, frontier_id: str) -> np.ndarray | None:
    """World centres of the cells of frontier ``frontier_id`` of a refresh (None when the
    refresh has no such frontier)."""
    if frontier_id not in layers.frontier_ids:
        return None
    f = layers.frontiers[layers.frontier_ids.index(frontier_id)]
    x, y = layers.occupancy.center_of(f.cells[:, 0], f.cells[:, 1])
    return np.stack([x, y], axis=1)


def goal_of_node(node: Any, layers: MapLayers | None) -> Goal:
    """The goal of a scene-graph node (module doc)."""
    if isinstance(node, (ObjectNode, DoorNode)):
        if isinstance(node, ObjectNode):
            front = carrier_kinds(node.affordances)[0]
            return Goal(node.id, "front" if front else "stand",
                        np.array([node.position[:2]], dtype=np.float64), node.room)
        return Goal(node.id, "stand", np.array([node.position[:2]], dtype=np.float64))
    if isinstance(node, RegionNode) and node.kind == "frontier" and layers is not None:
        pts = frontier_points(layers, node.id)
        if pts is not None and len(pts):
            return Goal(node.id, "cells", pts)
    assert isinstance(node, (RoomNode, RegionNode))
    return Goal(node.id, "point", np.array([node.position[:2]], dtype=np.float64))


def room_cells(occ: OccupancyMap, layers: MapLayers | None, room: str) -> np.ndarray | None:
    """Bool grid of the cells of ``occ`` that belong to ``room`` on the robot's map: those
    whose Voronoi node nearest along the floor (of ``layers``' graph) lies in ``room`` or
    in no room (a doorway's cut zone), and those no node reaches. None without layers or
    when no node lies in ``room``. A stand in these cells does not reach a piece through
    the wall it stands against."""
    if layers is None or room not in layers.node_rooms:
        return None
    labels = nearest_along_floor(occ, layers.voronoi.positions)
    keep = np.array([r is None or r == room for r in layers.node_rooms] + [True])
    return keep[labels]  # label -1 (no node) takes the last entry


def stand_cell(goal: Goal, occ: OccupancyMap, dist: np.ndarray, layers: MapLayers | None,
               reach: float, slack: float, look_in: float) -> tuple[float, float] | None:
    """Where to stand for a "stand", "front" or "view" goal (:class:`Goal`): among the
    cells of the goal's ``room`` (:func:`room_cells`) when it has one and such a cell
    qualifies, else among all (a "view" only in its room: a container is not seen into
    through the wall behind it); "view" by :func:`~sgtool.mapping.live_paths.view_goal`
    at ``look_in`` m, "front" by :func:`~sgtool.mapping.live_paths.front_goal` or else
    :func:`~sgtool.mapping.live_paths.stand_goal` (within ``reach``, ``slack``)."""
    xy = goal.points[0]

    def among(within: np.ndarray | None) -> tuple[float, float] | None:
        if goal.kind == "view":
            return view_goal(occ, dist, xy, look_in, within=within)
        front = front_goal(occ, dist, xy, reach, slack, within=within) \
            if goal.kind == "front" else None
        return front or stand_goal(occ, dist, xy, reach, slack, within)

    inside = None if goal.room is None else room_cells(occ, layers, goal.room)
    if inside is None:
        return among(None)
    return among(inside) if goal.kind == "view" else among(inside) or among(None)


def room_fan(occ: OccupancyMap, dist: np.ndarray, xy: Sequence[float], distance: float,
             layers: MapLayers | None, room: str | None
             ) -> tuple[float, tuple[int, int]] | None:
    """:func:`~sgtool.mapping.live_paths.open_fan` of a container at ``xy``, its rays
    ending in its ``room`` (:func:`room_cells`; any room when that is not known)."""
    inside = None if room is None else room_cells(occ, layers, room)
    return open_fan(occ, dist, xy, distance, within=inside)
