"""From posed RGB-D frames with instance ids to the hierarchical scene graph.

:class:`SceneGraphBuilder` runs the pipeline of DESIGN.md ("Mapping pipeline"):
``integrate(frame)`` fuses every frame into the voxel map (cheap, per frame);
``refresh(time_ns)`` rebuilds the graph layers (every K frames and at every action, the
caller decides; :meth:`SceneGraphBuilder.due` says when K frames have passed):

1. BEV occupancy (:mod:`sgtool.mapping.bev`): column flags are updated from the voxels new
   since the last refresh only; a full rebuild happens when the floor level estimate moves
   or voxels were removed (an instance changed state);
2. Voronoi graph (:mod:`sgtool.mapping.voronoi`): the ridge pixel graph is reused while the
   occupancy grid is unchanged; the component is the robot's;
3. rooms (:mod:`sgtool.scenegraph.room_segmentation`): door cells of open doors cut the
   graph, ids are kept stable by overlap with the previous refresh;
4. objects (:mod:`sgtool.scenegraph.assign`): instances seen with enough points, placed at
   their voxel centroid, first-level ones assigned by MoMa-LLM's weighted travel distance
   from their closest viewpoint, nested ones (``inside``/``ontop`` a seen parent) in their
   parent's room with the parent as node parent;
5. regions (:mod:`sgtool.scenegraph.regions`) and frontiers
   (:mod:`sgtool.scenegraph.frontiers`), frontier ids kept by proximity;
6. doors: rooms on either side from visible nodes nearby; a closed door with only one
   explored side leads to an unexplored room node (SCOUT sec. IV-A), placed
   ``unexplored_offset`` beyond the door;
7. room categories from the contained furniture (all objects when a room has none) with
   the configured :class:`~sgtool.scenegraph.categories.RoomClassifier`; a room with no
   object at all whose nodes span >= 3 m and stay within 0.9 m of a wall is a corridor
   (``BuilderConfig.corridor``), otherwise "unknown";
8. travel distances from the robot to every node over the Voronoi graph (entry: the
   visible nodes within ``entry_radius``; object and frontier: their node plus the
   straight last leg).

Without instance ids (``ids=None``, imported real data) the same code builds geometry
only: voxels, occupancy, Voronoi graph, frontiers, rooms without door cuts or categories.

Determinism: no wall clock or randomness in derived data, every iteration in id order,
and :meth:`SceneGraphBuilder.refresh` with ``from_scratch=True`` (every cache dropped;
used to measure the incremental gain) gives the same graph as the incremental path. The
room and frontier id trackers are history: replaying a log calls ``refresh`` at the same
frames, hence the same ids. Stage timings (wall clock, never in the graph) are kept in
:attr:`SceneGraphBuilder.timings` (from-scratch refreshes in ``timings_scratch``).
"""

from __future__ import annotations

import dataclasses
import hashlib
import math
import time
from collections import defaultdict
from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np
from scipy.sparse.csgraph import dijkstra
from scipy.spatial import cKDTree

from sgtool.log.frame import Frame
from sgtool.mapping.bev import (
    OCCUPIED,
    BevConfig,
    ColumnGrid,
    OccupancyGrid,
    classify_keys,
    floor_fans,
    floor_level,
    line_of_sight,
)
from sgtool.mapping.voronoi import (
    RidgeGraph,
    VoronoiConfig,
    VoronoiGraph,
    ridge_graph,
    voronoi_graph,
)
from sgtool.mapping.voxels import VoxelConfig, VoxelMap
from sgtool.scenegraph.assign import AssignConfig, assign_objects
from sgtool.scenegraph.categories import RoomClassifier
from sgtool.scenegraph.frontiers import Frontier, FrontierConfig, find_frontiers
from sgtool.scenegraph.graph import (
    DoorNode,
    ObjectNode,
    RegionNode,
    RobotState,
    RoomNode,
    SceneGraph,
)
from sgtool.scenegraph.instances import InstanceInfo
from sgtool.scenegraph.regions import RegionConfig, cluster_room
from sgtool.scenegraph.room_segmentation import (
    RoomConfig,
    RoomSegmentation,
    RoomTracker,
    door_density,
    opening_from_panel,
    room_neighbours,
    segment_rooms,
)

OBJECT_KINDS = ("object", "furniture")


@dataclass(frozen=True)
class BuilderConfig:
    voxels: VoxelConfig = VoxelConfig()
    bev: BevConfig = BevConfig()
    voronoi: VoronoiConfig = VoronoiConfig()
    rooms: RoomConfig = RoomConfig()
    assign: AssignConfig = AssignConfig()
    frontiers: FrontierConfig = FrontierConfig()
    regions: RegionConfig = RegionConfig()
    refresh_every: int = 10  # frames between refreshes (K)
    door_radius: float = 1.5  # m: visible nodes this close to a door name its rooms
    unexplored_offset: float = 1.0  # m beyond a closed door: the unexplored room
    entry_radius: float = 3.0  # m: visible nodes this close to a point are its entries
    frontier_match: float = 1.0  # m: a frontier keeps its id if its medoid moved less
    classify_kinds: tuple[str, ...] = ("furniture",)  # instance kinds voting for the type
    max_scores: int = 5  # room category scores kept per room
    corridor: str | None = "corridor"  # the type of an empty narrow room (None: unknown)
    corridor_clearance: float = 0.9  # m: no node of a narrow room is farther from a wall
    corridor_length: float = 3.0  # m: the span of its nodes at least


@dataclass(frozen=True, eq=False)
class DoorObservation:
    instance: int
    position: tuple[float, float]
    state: str
    rooms: tuple[str, ...]  # explored rooms on either side, nearest first
    unexplored_room: str | None
    node: int  # nearest visible node (-1: none)


@dataclass(frozen=True, eq=False)
class MapLayers:
    """The intermediate layers of the last refresh, for writers and viewers."""

    occupancy: OccupancyGrid
    voronoi: VoronoiGraph
    node_rooms: tuple[str | None, ...]  # room id of every Voronoi node (None: cut away)
    segmentation: RoomSegmentation
    door_cells: np.ndarray  # bool grid of the cells holding open-door voxels
    door_density: np.ndarray
    doors: tuple[DoorObservation, ...]
    frontiers: tuple[Frontier, ...]
    frontier_ids: tuple[str, ...]
    robot_nodes: tuple[int, ...]  # entry nodes of the robot


@dataclass
class _Frontiers:
    next_id: int = 0
    known: list[tuple[int, tuple[float, float]]] = field(default_factory=list)

    def assign(self, medoids: list[tuple[float, float]], radius: float) -> list[int]:
        pairs = []
        for i, (x, y) in enumerate(medoids):
            for fid, (ox, oy) in self.known:
                d = math.hypot(x - ox, y - oy)
                if d <= radius:
                    pairs.append((d, fid, i))
        pairs.sort()
        out: list[int | None] = [None] * len(medoids)
        used: set[int] = set()
        for _d, fid, i in pairs:
            if out[i] is None and fid not in used:
                out[i] = fid
                used.add(fid)
        result = []
        for i in range(len(medoids)):
            r = out[i]
            if r is None:
                r = self.next_id
                self.next_id += 1
            result.append(r)
        self.known = list(zip(result, medoids, strict=True))
        return result


class SceneGraphBuilder:
    """Incremental scene-graph construction (module doc)."""

    def __init__(self, instances: Mapping[int, InstanceInfo] | None = None,
                 classifier: RoomClassifier | None = None,
                 config: BuilderConfig | None = None) -> None:
        self.config = config or BuilderConfig()
        self.voxels = VoxelMap(self.config.voxels)
        self.instances: dict[int, InstanceInfo] = dict(sorted((instances or {}).items()))
        self.classifier = classifier
        self.trajectory: list[tuple[float, float]] = []
        self.robot: tuple[float, float, float] | None = None
        self.frames_since_refresh = 0
        self.timings: dict[str, list[float]] = defaultdict(list)
        self.timings_scratch: dict[str, list[float]] = defaultdict(list)  # from_scratch=True
        self._fans: list[np.ndarray] = []  # per frame: rays to the nearest ground hit
        self._carved = 0  # frames whose fans are carved into self._columns
        self._columns: ColumnGrid | None = None
        self._level: int | None = None
        self._removals = -1
        self._ridge: tuple[bytes, RidgeGraph] | None = None
        self._rooms = RoomTracker()
        self._frontiers = _Frontiers()
        self._class_memo: dict[tuple[str, ...], list[tuple[str, float]]] = {}
        self._panel_memo: dict[bytes, object] = {}  # door openings from swung panels
        self._last: tuple[tuple, SceneGraph] | None = None
        self._unexplored_pos: dict[str, tuple[float, float]] = {}
        self.layers: MapLayers | None = None

    # ----- input ------------------------------------------------------------------------
    def set_instances(self, instances: Mapping[int, InstanceInfo]) -> list[int]:
        """Replace the instance table; instances whose state changed (a door opened) lose
        their voxels, rebuilt from the frames that follow. Returns those ids."""
        changed = []
        for iid, new in sorted(instances.items()):
            old = self.instances.get(iid)
            if old is not None and old.state != new.state:
                changed.append(iid)
                self.voxels.forget_instance(iid)
        self.instances = dict(sorted(instances.items()))
        return changed

    def integrate(self, frame: Frame) -> None:
        t0 = time.perf_counter()
        src = frame.base_pose if frame.base_pose is not None else frame.pose
        x, y = float(src[0, 3]), float(src[1, 3])
        if frame.base_pose is not None:
            yaw = math.atan2(float(src[1, 0]), float(src[0, 0]))
        else:  # camera optical axis (z) projected on the floor
            yaw = math.atan2(float(src[1, 2]), float(src[0, 2]))
        self.voxels.integrate(frame, (x, y))
        k = frame.intrinsics
        vc = self.config.voxels
        self._fans.append(floor_fans(np.asarray(frame.depth), np.asarray(frame.pose), k.fx,
                                     k.fy, k.cx, k.cy, min_range=vc.min_range,
                                     max_range=vc.max_range))
        self.trajectory.append((x, y))
        self.robot = (x, y, yaw)
        self.frames_since_refresh += 1
        self.timings["integrate"].append((time.perf_counter() - t0) * 1e3)

    def due(self) -> bool:
        """True when ``refresh_every`` frames were integrated since the last refresh."""
        return self.frames_since_refresh >= self.config.refresh_every

    # ----- refresh ----------------------------------------------------------------------
    def refresh(self, time_ns: int | None = None, from_scratch: bool = False) -> SceneGraph:
        """The scene graph now (module doc). ``time_ns`` defaults to 0."""
        t_all = time.perf_counter()
        stamp = int(time_ns or 0)
        key = (self.voxels.version, len(self.trajectory), self.robot,
               tuple((i, v.state) for i, v in self.instances.items()))
        if not from_scratch and self._last is not None and self._last[0] == key:
            self.frames_since_refresh = 0
            return dataclasses.replace(self._last[1], time_ns=stamp)
        if from_scratch:
            self._columns = None
            self._ridge = None
            self._class_memo = {}
            self._panel_memo = {}
        timings = self.timings_scratch if from_scratch else self.timings
        tick = _Ticker(timings)
        cfg = self.config
        occ = self._occupancy()
        tick("bev")
        robot_xy = None if self.robot is None else (self.robot[0], self.robot[1])
        digest = hashlib.blake2b(occ.grid.tobytes(), digest_size=16).digest() + repr(
            (occ.origin, occ.grid.shape)).encode()
        if self._ridge is None or self._ridge[0] != digest:
            self._ridge = (digest, ridge_graph(occ, cfg.voronoi))
        vg = voronoi_graph(occ, cfg.voronoi, anchor=robot_xy, ridge=self._ridge[1])
        tick("voronoi")
        door_cells = self._door_cells(occ)
        density = door_density(door_cells, occ.resolution, cfg.rooms.door_bandwidth)
        seg = segment_rooms(vg, density, cfg.rooms)
        numbers = self._rooms.assign([vg.positions[r] for r in seg.rooms],
                                     cfg.rooms.match_radius)
        room_ids = [f"room:{n}" for n in numbers]
        node_room = seg.labels
        tick("rooms")
        blocked = occ.grid == OCCUPIED
        graph_all = vg.csgraph()
        objects = self._objects(vg, node_room, graph_all, occ, blocked)
        tick("assign")
        regions, node_region = self._regions(vg, seg, room_ids)
        objects = [self._place(o, node_room, room_ids, node_region) for o in objects]
        tick("regions")
        doors = self._doors(vg, node_room, room_ids, occ, blocked)
        tick("doors")
        frontiers = find_frontiers(occ, robot_xy, cfg.frontiers)
        fids = self._frontiers.assign([f.medoid for f in frontiers], cfg.frontier_match)
        frontier_ids = [f"frontier:{i}" for i in fids]
        f_nodes = self._nearest_visible(vg, np.flatnonzero(node_room >= 0),
                                        [f.medoid for f in frontiers], occ, blocked)
        tick("frontiers")
        rooms = self._room_nodes(vg, seg, room_ids, objects, doors)
        tick("categories")
        # distances from the robot over the unsplit graph
        robot_nodes: tuple[int, ...] = ()
        dist_node = np.full(len(vg.positions), np.inf)
        if robot_xy is not None and len(vg.positions):
            entries = self._entries(vg, robot_xy, occ, blocked)
            robot_nodes = tuple(int(e) for e in entries)
            if len(entries):
                off = np.hypot(*(vg.positions[entries] - np.asarray(robot_xy)).T)
                d = dijkstra(graph_all, directed=False, indices=entries)
                dist_node = np.min(d.reshape(len(entries), -1) + off[:, None], axis=0)
        distances: dict[str, float] = {}

        def put(node_id: str, value: float) -> None:
            if math.isfinite(value):
                distances[node_id] = float(value)

        room_index = {rid: i for i, rid in enumerate(room_ids)}
        for rid, i in room_index.items():
            put(rid, dist_node[seg.centres[i]])
        for reg_id, node in regions.items():
            put(reg_id, dist_node[node[1]])
        obj_dist: dict[int, float] = {}
        for o in objects:
            if o.node >= 0 and o.top == o.instance:
                leg = math.hypot(o.position[0] - vg.positions[o.node, 0],
                                 o.position[1] - vg.positions[o.node, 1])
                obj_dist[o.instance] = float(dist_node[o.node] + leg)
        for o in objects:
            if o.room is not None and o.top in obj_dist:
                put(f"obj:{o.instance}", obj_dist[o.top])
        door_dist: dict[int, float] = {}
        for dr in doors:
            if dr.node >= 0:
                leg = math.hypot(dr.position[0] - vg.positions[dr.node, 0],
                                 dr.position[1] - vg.positions[dr.node, 1])
                door_dist[dr.instance] = float(dist_node[dr.node] + leg)
                put(f"door:{dr.instance}", door_dist[dr.instance])
        for fid, f, node in zip(frontier_ids, frontiers, f_nodes, strict=True):
            if node >= 0:
                put(fid, dist_node[node] + math.hypot(f.medoid[0] - vg.positions[node, 0],
                                                      f.medoid[1] - vg.positions[node, 1]))
        for rn in rooms:
            if not rn.explored:
                dr = next(d for d in doors if d.unexplored_room == rn.id)
                if dr.instance in door_dist:
                    put(rn.id, door_dist[dr.instance] + math.hypot(
                        rn.position[0] - dr.position[0], rn.position[1] - dr.position[1]))
        tick("distances")
        # robot state
        robot = RobotState(position=(0.0, 0.0))
        if self.robot is not None:
            rroom = rreg = None
            lab = [e for e in robot_nodes if node_room[e] >= 0]
            if lab:
                best = min(lab, key=lambda e: (math.hypot(vg.positions[e, 0] - robot_xy[0],
                                                          vg.positions[e, 1] - robot_xy[1]),
                                               e))
                rroom = room_ids[int(node_room[best])]
                rreg = node_region.get(best)
            robot = RobotState(position=(self.robot[0], self.robot[1]), yaw=self.robot[2],
                               room=rroom, region=rreg)
        region_nodes = [RegionNode(id=rid, room=room, position=pos)
                        for rid, (room, _n, pos) in regions.items()]
        for fid, f, node in zip(frontier_ids, frontiers, f_nodes, strict=True):
            room = room_ids[int(node_room[node])] if node >= 0 else None
            if room is None:
                continue
            region_nodes.append(RegionNode(id=fid, room=room, position=f.medoid,
                                           kind="frontier", frontier_type=f.type,  # type: ignore[arg-type]
                                           size=f.size))
        object_nodes = []
        for o in objects:
            if o.room is None:
                continue
            info = self.instances[o.instance]
            object_nodes.append(ObjectNode(
                id=f"obj:{o.instance}", category=info.category,
                parent=o.parent, room=o.room, position=o.position, instance=o.instance,
                relation=info.relation if o.parent.startswith("obj:") else None,
                state=info.state, affordances=tuple(sorted(info.affordances)),
                explored=info.state != "closed",
            ))
        door_nodes = [DoorNode(
            id=f"door:{d.instance}", position=d.position, state=d.state,  # type: ignore[arg-type]
            rooms=tuple(sorted(d.rooms + ((d.unexplored_room,) if d.unexplored_room else ()))),
            instance=d.instance) for d in doors]
        sg = SceneGraph(robot=robot, rooms=tuple(rooms), regions=tuple(region_nodes),
                        objects=tuple(object_nodes), doors=tuple(door_nodes),
                        distances=distances, time_ns=stamp)
        self.layers = MapLayers(
            occupancy=occ, voronoi=vg,
            node_rooms=tuple(room_ids[int(i)] if i >= 0 else None for i in node_room),
            segmentation=seg, door_cells=door_cells, door_density=density,
            doors=tuple(doors), frontiers=tuple(frontiers), frontier_ids=tuple(frontier_ids),
            robot_nodes=robot_nodes,
        )
        self._last = (key, sg)
        self.frames_since_refresh = 0
        tick("assemble")
        timings["refresh"].append((time.perf_counter() - t_all) * 1e3)
        return sg

    # ----- stages -----------------------------------------------------------------------
    def _occupancy(self) -> OccupancyGrid:
        cfg = self.config.bev
        res = self.voxels.resolution
        lo, hist = self.voxels.level_histogram()
        level = floor_level(cfg, res, lo, hist)
        if (self._columns is None or level != self._level
                or self.voxels.removals != self._removals):
            keys, _ = self.voxels.entries()
            self.voxels.drain_new_keys()
            cg = ColumnGrid(res, cfg)
            cg.add(classify_keys(keys, level, res, cfg, presorted=True), self.trajectory)
            self._columns, self._level, self._removals = cg, level, self.voxels.removals
            self._carved = 0
        else:
            new = self.voxels.drain_new_keys()
            self._columns.add(classify_keys(new, level, res, cfg), self.trajectory)
        if self._carved < len(self._fans):
            self._columns.carve(np.concatenate(self._fans[self._carved:]), level)
            self._carved = len(self._fans)
        return self._columns.occupancy(self.trajectory, level)

    def _door_cells(self, occ: OccupancyGrid) -> np.ndarray:
        """Door evidence (:mod:`sgtool.scenegraph.room_segmentation`): the *passable* columns
        of each open (or state-unknown) door -- its opening under the lintel, not the swung panel,
        whose cells would cut the room it stands in -- else the panel's closed position,
        else all its columns."""
        cells = np.zeros(occ.shape, dtype=bool)
        ix0 = int(round(occ.origin[0] / occ.resolution))
        iy0 = int(round(occ.origin[1] / occ.resolution))
        doors = [iid for iid, v in self.instances.items()
                 if v.kind == "door" and v.state != "closed"]
        occupied: np.ndarray | None = None
        for ijk in self.voxels.voxels_of(doors).values():
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
                got = opening_from_panel(r, c, occupied, int(0.4 / occ.resolution),
                                         memo=self._panel_memo)
                if got is not None:
                    r, c = got
            cells[r, c] = True
        return cells

    def _seen(self, kinds: tuple[str, ...]) -> list[tuple[InstanceInfo, tuple[float, ...],
                                                          tuple[float, float] | None]]:
        out = []
        min_pts = self.config.voxels.min_points
        for iid in self.voxels.observed_instances():
            info = self.instances.get(iid)
            if info is None or info.kind not in kinds:
                continue
            obs = self.voxels.observation(iid)
            if obs is None or obs.max_points < min_pts or obs.centroid is None:
                continue
            out.append((info, obs.centroid, obs.viewpoint))
        return out

    def _objects(self, vg: VoronoiGraph, node_room: np.ndarray, graph, occ: OccupancyGrid,  # noqa: ANN001
                 blocked: np.ndarray) -> list[_Obj]:
        seen = self._seen(OBJECT_KINDS)
        by_id = {info.id: (info, c, vp) for info, c, vp in seen}

        def top_of(iid: int) -> int:
            cur, hops = iid, 0
            while hops < 32:
                p = by_id[cur][0].parent
                if p is None or p not in by_id or p == cur:
                    return cur
                cur, hops = p, hops + 1
            return cur

        tops = sorted({top_of(i) for i in by_id})
        top_row = {iid: j for j, iid in enumerate(tops)}
        if tops and len(vg.positions):
            pts = np.asarray([by_id[i][1][:2] for i in tops], dtype=np.float64)
            vps = np.asarray([by_id[i][2] if by_id[i][2] is not None else (np.nan, np.nan)
                              for i in tops], dtype=np.float64)
            asg = assign_objects(vg.positions, node_room, graph, pts, vps, occ, blocked,
                                 self.config.assign)
            nodes = asg.node
        else:
            nodes = np.full(len(tops), -1, dtype=np.int64)
        node_of_top = {iid: int(nodes[top_row[iid]]) for iid in tops}
        out = []
        for iid in sorted(by_id):
            info, c, _vp = by_id[iid]
            top = top_of(iid)
            parent_id = info.parent if (top != iid and info.parent is not None) else None
            out.append(_Obj(iid, tuple(float(v) for v in c), top, node_of_top[top],
                            parent_id))
        return out

    @staticmethod
    def _place(o: _Obj, node_room: np.ndarray, room_ids: list[str],
               node_region: dict[int, str]) -> _Obj:
        """Room and parent node id of an object from its first-level ancestor's node."""
        if o.node < 0 or node_room[o.node] < 0:
            return o
        room = room_ids[int(node_room[o.node])]
        parent = (f"obj:{o.parent_instance}" if o.parent_instance is not None
                  else node_region[o.node])
        return dataclasses.replace(o, room=room, parent=parent)

    def _regions(self, vg: VoronoiGraph, seg: RoomSegmentation, room_ids: list[str]
                 ) -> tuple[dict[str, tuple[str, int, tuple[float, float]]], dict[int, str]]:
        regions: dict[str, tuple[str, int, tuple[float, float]]] = {}
        node_region: dict[int, str] = {}
        for i, nodes in enumerate(seg.rooms):
            rid = room_ids[i]
            num = rid.split(":", 1)[1]
            inside = np.isin(vg.edges, nodes).all(axis=1) if len(vg.edges) else np.zeros(0, bool)
            length = float(vg.lengths[inside].sum()) if len(vg.edges) else 0.0
            centre = int(np.searchsorted(nodes, seg.centres[i]))
            reg = cluster_room(vg.positions[nodes], length, centre, self.config.regions)
            for k, c in enumerate(reg.centres.tolist(), start=1):
                node = int(nodes[c])
                reg_id = f"region:{num}.{k}"
                regions[reg_id] = (rid, node, (float(vg.positions[node, 0]),
                                               float(vg.positions[node, 1])))
            for j, n in enumerate(nodes.tolist()):
                node_region[int(n)] = f"region:{num}.{int(reg.labels[j]) + 1}"
        self._node_region = node_region
        return regions, node_region

    def _doors(self, vg: VoronoiGraph, node_room: np.ndarray, room_ids: list[str],
               occ: OccupancyGrid, blocked: np.ndarray) -> list[DoorObservation]:
        out = []
        cfg = self.config
        labelled = np.flatnonzero(node_room >= 0)
        tree = cKDTree(vg.positions[labelled]) if len(labelled) else None
        for info, c, _vp in self._seen(("door",)):
            pos = (float(c[0]), float(c[1]))
            rooms: list[str] = []
            nearest = -1
            if tree is not None:
                near = labelled[np.asarray(sorted(tree.query_ball_point(pos, cfg.door_radius)),
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
                far = (pos[0] + cfg.unexplored_offset * float(u[0]),
                       pos[1] + cfg.unexplored_offset * float(u[1]))
                unexplored = f"room:{self._rooms.unexplored_room(info.id, far)}"
                self._unexplored_pos[unexplored] = far
            out.append(DoorObservation(info.id, pos, info.state or "open", tuple(rooms),
                                       unexplored, nearest))
        return out

    def _room_nodes(self, vg: VoronoiGraph, seg: RoomSegmentation, room_ids: list[str],
                    objects: list[_Obj], doors: list[DoorObservation]) -> list[RoomNode]:
        nb: dict[str, set[str]] = {rid: set() for rid in room_ids}
        for a, b in room_neighbours(vg, seg):
            nb[room_ids[a]].add(room_ids[b])
            nb[room_ids[b]].add(room_ids[a])
        for d in doors:
            joined = list(d.rooms) + ([d.unexplored_room] if d.unexplored_room else [])
            for a in joined:
                for b in joined:
                    if a != b and a in nb:
                        nb[a].add(b)
        cats: dict[str, list[str]] = defaultdict(list)
        voters: dict[str, list[str]] = defaultdict(list)
        for o in objects:
            if o.room is None:
                continue
            info = self.instances[o.instance]
            cats[o.room].append(info.category)
            if info.kind in self.config.classify_kinds:
                voters[o.room].append(info.category)
        out = []
        for i, rid in enumerate(room_ids):
            c = seg.centres[i]
            scores: list[tuple[str, float]] = []
            if self.classifier is not None:
                evidence = tuple(sorted(voters.get(rid) or cats.get(rid) or ()))
                if evidence:
                    got = self._class_memo.get(evidence)
                    if got is None:
                        got = list(self.classifier.classify(list(evidence)))
                        self._class_memo[evidence] = got
                    scores = got[: self.config.max_scores]
                elif self._corridor_like(vg, seg.rooms[i]):
                    scores = [(str(self.config.corridor), 1.0)]
            out.append(RoomNode(
                id=rid, category=scores[0][0] if scores else "unknown",
                position=(float(vg.positions[c, 0]), float(vg.positions[c, 1])),
                explored=True, category_scores=tuple((r, float(p)) for r, p in scores),
                neighbours=tuple(sorted(nb[rid])),
            ))
        for d in doors:
            if d.unexplored_room is None:
                continue
            pos = self._unexplored_pos[d.unexplored_room]
            out.append(RoomNode(id=d.unexplored_room, position=pos, explored=False,
                                neighbours=tuple(sorted(d.rooms))))
        return out

    # ----- helpers ----------------------------------------------------------------------
    def _corridor_like(self, vg: VoronoiGraph, nodes: np.ndarray) -> bool:
        """An empty room that is long (its nodes span ``corridor_length``) and narrow (no
        node farther than ``corridor_clearance`` from a wall): with no object to vote,
        the geometry says corridor (transparent rule, off with ``corridor=None``)."""
        cfg = self.config
        if cfg.corridor is None or len(nodes) < 2 or not self.instances:
            return False  # without semantics an empty room says nothing
        p = vg.positions[nodes]
        span = float(np.hypot(*(p.max(axis=0) - p.min(axis=0))))
        return (span >= cfg.corridor_length
                and float(vg.clearance[nodes].max()) <= cfg.corridor_clearance)

    def _entries(self, vg: VoronoiGraph, xy: tuple[float, float], occ: OccupancyGrid,
                 blocked: np.ndarray) -> np.ndarray:
        """Visible nodes within ``entry_radius`` of ``xy`` (else the nearest node)."""
        return self._visible_near(vg, np.arange(len(vg.positions)), [xy], occ, blocked)[0]

    def _visible_near(self, vg: VoronoiGraph, cand: np.ndarray,
                      points: list[tuple[float, float]], occ: OccupancyGrid,
                      blocked: np.ndarray) -> list[np.ndarray]:
        """Per point: the candidate nodes within ``entry_radius`` visible from it, else the
        nearest candidate (one batched line-of-sight test for all points)."""
        pos = vg.positions
        if len(cand) == 0 or not points:
            return [np.zeros(0, dtype=np.int64) for _ in points]
        tree = cKDTree(pos[cand])
        near = [cand[np.asarray(sorted(tree.query_ball_point(p, self.config.entry_radius)),
                                dtype=np.int64)] for p in points]
        a = np.concatenate([np.repeat(np.asarray([p]), len(n), axis=0)
                            for p, n in zip(points, near, strict=True)] or [np.zeros((0, 2))])
        idx = np.concatenate(near) if near else np.zeros(0, dtype=np.int64)
        vis = line_of_sight(blocked, occ, a, pos[idx]) if len(idx) else np.zeros(0, bool)
        out = []
        at = 0
        for p, n in zip(points, near, strict=True):
            sel = vis[at:at + len(n)]
            at += len(n)
            if sel.any():
                out.append(n[sel])
            else:
                out.append(np.asarray([int(cand[int(tree.query(p)[1])])], dtype=np.int64))
        return out

    def _nearest_visible(self, vg: VoronoiGraph, cand: np.ndarray,
                         points: list[tuple[float, float]], occ: OccupancyGrid,
                         blocked: np.ndarray) -> list[int]:
        """Per point: the nearest visible candidate node (see :meth:`_visible_near`),
        -1 without candidates."""
        out = []
        for p, e in zip(points, self._visible_near(vg, cand, points, occ, blocked),
                        strict=True):
            if len(e) == 0:
                out.append(-1)
                continue
            d = np.hypot(vg.positions[e, 0] - p[0], vg.positions[e, 1] - p[1])
            out.append(int(e[int(np.lexsort((e, d))[0])]))
        return out

    def stage_summary(self, from_scratch: bool = False) -> dict[str, tuple[float, float, int]]:
        """Per stage: (median ms, max ms, count) of the incremental refreshes (or of the
        from-scratch ones)."""
        t = self.timings_scratch if from_scratch else self.timings
        return {k: (float(np.median(v)), float(np.max(v)), len(v))
                for k, v in sorted(t.items()) if v}


@dataclass(frozen=True)
class _Obj:
    instance: int
    position: tuple[float, ...]
    top: int  # first-level ancestor (itself when first-level)
    node: int  # Voronoi node of the first-level ancestor, -1 when unassigned
    parent_instance: int | None  # the seen parent of a nested object
    room: str | None = None
    parent: str = ""


class _Ticker:
    def __init__(self, timings: dict[str, list[float]]) -> None:
        self.timings = timings
        self.t = time.perf_counter()

    def __call__(self, stage: str) -> None:
        now = time.perf_counter()
        self.timings[stage].append((now - self.t) * 1e3)
        self.t = now
