"""Quality of a built scene graph against ground-truth room polygons.

The figures of the issue: room count error, the share of Voronoi nodes whose room agrees
with the ground-truth polygon (purity, and the adjusted Rand index of the two node
partitions), object-to-room accuracy, room category accuracy (MoMa-LLM reports 27.6% in
simulation, paper sec. IV, under-segmentation of open-plan layouts being the main cause).

Predicted rooms are matched to ground truth through their nodes: a predicted room stands
for the ground-truth room holding most of its nodes. Every figure is given twice: against
the polygons as they are (``strict``), and with rooms joined by a doorless passage merged
into one (``merged``): door-based segmentation cannot split an open-plan kitchen from its
living room, so ``strict`` shows the price of that and ``merged`` the rest.

Pure functions over plain inputs (polygons as point lists), no dependency on the house
spec module.
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from sgtool.semantics.text import category_text

Polygon = Sequence[tuple[float, float]]


def points_in_polygon(x: np.ndarray, y: np.ndarray, poly: Polygon) -> np.ndarray:
    """Even-odd rule, vectorised over points."""
    inside = np.zeros(len(x), dtype=bool)
    n = len(poly)
    for i in range(n):
        x0, y0 = poly[i]
        x1, y1 = poly[(i + 1) % n]
        cross = (y0 > y) != (y1 > y)
        with np.errstate(divide="ignore", invalid="ignore"):
            xi = x0 + (y - y0) * (x1 - x0) / (y1 - y0)
        inside ^= cross & (x < xi)
    return inside


def gt_rooms_of(points: np.ndarray, polygons: Mapping[str, Polygon]) -> list[str | None]:
    """Ground-truth room of each point (None outside every polygon; first match wins in
    sorted id order)."""
    out: list[str | None] = [None] * len(points)
    if len(points) == 0:
        return out
    x, y = points[:, 0], points[:, 1]
    for rid in sorted(polygons):
        hit = points_in_polygon(x, y, polygons[rid])
        for i in np.flatnonzero(hit):
            if out[i] is None:
                out[i] = rid
    return out


def adjusted_rand_index(a: Sequence[object], b: Sequence[object]) -> float:
    """Adjusted Rand index of two labelings of the same items (Hubert & Arabie 1985)."""
    n = len(a)
    if n < 2:
        return 1.0
    pairs = Counter(zip(a, b, strict=True))
    ca, cb = Counter(a), Counter(b)

    def c2(k: int) -> float:
        return k * (k - 1) / 2.0

    index = sum(c2(v) for v in pairs.values())
    sa, sb = sum(c2(v) for v in ca.values()), sum(c2(v) for v in cb.values())
    expected = sa * sb / c2(n)
    top = (sa + sb) / 2.0
    if top == expected:
        return 1.0
    return float((index - expected) / (top - expected))


@dataclass(frozen=True)
class Quality:
    gt_rooms: int  # ground-truth rooms (after merging, for the merged variant)
    gt_rooms_seen: int  # ground-truth rooms holding a Voronoi node or a camera position
    rooms: int  # predicted explored rooms
    room_count_error: int  # rooms - gt_rooms_seen
    purity: float  # share of nodes in the majority ground-truth room of their room
    ari: float  # adjusted Rand index of node partitions (nodes in some room and polygon)
    objects: int
    object_accuracy: float  # objects whose room stands for their ground-truth room
    categorised: int  # predicted rooms with a category other than "unknown"
    category_accuracy: float  # predicted rooms whose category is their gt room's category
    # seen ground-truth rooms holding a Voronoi node that some predicted room holds: purity
    # and ARI say how those nodes are split, this how much of the house they cover
    gt_rooms_with_nodes: int = 0
    # pieces of the house (furniture and small objects) and how many of them the graph
    # holds: a map that never saw half the house scores its objects over what it saw
    house_objects: int = 0
    objects_seen: int = 0
    # adjusted Rand index of the scored objects' predicted rooms against their true rooms:
    # which objects share a room, no position asked, so a map moved by pose drift keeps it
    object_ari: float = 0.0


def evaluate(node_xy: np.ndarray, node_rooms: Sequence[str | None],
             room_categories: Mapping[str, str], object_rooms: Mapping[str, str],
             object_gt: Mapping[str, str], polygons: Mapping[str, Polygon],
             gt_categories: Mapping[str, str],
             merge: Mapping[str, str] | None = None,
             visited: Sequence[tuple[float, float]] = ()) -> Quality:
    """Scores of one graph (module doc). ``node_xy``/``node_rooms``: Voronoi node positions
    and predicted room ids (None: no room); ``room_categories``: predicted explored room ->
    category; ``object_rooms``/``object_gt``: object id -> predicted / ground-truth room;
    ``merge``: ground-truth room -> representative (doorless groups), identity if None;
    ``visited``: the camera's (x, y) positions. A room counts as seen when it holds a
    Voronoi node or the camera stood in it, so a map that lost rooms the robot was in shows
    a room count error, not a perfect score over what is left of it."""
    rep = dict(merge or {})

    def m(r: str | None) -> str | None:
        return None if r is None else rep.get(r, r)

    gt_nodes = [m(r) for r in gt_rooms_of(np.asarray(node_xy).reshape(-1, 2), polygons)]
    pairs = [(p, g) for p, g in zip(node_rooms, gt_nodes, strict=True)
             if p is not None and g is not None]
    majority: dict[str, str] = {}
    by_room: dict[str, Counter[str]] = {}
    for p, g in pairs:
        by_room.setdefault(p, Counter())[g] += 1
    for p, cnt in by_room.items():
        majority[p] = sorted(cnt.items(), key=lambda kv: (-kv[1], kv[0]))[0][0]
    purity = (sum(cnt[majority[p]] for p, cnt in by_room.items()) / len(pairs)) if pairs else 0.0
    ari = adjusted_rand_index([p for p, _ in pairs], [g for _, g in pairs]) if pairs else 0.0
    gt_all = {m(r) for r in polygons}
    stood = gt_rooms_of(np.asarray(visited, dtype=float).reshape(-1, 2), polygons)
    seen = {g for _, g in pairs} | {r for r in map(m, stood) if r is not None}
    rooms = sorted(room_categories)
    scored = [o for o in sorted(object_rooms) if o in object_gt]
    obj_ok = [majority.get(object_rooms[o]) == m(object_gt[o]) for o in scored]
    obj_ari = adjusted_rand_index([object_rooms[o] for o in scored],
                                  [m(object_gt[o]) for o in scored]) if scored else 0.0
    gt_cat: dict[str | None, set[str]] = {}
    for r, c in gt_categories.items():  # "Living Room" and "living_room" read the same
        gt_cat.setdefault(m(r), set()).add(category_text(c))
    # a merged open-plan room may be called by any of its parts' categories
    cat_ok = [category_text(room_categories[r]) in gt_cat.get(majority.get(r), set())
              for r in rooms]
    return Quality(
        gt_rooms=len(gt_all), gt_rooms_seen=len(seen), rooms=len(rooms),
        room_count_error=len(rooms) - len(seen), purity=float(purity), ari=float(ari),
        objects=len(obj_ok), object_accuracy=float(np.mean(obj_ok)) if obj_ok else 0.0,
        categorised=sum(room_categories[r] != "unknown" for r in rooms),
        category_accuracy=float(np.mean(cat_ok)) if cat_ok else 0.0,
        gt_rooms_with_nodes=len({g for _, g in pairs}), object_ari=float(obj_ari),
    )
