"""Object-search episodes in a house: what to find, where the robot starts, how far it is.

An episode (as in SCOUT's SymSearch and its OmniGibson benchmark) names a query category
(a small object's readable category), the ids of all instances of it in the house (finding
any one succeeds): the small objects of that category and any furniture whose category
reads the same (the environments count a piece of the query category as found), a start
pose, and whether the target is hidden: no piece of the category, and every small object
needs something opened before it can be seen (:func:`sgtool.house.spec.hidden_objects`:
walking up to a piece shows what is on its top, even when it is closed; what is inside a
closed piece, or inside a closed object within it, needs opening).

``shortest_path`` is the optimal travel distance used by SPL: the geodesic on the house's
occupancy grid (robot radius 0.2 m, 8-connected, closed doors passable because the robot
may open them) from the start to the nearest place where the robot can reach a target:
a free cell in the target's room whose centre is within ``reach`` (1 m) of the footprint
of the target's furniture (a small object's: the piece at the bottom of its chain of
parents; SCOUT, Fig. 5 f: the closest unoccupied pixel to the goal object within the same
room, then A* on the dilated map).

Starts are the house's start poses; an episode prefers a start outside every target room
(starting next to the target is not a search), and, when the start drawn cannot reach a
target (a room no door leads into, on either side), draws again among the starts that can;
when none can, it starts inside a target's room (the reachable cell nearest its centroid,
:func:`sgtool.datasets.start_poses.reachability`), as the symbolic bench searches a
walled-off room from inside.
"""

from __future__ import annotations

import math
from collections import defaultdict
from dataclasses import dataclass

import numpy as np

from sgtool.arg_checks import of_type, whole
from sgtool.datasets.footprint_reach import Window, full_mask, near_footprint
from sgtool.errors import SgtoolError
from sgtool.house.spec import (
    Furniture,
    HouseSpec,
    StartPose,
    enclosed,
    hidden_objects,
    spec_id_key,
)
from sgtool.mapping.occupancy import OccupancyMap, astar, geodesic_distances, house_occupancy
from sgtool.mapping.raster import cell_centers, polygon_mask
from sgtool.semantics.text import category_text

REACH = 1.0


@dataclass(frozen=True)
class Episode:
    """One search episode of a house (:func:`list_episodes`): find ``query`` (a readable
    category; ``synset`` its BEHAVIOR-1K synset) from ``start``. ``targets`` are the spec
    ids of its instances (objects, then furniture), in ``target_rooms``; ``hidden`` when
    every instance needs something opened to be seen; ``shortest_path`` the geodesic in
    metres to the nearest place a target is seen from (inf when none can be reached)."""

    id: str
    query: str  # readable category
    synset: str
    targets: tuple[str, ...]  # object ids, then furniture ids of the category, each sorted
    target_rooms: tuple[str, ...]  # room ids, sorted
    start: StartPose
    hidden: bool  # every instance needs something opened to be seen
    shortest_path: float  # metres, inf when no target can be reached
    description: str  # "inside a closed cabinet in the kitchen"

    def to_dict(self) -> dict:
        return {
            "id": self.id, "query": self.query, "synset": self.synset,
            "targets": list(self.targets), "target_rooms": list(self.target_rooms),
            "start": {"x": self.start.x, "y": self.start.y, "yaw": self.start.yaw,
                      "room": self.start.room},
            "hidden": self.hidden,
            "shortest_path": (round(self.shortest_path, 4)
                              if math.isfinite(self.shortest_path) else None),
            "description": self.description,
        }


def room_raster(spec: HouseSpec, occ: OccupancyMap) -> np.ndarray:
    """Int grid: index into ``spec.rooms`` of the room holding each cell centre, -1 outside
    (on a shared border the first room in id order wins, as in :func:`room_at`)."""
    out = np.full(occ.shape, -1, np.int32)
    for i in reversed(range(len(spec.rooms))):
        out[polygon_mask(occ, spec.rooms[i].polygon)] = i
    return out


def _describe(spec: HouseSpec, obj_ids: list[str]) -> str:
    """Where the first instance is, through its chain of parents: "inside a closed box
    inside a closed cabinet in the kitchen (+2 more)"."""
    holders = spec.holder_by_id()
    o = spec.object_by_id()[obj_ids[0]]
    parts = []
    while True:
        p = holders[o.parent]
        shut = enclosed(o, p)
        where = "inside" if o.relation == "inside" else "on a shelf of" if shut else "on top of"
        thing = f"{p.state} {p.category}" if p.state and shut else p.category
        article = "an" if thing[:1].lower() in "aeiou" else "a"
        parts.append(f"{where} {article} {thing}")
        if isinstance(p, Furniture):
            break
        o = p
    room = spec.room(p.room).category.replace("_", " ")
    more = f" (+{len(obj_ids) - 1} more)" if len(obj_ids) > 1 else ""
    return f"{' '.join(parts)} in the {room}{more}"


class EpisodeGeometry:
    """Occupancy, room raster and goal masks of one house, shared by its episodes."""

    def __init__(self, spec: HouseSpec, reach: float = REACH, resolution: float = 0.05,
                 robot_radius: float = 0.2):
        if reach < robot_radius + 2 * resolution - 1e-9:
            raise SgtoolError(f"reach {reach:g} m: at least {robot_radius + 2 * resolution:g} m "
                              f"(the robot's centre stays {robot_radius:g} m from furniture, "
                              "so nothing nearer is reached)")
        self.spec = spec
        self.reach = reach
        self.occ = house_occupancy(spec, resolution=resolution, robot_radius=robot_radius,
                                   closed_doors_free=True)
        self.rooms = room_raster(spec, self.occ)
        self.X, self.Y = cell_centers(self.occ)
        self._room_index = {r.id: i for i, r in enumerate(spec.rooms)}
        self._roots = spec.root_furniture()
        self._dist: dict[tuple[float, float], np.ndarray] = {}
        self._near: dict[str, tuple[Window, np.ndarray] | None] = {}

    def near(self, piece: Furniture) -> tuple[Window, np.ndarray] | None:
        """(window, mask over it) of the free cells of ``piece``'s room within ``reach`` of
        its footprint (:func:`~sgtool.datasets.footprint_reach.near_footprint`), memoised
        per piece id; None when there is no such cell."""
        if piece.id in self._near:
            return self._near[piece.id]
        near = near_footprint(self.occ, self.X, self.Y, piece, self.reach)
        if near is not None:
            w, m = near
            m = m & (self.rooms[w] == self._room_index[piece.room]) & ~self.occ.blocked[w]
            near = (w, m) if m.any() else None
        self._near[piece.id] = near
        return near

    def _piece(self, target_id: str) -> Furniture:
        furn = self.spec.furniture_by_id()
        if target_id not in furn:
            target_id = self._roots[target_id]
        return furn[target_id]

    def goal_mask(self, target_id: str) -> np.ndarray:
        """Free cells of the target's room within ``reach`` of its furniture's footprint (a
        small object's furniture is the piece at the bottom of its chain of parents)."""
        return full_mask(self.occ.shape, self.near(self._piece(target_id)))

    def distances(self, start: StartPose) -> np.ndarray:
        key = (start.x, start.y)
        if key not in self._dist:
            self._dist[key] = geodesic_distances(self.occ, key, max_snap=1.0)
        return self._dist[key]

    def unreachable_holders(self) -> list[tuple[Furniture, list[str]]]:
        """The pieces at the bottom of small objects' chains of parents that the robot
        cannot get within ``reach`` of from any start pose of the house, in a room whose
        floor it does reach elsewhere (furniture around them closes the way: their targets
        are found by sight in the closed loop, never opened), each with the ids of the
        objects it holds; spec order. A room the robot cannot enter at all (too narrow, or
        walled off) is not these pieces' fault and is left out."""
        held: dict[str, list[str]] = defaultdict(list)
        for o in self.spec.objects:
            held[self._piece(o.id).id].append(o.id)
        reached = np.zeros(self.occ.shape, dtype=bool)
        for s in self.spec.starts:
            reached |= np.isfinite(self.distances(s))
        out = []
        for piece in self.spec.furniture:
            if piece.id not in held or not reached[
                    self.rooms == self._room_index[piece.room]].any():
                continue
            near = self.near(piece)
            if near is None or not reached[near[0]][near[1]].any():
                out.append((piece, held[piece.id]))
        return out

    def shortest_path(self, start: StartPose, target_ids: list[str]) -> float:
        """Geodesic to the nearest target (small object or furniture ids)."""
        return self._nearest_goal(start, target_ids)[0]

    def shortest_route(self, start: StartPose, target_ids: list[str]
                       ) -> list[tuple[float, float]] | None:
        """A route of :meth:`shortest_path`'s length: the start, then the centres of the
        8-connected path's cells to the nearest goal cell (world x, y); None when no target
        is reached."""
        best, goal = self._nearest_goal(start, target_ids)
        if math.isinf(best):
            return None
        path = astar(self.occ, (start.x, start.y), (self.X[goal], self.Y[goal]), max_snap=1.0)
        return None if path is None else [(start.x, start.y), *path[1:]]

    def _nearest_goal(self, start: StartPose, target_ids: list[str]
                      ) -> tuple[float, tuple[int, int]]:
        """(geodesic, grid cell (row, col)) of the goal cell of the targets nearest to
        ``start`` (the first target's on a tie); (inf, (0, 0)) when none is reached."""
        d = self.distances(start)
        best, goal = math.inf, (0, 0)
        for oid in target_ids:
            near = self.near(self._piece(oid))
            if near is None:
                continue
            (rows, cols), mask = near
            sub = np.where(mask, d[rows, cols], np.inf)
            k = np.unravel_index(int(np.argmin(sub)), sub.shape)
            if sub[k] < best:
                best = float(sub[k])
                goal = ((rows.start or 0) + int(k[0]), (cols.start or 0) + int(k[1]))
        return best, goal


def draw_start(spec: HouseSpec, geo: EpisodeGeometry, rooms: tuple[str, ...],
               targets: list[str], rng: np.random.Generator,
               seed: int) -> tuple[StartPose, float]:
    """An episode's start and shortest path (module doc): drawn with ``rng`` among the
    starts outside the target ``rooms`` (all, when none is); when it reaches no target,
    drawn again among the starts that do; when none does, inside a target room."""
    starts = [s for s in spec.starts if s.room not in rooms] or list(spec.starts)
    start = starts[int(rng.integers(len(starts)))]
    path = geo.shortest_path(start, targets)
    if math.isinf(path):  # a walled-off room on one side: a start that reaches one
        able = [s for s in spec.starts if math.isfinite(geo.shortest_path(s, targets))]
        if able:
            able = [s for s in able if s.room not in rooms] or able
            start = able[int(rng.integers(len(able)))]
            path = geo.shortest_path(start, targets)
        else:  # no start of the file reaches one: search from inside, as the bench does
            start, path = _start_inside(spec, geo, rooms, targets, seed) or (start, path)
    return start, path


def _start_inside(spec: HouseSpec, geo: EpisodeGeometry, rooms: tuple[str, ...],
                  targets: list[str], seed: int) -> tuple[StartPose, float] | None:
    """A start in one of the target ``rooms`` (in order) that reaches a target, with its
    path; None when there is none."""
    from sgtool.datasets.start_poses import reachability

    for room in rooms:
        for s in reachability(spec, seed, origin_room=room).starts:
            if s.room == room and math.isfinite(path := geo.shortest_path(s, targets)):
                return s, path
    return None


def list_episodes(spec: HouseSpec, n: int | None = None, seed: int | None = None,
                  reach: float = REACH,
                  geometry: EpisodeGeometry | None = None) -> list[Episode]:
    """Search episodes in ``spec``: one per small-object category (its
    :func:`~sgtool.semantics.text.category_text`, so spellings of one name are one query;
    sorted) when ``n`` is None, else ``n`` episodes drawn with ``seed`` (categories
    without replacement while they last, then again with other starts). ``seed`` (the
    start poses' draw too) defaults to the house's own, the seed ``bench`` and
    ``run-bench`` draw with, so ``run --episode K`` is episode K of ``sgtool scenes
    episodes``. ``geometry``: the house's
    :class:`EpisodeGeometry` with this ``reach``, to share with other listings."""
    of_type("spec", spec, HouseSpec, "a HouseSpec (sgtool.load_house(path))")
    whole("n", n, 0, optional=True)
    whole("seed", seed, optional=True)
    seed = spec.seed if seed is None else seed
    if not spec.objects or not spec.starts:
        return []
    by_cat: dict[str, list[str]] = defaultdict(list)
    synset_of: dict[str, str] = {}
    for o in spec.objects:  # spellings of one category ("Soap Bar", "soap_bar") are one query
        text = category_text(o.category)
        by_cat[text].append(o.id)
        synset_of.setdefault(text, o.synset)
    cats = sorted(by_cat)
    rng = np.random.default_rng(seed)
    if n is None:
        chosen = cats
    else:
        chosen = []
        while len(chosen) < n:
            take = min(n - len(chosen), len(cats))
            chosen += [cats[i] for i in sorted(rng.choice(len(cats), size=take,
                                                          replace=False).tolist())]
    geo = geometry or EpisodeGeometry(spec, reach=reach)
    objs = spec.object_by_id()
    furn = spec.furniture_by_id()
    hidden_ids = hidden_objects(spec)
    furn_by_text: dict[str, list[str]] = defaultdict(list)
    for f in spec.furniture:
        furn_by_text[category_text(f.category)].append(f.id)
    out = []
    for i, cat in enumerate(chosen):
        ids = sorted(by_cat[cat], key=spec_id_key)
        pieces = sorted(furn_by_text.get(cat, ()), key=spec_id_key)
        rooms = tuple(sorted({objs[o].room for o in ids} |
                             {furn[f].room for f in pieces}, key=spec_id_key))
        start, path = draw_start(spec, geo, rooms, ids + pieces, rng, seed)
        hidden = not pieces and all(o in hidden_ids for o in ids)
        out.append(Episode(
            id=f"ep_{i}", query=cat, synset=synset_of[cat], targets=tuple(ids + pieces),
            target_rooms=rooms, start=start, hidden=hidden, shortest_path=path,
            description=_describe(spec, ids),
        ))
    return out


def pick_episode(house: HouseSpec, query: str | None = None, index: int | None = None
                 ) -> tuple[int, Episode]:
    """(index, episode) of ``house``'s search episodes (``sgtool scenes episodes``, one per
    small-object category): the one of category ``query``, else number ``index`` (0)."""
    of_type("house", house, HouseSpec, "a HouseSpec (sgtool.load_house(path))")
    eps = list_episodes(house)
    if not eps:
        raise SgtoolError("the house has no search episodes (it needs small objects and "
                          "start poses)")
    if query is not None:
        of_type("query", query, str, "a category name (an episode number is index=)")
        if index is not None:
            raise SgtoolError("give either a query (--query, query=) or an episode index "
                              "(--episode, index=), not both")
        want = category_text(query)
        for i, e in enumerate(eps):
            if category_text(e.query) == want:
                return i, e
        cats = ", ".join(e.query for e in eps)
        raise SgtoolError(f"no object of category {query!r} in the house; its small-object "
                          f"categories are: {cats}")
    k = 0 if index is None else int(index)
    if not 0 <= k < len(eps):
        raise SgtoolError(f"episode {k}: the house has {len(eps)} episodes "
                          f"(0..{len(eps) - 1}; see `sgtool scenes episodes`)")
    return k, eps[k]
