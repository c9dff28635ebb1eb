"""Where a skill of the robot goes: the goal of a scene-graph node on the robot's own map.

A :class:`Goal` names what to drive to; :meth:`sgtool.recorders.sim.live_skills.LiveSkills.select`
turns it into a cell of the map at every plan. An object or door node is a place to stand
within reach of (a container's: in front of its opening when the map shows one), a
frontier node its cluster's cells (the nearest reachable one), a room or region node a
point (the reachable cell nearest it).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from sgtool.scenegraph.examined import carrier_kinds
from sgtool.scenegraph.graph import DoorNode, ObjectNode, RegionNode, RoomNode

if TYPE_CHECKING:
    from sgtool.scenegraph.builder import MapLayers


@dataclass(frozen=True, eq=False)
class Goal:
    """Where a skill goes: ``kind`` "stand" (within reach of ``points[0]``, facing it),
    "front" (a container at ``points[0]``: standing so, in front of its opening when the
    map shows one, :func:`~sgtool.mapping.live_paths.front_goal`), "view" (where a
    container at ``points[0]`` is seen whole, facing it:
    :func:`~sgtool.mapping.live_paths.view_goal`), "point" (the reachable cell nearest
    ``points[0]``) or "cells" (the nearest reachable of ``points``, a frontier's
    cluster)."""

    label: str
    kind: str
    points: np.ndarray = field(default_factory=lambda: np.zeros((0, 2)))

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
        front = isinstance(node, ObjectNode) and carrier_kinds(node.affordances)[0]
        return Goal(node.id, "front" if front else "stand",
                    np.array([node.position[:2]], dtype=np.float64))
    if isinstance(node, RegionNode) and node.kind == "frontier" and layers is not None:
        pts = frontier_points(layers, node.id)
        if pts is not None and len(pts):
            return Goal(node.id, "cells", pts)
    assert isinstance(node, (RoomNode, RegionNode))
    return Goal(node.id, "point", np.array([node.position[:2]], dtype=np.float64))
