"""The room layer of the scene graph: regions within each room, and the room nodes with
their neighbours and categories.

Room categories come from the contained furniture (all objects when a room has none) with
the configured :class:`~sgtool.scenegraph.categories.RoomClassifier`; a long, narrow room
(:func:`corridor_like`) with no object at all is a corridor (``BuilderConfig.corridor``),
any other empty room "unknown", and a long, narrow one joining ``corridor_hub`` rooms has
its corridor score weighed ``corridor_odds`` times. Rooms seen only through a closed door
are unexplored room nodes.
"""

from __future__ import annotations

import hashlib
import math
from collections import defaultdict
from collections.abc import Mapping
from typing import Any

import numpy as np
from scipy.spatial.distance import pdist

from sgtool.errors import SgtoolError, returned_text
from sgtool.mapping.voronoi import VoronoiGraph
from sgtool.scenegraph.builder_config import BuilderConfig
from sgtool.scenegraph.categories import RoomClassifier
from sgtool.scenegraph.door_evidence import DoorObservation
from sgtool.scenegraph.graph import RoomNode
from sgtool.scenegraph.instances import InstanceInfo
from sgtool.scenegraph.object_placement import PlacedObject
from sgtool.scenegraph.regions import RegionConfig, cluster_room
from sgtool.scenegraph.regions import Regions as RoomRegions
from sgtool.scenegraph.room_segmentation import RoomSegmentation, room_neighbours

# region id -> (room id, its Voronoi node, its position)
Regions = dict[str, tuple[str, int, tuple[float, float]]]


def room_regions(vg: VoronoiGraph, seg: RoomSegmentation, room_ids: list[str],
                 config: RegionConfig, memo: dict[bytes, RoomRegions] | None = None
                 ) -> tuple[Regions, dict[int, str]]:
    """The regions of every room, and the region id of every node of a room. ``memo``
    keeps each room's clustering across calls, keyed by its inputs (node positions, edge
    length, centre, config): an unchanged room clusters the same."""
    regions: Regions = {}
    node_region: dict[int, str] = {}
    lengths = room_edge_lengths(vg, seg)
    for i, nodes in enumerate(seg.rooms):
        rid = room_ids[i]
        num = rid.split(":", 1)[1]
        length = float(lengths[i].sum()) if len(vg.edges) else 0.0
        centre = int(np.searchsorted(nodes, seg.centres[i]))
        reg = _clustered(vg.positions[nodes], length, centre, config, memo)
        for k, c in enumerate(reg.centres.tolist(), start=1):
            node = int(nodes[c])
            reg_id = f"region:{num}.{k}"
            regions[reg_id] = (rid, node, (float(vg.positions[node, 0]),
                                           float(vg.positions[node, 1])))
        names = [f"region:{num}.{k}" for k in range(1, int(reg.labels.max(initial=-1)) + 2)]
        node_region.update(zip(nodes.tolist(), [names[k] for k in reg.labels.tolist()],
                               strict=True))
    return regions, node_region


def _clustered(positions: np.ndarray, length: float, centre: int, config: RegionConfig,
               memo: dict[bytes, RoomRegions] | None) -> RoomRegions:
    if memo is None:
        return cluster_room(positions, length, centre, config)
    h = hashlib.blake2b(digest_size=16)
    h.update(repr((positions.shape, positions.dtype.str, length, centre, config)).encode())
    h.update(np.ascontiguousarray(positions).tobytes())
    key = h.digest()
    got = memo.get(key)
    if got is None:
        got = cluster_room(positions, length, centre, config)
        if len(memo) > 1024:
            memo.clear()
        memo[key] = got
    return got


def room_edge_lengths(vg: VoronoiGraph, seg: RoomSegmentation) -> list[np.ndarray]:
    """Per room, the lengths of the Voronoi edges with both ends in it, in edge order (one
    pass over the edges, not one per room)."""
    if not len(vg.edges):
        return [np.zeros(0) for _ in seg.rooms]
    lab = seg.labels[vg.edges]
    inside = np.flatnonzero((lab[:, 0] == lab[:, 1]) & (lab[:, 0] >= 0))
    owner = lab[inside, 0]
    order = np.argsort(owner, kind="stable")
    bounds = np.searchsorted(owner[order], np.arange(seg.count + 1))
    sel = vg.lengths[inside[order]]
    return [sel[bounds[i]:bounds[i + 1]] for i in range(seg.count)]


def room_nodes(
    vg: VoronoiGraph, seg: RoomSegmentation, room_ids: list[str], objects: list[PlacedObject],
    doors: list[DoorObservation], unexplored_pos: Mapping[str, tuple[float, float]],
    instances: Mapping[int, InstanceInfo], classifier: RoomClassifier | None,
    class_memo: dict[tuple[str, ...], list[tuple[str, float]]], config: BuilderConfig,
) -> list[RoomNode]:
    """The explored rooms (neighbours, category scores) then the unexplored ones behind
    closed doors; ``class_memo`` caches the classifier's answers across calls."""
    nb: dict[str, set[str]] = {rid: set() for rid in room_ids}
    for a, b in room_neighbours(vg, seg):
        nb[room_ids[a]].add(room_ids[b])
        nb[room_ids[b]].add(room_ids[a])
    for d in doors:
        joined = list(d.rooms) + ([d.unexplored_room] if d.unexplored_room else [])
        for one in joined:
            for other in joined:
                if one != other and one in nb:
                    nb[one].add(other)
    cats: dict[str, list[str]] = defaultdict(list)
    voters: dict[str, list[str]] = defaultdict(list)
    for o in objects:
        if o.room is None:
            continue
        info = instances[o.instance]
        cats[o.room].append(info.category)
        if info.kind in config.classify_kinds:
            voters[o.room].append(info.category)
    out = []
    for i, rid in enumerate(room_ids):
        c = seg.centres[i]
        scores: list[tuple[str, float]] = []
        if classifier is not None:
            evidence = tuple(sorted(voters.get(rid) or cats.get(rid) or ()))
            if evidence:
                got = class_memo.get(evidence)
                if got is None:
                    got = class_memo[evidence] = checked_scores(
                        classifier, classifier.classify(list(evidence)))
                hub = 0 < config.corridor_hub <= len(nb[rid]) and corridor_like(
                    vg, seg.rooms[i], config, semantic=bool(instances))
                if hub and not got:  # the classifier says nothing: as an empty room
                    got = [(str(config.corridor), 1.0)]
                elif hub:
                    got = weigh_type(got, str(config.corridor), config.corridor_odds)
                scores = got[: config.max_scores]
            elif corridor_like(vg, seg.rooms[i], config, semantic=bool(instances)):
                scores = [(str(config.corridor), 1.0)]
        out.append(RoomNode(
            id=rid, category=scores[0][0] if scores else "unknown",
            position=(float(vg.positions[c, 0]), float(vg.positions[c, 1])),
            explored=True, category_scores=tuple((r, float(p)) for r, p in scores),
            neighbours=tuple(sorted(nb[rid])),
        ))
    for d in doors:
        if d.unexplored_room is None:
            continue
        out.append(RoomNode(id=d.unexplored_room, position=unexplored_pos[d.unexplored_room],
                            explored=False, neighbours=tuple(sorted(d.rooms))))
    return out


def checked_scores(classifier: RoomClassifier, got: Any) -> list[tuple[str, float]]:
    """A classifier's answer as (category, score) pairs, each a non-empty name and a
    finite score in [0, 1]; anything else is one line naming the classifier (a user's
    classifier, given to ``replay(room_classifier=...)``, writes into the graph)."""
    def fail(why: str) -> SgtoolError:
        return SgtoolError(f"room classifier {type(classifier).__name__}: classify() {why}")

    try:
        pairs = [(r, p) for r, p in got]
    except (TypeError, ValueError):
        raise fail(f"returned {returned_text(got)}, not (category, score) pairs") from None
    for r, p in pairs:
        if not isinstance(r, str) or not r:
            raise fail(f"named a category {r!r}, not a room type's name")
        ok = isinstance(p, int | float | np.integer | np.floating) and not isinstance(p, bool)
        if not (ok and math.isfinite(p) and 0.0 <= p <= 1.0):
            raise fail(f"scored {r!r} {p!r}: a score is a number in [0, 1]")
    return [(r, float(p)) for r, p in pairs]


def weigh_type(scores: list[tuple[str, float]], room_type: str, odds: float
               ) -> list[tuple[str, float]]:
    """``scores`` (a classifier's answer) with ``room_type``'s score weighed ``odds`` times
    (a prior the objects do not know of), scaled back to the answer's own total (no other
    type's score grows) and ranked again (best first, ties by name); as they are when they
    do not name ``room_type`` (a classifier that answers one type, as the LLM's does, has
    no distribution to weigh) or score nothing."""
    if room_type not in dict(scores):
        return scores
    weighed = [(r, p * odds if r == room_type else p) for r, p in scores]
    before, after = sum(p for _, p in scores), sum(p for _, p in weighed)
    if not (before > 0 and after > 0):
        return scores
    scale = before / after
    return sorted(((r, p * scale) for r, p in weighed), key=lambda rp: (-rp[1], rp[0]))


def corridor_like(vg: VoronoiGraph, nodes: np.ndarray, config: BuilderConfig,
                  semantic: bool = True) -> bool:
    """A room that is long (two of its nodes ``corridor_length`` apart) and narrow (no node
    farther than ``corridor_clearance`` from a wall). Such a room with no object to vote is
    a corridor; one joining ``corridor_hub`` rooms or more has its corridor score weighed
    ``corridor_odds`` times (a hall's shelves and console tables vote for a utility room
    or a living room; a galley kitchen's stove and fridge still name a kitchen).
    Transparent rules, off with ``corridor=None``; without semantics (``semantic=False``:
    no instance table) a room's shape says nothing."""
    if config.corridor is None or len(nodes) < 2 or not semantic:
        return False
    if float(vg.clearance[nodes].max()) > config.corridor_clearance:
        return False  # (before the pairwise distances, which cost more)
    # the longest distance between two of its nodes (a bounding box's diagonal grew as
    # the house turned: a 2.7 m room was 3.2 m long at 45 degrees)
    return float(pdist(vg.positions[nodes]).max()) >= config.corridor_length
