"""The observed scene graph of a symbolic episode, kept up to date step by step.

:class:`ObservedGraph` holds the nodes the agent has seen and is told by the environment
what each step changed: a piece of furniture or a small object revealed or changed (its
state, whether its contents were looked at), or the layout (rooms known or explored,
regions revealed, doors seen, opened or closed). Only what changed is rebuilt; node
objects are shared between steps (they are frozen, memoised per state by
:class:`~sgtool.recorders.symbolic_environment.house.SymbolicHouse`). Travel distances
change at every step (the agent moves) and are read from the house's distance row in one
vectorised look-up.

The graph is the one the environment's rules define (module doc of
:mod:`~sgtool.recorders.symbolic_environment.environment`): rooms known, in id order
(explored ones with their category and neighbours); the regions of explored rooms
(revealed ones, the others as "unexplored area" frontiers); visible furniture, then seen
small objects, in index order; doors seen; finite travel distances from the agent, in that
order (a room's is that of its nearest region, a door's that of its nearer side).
"""

from __future__ import annotations

import bisect
import math
from itertools import compress
from typing import TYPE_CHECKING

import numpy as np

from sgtool.scenegraph.graph import (
    DoorNode,
    ObjectNode,
    RegionNode,
    RobotState,
    RoomNode,
    SceneGraph,
)

if TYPE_CHECKING:
    from sgtool.recorders.symbolic_environment.environment import SymbolicEnv



_Ids = tuple[list[str], np.ndarray]  # node ids and their places (one distance look-up)


class ObservedGraph:
    """The observed graph of one :class:`SymbolicEnv` episode (module doc)."""

    def __init__(self, env: SymbolicEnv) -> None:
        self._env = env
        self._h = env.house
        self._furn: list[int] = []  # visible furniture, ascending
        self._obj: list[int] = []  # seen small objects, ascending
        self._furn_nodes: dict[int, ObjectNode] = {}
        self._room_nodes: dict[tuple[int, bool, tuple[str, ...]], RoomNode] = {}
        self._region_nodes: dict[tuple[int, bool], RegionNode] = {}
        self._obj_nodes: dict[int, ObjectNode] = {}
        # what is rebuilt when it changed (None: to rebuild)
        self._objects: tuple[ObjectNode, ...] | None = None
        self._items: _Ids | None = None  # furniture and objects
        self._rooms: tuple[tuple[RoomNode, ...], tuple[tuple[str, tuple[int, ...]], ...]] | \
            None = None  # the nodes, (room id, its regions' places) each
        self._regions: tuple[tuple[RegionNode, ...], _Ids] | None = None
        self._doors: tuple[tuple[DoorNode, ...], tuple[tuple[str, int, int], ...]] | None = \
            None  # the nodes, (door id, place of each side) each
        self._room_index: tuple[object, tuple[list[str], np.ndarray, np.ndarray]] | None = \
            None  # (the rooms entry, its places for one look-up)

    # ----- what changed ---------------------------------------------------------------
    def show_furniture(self, f: int) -> None:
        """Furniture ``f`` is visible, in its current state (new or changed)."""
        env = self._env
        self._put(self._furn_nodes, self._furn, f,
                  self._h.furniture_node(f, env.furn_state[f], f in env.furn_explored))

    def show_object(self, j: int) -> None:
        """Small object ``j`` is seen, in its current state (new or changed)."""
        env, h = self._env, self._h
        self._put(self._obj_nodes, self._obj, j,
                  h.object_node(j, env.obj_state[j],
                                h.obj_has_affordances[j] and j in env.obj_explored))

    def _put(self, nodes: dict[int, ObjectNode], order: list[int], k: int,
             node: ObjectNode) -> None:
        old = nodes.get(k)
        if old is node:
            return
        if old is None:  # newly in view
            bisect.insort(order, k)
            self._items = None
        nodes[k] = node
        self._objects = None

    def rooms_changed(self) -> None:
        """A room became known or explored."""
        self._rooms = None

    def regions_changed(self) -> None:
        """A region was revealed or a room explored (its regions appear)."""
        self._regions = None

    def doors_changed(self) -> None:
        """A door was seen, opened or closed."""
        self._doors = None

    # ----- the graph ------------------------------------------------------------------
    def _build_rooms(self) -> tuple[tuple[RoomNode, ...], tuple[tuple[str, tuple[int, ...]],
                                                                 ...]]:
        env, h = self._env, self._h
        known = sorted(env.known_rooms)
        rooms = []
        for ri in known:
            explored = ri in env.explored_rooms
            name = h.room_names[ri]
            neighbours = tuple(sorted({h.room_ids[o] for o, _ in h.links[ri]
                                       if o in env.known_rooms})) if explored else ()
            key = (ri, explored, neighbours)
            node = self._room_nodes.get(key)
            if node is None:  # the same node object while the room is unchanged
                node = self._room_nodes[key] = RoomNode(
                    id=h.room_ids[ri], category=name if explored else "unknown",
                    position=h.room_centroids[ri], explored=explored,
                    category_scores=((name, 1.0),) if explored else (),
                    neighbours=neighbours)
            rooms.append(node)
        return tuple(rooms), tuple((h.room_ids[ri], h.room_places[ri]) for ri in known)

    def _build_regions(self) -> tuple[tuple[RegionNode, ...], _Ids]:
        env, h = self._env, self._h
        regions, places = [], []
        for ri in sorted(env.explored_rooms):
            for reg in h.room_regions[ri]:
                r = h.regions[reg]
                revealed = reg in env.revealed_regions
                node = self._region_nodes.get((reg, revealed))
                if node is None:
                    node = self._region_nodes[(reg, revealed)] = RegionNode(
                        id=r.id, room=h.room_ids[ri], position=r.center,
                        kind="region" if revealed else "frontier",
                        frontier_type=None if revealed else "unexplored area")
                regions.append(node)
                places.append(r.place)
        return tuple(regions), ([r.id for r in regions], np.asarray(places, dtype=np.intp))

    def _build_doors(self) -> tuple[tuple[DoorNode, ...], tuple[tuple[str, int, int], ...]]:
        env, h = self._env, self._h
        seen = sorted(env.visible_doors)
        doors = tuple(DoorNode(
            id=f"door:{di}", position=(float(h.spec.doors[di].center[0]),
                                       float(h.spec.doors[di].center[1])),
            state="open" if di in env.open_doors else "closed", rooms=h.door_rooms[di],
            instance=-1) for di in seen)
        return doors, tuple((f"door:{di}", *h.door_sides[di]) for di in seen)

    def _build_items(self) -> _Ids:
        h = self._h
        ids = [h.furn_ids[f] for f in self._furn] + [h.obj_ids[j] for j in self._obj]
        places = [h.furn_place[f] for f in self._furn] + [h.obj_place[j] for j in self._obj]
        return ids, np.asarray(places, dtype=np.intp)

    def _room_places(self) -> tuple[list[str], np.ndarray, np.ndarray]:
        """The known rooms' ids, their regions' places end to end, and where each room's
        start (for one ``reduceat``), kept with the rooms they are of."""
        rooms = self._rooms
        hit = self._room_index
        if hit is not None and hit[0] is rooms:
            return hit[1]
        pairs = rooms[1] if rooms is not None else ()
        rids = [r for r, ps in pairs]
        sizes = [len(ps) for _, ps in pairs]
        if 0 in sizes:
            raise ValueError("a known room without regions")
        flat = np.asarray([p for _, ps in pairs for p in ps], dtype=np.intp)
        starts = np.cumsum([0, *sizes[:-1]]).astype(np.intp)
        self._room_index = (rooms, (rids, flat, starts))
        return self._room_index[1]

    def graph(self, dist: np.ndarray) -> SceneGraph:
        """The observed graph with travel distances ``dist`` (from the agent's place to
        every place of the house; only finite ones are kept)."""
        env, h = self._env, self._h
        if self._rooms is None:
            self._rooms = self._build_rooms()
        if self._regions is None:
            self._regions = self._build_regions()
        if self._doors is None:
            self._doors = self._build_doors()
        if self._objects is None:
            self._objects = tuple(self._furn_nodes[f] for f in self._furn) + \
                tuple(self._obj_nodes[j] for j in self._obj)
        if self._items is None:
            self._items = self._build_items()
        distances: dict[str, float] = {}
        rids, flat, starts = self._room_places()
        if rids:
            near = np.minimum.reduceat(dist[flat], starts)  # each room's nearest region
            if np.isnan(near).any():  # (never: distances are finite or inf) as min() does
                near = np.array([min(dist[p] for p in ps) for _, ps in self._rooms[1]])
            distances.update((r, d) for r, d in zip(rids, near.tolist(), strict=True)
                             if math.isfinite(d))
        for ids, places in (self._regions[1], self._items):
            vals = dist[places]
            fin = np.isfinite(vals)
            if fin.all():
                distances.update(zip(ids, vals.tolist(), strict=True))
            else:
                distances.update(zip(compress(ids, fin.tolist()), vals[fin].tolist(),
                                     strict=True))
        for did, a, b in self._doors[1]:
            d = float(min(dist[a], dist[b]))
            if math.isfinite(d):
                distances[did] = d
        here = env.place
        robot = RobotState(position=h.places[here], room=h.room_ids[h.place_room[here]],
                           region=h.place_region.get(here))
        return SceneGraph(robot=robot, rooms=self._rooms[0], regions=self._regions[0],
                          objects=self._objects, doors=self._doors[0], distances=distances)
