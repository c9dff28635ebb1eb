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
_DoorPlaces = tuple[list[str], np.ndarray, np.ndarray]  # door ids, the places of each side


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
        self._room_parts: dict[int, RoomNode] = {}  # per known room index: its node
        self._seen: tuple[set[int], set[int]] = (set(), set())  # rooms known, explored then
        # per explored room index: its region nodes, their ids and places
        self._region_parts: dict[int, tuple[list[RegionNode], list[str], list[int]]] = {}
        self._obj_nodes: dict[int, ObjectNode] = {}
        # what is rebuilt when it changed (None: to rebuild)
        self._objects: tuple[ObjectNode, ...] | None = None
        self._items: _Ids | None = None  # furniture and objects
        self._rooms: tuple[tuple[RoomNode, ...], tuple[tuple[str, tuple[int, ...]], ...]] | \
            None = None  # the nodes, (room id, its regions' places) each
        self._regions: tuple[tuple[RegionNode, ...], _Ids] | None = None
        self._door_nodes: dict[tuple[int, bool], DoorNode] = {}
        self._doors: tuple[tuple[DoorNode, ...], _DoorPlaces] | None = None
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

    def regions_changed(self, room: int | None = None) -> None:
        """A region of room index ``room`` was revealed, or the room explored (its regions
        appear); None: any room's."""
        self._regions = None
        if room is None:
            self._region_parts.clear()
        else:
            self._region_parts.pop(room, None)

    def doors_changed(self) -> None:
        """A door was seen, opened or closed."""
        self._doors = None

    # ----- the graph ------------------------------------------------------------------
    def _build_rooms(self) -> tuple[tuple[RoomNode, ...], tuple[tuple[str, tuple[int, ...]],
                                                                 ...]]:
        env, h = self._env, self._h
        # a room's node changes when it becomes known or explored, or a room linked to it
        # becomes known (its neighbours); the sets only grow within an episode
        seen_known, seen_explored = self._seen
        if seen_known <= env.known_rooms and seen_explored <= env.explored_rooms:
            new = env.known_rooms - seen_known
            for ri in new | (env.explored_rooms - seen_explored):
                self._room_parts.pop(ri, None)
            for ri in new:
                for o, _ in h.links[ri]:
                    self._room_parts.pop(o, None)
        else:
            self._room_parts.clear()
        self._seen = (set(env.known_rooms), set(env.explored_rooms))
        known = sorted(env.known_rooms)
        rooms = []
        for ri in known:
            node = self._room_parts.get(ri)
            if node is None:
                node = self._room_parts[ri] = self._room_node(ri)
            rooms.append(node)
        return tuple(rooms), tuple((h.room_ids[ri], h.room_places[ri]) for ri in known)

    def _room_node(self, ri: int) -> RoomNode:
        """The node of known room ``ri`` (the same object while the room is unchanged)."""
        env, h = self._env, self._h
        explored = ri in env.explored_rooms
        name = h.room_names[ri]
        neighbours = tuple(sorted({h.room_ids[o] for o, _ in h.links[ri]
                                   if o in env.known_rooms})) if explored else ()
        key = (ri, explored, neighbours)
        node = self._room_nodes.get(key)
        if node is None:
            node = self._room_nodes[key] = RoomNode(
                id=h.room_ids[ri], category=name if explored else "unknown",
                position=h.room_centroids[ri], explored=explored,
                category_scores=((name, 1.0),) if explored else (), neighbours=neighbours)
        return node

    def _build_regions(self) -> tuple[tuple[RegionNode, ...], _Ids]:
        regions: list[RegionNode] = []
        ids: list[str] = []
        places: list[int] = []
        parts = self._region_parts
        for ri in sorted(self._env.explored_rooms):
            part = parts.get(ri)
            if part is None:  # (kept per room until one of its regions changes)
                part = parts[ri] = self._room_regions(ri)
            regions += part[0]
            ids += part[1]
            places += part[2]
        return tuple(regions), (ids, np.asarray(places, dtype=np.intp))

    def _room_regions(self, ri: int) -> tuple[list[RegionNode], list[str], list[int]]:
        """The region nodes of explored room ``ri``, their ids and places."""
        env, h = self._env, self._h
        regions, places = [], []
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
        return regions, [r.id for r in regions], places

    def _build_doors(self) -> tuple[tuple[DoorNode, ...], _DoorPlaces]:
        env, h = self._env, self._h
        seen = sorted(env.visible_doors)
        doors = []
        for di in seen:
            is_open = di in env.open_doors
            node = self._door_nodes.get((di, is_open))
            if node is None:  # the same node object while the door is unchanged
                node = self._door_nodes[(di, is_open)] = DoorNode(
                    id=f"door:{di}", position=(float(h.spec.doors[di].center[0]),
                                               float(h.spec.doors[di].center[1])),
                    state="open" if is_open else "closed", rooms=h.door_rooms[di],
                    instance=-1)
            doors.append(node)
        sides = np.asarray([h.door_sides[di] for di in seen], dtype=np.intp).reshape(-1, 2)
        return tuple(doors), ([d.id for d in doors], sides[:, 0], sides[:, 1])

    def _build_items(self) -> _Ids:
        h = self._h
        ids = [*map(h.furn_ids.__getitem__, self._furn), *map(h.obj_ids.__getitem__, self._obj)]
        places = [*map(h.furn_place.__getitem__, self._furn),
                  *map(h.obj_place.__getitem__, self._obj)]
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
            self._objects = (*map(self._furn_nodes.__getitem__, self._furn),
                             *map(self._obj_nodes.__getitem__, self._obj))
        if self._items is None:
            self._items = self._build_items()
        distances: dict[str, float] = {}
        rids, flat, starts = self._room_places()
        if rids:
            near = np.minimum.reduceat(dist[flat], starts)  # each room's nearest region
            if math.isfinite(np.add.reduce(near)):  # all finite (else the sum is not)
                distances.update(zip(rids, near.tolist(), strict=True))
            else:
                if np.isnan(near).any():  # (never: distances are finite or inf) as min()
                    near = np.array([min(dist[p] for p in ps) for _, ps in self._rooms[1]])
                distances.update((r, d) for r, d in zip(rids, near.tolist(), strict=True)
                                 if math.isfinite(d))
        for ids, places in (self._regions[1], self._items):
            vals = dist[places]
            if math.isfinite(np.add.reduce(vals)):  # all finite
                distances.update(zip(ids, vals.tolist(), strict=True))
            else:
                fin = np.isfinite(vals)
                distances.update(zip(compress(ids, fin.tolist()), vals[fin].tolist(),
                                     strict=True))
        dids, a, b = self._doors[1]
        if dids:  # each door's nearer side
            vals = np.minimum(dist[a], dist[b])
            fin = np.isfinite(vals)
            distances.update(zip(compress(dids, fin.tolist()), vals[fin].tolist(),
                                 strict=True))
        here = env.place
        robot = RobotState(position=h.places[here], room=h.room_ids[h.place_room[here]],
                           region=h.place_region.get(here))
        return SceneGraph(robot=robot, rooms=self._rooms[0], regions=self._regions[0],
                          objects=self._objects, doors=self._doors[0], distances=distances)
