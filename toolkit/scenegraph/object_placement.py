"""Objects of the scene graph: the seen instances, each first-level one at a Voronoi node
(:mod:`sgtool.scenegraph.assign`, MoMa-LLM's weighted travel distance from its closest
viewpoint), nested ones (``inside``/``ontop`` a seen parent) where their first-level
ancestor is, with the parent as node parent."""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np
from scipy.sparse import csr_matrix

from sgtool.mapping.grid import OccupancyGrid
from sgtool.mapping.voronoi import VoronoiGraph
from sgtool.mapping.vote_store import sorted_unique
from sgtool.mapping.voxels import LABEL_MASK, VOXEL_SHIFT, VoxelMap
from sgtool.scenegraph.assign import AssignCache, AssignConfig, assign_objects
from sgtool.scenegraph.instances import InstanceInfo
from sgtool.scenegraph.object_evidence import EvidenceRule, WonVoxels, is_object, won_voxels

OBJECT_KINDS = ("object", "furniture")

# (info, voxel centroid, closest viewpoint) of an instance seen well enough
SeenInstance = tuple[InstanceInfo, tuple[float, float, float], tuple[float, float] | None]


@dataclass(frozen=True)
class PlacedObject:
    instance: int
    position: tuple[float, float, float]
    top: int  # first-level ancestor (itself when first-level)
    node: int  # Voronoi node of the first-level ancestor, -1 when unassigned
    parent_instance: int | None  # the seen parent of a nested object
    room: str | None = None
    parent: str = ""


def seen_instances(voxels: VoxelMap, instances: Mapping[int, InstanceInfo],
                   kinds: tuple[str, ...], min_points: int,
                   evidence: EvidenceRule | None = None) -> list[SeenInstance]:
    """(info, voxel centroid, closest viewpoint) of the instances of ``kinds`` seen with at
    least ``min_points`` points in one frame, in id order. With an ``evidence`` rule, an
    instance of :data:`OBJECT_KINDS` must also have the evidence it asks for and stands at
    the centroid of the voxels it wins (:mod:`sgtool.scenegraph.object_evidence`)."""
    out: list[SeenInstance] = []
    frames: dict[int, int] = {}
    for iid in voxels.observed_instances():
        info = instances.get(iid)
        if info is None or info.kind not in kinds:
            continue
        obs = voxels.observation(iid)
        if obs is None or obs.max_points < min_points or obs.centroid is None:
            continue
        out.append((info, obs.centroid, obs.viewpoint))
        frames[iid] = obs.frames
    if evidence is None:
        return out
    weigh = [info.id for info, _, _ in out if info.kind in OBJECT_KINDS]
    labels = voxels.labels_of(np.asarray(weigh, dtype=np.int64))
    won = _won_by(voxels, labels)
    kept: list[SeenInstance] = []
    label_of = dict(zip(weigh, labels.tolist(), strict=True))
    for info, c, vp in out:
        if info.kind in OBJECT_KINDS:
            lab = label_of[info.id]
            at = won.centroid(lab, voxels.resolution)
            if at is None or not is_object(frames[info.id], int(won.count[lab]), evidence):
                continue
            c = at
        kept.append((info, c, vp))
    return kept


def _won_by(voxels: VoxelMap, labels: np.ndarray) -> WonVoxels:
    """The voxels each of ``labels`` wins, looked up among the voxels they got votes in."""
    n = int(labels.max()) + 1 if len(labels) else 0
    keys, _ = voxels.entries()
    if n == 0 or len(keys) == 0:
        return won_voxels(np.zeros(0, np.int64), np.zeros(0, np.int64), n)
    mine = np.zeros(LABEL_MASK + 1, dtype=bool)
    mine[labels] = True
    vk = sorted_unique(keys[mine[keys & LABEL_MASK]] >> VOXEL_SHIFT)
    return won_voxels(vk, voxels.winning_labels(vk), n)


def place_objects(seen: list[SeenInstance], vg: VoronoiGraph, node_room: np.ndarray,
                  graph: csr_matrix, occ: OccupancyGrid, blocked: np.ndarray,
                  config: AssignConfig, cache: AssignCache | None = None
                  ) -> list[PlacedObject]:
    """Every seen object with its first-level ancestor and that ancestor's node
    (``cache``: see :class:`~sgtool.scenegraph.assign.AssignCache`)."""
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
        asg = assign_objects(vg.positions, node_room, graph, pts, vps, occ, blocked, config,
                             cache)
        nodes = asg.node
    else:
        nodes = np.full(len(tops), -1, dtype=np.int64)
    node_of_top = {iid: int(nodes[top_row[iid]]) for iid in tops}
    out = []
    for iid in sorted(by_id):
        info, c, _vp = by_id[iid]
        top = top_of(iid)
        parent_id = info.parent if (top != iid and info.parent is not None) else None
        out.append(PlacedObject(iid, (float(c[0]), float(c[1]), float(c[2])), top,
                                node_of_top[top], parent_id))
    return out


def place_in_room(o: PlacedObject, node_room: np.ndarray, room_ids: list[str],
                  node_region: dict[int, str]) -> PlacedObject:
    """Room and parent node id of an object from its first-level ancestor's node."""
    if o.node < 0 or node_room[o.node] < 0:
        return o
    room = room_ids[int(node_room[o.node])]
    parent = (f"obj:{o.parent_instance}" if o.parent_instance is not None
              else node_region[o.node])
    return dataclasses.replace(o, room=room, parent=parent)
