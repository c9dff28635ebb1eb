"""The settings of the scene-graph builder, one frozen record of every stage's settings."""

from __future__ import annotations

from dataclasses import dataclass

from sgtool.mapping.bev import BevConfig
from sgtool.mapping.free_space import FreeSpaceConfig
from sgtool.mapping.voronoi import VoronoiConfig
from sgtool.mapping.voxels import VoxelConfig
from sgtool.scenegraph.assign import AssignConfig
from sgtool.scenegraph.frontiers import FrontierConfig
from sgtool.scenegraph.regions import RegionConfig
from sgtool.scenegraph.room_segmentation import RoomConfig


@dataclass(frozen=True)
class BuilderConfig:
    voxels: VoxelConfig = VoxelConfig()
    bev: BevConfig = BevConfig()
    free_space: FreeSpaceConfig = FreeSpaceConfig()  # depth rays clear weak voxels
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
    # a narrow room joining this many rooms (0: never) has its corridor score weighed
    # corridor_odds times: such rooms are mostly corridors, whatever a hall holds
    corridor_hub: int = 4
    corridor_odds: float = 10.0
    # a container or supporter is examined once close frames saw into (onto) enough of it
    # (sgtool.scenegraph.examined.look_into); False: from any close view, the older rule
    look_inside: bool = True
