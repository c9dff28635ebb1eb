"""A replayed scene graph scored against the house it was recorded in.

A simulated log carries its house spec (attachment ``house.json``) and every instance of
its ``sgtool.Instances`` table names the spec element it stands for (``spec_id``), so the
ground truth of every figure of :mod:`sgtool.scenegraph.quality` is in the log: room
polygons and categories, and the room of every piece of furniture and every small object.
Figures are given ``strict`` (against the polygons as they are) and ``merged`` (rooms joined
by a doorless open-plan passage count as one: door-based segmentation cannot split them).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import asdict
from functools import partial

from sgtool.house.spec import HouseSpec
from sgtool.scenegraph.builder import MapLayers
from sgtool.scenegraph.graph import SceneGraph
from sgtool.scenegraph.instances import InstanceInfo
from sgtool.scenegraph.quality import Quality, evaluate


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


def score(spec: HouseSpec, instances: Mapping[int, InstanceInfo], layers: MapLayers,
          graph: SceneGraph, visited: Sequence[tuple[float, float]] = ()
          ) -> dict[str, Quality]:
    """``{"strict": Quality, "merged": Quality}`` of ``graph`` (module doc); ``visited``:
    the camera's (x, y) positions (the builder's ``trajectory``), whose rooms count as
    seen."""
    rooms_by_spec = ({f.id: f.room for f in spec.furniture}
                     | {o.id: o.room for o in spec.objects})
    object_gt: dict[str, str] = {}
    for o in graph.objects:
        info = instances.get(o.instance)
        if info is not None and info.spec_id in rooms_by_spec:
            object_gt[o.id] = rooms_by_spec[info.spec_id]
    of_graph = partial(
        evaluate,
        node_xy=layers.voronoi.positions, node_rooms=layers.node_rooms,
        room_categories={r.id: r.category for r in graph.rooms if r.explored},
        object_rooms={o.id: o.room for o in graph.objects}, object_gt=object_gt,
        polygons={r.id: r.polygon for r in spec.rooms},
        gt_categories={r.id: r.category for r in spec.rooms}, visited=visited,
    )
    return {"strict": of_graph(), "merged": of_graph(merge=passage_groups(spec))}


def score_lines(scores: Mapping[str, Quality], graph_objects: int | None = None) -> list[str]:
    """One line per scoring; objects none of which could be scored (no instance of the
    graph's objects names an element of the spec: ``spec_id`` in the instance table) are
    said so, not scored as 0 %, as is a graph without objects (``graph_objects``: how many
    the graph holds, 0 says so; None: not known)."""
    out = []
    for name, v in scores.items():
        objects = (f"objects in the right room {v.object_accuracy:.1%} of {v.objects}"
                   if v.objects else "no object in the graph to score" if graph_objects == 0
                   else "objects not scored (no object's instance names a spec element: "
                   "spec_id in the instance table)")
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
            d["object_accuracy"] = None
        if not v.rooms:
            d["category_accuracy"] = None
        return d

    return {k: figures(v) for k, v in scores.items()}
