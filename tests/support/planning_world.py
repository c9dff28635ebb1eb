"""A random house revealed as the planner acts (a miniature SymSearch), for planner tests."""

from __future__ import annotations

import dataclasses

import numpy as np

from sgtool.planning.base import Action, Feedback
from sgtool.scenegraph.graph import (
    DoorNode,
    ObjectNode,
    RegionNode,
    RobotState,
    RoomNode,
    SceneGraph,
)

ROOMS = ["kitchen", "bathroom", "bedroom", "living_room", "garage"]
FURNITURE = ["bottom_cabinet", "fridge", "wardrobe", "shelf", "table", "sink", "bed"]
SMALL = ["plate", "toothbrush", "book", "apple", "towel", "hammer"]


class World:
    """A random house revealed as the planner acts (a miniature SymSearch)."""

    def __init__(self, seed: int) -> None:
        rng = np.random.default_rng(seed)
        n = int(rng.integers(2, 6))
        self.rooms = []
        self.objects: list[ObjectNode] = []
        self.hidden: dict[str, list[ObjectNode]] = {}  # container/frontier/room -> contents
        self.regions: list[RegionNode] = []
        self.doors: list[DoorNode] = []
        self._true_cat: dict[str, str] = {}
        k = 0
        for i in range(n):
            rid = f"room:{i + 1}"
            cat = ROOMS[int(rng.integers(len(ROOMS)))]
            explored = i == 0 or bool(rng.random() < 0.5)
            self.rooms.append(RoomNode(rid, cat if explored else "unknown", (6.0 * i, 0.0),
                                       explored))
            self._true_cat[rid] = cat
            fid = f"frontier:{i + 1}"
            self.regions.append(RegionNode(fid, rid, (6.0 * i, 3.0), "frontier",
                                           "unexplored area", 1.0))
            for _ in range(int(rng.integers(1, 4))):
                k += 1
                f = FURNITURE[int(rng.integers(len(FURNITURE)))]
                openable = f in ("bottom_cabinet", "fridge", "wardrobe")
                o = ObjectNode(f"obj:{k}", f, f"region:{i + 1}.1", rid,
                               (6.0 * i + rng.uniform(-2, 2), rng.uniform(-2, 2), 0.0),
                               state="closed" if openable else None,
                               affordances=("open",) if openable else ("explore",))
                bucket = rid if not explored else None
                if bucket:
                    self.hidden.setdefault(rid, []).append(o)
                else:
                    self.objects.append(o)
                for _ in range(int(rng.integers(0, 3))):
                    k += 1
                    s = SMALL[int(rng.integers(len(SMALL)))]
                    inner = ObjectNode(f"obj:{k}", s, o.id, rid, o.position, relation="inside")
                    self.hidden.setdefault(o.id, []).append(inner)
            if i > 0 and not explored:
                self.doors.append(DoorNode(f"door:{i}", (6.0 * i - 3, 0.0), "closed",
                                           (f"room:{i}", rid)))
        self.query = SMALL[int(rng.integers(len(SMALL)))]
        self.robot = (0.0, 0.0)

    def graph(self) -> SceneGraph:
        nodes = [*self.rooms, *self.regions, *self.objects, *self.doors]
        dist = {n.id: float(np.hypot(n.position[0] - self.robot[0],
                                     n.position[1] - self.robot[1])) for n in nodes}
        return SceneGraph(RobotState(self.robot, room="room:1"), tuple(self.rooms),
                          tuple(self.regions), tuple(self.objects), tuple(self.doors), dist)

    def execute(self, a: Action) -> Feedback:
        node_id = a.target
        assert node_id is not None
        if node_id.startswith("room:"):
            i = [r.id for r in self.rooms].index(node_id)
            self.rooms[i] = dataclasses.replace(self.rooms[i], explored=True,
                                                category=self._true_cat[node_id])
        elif node_id.startswith("frontier:"):
            self.regions = [r for r in self.regions if r.id != node_id]
        elif node_id.startswith("door:"):
            self.doors = [dataclasses.replace(d, state="open") if d.id == node_id else d
                          for d in self.doors]
        else:
            self.objects = [dataclasses.replace(o, explored=True,
                                                state="open" if o.state else None)
                            if o.id == node_id else o for o in self.objects]
        self.objects.extend(self.hidden.pop(node_id, []))
        return Feedback(a, "success")
