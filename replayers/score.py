"""A replayed scene graph scored against the house it was recorded in.

A simulated log carries its house spec (attachment ``house.json``) and every instance of
its ``sgtool.Instances`` table names the spec element it stands for (``spec_id``), so the
ground truth of every figure of :mod:`sgtool.scenegraph.quality` is in the log: room
polygons and categories, and the room of every piece of furniture and every small object.
Figures are given ``strict`` (against the polygons as they are) and ``merged`` (rooms joined
by a doorless open-plan passage count as one: door-based segmentation need not split them;
a group the graph does split, each of its predicted rooms mostly in another of the group's
rooms, is scored as its rooms, so either form is right).
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Mapping, Sequence
from dataclasses import asdict, dataclass, replace
from functools import partial
from typing import Any

import numpy as np

from sgtool.house.spec import HouseSpec
from sgtool.log import schemas as S
from sgtool.log.codec import decode_transform
from sgtool.log.poses import planar_fit
from sgtool.scenegraph.builder import MapLayers
from sgtool.scenegraph.graph import SceneGraph
from sgtool.scenegraph.instances import InstanceInfo
from sgtool.scenegraph.quality import Quality, evaluate, gt_rooms_of


def passage_groups(spec: HouseSpec) -> dict[str, str]:
    """Room id -> representative (the smallest id) of its group of rooms joined by
    doorless passages; rooms without passages are absent."""
    parent: dict[str, str] = {}

    def find(r: str) -> str:
        while parent.get(r, r) != r:
            r = parent[r]
        return r

    for p in spec.passages:
        a, b = (find(r) for r in p.rooms)
        if a != b:
            keep, drop = min(a, b), max(a, b)
            parent[drop] = keep
            parent.setdefault(keep, keep)
    return {r: find(r) for r in sorted(parent)}


@dataclass(frozen=True)
class TruthAlignment:
    """How a drifted map is carried onto the house before it is scored: ``transform`` (4x4,
    the map's frame -> the house's) is the rotation and shift that best carries the logged
    base poses onto the true ones (:func:`~sgtool.log.poses.planar_fit`) over ``frames``
    frames; ``rms_m`` is what remains of the position error after it (the map's warp,
    which no rigid shift removes)."""

    transform: np.ndarray
    frames: int
    rms_m: float

    def line(self) -> str:
        return (f"map aligned to the true poses before scoring (pose drift): a rigid fit "
                f"over {self.frames} frames, {self.rms_m:.3f} m RMS left")


def truth_alignment(reader: Any, until_ns: int | None = None) -> TruthAlignment | None:
    """The :class:`TruthAlignment` of a log whose ``/tf`` holds the true base pose
    (``world -> base_truth``, written by a simulated recording with pose drift) beside the
    logged one (``world -> base``) at the same times; None for a log without it.
    ``until_ns``: only the poses up to this log time (the last frame a replay stopped at
    with ``max_frames``: the map holds only those)."""
    base: dict[int, np.ndarray] = {}
    truth: dict[int, np.ndarray] = {}
    if not reader.has(S.TF):
        return None
    for m in reader.messages([S.TF]):
        if m.message.parent_frame_id != S.WORLD_FRAME:
            continue
        child = m.message.child_frame_id
        if child in (S.BASE_FRAME, S.TRUE_BASE_FRAME):
            (base if child == S.BASE_FRAME else truth)[m.log_time_ns] = \
                decode_transform(m.message)
    times = sorted(t for t in set(base) & set(truth) if until_ns is None or t <= until_ns)
    if not times:
        return None
    src = [base[t] for t in times]
    dst = [truth[t] for t in times]
    fit = planar_fit(src, dst)
    moved = np.array([(fit @ p)[:2, 3] for p in src])
    rms = float(np.sqrt(np.mean(np.sum((moved - np.array([p[:2, 3] for p in dst])) ** 2,
                                       axis=1))))
    return TruthAlignment(fit, len(times), rms)


def _carried(xy: Any, transform: np.ndarray | None) -> Any:
    """Points (x, y) in the map's frame carried into the house's by ``transform``."""
    if transform is None:
        return xy
    p = np.asarray(xy, dtype=float).reshape(-1, 2)
    return p @ transform[:2, :2].T + transform[:2, 3]


def score(spec: HouseSpec, instances: Mapping[int, InstanceInfo], layers: MapLayers,
          graph: SceneGraph, visited: Sequence[tuple[float, float]] = (),
          align: TruthAlignment | None = None) -> dict[str, Quality]:
    """``{"strict": Quality, "merged": Quality}`` of ``graph`` (module doc); ``visited``:
    the camera's (x, y) positions (the builder's ``trajectory``), whose rooms count as
    seen. With ``align`` (:func:`truth_alignment`) the map's positions are carried onto
    the house first: a drifted map is scored for its rooms, not for its shift."""
    transform = None if align is None else align.transform
    node_xy = _carried(layers.voronoi.positions, transform)
    visited = _carried(visited, transform) if len(visited) else visited
    rooms_by_spec = ({f.id: f.room for f in spec.furniture}
                     | {o.id: o.room for o in spec.objects})
    object_gt: dict[str, str] = {}
    for o in graph.objects:
        info = instances.get(o.instance)
        if info is not None and info.spec_id in rooms_by_spec:
            object_gt[o.id] = rooms_by_spec[info.spec_id]
    of_graph = partial(
        evaluate,
        node_xy=node_xy, node_rooms=layers.node_rooms,
        room_categories={r.id: r.category for r in graph.rooms if r.explored},
        object_rooms={o.id: o.room for o in graph.objects}, object_gt=object_gt,
        polygons={r.id: r.polygon for r in spec.rooms},
        gt_categories={r.id: r.category for r in spec.rooms}, visited=visited,
    )
    merge = split_groups_kept_apart(passage_groups(spec), node_xy,
                                    layers.node_rooms, {r.id: r.polygon for r in spec.rooms})
    seen = {info.spec_id for o in graph.objects
            if (info := instances.get(o.instance)) is not None and info.spec_id in rooms_by_spec}
    cover = {"house_objects": len(rooms_by_spec), "objects_seen": len(seen)}
    return {"strict": replace(of_graph(), **cover),
            "merged": replace(of_graph(merge=merge), **cover)}


def split_groups_kept_apart(merge: Mapping[str, str], node_xy: Any,
                            node_rooms: Sequence[str | None],
                            polygons: Mapping[str, Any]) -> dict[str, str]:
    """``merge`` (room -> its passage group's representative) as the graph splits each
    group: rooms of a group whose Voronoi nodes lie mostly in one predicted room stay
    merged, rooms the graph gives predicted rooms of their own are scored apart; a room
    without nodes stays with its group's representative, as before."""
    gt = gt_rooms_of(np.asarray(node_xy, dtype=float).reshape(-1, 2), polygons)
    of_gt: dict[str, Counter[str]] = {}  # ground-truth room -> its nodes' predicted rooms
    for p, g in zip(node_rooms, gt, strict=True):
        if p is not None and g is not None and g in merge:
            of_gt.setdefault(g, Counter())[p] += 1
    # the key a room is grouped by: its group and where the graph put most of it
    key = {r: (merge[r], min(of_gt[r].items(), key=lambda kv: (-kv[1], kv[0]))[0]
               if r in of_gt else None) for r in merge}
    out: dict[str, str] = {}
    for group in sorted(set(merge.values())):
        members = sorted(r for r in merge if merge[r] == group)
        placed = sorted({p for r in members if (p := key[r][1]) is not None})
        for p in placed:  # the members the graph put in one predicted room: one room
            same = [r for r in members if key[r][1] == p]
            if len(placed) == 1:  # not split: the whole group, rooms without nodes too
                same = members
            if len(same) > 1:
                out.update({r: min(same) for r in same})
        if not placed and len(members) > 1:
            out.update({r: group for r in members})
    return out


def score_lines(scores: Mapping[str, Quality], graph_objects: int | None = None) -> list[str]:
    """One line per scoring; objects none of which could be scored (no instance of the
    graph's objects names an element of the spec: ``spec_id`` in the instance table) are
    said so, not scored as 0 %, as is a graph without objects (``graph_objects``: how many
    the graph holds, 0 says so; None: not known)."""
    out = []
    for name, v in scores.items():
        objects = (f"objects in the right room {v.object_accuracy:.1%} of {v.objects} "
                   f"(ARI of their rooms {v.object_ari:.3f})"
                   if v.objects else "no object in the graph to score" if graph_objects == 0
                   else "objects not scored (no object's instance names a spec element: "
                   "spec_id in the instance table)")
        if v.house_objects and v.objects:
            objects += f" ({v.objects_seen} of the house's {v.house_objects} pieces seen)"
        out.append(
            f"quality ({name}): rooms {v.rooms} vs {v.gt_rooms_seen} seen of {v.gt_rooms} "
            f"(error {v.room_count_error:+d}); Voronoi nodes in the right room: purity "
            f"{v.purity:.3f}, ARI {v.ari:.3f} (nodes in {v.gt_rooms_with_nodes} of the "
            f"{v.gt_rooms_seen} seen rooms); {objects}; room categories right "
            f"{v.category_accuracy:.1%} of {v.rooms} ({v.categorised} categorised)")
    return out


def score_dict(scores: Mapping[str, Quality]) -> dict[str, dict[str, float | int | None]]:
    """The figures of each scoring; an accuracy over nothing (no object scored, no
    explored room) is None, not 0."""
    def figures(v: Quality) -> dict[str, float | int | None]:
        d: dict[str, float | int | None] = dict(asdict(v))
        if not v.objects:
            d["object_accuracy"] = d["object_ari"] = None
        if not v.rooms:
            d["category_accuracy"] = None
        return d

    return {k: figures(v) for k, v in scores.items()}
