"""Doors in the scene graph: the grid cells that say "doorway" to the room segmentation,
and each seen door's rooms.

- :func:`doorways`: from the voxels of the open (or state-unknown) doors
  (:func:`open_doors`), the *passable* columns of each door -- its
  opening under the lintel, not the swung panel, whose cells would cut the room it stands
  in (when they are at least ``PASSABLE_SHARE`` of its columns: a panel smeared by depth
  noise or drift reaches a few passable columns) -- else the panel's closed position
  (:func:`~sgtool.scenegraph.door_panel.opening_from_panel`) found from its core columns
  (those with at least ``CORE_SHARE`` of its fullest column's voxels), else from its line
  (the core continued by the thinner columns in line with it: :func:`panel_cells`), else
  its core columns. A door seen as a panel whose doorway was not found (a door standing
  partly open, as a rule; or a panel smeared by drift through its thickened wall) also
  marks the floor within ``UNSURE_REACH`` (or its panel's length, when longer) of its
  core as *unsure*: its doorway lies somewhere there, so the room segmentation joins no
  floor through it. Its doorway is then also looked for under its lintel: the floor
  seen free under something overhead (``LINTEL_BAND``, given as ``overhead``) within
  that reach and ``LINTEL_TOUCH`` of its core, where a wall stands on both sides along
  the wall's line (drift smears a lintel as deep as the wall, too deep for
  :mod:`sgtool.scenegraph.lintels`); the wall's line through that floor's centre, jamb
  to jamb, is door evidence too. A door whose doorway was found also gives its leaf:
  its cells more than ``LEAF_OFF`` off the doorway's line, and their faces; the room
  segmentation's floor join crosses it (a leaf swung into a room is no wall of it).
- :func:`observe_doors`: the rooms on either side of a door from the visible Voronoi nodes
  within ``door_radius``; a closed door with only one explored side leads to an unexplored
  room node (SCOUT sec. IV-A), placed ``unexplored_offset`` beyond the door.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np
from scipy import ndimage
from scipy.spatial import cKDTree

from sgtool.mapping.bev import line_of_sight
from sgtool.mapping.grid import FREE, OCCUPIED, OccupancyGrid, grid_at
from sgtool.mapping.occupancy import within_cells
from sgtool.mapping.voronoi import VoronoiGraph
from sgtool.scenegraph.door_panel import opening_from_panel
from sgtool.scenegraph.instances import InstanceInfo
from sgtool.scenegraph.object_placement import SeenInstance
from sgtool.scenegraph.room_segmentation import JOIN_SEAL, RoomTracker
from sgtool.vocabulary import OpenState

PASSABLE_SHARE = 0.25  # passable share of a door's columns that makes them its opening
CORE_SHARE = 0.5  # a panel's column holds at least this share of its fullest column's voxels
LINE_SLACK = 0.9  # cells across a panel's line that are on it (a slanted line's cells: <0.71)
LINE_GAP = 2  # cells a panel's line may miss between cells that continue it
LINTEL_TOUCH = 0.25  # m: a lintel this close to a panel is its doorway's (doorways())
UNSURE_REACH = 0.9  # m: a door leaf's width (interior doors 0.7-0.9 m), at least
LEAF_OFF = JOIN_SEAL  # m off the doorway's line: a leaf's cells out of its wall
LEAF_SKIN = 0.1  # m: occupied cells this deep beside a leaf's labelled cells are its face


@dataclass(frozen=True, eq=False)
class DoorObservation:
    instance: int
    position: tuple[float, float]
    state: OpenState
    rooms: tuple[str, ...]  # explored rooms on either side, nearest first
    unexplored_room: str | None
    node: int  # nearest visible node (-1: none)


def open_doors(instances: Mapping[int, InstanceInfo]) -> list[int]:
    """The door instances that are open or of unknown state."""
    return [iid for iid, v in instances.items() if v.kind == "door" and v.state != "closed"]


@dataclass(frozen=True, eq=False)
class Doorways:
    """What :func:`doorways` finds (bool grids the shape of the occupancy grid)."""

    cells: np.ndarray  # the door evidence
    centres: dict[int, tuple[float, float]]  # door id -> x, y (m) of its doorway
    unsure: np.ndarray  # floor near a door whose doorway was not found
    leaves: np.ndarray  # swung leaves standing in a room, off their doorway's wall


def doorways(occ: OccupancyGrid, door_voxels: Mapping[int, np.ndarray],
             panel_memo: dict[bytes, object], overhead: np.ndarray | None = None
             ) -> Doorways:
    """The door evidence (module doc) from the voxels (ijk) of each open door,
    in any order (e.g. from :class:`sgtool.scenegraph.door_voxels.DoorVoxels`), the
    centre (x, y in m) of each door's cells in it: its doorway, where a swung panel's
    centroid stands beside it; the unsure floor; and the leaves: the cells of a door
    whose doorway was found that are not its doorway and lie farther than ``LEAF_OFF``
    from the doorway's line (out of its wall), and the occupied cells beside them (the
    leaf's faces): a leaf swung into a room is no wall of it (a leaf that meets a
    cabinet closes a pocket of floor off the room).
    ``panel_memo`` caches the openings found from swung panels across calls. The cells of
    every door are looked up at once; only a door with too few passable cells (a swung
    panel) is looked at on its own."""
    cells = np.zeros(occ.shape, dtype=bool)
    unsure = np.zeros(occ.shape, dtype=bool)
    leaves = np.zeros(occ.shape, dtype=bool)
    centres: dict[int, tuple[float, float]] = {}
    ids = [iid for iid, ijk in sorted(door_voxels.items()) if len(ijk)]
    parts = [door_voxels[iid] for iid in ids]
    if not parts:
        return Doorways(cells, centres, unsure, leaves)
    ix0 = int(round(occ.origin[0] / occ.resolution))
    iy0 = int(round(occ.origin[1] / occ.resolution))
    door = np.repeat(np.arange(len(parts)), [len(p) for p in parts])
    ijk = np.concatenate(parts)
    r, c = ijk[:, 1] - iy0, ijk[:, 0] - ix0
    ok = occ.inside(r, c)
    r, c, door = r[ok], c[ok], door[ok]
    passable = occ.grid[r, c] != OCCUPIED
    # a door's opening is its passable columns when they are a fair share of its columns
    # (a lintel over the opening); a few passable columns of a smeared panel are not
    cell_id = door * occ.grid.size + r * occ.shape[1] + c
    first = np.unique(cell_id, return_index=True)[1]
    n_cells = np.bincount(door[first], minlength=len(parts))
    n_pass = np.bincount(door[first][passable[first]], minlength=len(parts))
    open_door = n_pass >= np.maximum(PASSABLE_SHARE * n_cells, 1)
    use = passable & open_door[door]
    cells[r[use], c[use]] = True  # the passable cells of a door with an opening
    for i in np.flatnonzero(open_door).tolist():
        mine = use & (door == i)
        centres[ids[i]] = _centre(occ, r[mine], c[mine])
        leaf = ~passable & (door == i)
        _mark_leaf(leaves, r[leaf], c[leaf], r[mine], c[mine], occ)
    occupied: np.ndarray | None = None
    free: np.ndarray | None = None
    for i in np.flatnonzero(~open_door).tolist():  # doors seen as their panel (mostly)
        mine = door == i
        if not mine.any():
            continue
        cell, count = np.unique(r[mine] * (occ.shape[1] + 1) + c[mine], return_counts=True)
        if occupied is None or free is None:
            occupied, free = occ.grid == OCCUPIED, occ.grid == FREE
        pr, pc = np.divmod(cell, occ.shape[1] + 1)
        core, line = panel_cells(pr, pc, count, occupied)
        got = None
        for panel in (core, line) if len(line[0]) > len(core[0]) else (core,):
            got = opening_from_panel(*panel, occupied, int(0.4 / occ.resolution),
                                     memo=panel_memo, free=free)
            if got is not None:
                _mark_leaf(leaves, *panel, np.asarray(got[0]), np.asarray(got[1]), occ)
                break
        pr, pc = core if got is None else got
        cells[pr, pc] = True  # the panel's doorway, else its core cells
        centres[ids[i]] = _centre(occ, np.asarray(pr), np.asarray(pc))
        if got is None:
            near = _near_panel(unsure, np.asarray(pr), np.asarray(pc), occ.resolution)
            if overhead is not None and near is not None:  # its doorway, under its lintel
                cells |= _lintel_by_panel(near, np.asarray(pr), np.asarray(pc),
                                          overhead & free, occupied,
                                          LINTEL_TOUCH / occ.resolution)
    return Doorways(cells, centres, unsure, leaves)


def _mark_leaf(leaves: np.ndarray, rows: np.ndarray, cols: np.ndarray,
               door_rows: np.ndarray, door_cols: np.ndarray, occ: OccupancyGrid) -> None:
    """Mark in ``leaves`` the cells (``rows``, ``cols``) of a door's leaf farther than
    ``LEAF_OFF`` from the line of its doorway's cells (``door_rows``, ``door_cols``):
    the part of the leaf out of the wall the doorway is in; and the occupied cells up to
    ``LEAF_SKIN`` across the leaf from them, each step only beyond an occupied one (its
    faces, whose voxels often carry the label of what stands behind them, two cells thick
    under depth noise), not along it (its end may meet a wall). A face whose line stays
    occupied for ``LEAF_OFF`` past the leaf's free end is a wall the leaf lies against (a
    leaf's skin ends with the leaf): not marked, nor anything beyond it."""
    if len(rows) == 0 or len(door_rows) < 2:
        return
    across = _normal(door_rows, door_cols)
    pts = np.stack([cols, rows], axis=1).astype(np.float64)
    signed = (pts - np.stack([door_cols, door_rows], axis=1).mean(axis=0)) @ across
    body = np.abs(signed) * occ.resolution > LEAF_OFF
    if not body.any():
        return
    rows, cols, signed, pts = rows[body], cols[body], signed[body], pts[body]
    leaves[rows, cols] = True
    if len(rows) < 2:
        return
    face = _normal(rows, cols)
    out = np.array([face[1], -face[0]])  # along the leaf, away from its doorway
    out = out if out @ across * np.sign(signed.mean()) >= 0 else -out
    tip = pts[int(np.argmax(np.abs(signed)))]
    across_leaf = pts @ face - tip @ face  # the leaf's cells across it, from the tip's
    past = np.arange(1.0, LEAF_OFF / occ.resolution + 1.0)
    skin = max(1, int(round(LEAF_SKIN / occ.resolution)))
    for side in (1.0, -1.0):
        alive = np.ones(len(rows), dtype=bool)  # the leaf's cells whose face goes on
        for k in range(1, skin + 1):
            edge = across_leaf.max() + k if side > 0 else across_leaf.min() - k
            line = tip + edge * face + past[:, None] * out  # the face's line past the end
            lr = np.round(line[:, 1]).astype(np.int64)
            lc = np.round(line[:, 0]).astype(np.int64)
            if occ.inside(lr, lc).all() and (occ.grid[lr, lc] == OCCUPIED).all():
                break  # a wall runs on along it
            fr = np.round(rows + side * k * face[1]).astype(np.int64)
            fc = np.round(cols + side * k * face[0]).astype(np.int64)
            ok = alive & occ.inside(fr, fc)
            hit = np.zeros(len(rows), dtype=bool)
            hit[ok] = occ.grid[fr[ok], fc[ok]] == OCCUPIED
            leaves[fr[hit], fc[hit]] = True
            alive = hit
            if not alive.any():
                break


def _normal(rows: np.ndarray, cols: np.ndarray) -> np.ndarray:
    """The unit vector (x = column, y = row) across the principal axis of the cells."""
    pts = np.stack([cols, rows], axis=1).astype(np.float64)
    cen = pts - pts.mean(axis=0)
    evecs = np.linalg.eigh(cen.T @ cen)[1]
    return np.array([-evecs[1, -1], evecs[0, -1]])


def _lintel_by_panel(near: np.ndarray, rows: np.ndarray, cols: np.ndarray,
                     overhead_floor: np.ndarray, occupied: np.ndarray,
                     touch_cells: float) -> np.ndarray:
    """Bool grid: the doorway, under its lintel, of a panel (cells ``rows``, ``cols``)
    whose closed position was not found (a door is hinged at its doorway, under whose
    lintel the floor is seen however drift smears the lintel and the wall). The
    8-connected pieces of ``overhead_floor`` (floor seen free with something overhead)
    within ``near`` (the panel's reach) that come within ``touch_cells`` of the panel;
    of those, the cells with an ``occupied`` cell on both sides along the wall's line
    (across the panel's principal axis) within the panel's span; the doorway is the
    wall's line through their centre, to the first occupied cell each way (none when a
    side has none within the span). All False when there is none."""
    panel = np.zeros(near.shape, dtype=bool)
    panel[rows, cols] = True
    touch = within_cells(panel, touch_cells)
    labels, _ = ndimage.label(overhead_floor & near, structure=np.ones((3, 3), dtype=bool))
    mine = np.unique(labels[touch & (labels > 0)])
    got = np.isin(labels, mine) & (labels > 0)
    if not got.any() or len(rows) < 2:
        return np.zeros_like(got)
    # only the cells in the gap of the wall the door is hinged to: occupied cells on
    # both sides along the wall's line (across the panel's line), within the panel's
    # reach; drift smears a lintel out of its wall, as it smears the wall
    t = _normal(rows, cols)
    reach = math.hypot(int(rows.max() - rows.min()), int(cols.max() - cols.min())) + 1
    gr, gc = np.nonzero(got)
    at = np.stack([gc, gr], axis=1).astype(np.float64)
    steps = np.arange(1.0, reach + 1.0)
    keep = np.ones(len(gr), dtype=bool)
    for side in (1.0, -1.0):
        p = at[:, None, :] + side * steps[None, :, None] * t[None, None, :]
        hit = grid_at(p.reshape(-1, 2), occupied).reshape(len(gr), len(steps))
        keep &= hit.any(axis=1)
    out = np.zeros_like(got)
    if not keep.any():
        return out
    # the doorway: the wall's line through the lintel's centre, jamb to jamb (one cell
    # thick, as a panel's closed position: a smeared lintel's depth would cut a
    # corridor that drift narrows in front of the doorway)
    centre = at[keep].mean(axis=0)
    for side in (1.0, -1.0):
        p = centre[None, :] + side * np.arange(0.0, reach + 0.5, 0.5)[:, None] * t[None, :]
        hit = grid_at(p, occupied)
        if not hit.any():
            return np.zeros_like(got)
        p = p[:int(np.argmax(hit))]
        r = np.round(p[:, 1]).astype(np.int64)
        c = np.round(p[:, 0]).astype(np.int64)
        out[r, c] = True
    return out


def _near_panel(unsure: np.ndarray, rows: np.ndarray, cols: np.ndarray,
                resolution: float) -> np.ndarray | None:
    """Mark in ``unsure`` the cells within the reach of a panel's cells: its span (the
    diagonal of their bounding box, plus a cell), at least ``UNSURE_REACH``; those cells
    (None: no panel cells)."""
    if len(rows) == 0:
        return None
    span = math.hypot(int(rows.max() - rows.min()), int(cols.max() - cols.min())) + 1
    panel = np.zeros(unsure.shape, dtype=bool)
    panel[rows, cols] = True
    near = within_cells(panel, max(span, UNSURE_REACH / resolution))
    unsure |= near
    return near


_Cells = tuple[np.ndarray, np.ndarray]


def panel_cells(rows: np.ndarray, cols: np.ndarray, counts: np.ndarray,
                occupied: np.ndarray) -> tuple[_Cells, _Cells]:
    """The (rows, cols) of a door seen as its swung panel, from its cells (``rows``,
    ``cols``) and the voxels each holds: its core (cells holding at least ``CORE_SHARE``
    of the most voxels any cell holds; a panel smeared by depth noise or drift grows thin
    columns beside it), and its line: the core and the cells on the core's line (within
    ``LINE_SLACK`` cells across it) that continue it with gaps of at most ``LINE_GAP``
    cells (a panel seen only in part near its hinge, where it stands in the corner, holds
    fewer voxels there). A cell with an ``occupied`` cell on both sides across the line
    is in a wall and continues nothing."""
    core = counts >= CORE_SHARE * counts.max(initial=0)
    if core.sum() < 2:
        return (rows[core], cols[core]), (rows[core], cols[core])
    pts = np.stack([cols, rows], axis=1).astype(np.float64)
    mean = pts[core].mean(axis=0)
    cen = pts - mean
    evals, evecs = np.linalg.eigh(cen[core].T @ cen[core])
    a = evecs[:, int(np.argmax(evals))]
    t = np.array([-a[1], a[0]])
    along, across = cen @ a, np.abs(cen @ t)
    lo, hi = float(along[core].min()), float(along[core].max())
    walled = grid_at(pts + t, occupied) & grid_at(pts - t, occupied)
    on_line = np.sort(along[~core & ~walled & (across <= LINE_SLACK)])
    for x in on_line[on_line > hi]:  # continue the core past each end, gap by gap
        if x - hi > LINE_GAP + 1:
            break
        hi = float(x)
    for x in on_line[on_line < lo][::-1]:
        if lo - x > LINE_GAP + 1:
            break
        lo = float(x)
    keep = core | (~walled & (across <= LINE_SLACK) & (along >= lo) & (along <= hi))
    return (rows[core], cols[core]), (rows[keep], cols[keep])


def _centre(occ: OccupancyGrid, rows: np.ndarray, cols: np.ndarray) -> tuple[float, float]:
    """The mean of the centres of the cells (``rows``, ``cols``) of ``occ`` (each cell
    once)."""
    key = np.unique(rows.astype(np.int64) * (occ.shape[1] + 1) + cols.astype(np.int64))
    rr, cc = np.divmod(key, occ.shape[1] + 1)
    x, y = occ.center_of(rr, cc)
    return float(np.mean(x)), float(np.mean(y))


def observe_doors(
    seen: list[SeenInstance], vg: VoronoiGraph, node_room: np.ndarray, room_ids: list[str],
    occ: OccupancyGrid, blocked: np.ndarray, tracker: RoomTracker, door_radius: float,
    unexplored_offset: float, doorways: Mapping[int, tuple[float, float]] | None = None,
) -> tuple[list[DoorObservation], dict[str, tuple[float, float]]]:
    """The seen doors with their rooms (module doc), and the position of every unexplored
    room node behind them (``tracker`` names those rooms). A door stands at its doorway
    when ``doorways`` (door id -> x, y from :func:`doorways`) has it, else at the centroid
    of its voxels (a closed panel fills its doorway)."""
    out = []
    unexplored_pos: dict[str, tuple[float, float]] = {}
    at = doorways or {}
    points = [at.get(info.id, (float(c[0]), float(c[1]))) for info, c, _ in seen]
    visible = visible_labelled_nodes(points, vg, node_room, occ, blocked, door_radius)
    for (info, _c, _vp), pos, near in zip(seen, points, visible, strict=True):
        rooms: list[str] = []
        nearest = -1
        if near is not None and len(near):
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
            far = (pos[0] + unexplored_offset * float(u[0]),
                   pos[1] + unexplored_offset * float(u[1]))
            unexplored = f"room:{tracker.unexplored_room(info.id, far)}"
            unexplored_pos[unexplored] = far
        out.append(DoorObservation(info.id, pos, info.state or "open", tuple(rooms),
                                   unexplored, nearest))
    return out, unexplored_pos


def visible_labelled_nodes(points: list[tuple[float, float]], vg: VoronoiGraph,
                           node_room: np.ndarray, occ: OccupancyGrid, blocked: np.ndarray,
                           radius: float) -> list[np.ndarray | None]:
    """Per point (x, y in m): the indices of the nodes of ``vg`` with a room
    (``node_room >= 0``) within ``radius`` m whose segment to the point is clear of
    ``blocked`` cells of ``occ`` but for its last 0.3 m (ascending; None for every point
    when no node has a room). All points in one k-d tree query and one batched
    line-of-sight test (:func:`sgtool.mapping.bev.line_of_sight`)."""
    labelled = np.flatnonzero(node_room >= 0)
    if not len(labelled):
        return [None] * len(points)
    if not points:
        return []
    tree = cKDTree(vg.positions[labelled])
    near = [labelled[np.asarray(hits, dtype=np.int64)] for hits in tree.query_ball_point(
        np.asarray(points, dtype=np.float64), radius, return_sorted=True)]
    ends = np.repeat(np.asarray(points, dtype=np.float64), [len(n) for n in near], axis=0)
    vis = line_of_sight(blocked, occ, vg.positions[np.concatenate(near)], ends, skip_end=0.3)
    out: list[np.ndarray | None] = []
    at = 0
    for n in near:
        out.append(n[vis[at:at + len(n)]])
        at += len(n)
    return out
