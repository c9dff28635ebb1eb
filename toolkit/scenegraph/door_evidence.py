"""Doors in the scene graph: the grid cells that say "doorway" to the room segmentation,
and each seen door's rooms.

- :func:`door_cells`: the *passable* columns of each open (or state-unknown) door -- its
  opening under the lintel, not the swung panel, whose cells would cut the room it stands
  in -- else the panel's closed position
  (:func:`~sgtool.scenegraph.room_segmentation.opening_from_panel`), else all its columns.
- :func:`observe_doors`: the rooms on either side of a door from the visible Voronoi nodes
  within ``door_radius``; a closed door with only one explored side leads to an unexplored
  room node (SCOUT sec. IV-A), placed ``unexplored_offset`` beyond the door.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

from sgtool.mapping.bev import line_of_sight
from sgtool.mapping.grid import OCCUPIED, OccupancyGrid
from sgtool.mapping.voronoi import VoronoiGraph
from sgtool.mapping.voxels import VoxelMap
from sgtool.scenegraph.instances import InstanceInfo
from sgtool.scenegraph.object_placement import SeenInstance
from sgtool.scenegraph.room_segmentation import RoomTracker, opening_from_panel


@dataclass(frozen=True, eq=False)
class DoorObservation:
    instance: int
    position: tuple[float, float]
    state: str
    rooms: tuple[str, ...]  # explored rooms on either side, nearest first
    unexplored_room: str | None
    node: int  # nearest visible node (-1: none)


def door_cells(occ: OccupancyGrid, instances: Mapping[int, InstanceInfo], voxels: VoxelMap,
               panel_memo: dict[bytes, object]) -> np.ndarray:
    """Bool grid of the door evidence of the open (or state-unknown) doors (module doc);
    ``panel_memo`` caches the openings found from swung panels across calls."""
    return door_cells_of(occ, voxels.voxels_of(open_doors(instances)), panel_memo)


def open_doors(instances: Mapping[int, InstanceInfo]) -> list[int]:
    """The door instances that are open or of unknown state."""
    return [iid for iid, v in instances.items() if v.kind == "door" and v.state != "closed"]


def door_cells_of(occ: OccupancyGrid, door_voxels: Mapping[int, np.ndarray],
                  panel_memo: dict[bytes, object]) -> np.ndarray:
    """:func:`door_cells` from the voxels (ijk) of each open door, in any order (e.g. from
    :class:`sgtool.scenegraph.door_voxels.DoorVoxels`)."""
    cells = np.zeros(occ.shape, dtype=bool)
    ix0 = int(round(occ.origin[0] / occ.resolution))
    iy0 = int(round(occ.origin[1] / occ.resolution))
    occupied: np.ndarray | None = None
    for _, ijk in sorted(door_voxels.items()):
        if not len(ijk):
            continue
        r, c = ijk[:, 1] - iy0, ijk[:, 0] - ix0
        ok = occ.inside(r, c)
        r, c = r[ok], c[ok]
        passable = occ.grid[r, c] != OCCUPIED
        if passable.any():
            r, c = r[passable], c[passable]
        else:
            cell = np.unique(r * (occ.shape[1] + 1) + c)
            r, c = np.divmod(cell, occ.shape[1] + 1)
            if occupied is None:
                occupied = occ.grid == OCCUPIED
            got = opening_from_panel(r, c, occupied, int(0.4 / occ.resolution), memo=panel_memo)
            if got is not None:
                r, c = got
        cells[r, c] = True
    return cells


def observe_doors(
    seen: list[SeenInstance], vg: VoronoiGraph, node_room: np.ndarray, room_ids: list[str],
    occ: OccupancyGrid, blocked: np.ndarray, tracker: RoomTracker, door_radius: float,
    unexplored_offset: float,
) -> tuple[list[DoorObservation], dict[str, tuple[float, float]]]:
    """The seen doors with their rooms (module doc), and the position of every unexplored
    room node behind them (``tracker`` names those rooms)."""
    out = []
    unexplored_pos: dict[str, tuple[float, float]] = {}
    labelled = np.flatnonzero(node_room >= 0)
    tree = cKDTree(vg.positions[labelled]) if len(labelled) else None
    for info, c, _vp in seen:
        pos = (float(c[0]), float(c[1]))
        rooms: list[str] = []
        nearest = -1
        if tree is not None:
            near = labelled[np.asarray(sorted(tree.query_ball_point(pos, door_radius)),
                                       dtype=np.int64)]
            if len(near):
                vis = line_of_sight(blocked, occ, vg.positions[near],
                                    np.repeat(np.asarray([pos]), len(near), axis=0),
                                    skip_end=0.3)
                near = near[vis]
            if len(near):
                d = np.hypot(*(vg.positions[near] - np.asarray(pos)).T)
                order = np.lexsort((near, d))
                nearest = int(near[order[0]])
                for j in order:
                    rid = room_ids[int(node_room[near[j]])]
                    if rid not in rooms:
                        rooms.append(rid)
                    if len(rooms) == 2:
                        break
        unexplored = None
        if info.state == "closed" and len(rooms) == 1 and nearest >= 0:
            v = np.asarray(pos) - vg.positions[nearest]
            n = float(np.hypot(*v))
            u = v / n if n > 1e-9 else np.zeros(2)
            far = (pos[0] + unexplored_offset * float(u[0]),
                   pos[1] + unexplored_offset * float(u[1]))
            unexplored = f"room:{tracker.unexplored_room(info.id, far)}"
            unexplored_pos[unexplored] = far
        out.append(DoorObservation(info.id, pos, info.state or "open", tuple(rooms),
                                   unexplored, nearest))
    return out, unexplored_pos
