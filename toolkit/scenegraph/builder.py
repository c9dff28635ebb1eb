"""From posed RGB-D frames with instance ids to the hierarchical scene graph.

:class:`SceneGraphBuilder` runs the pipeline of DESIGN.md ("Mapping pipeline"):
``integrate(frame)`` fuses every frame into the voxel map (cheap, per frame);
``refresh(time_ns)`` rebuilds the graph layers (every K frames and at every action, the
caller decides; :meth:`SceneGraphBuilder.due` says when K frames have passed):

1. BEV occupancy (:mod:`sgtool.mapping.bev`): column flags are updated from the voxels new
   since the last refresh only; when voxels were removed (an instance changed state) only
   the columns that held them are classified again (:mod:`sgtool.mapping.column_update`);
   a full rebuild happens when the floor level estimate moves or the grid would shrink;
2. Voronoi graph (:mod:`sgtool.mapping.voronoi`): the ridge pixel graph is reused while the
   free cells are unchanged, else its distance field and ridge cells are recomputed around
   the changed cells only (:mod:`sgtool.mapping.ridge_window`); the components are the
   robot's and every one its trajectory passed through
   (:func:`~sgtool.mapping.voronoi.visited_components`);
3. rooms (:mod:`sgtool.scenegraph.room_segmentation`): door cells of the voxels the open
   doors win (:mod:`sgtool.scenegraph.door_evidence`,
   :meth:`sgtool.scenegraph.door_voxels.DoorVoxels.won`), within ``DOOR_REACH`` of
   their median (:func:`sgtool.scenegraph.door_voxels.near_median`), in columns where at
   least ``DOOR_MIN_FRAMES`` frames gave the door a voxel, and the lintels over
   doorways no door leaf was seen in (:mod:`sgtool.scenegraph.lintels`) cut the graph;
   ids are kept stable by overlap with the previous refresh;
4. objects (:mod:`sgtool.scenegraph.object_placement`, :mod:`sgtool.scenegraph.assign`):
   instances seen with enough points in a frame, given points by at least
   ``OBJECT_EVIDENCE.min_frames`` frames and winning a voxel
   (:mod:`sgtool.scenegraph.object_evidence`), placed at the centroid of the voxels they
   win, first-level ones
   assigned by MoMa-LLM's weighted travel distance from their closest viewpoint, nested
   ones (``inside``/``ontop`` a seen parent) in their parent's room with the parent as
   node parent;
5. regions (:mod:`sgtool.scenegraph.regions`) and frontiers
   (:mod:`sgtool.scenegraph.frontiers`), frontier ids kept by proximity
   (:mod:`sgtool.scenegraph.frontier_ids`);
6. doors (:mod:`sgtool.scenegraph.door_evidence`), an open one at its doorway (the
   centre of its cells of stage 3): rooms on either side from visible nodes nearby; a
   closed door with only one explored side leads to an unexplored room node (SCOUT sec.
   IV-A), placed ``unexplored_offset`` beyond the door;
7. room categories (:mod:`sgtool.scenegraph.room_nodes`) from the contained furniture (all
   objects when a room has none) with the configured
   :class:`~sgtool.scenegraph.categories.RoomClassifier`, a long, narrow room's shape
   (:func:`~sgtool.scenegraph.room_nodes.corridor_like`) speaking for a corridor;
8. travel distances (:mod:`sgtool.scenegraph.travel`) from the robot to every node over
   the Voronoi graph (entry: the visible nodes within ``entry_radius``; object and
   frontier: their node plus the straight last leg);
9. assembly of the nodes into the graph (:mod:`sgtool.scenegraph.assembly`).

Before the stages, a robot's body is free-space evidence: the voxels in the BEV height band
within ``BODY_RADIUS`` of the base's positions (frames with a base pose: a hand-held camera
has no body below it) new since the last refresh that never had an instance's label are dropped
(:meth:`~sgtool.mapping.voxels.VoxelMap.clear_unlabelled_around`); a later frame that sees
something there puts it back. Depth is free-space evidence too: every ``VIEW_STRIDE``-th
frame since the last refresh counts a miss on each weak voxel of the band it saw through
(:meth:`~sgtool.mapping.voxels.VoxelMap.clear_seen_through`,
:mod:`sgtool.mapping.free_space`).

Each stage is one method of :class:`SceneGraphBuilder` or one function of those modules;
``refresh`` runs them in this order and times each.

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
import math
import time
from collections import defaultdict
from collections.abc import Callable, Mapping
from dataclasses import dataclass

import numpy as np

from sgtool.log.frame import Frame
from sgtool.mapping.bev import (
    ColumnGrid,
    classify_keys,
    columns_between,
    floor_fans,
    floor_level,
    floor_levels,
)
from sgtool.mapping.column_update import fresh_extent, reclassify_columns
from sgtool.mapping.free_space import View
from sgtool.mapping.grid import FREE, OCCUPIED, OccupancyGrid
from sgtool.mapping.voronoi import (
    RidgeGraph,
    VoronoiGraph,
    ridge_graph,
    visited_components,
    voronoi_graph,
)
from sgtool.mapping.voxels import COLUMN_SHIFT, LABEL_MASK, VoxelMap
from sgtool.scenegraph.assembly import GraphParts, assemble_graph, robot_state
from sgtool.scenegraph.assign import AssignCache
from sgtool.scenegraph.builder_config import BuilderConfig
from sgtool.scenegraph.categories import RoomClassifier
from sgtool.scenegraph.door_evidence import DoorObservation, doorways, observe_doors, open_doors
from sgtool.scenegraph.door_voxels import DoorVoxels, near_median
from sgtool.scenegraph.examined import (
    FramePoints,
    PieceView,
    carrier_kinds,
    close_views,
    look_into,
)
from sgtool.scenegraph.frontier_ids import FrontierTracker
from sgtool.scenegraph.frontiers import Frontier, find_frontiers
from sgtool.scenegraph.graph import SceneGraph
from sgtool.scenegraph.instances import InstanceInfo
from sgtool.scenegraph.lintels import LINTEL_BAND, lintel_doorways
from sgtool.scenegraph.object_evidence import EvidenceRule
from sgtool.scenegraph.object_placement import (
    OBJECT_KINDS,
    SeenInstance,
    place_in_room,
    place_objects,
    seen_instances,
)
from sgtool.scenegraph.regions import Regions as RoomRegions
from sgtool.scenegraph.room_nodes import room_nodes, room_regions
from sgtool.scenegraph.room_segmentation import (
    RoomSegmentation,
    RoomTracker,
    door_density,
    segment_rooms,
)
from sgtool.scenegraph.travel import node_distances, travel_distances
from sgtool.scenegraph.visibility import entry_nodes, nearest_visible

BODY_RADIUS = 0.2  # m: unlabelled voxels this close to where the robot stood are dropped
DOOR_REACH = 1.5  # m: a door's evidence is its won voxels this close to their median
DOOR_MIN_FRAMES = 2  # a door column is evidence with a voxel this many frames gave the door
OBJECT_EVIDENCE = EvidenceRule()  # frames and won voxels that make an object
VIEW_STRIDE = 2  # every this many frames, one is free-space evidence (neighbours see alike)

__all__ = ["BODY_RADIUS", "DOOR_MIN_FRAMES", "DOOR_REACH", "OBJECT_EVIDENCE", "VIEW_STRIDE",
           "BuilderConfig", "DoorObservation", "MapLayers", "SceneGraphBuilder"]


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


@dataclass(frozen=True, eq=False)
class _Ridge:
    """The ridge pixel graph of a free mask on a grid placement (``repr`` of origin, shape
    and resolution); ``version`` counts the ridges computed since the last from-scratch
    refresh, so a graph made from this ridge can be recognised by it."""

    place: str
    free: np.ndarray
    version: int
    ridge: RidgeGraph


@dataclass(frozen=True, eq=False)
class _Rooms:
    """The rooms stage of a refresh: door evidence, its density and the segmentation."""

    door_cells: np.ndarray
    density: np.ndarray
    seg: RoomSegmentation
    room_ids: list[str]
    doorways: dict[int, tuple[float, float]]  # open door id -> centre of its door cells


class SceneGraphBuilder:
    """Incremental scene-graph construction (module doc)."""

    # the clock of the stage timings: wall time; a benchmark on a loaded machine may set
    # ``time.thread_time`` (CPU time of the thread) instead
    clock = staticmethod(time.perf_counter)

    def __init__(self, instances: Mapping[int, InstanceInfo] | None = None,
                 classifier: RoomClassifier | None = None,
                 config: BuilderConfig | None = None) -> None:
        self.config = config or BuilderConfig()
        self.voxels = VoxelMap(self.config.voxels)
        self.instances: dict[int, InstanceInfo] = dict(sorted((instances or {}).items()))
        self.classifier = classifier
        self.trajectory: list[tuple[float, float]] = []
        # instances looked at from close by (:mod:`sgtool.scenegraph.examined`), in any state
        # since their last state change
        self.examined: set[int] = set()
        self._pieces: dict[int, PieceView] = {}  # what close frames showed of carriers
        self.robot: tuple[float, float, float] | None = None
        self.frames_since_refresh = 0
        self._body: list[tuple[float, float]] = []  # where a robot's base stood, per frame
        self._cleared = 0  # points of _body whose body cleared the voxels around them
        self._views: list[View] = []  # depth frames not yet used as free-space evidence
        self.seen_through_entries = 0  # voxel entries dropped as seen through by depth
        self.cleared_entries = 0  # voxel entries dropped by the robot's body
        self.timings: dict[str, list[float]] = defaultdict(list)
        self.timings_scratch: dict[str, list[float]] = defaultdict(list)  # from_scratch=True
        self._fans: list[np.ndarray] = []  # per frame: rays to the nearest ground hit
        self._carved = 0  # frames whose fans are carved into self._carve
        self._carve: ColumnGrid | None = None  # carved ground cells (flags CARVED only)
        self._carve_level: int | None = None
        self._columns: ColumnGrid | None = None
        self._level: int | None = None
        self._removals = -1
        self._door_voxels = DoorVoxels()  # the door keys, kept with the BEV columns
        self._ridge: _Ridge | None = None
        self._graph: tuple[tuple[int, tuple[int, ...]], VoronoiGraph] | None = None
        self._rooms = RoomTracker()
        self._frontiers = FrontierTracker()
        self._class_memo: dict[tuple[str, ...], list[tuple[str, float]]] = {}
        self._panel_memo: dict[bytes, object] = {}  # door openings from swung panels
        # door density of these cells: (resolution, door cells, density)
        self._density: tuple[float, np.ndarray, np.ndarray] | None = None
        self._centre_memo: dict[bytes, int] = {}  # room centres by their sub-graph
        self._region_memo: dict[bytes, RoomRegions] = {}  # room clusterings by their inputs
        self._assign_cache = AssignCache()  # Dijkstra rows and sight lines of assignment
        self._last: tuple[tuple, SceneGraph] | None = None
        self.layers: MapLayers | None = None
        self._warm_classifier()

    def _warm_classifier(self) -> None:
        """Load the classifier's per-category evidence for every object category of the
        instance table now, before frames arrive, rather than at the first refresh that
        sees one (a classifier with a memoised ``votes(category)``, as the learned
        containment model, is asked once per category; answers do not change)."""
        votes = getattr(self.classifier, "votes", None)
        if not callable(votes):
            return
        for cat in sorted({i.category for i in self.instances.values()
                           if i.kind in OBJECT_KINDS}):
            votes(cat)

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
                self.examined.discard(iid)
                self._pieces.pop(iid, None)
        self.instances = dict(sorted(instances.items()))
        self._warm_classifier()
        return changed

    def integrate(self, frame: Frame) -> None:
        t0 = self.clock()
        src = frame.base_pose if frame.base_pose is not None else frame.pose
        x, y = float(src[0, 3]), float(src[1, 3])
        if frame.base_pose is not None:
            yaw = math.atan2(float(src[1, 0]), float(src[0, 0]))
        else:  # camera optical axis (z) projected on the floor
            yaw = math.atan2(float(src[1, 2]), float(src[0, 2]))
        self.voxels.integrate(frame, (x, y))
        if frame.ids is not None:
            self._examine(frame)
        if len(self.trajectory) % VIEW_STRIDE == 0 and np.all(np.isfinite(frame.pose)):
            self._views.append(View.of(frame.pose, frame.intrinsics, np.asarray(frame.depth),
                                       self.config.voxels.min_range))
        k = frame.intrinsics
        vc = self.config.voxels
        self._fans.append(floor_fans(np.asarray(frame.depth), np.asarray(frame.pose), k.fx,
                                     k.fy, k.cx, k.cy, min_range=vc.min_range,
                                     max_range=vc.max_range))
        self.trajectory.append((x, y))
        self._body += [(x, y)] if frame.base_pose is not None else []  # hand-held: no body
        self.robot = (x, y, yaw)
        self.frames_since_refresh += 1
        self.timings["integrate"].append((self.clock() - t0) * 1e3)

    def _examine(self, frame: Frame) -> None:
        """Add to :attr:`examined` what this frame looked at from close by: any instance
        in a close view, a container or supporter only once close frames saw into (onto)
        enough of it (:meth:`sgtool.scenegraph.examined.PieceView.searched`; with
        ``look_inside`` off, from the close view alone)."""
        ids = np.asarray(frame.ids)
        depth = np.asarray(frame.depth)
        points: FramePoints | None = None  # back-projected once, when a carrier needs it
        for iid in close_views(ids, depth, self.config.voxels.min_points):
            if iid in self.examined:
                continue
            info = self.instances.get(iid)
            container, supporter = (False, False) if info is None else \
                carrier_kinds(info.affordances, info.kind == "object")
            if not (self.config.look_inside and (container or supporter)):
                self.examined.add(iid)
                continue
            if points is None:
                points = FramePoints.of(ids, depth, frame.pose, frame.intrinsics,
                                        self.config.voxels.resolution)
            view = self._pieces.setdefault(iid, PieceView())
            look_into(view, iid, points)
            if view.searched(container, supporter):
                self.examined.add(iid)

    def due(self) -> bool:
        """True when ``refresh_every`` frames were integrated since the last refresh."""
        return self.frames_since_refresh >= self.config.refresh_every

    # ----- refresh ----------------------------------------------------------------------
    def refresh(self, time_ns: int | None = None, from_scratch: bool = False) -> SceneGraph:
        """The scene graph now (module doc). ``time_ns`` defaults to 0."""
        t_all = self.clock()
        stamp = int(time_ns or 0)
        self._clear_footprint()
        t_body = self.clock()
        key = (self.voxels.version, len(self.trajectory), self.robot,
               tuple((i, v.state) for i, v in self.instances.items()))
        if not from_scratch and self._last is not None and self._last[0] == key:
            self.frames_since_refresh = 0
            return dataclasses.replace(self._last[1], time_ns=stamp)
        if from_scratch:
            self._columns = None
            self._carve = None
            self._ridge = None
            self._graph = None
            self._assign_cache = AssignCache()
            self._class_memo = {}
            self._panel_memo = {}
            self._density = None
            self._centre_memo = {}
            self._region_memo = {}
        timings = self.timings_scratch if from_scratch else self.timings
        timings["body"].append((t_body - t_all) * 1e3)  # the body's free space (and flush)
        tick = _Ticker(timings, self.clock)
        cfg = self.config
        occ = self._occupancy()
        tick("bev")
        robot_xy = None if self.robot is None else (self.robot[0], self.robot[1])
        vg = self._voronoi(occ, robot_xy)
        tick("voronoi")
        rooms = self._segment(occ, vg)
        node_room = rooms.seg.labels
        tick("rooms")
        blocked = occ.grid == OCCUPIED
        graph_all = vg.csgraph()
        seen = self._seen(OBJECT_KINDS + ("door",))  # one pass over the instances seen
        objects = place_objects([s for s in seen if s[0].kind in OBJECT_KINDS], vg,
                                node_room, graph_all, occ, blocked, cfg.assign,
                                self._assign_cache)
        tick("assign")
        regions, node_region = room_regions(vg, rooms.seg, rooms.room_ids, cfg.regions,
                                            self._region_memo)
        objects = [place_in_room(o, node_room, rooms.room_ids, node_region) for o in objects]
        tick("regions")
        doors, unexplored_pos = observe_doors(
            [s for s in seen if s[0].kind == "door"], vg, node_room, rooms.room_ids, occ,
            blocked, self._rooms, cfg.door_radius, cfg.unexplored_offset, rooms.doorways)
        tick("doors")
        frontiers, frontier_ids, f_nodes = self._frontier_stage(occ, vg, robot_xy, node_room,
                                                                blocked)
        tick("frontiers")
        room_list = room_nodes(vg, rooms.seg, rooms.room_ids, objects, doors, unexplored_pos,
                               self.instances, self.classifier, self._class_memo, cfg)
        tick("categories")
        parts = GraphParts(seg=rooms.seg, room_ids=rooms.room_ids, regions=regions,
                           node_region=node_region, objects=objects, doors=doors,
                           frontiers=frontiers, frontier_ids=frontier_ids,
                           frontier_nodes=f_nodes, rooms=room_list)
        robot_nodes: tuple[int, ...] = ()
        if robot_xy is not None and len(vg.positions):
            robot_nodes = tuple(int(e) for e in entry_nodes(vg, robot_xy, occ, blocked,
                                                            cfg.entry_radius))
        distances = travel_distances(vg, node_distances(vg, graph_all, robot_xy, robot_nodes),
                                     parts)
        tick("distances")
        sg = assemble_graph(parts, robot_state(self.robot, robot_nodes, vg, parts),
                            self.instances, distances, stamp, self.examined)
        self.layers = MapLayers(
            occupancy=occ, voronoi=vg,
            node_rooms=tuple(rooms.room_ids[i] if i >= 0 else None for i in node_room.tolist()),
            segmentation=rooms.seg, door_cells=rooms.door_cells, door_density=rooms.density,
            doors=tuple(doors), frontiers=tuple(frontiers), frontier_ids=tuple(frontier_ids),
            robot_nodes=robot_nodes,
        )
        self._last = (key, sg)
        self.frames_since_refresh = 0
        tick("assemble")
        timings["refresh"].append((self.clock() - t_all) * 1e3)
        return sg

    # ----- stages -----------------------------------------------------------------------
    def _clear_footprint(self) -> None:
        """The robot's body is free-space evidence (module doc): drop the unlabelled voxels
        of the BEV height band within ``BODY_RADIUS`` of the trajectory points new since
        the last refresh."""
        if self._cleared >= len(self._body) and not self._views:
            return
        cfg = self.config.bev
        res = self.voxels.resolution
        lo, hist = self.voxels.level_histogram()
        level = floor_level(cfg, res, lo, hist)
        tol = floor_levels(cfg, res)
        top = int(round(cfg.band_top / res))
        if self._views:
            views, self._views = self._views, []
            self.seen_through_entries += self.voxels.clear_seen_through(
                views, level + tol + 1, level + top, self.config.free_space)
        if self._cleared >= len(self._body):
            return
        pts = np.asarray(self._body[self._cleared:], dtype=np.float64)
        self._cleared = len(self._body)
        self.cleared_entries += self.voxels.clear_unlabelled_around(
            pts, BODY_RADIUS, level + tol + 1, level + top)

    def columns_between(self, grid: OccupancyGrid, low: float, high: float) -> np.ndarray:
        """Bool mask over ``grid``'s cells: the voxel columns holding something from ``low``
        to ``high`` metres above the floor level of the last refresh (what a camera at
        ``low`` cannot see over); all False before a refresh made the occupancy."""
        mask = np.zeros(grid.shape, dtype=bool)
        if self._level is None:
            return mask
        res = self.voxels.resolution
        cols = columns_between(self.voxels.merged_keys(), self._level, res, low, high, True)
        if len(cols):
            r, c = grid.cell_of((cols[:, 0] + 0.5) * res, (cols[:, 1] + 0.5) * res)
            h, w = grid.shape
            ok = (r >= 0) & (r < h) & (c >= 0) & (c < w)
            mask[r[ok], c[ok]] = True
        return mask

    def _occupancy(self) -> OccupancyGrid:
        cfg = self.config.bev
        res = self.voxels.resolution
        lo, hist = self.voxels.level_histogram()
        level = floor_level(cfg, res, lo, hist)
        # the carved ground lives in its own grid, kept while the floor level stays: a
        # rebuild of the columns (a door opened) does not carve every frame again
        if self._carve is None or self._carve_level != level:
            self._carve, self._carve_level, self._carved = ColumnGrid(res, cfg), level, 0
        if self._carved < len(self._fans):
            self._carve.carve(np.concatenate(self._fans[self._carved:]), level)
            self._carved = len(self._fans)
        rebuild = self._columns is None or level != self._level
        removed = not rebuild and self.voxels.removals != self._removals
        if removed and not self._columns_after_removal(level):
            rebuild = True
        if rebuild:
            keys, _ = self.voxels.entries()
            self.voxels.drain_new_keys()
            self.voxels.drain_removed_keys()
            cg = ColumnGrid(res, cfg)
            cg.add(classify_keys(keys, level, res, cfg, presorted=True), self.trajectory)
            self._columns, self._level, self._removals = cg, level, self.voxels.removals
            self._door_voxels.reset(keys, self.voxels.label_ids(), self._door_ids())
        elif not removed:
            assert self._columns is not None  # not rebuilt: the columns exist
            new = self.voxels.drain_new_keys()
            self._columns.add(classify_keys(new, level, res, cfg), self.trajectory)
            if self._door_voxels.stale(self._door_ids()):  # a new instance table
                self._door_voxels.reset(self.voxels.entries()[0], self.voxels.label_ids(),
                                        self._door_ids())
            else:
                self._door_voxels.add(new, self.voxels.label_ids())
        assert self._columns is not None and self._carve is not None
        self._columns.merge(self._carve)
        return self._columns.occupancy(self.trajectory, level)

    def _columns_after_removal(self, level: int) -> bool:
        """Update the column grid for the keys new and removed since the last refresh by
        classifying again only the columns that lost voxels; False when only a rebuild
        gives the grid a rebuild would (its extent would shrink): rebuild then."""
        cg, carve = self._columns, self._carve
        assert cg is not None and carve is not None
        keys, _ = self.voxels.entries()
        new = self.voxels.drain_new_keys()
        gone = self.voxels.drain_removed_keys()
        cg.add(classify_keys(new, level, cg.resolution, cg.config), self.trajectory)
        if not reclassify_columns(cg, keys, np.unique(gone >> COLUMN_SHIFT), level):
            return False
        cg.merge(carve)
        if fresh_extent(cg, self.trajectory, carve) != cg.extent:
            return False
        self._removals = self.voxels.removals
        label_ids, doors = self.voxels.label_ids(), self._door_ids()
        if self._door_voxels.stale(doors) or _any_door(gone, label_ids, doors):
            self._door_voxels.reset(keys, label_ids, doors)
        else:  # no door lost voxels: the door keys are those kept plus the new ones
            self._door_voxels.add(new, label_ids)
        return True

    def _voronoi(self, occ: OccupancyGrid, robot_xy: tuple[float, float] | None
                 ) -> VoronoiGraph:
        """The Voronoi graph of the components the robot passed through; the ridge pixel
        graph is reused while the free cells are unchanged (it depends on nothing else)
        and otherwise computed from the previous one (only around the changed cells), the
        graph is reused while the ridge, its components and the grid's placement are."""
        cfg = self.config.voronoi
        free = occ.grid == FREE
        free.setflags(write=False)  # kept to recognise the same free cells next time
        place = repr((occ.origin, occ.grid.shape, occ.resolution))
        got = self._ridge
        if got is None or got.place != place or not np.array_equal(got.free, free):
            previous = None if got is None else got.ridge
            version = 0 if got is None else got.version + 1
            self._ridge = _Ridge(place, free, version,
                                 ridge_graph(occ, cfg, previous=previous))
        ridge = self._ridge
        assert ridge is not None
        track = np.asarray(self.trajectory, dtype=np.float64).reshape(-1, 2)
        key = (ridge.version, visited_components(occ, ridge.ridge, robot_xy, track))
        if self._graph is None or self._graph[0] != key:  # same ridge, same components
            self._graph = (key, voronoi_graph(occ, cfg, anchor=robot_xy, ridge=ridge.ridge,
                                              trajectory=track, components=key[1]))
        return self._graph[1]

    def _segment(self, occ: OccupancyGrid, vg: VoronoiGraph) -> _Rooms:
        """Rooms: the door evidence cuts the graph; ids stay stable by overlap."""
        cfg = self.config.rooms
        won = self._door_voxels.won(open_doors(self.instances), self.voxels.winning_labels,
                                    self.voxels.frame_counts, DOOR_MIN_FRAMES)
        reach = DOOR_REACH / self.voxels.resolution
        won = {iid: near_median(ijk, reach) for iid, ijk in won.items()}
        overhead = self.columns_between(occ, *LINTEL_BAND)
        found = doorways(occ, won, self._panel_memo, overhead)
        cells, centres = found.cells | lintel_doorways(occ, overhead, found.cells), found.centres
        cells.setflags(write=False)  # kept to recognise the same cells next time
        got = self._density
        if got is None or got[0] != occ.resolution or not np.array_equal(got[1], cells):
            # not the same cells: blur them (the same cells: the same blur)
            got = (occ.resolution, cells, door_density(cells, occ.resolution,
                                                       cfg.door_bandwidth))
            got[2].setflags(write=False)
            self._density = got
        density = got[2]
        seg = segment_rooms(vg, density, cfg, self._centre_memo, occ, found.unsure | cells,
                            self._body, found.leaves, cells)
        numbers = self._rooms.assign([vg.positions[r] for r in seg.rooms], cfg.match_radius)
        return _Rooms(cells, density, seg, [f"room:{n}" for n in numbers], centres)

    def _frontier_stage(self, occ: OccupancyGrid, vg: VoronoiGraph,
                        robot_xy: tuple[float, float] | None, node_room: np.ndarray,
                        blocked: np.ndarray) -> tuple[list[Frontier], list[str], list[int]]:
        """Frontiers, their stable ids and their nearest visible room nodes."""
        cfg = self.config
        parts = None if self._columns is None else self._columns.unknown_parts_of(occ)
        frontiers = find_frontiers(occ, robot_xy, cfg.frontiers, parts)
        fids = self._frontiers.assign([f.medoid for f in frontiers], cfg.frontier_match)
        nodes = nearest_visible(vg, np.flatnonzero(node_room >= 0),
                                [f.medoid for f in frontiers], occ, blocked, cfg.entry_radius)
        return frontiers, [f"frontier:{i}" for i in fids], nodes

    def _door_ids(self) -> list[int]:
        return [iid for iid, v in self.instances.items() if v.kind == "door"]

    def _seen(self, kinds: tuple[str, ...]) -> list[SeenInstance]:
        return seen_instances(self.voxels, self.instances, kinds, self.config.voxels.min_points,
                              OBJECT_EVIDENCE)

    def stage_summary(self, from_scratch: bool = False) -> dict[str, tuple[float, float, int]]:
        """Per stage: (median ms, max ms, count) of the incremental refreshes (or of the
        from-scratch ones)."""
        t = self.timings_scratch if from_scratch else self.timings
        return {k: (float(np.median(v)), float(np.max(v)), len(v))
                for k, v in sorted(t.items()) if v}


def _any_door(keys: np.ndarray, label_ids: np.ndarray, doors: list[int]) -> bool:
    """True when a (voxel, label) key is labelled with one of the ``doors`` (labels past
    ``label_ids``: no instance)."""
    lab = keys & LABEL_MASK
    lab = lab[lab < len(label_ids)]
    return bool(np.isin(label_ids[lab], np.asarray(doors, dtype=np.int64)).any())


class _Ticker:
    def __init__(self, timings: dict[str, list[float]], clock: Callable[[], float]) -> None:
        self.timings = timings
        self.clock = clock
        self.t = clock()

    def __call__(self, stage: str) -> None:
        now = self.clock()
        self.timings[stage].append((now - self.t) * 1e3)
        self.t = now
