"""What a pinned refresh keeps of its map layers: the Voronoi graph's size and the rooms'
node counts and areas (small; the scene graph itself is pinned as canonical JSON).

A room's area is the area of its outline as ``/map/rooms`` draws it (the convex hull of its
Voronoi nodes grown by :data:`~sgtool.scenegraph.derived_layers.ROOM_MARGIN`), in m², so
the same figure comes from a replay (:func:`layer_summary`) and from a derived log's
``/map/voronoi`` and ``/map/rooms`` messages (:func:`summary_of_messages`). Areas are
canonical floats (:mod:`sgtool.canonical`).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from sgtool.canonical import canonical_float
from sgtool.house.geometry import signed_area
from sgtool.scenegraph.builder import MapLayers
from sgtool.scenegraph.derived_layers import ROOM_MARGIN, room_hull_of


@dataclass(frozen=True)
class LayerSummary:
    """Voronoi graph size (nodes, edges) and the area in m² of every room (by id)."""

    voronoi_nodes: int = 0
    voronoi_edges: int = 0
    rooms: Mapping[str, float] = field(default_factory=dict)

    def to_dict(self) -> dict[str, Any]:
        return {"voronoi": [self.voronoi_nodes, self.voronoi_edges],
                "rooms": dict(sorted(self.rooms.items()))}

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> LayerSummary:
        n, e = d["voronoi"]
        return cls(int(n), int(e), {str(k): float(v) for k, v in d["rooms"].items()})

    def area(self, room: str) -> float | None:
        return self.rooms.get(room)


def outline_area(points: np.ndarray) -> float:
    """Area in m² of the outline of ``points`` ((n, 2) x, y) as ``/map/rooms`` draws it."""
    pts = np.ascontiguousarray(points, dtype=np.float64).reshape(-1, 2)
    hull = room_hull_of(pts.tobytes(), ROOM_MARGIN)
    return canonical_float(abs(signed_area([(float(x), float(y)) for x, y in hull.tolist()]))
                           if len(hull) >= 3 else 0.0)


def layer_summary(layers: MapLayers | None) -> LayerSummary | None:
    """The summary of one refresh's map layers (None without layers)."""
    if layers is None:
        return None
    vg = layers.voronoi
    by_room: dict[str, list[int]] = {}
    for n, r in enumerate(layers.node_rooms):
        if r is not None:
            by_room.setdefault(r, []).append(n)
    xy = np.asarray(vg.positions, dtype=np.float64).reshape(-1, 2)
    rooms = {r: outline_area(xy[np.asarray(nodes)]) for r, nodes in sorted(by_room.items())}
    return LayerSummary(len(xy), int(np.asarray(vg.edges).reshape(-1, 2).shape[0]), rooms)


def summary_of_messages(voronoi: Any | None, rooms: Any | None) -> LayerSummary | None:
    """The summary from a derived log's ``/map/voronoi`` and ``/map/rooms`` SceneUpdates
    (decoded protobuf messages; None when the log has neither at that refresh)."""
    if voronoi is None and rooms is None:
        return None
    nodes = edges = 0
    for ent in getattr(voronoi, "entities", ()):
        nodes += len(ent.spheres)
        edges += sum(len(line.points) // 2 for line in ent.lines)
    out: dict[str, float] = {}
    for ent in getattr(rooms, "entities", ()):
        loop: Sequence[tuple[float, float]] = [
            (p.x, p.y) for line in ent.lines for p in line.points]
        out[ent.id] = canonical_float(abs(signed_area(loop))) if len(loop) >= 3 else 0.0
    return LayerSummary(nodes, edges, out)
