"""Shortcuts of the rooms stage (issue 20) equal the plain computation, bit for bit."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import ndimage
from scipy.spatial import cKDTree

from sgtool.mapping.bev import line_of_sight
from sgtool.mapping.grid import FREE, OCCUPIED, OccupancyGrid
from sgtool.mapping.voronoi import VoronoiGraph
from sgtool.scenegraph import door_panel
from sgtool.scenegraph.door_evidence import (
    PASSABLE_SHARE,
    doorways,
    panel_cells,
    visible_labelled_nodes,
)
from sgtool.scenegraph.door_panel import opening_from_panel, ray_shares
from sgtool.scenegraph.room_segmentation import room_overlaps


def door_cells_of(occ, door_voxels, memo):
    """The door evidence grid of :func:`doorways` (its cells, not the doorway centres)."""
    return doorways(occ, door_voxels, memo).cells


def _share(p0: np.ndarray, direction: np.ndarray, lo: float, hi: float,
           grid: np.ndarray, origin: tuple[int, int] = (0, 0)) -> float:
    """One ray at a time, as ``_opening`` sampled before its rays were batched."""
    h, w = grid.shape
    f = np.linspace(lo, hi, max(2, int(np.ceil(2 * (hi - lo)))))
    p = p0[None, :] + direction[None, :] * f[:, None]
    c = np.round(p[:, 0]).astype(np.int64) - origin[1]
    r = np.round(p[:, 1]).astype(np.int64) - origin[0]
    ok = (r >= 0) & (r < h) & (c >= 0) & (c < w)
    return float(grid[r[ok], c[ok]].mean()) if ok.any() else 0.0


def _reference_shares(rays, occupied, grown, origin=(0, 0)):  # noqa: ANN001, ANN202
    return [_share(p0, d, lo, hi, grown if g else occupied, origin)
            for p0, d, lo, hi, g in rays]


@pytest.mark.parametrize("seed", range(10))
def test_batched_shares_equal_one_ray_at_a_time(seed):
    rng = np.random.default_rng(seed)
    occupied = rng.random((int(rng.integers(10, 60)), int(rng.integers(10, 60)))) < 0.3
    grown = ndimage.binary_dilation(occupied)
    rays = []
    for _ in range(48):
        ang = rng.uniform(0, 2 * np.pi)
        width = rng.uniform(2.0, 30.0)
        lo = rng.uniform(0.0, 1.2) * width
        rays.append((rng.uniform(-10, 70, size=2), np.array([np.cos(ang), np.sin(ang)]),
                     lo, lo + rng.uniform(0.0, 0.8) * width, bool(rng.random() < 0.5)))
    got = ray_shares(rays, occupied, grown)
    want = _reference_shares(rays, occupied, grown)
    assert got == want
    assert any(0.0 < x < 1.0 for x in want) and 0.0 in want  # partial shares and off-grid


@pytest.mark.parametrize("seed", range(10))
def test_panel_openings_equal_the_ray_by_ray_search(seed, monkeypatch):
    """A swung door panel in a wall with a gap (random hinge, side, length, clutter):
    the doorway found with batched rays is the one found ray by ray."""
    rng = np.random.default_rng(100 + seed)
    occupied = np.zeros((80, 80), dtype=bool)
    wall = int(rng.integers(30, 50))
    gap0 = int(rng.integers(20, 40))
    width = int(rng.integers(8, 18))
    occupied[wall, :gap0] = True
    occupied[wall, gap0 + width:] = True
    side = 1 if rng.random() < 0.5 else -1
    rows = wall + side * np.arange(1, width)
    cols = np.full(len(rows), gap0)
    occupied[rows, cols] = True
    occupied |= rng.random(occupied.shape) < 0.03
    got = opening_from_panel(rows, cols, occupied, min_width=8)
    monkeypatch.setattr(door_panel, "ray_shares", _reference_shares)
    want = opening_from_panel(rows, cols, occupied, min_width=8)
    assert (got is None) == (want is None)
    if want is not None:
        assert got is not None
        assert np.array_equal(got[0], want[0]) and np.array_equal(got[1], want[1])


def _door_cells_one_by_one(occ, door_voxels, panel_memo):  # noqa: ANN001, ANN202
    """``door_cells_of`` one door at a time."""
    cells = np.zeros(occ.shape, dtype=bool)
    ix0 = int(round(occ.origin[0] / occ.resolution))
    iy0 = int(round(occ.origin[1] / occ.resolution))
    occupied = None
    for _, ijk in sorted(door_voxels.items()):
        if not len(ijk):
            continue
        r, c = ijk[:, 1] - iy0, ijk[:, 0] - ix0
        ok = occ.inside(r, c)
        r, c = r[ok], c[ok]
        passable = occ.grid[r, c] != OCCUPIED
        n_cells = len(set(zip(r.tolist(), c.tolist(), strict=True)))
        n_pass = len(set(zip(r[passable].tolist(), c[passable].tolist(), strict=True)))
        if n_pass and n_pass >= PASSABLE_SHARE * n_cells:
            r, c = r[passable], c[passable]
        else:
            cell, count = np.unique(r * (occ.shape[1] + 1) + c, return_counts=True)
            r, c = np.divmod(cell, occ.shape[1] + 1)
            if occupied is None:
                occupied = occ.grid == OCCUPIED
            core, line = panel_cells(r, c, count, occupied)
            r, c = core
            for panel in (core, line):  # the core, else the line
                got = opening_from_panel(*panel, occupied, int(0.4 / occ.resolution),
                                         memo=panel_memo, free=occ.grid == FREE)
                if got is not None:
                    r, c = got
                    break
        cells[r, c] = True
    return cells


@pytest.mark.parametrize("seed", range(12))
def test_door_cells_of_all_doors_at_once_equal_one_door_at_a_time(seed):
    """Doors with passable cells, doors seen as a swung panel in a wall with a gap (some
    found as a doorway, some not), doors partly or wholly off the grid, empty doors."""
    rng = np.random.default_rng(300 + seed)
    h, w = 90, 120
    g = np.full((h, w), FREE, dtype=np.int8)
    doors: dict[int, np.ndarray] = {}
    origin = (float(rng.integers(-20, 20)) * 0.05, float(rng.integers(-20, 20)) * 0.05)
    ix0, iy0 = int(round(origin[0] / 0.05)), int(round(origin[1] / 0.05))
    for iid in rng.permutation(12).tolist():
        kind = rng.choice(["open", "panel", "off", "empty"])
        if kind == "empty":
            doors[iid] = np.zeros((0, 3), np.int64)
            continue
        r0, c0 = int(rng.integers(5, h - 25)), int(rng.integers(5, w - 25))
        width = int(rng.integers(8, 16))
        if kind == "panel":  # a wall with a gap, the panel swung from its jamb
            g[r0, :c0] = OCCUPIED
            g[r0, c0 + width:] = OCCUPIED
            rows = r0 + np.arange(1, width)
            cols = np.full(len(rows), c0)
            g[rows, cols] = OCCUPIED
            seen = int(rng.integers(0, width // 2))  # near the hinge seen thinly
            rows = np.concatenate([rows, np.repeat(rows[seen:], 2)])
            cols = np.full(len(rows), c0)
        else:
            rows = np.full(width, r0)
            cols = c0 + np.arange(width)
            g[rows[: width // 3], cols[: width // 3]] = OCCUPIED  # the lintel over part
            if kind == "off":
                rows = rows - 200 * int(rng.integers(0, 2))
        z = rng.integers(0, 30, size=len(rows))
        doors[iid] = np.stack([cols + ix0, rows + iy0, z], axis=1).astype(np.int64)
    occ = OccupancyGrid(g, origin, 0.05)
    got = door_cells_of(occ, doors, {})
    want = _door_cells_one_by_one(occ, doors, {})
    assert np.array_equal(got, want)
    assert want.any()


@pytest.mark.parametrize("seed", range(8))
def test_door_sight_lines_of_all_doors_at_once_equal_one_door_at_a_time(seed):
    rng = np.random.default_rng(900 + seed)
    g = np.full((60, 80), FREE, dtype=np.int8)
    for _ in range(6):
        r, c = int(rng.integers(0, 55)), int(rng.integers(0, 75))
        g[r:r + int(rng.integers(1, 5)), c:c + int(rng.integers(1, 20))] = OCCUPIED
    occ = OccupancyGrid(g, (0.0, 0.0), 0.05)
    blocked = g == OCCUPIED
    pos = rng.uniform((0, 0), (4, 3), size=(50, 2))
    vg = VoronoiGraph(None, pos, np.ones(50), np.zeros((50, 2), np.int64),
                      np.zeros((0, 2), np.int64), np.zeros(0), (), np.zeros((1, 1), bool))
    node_room = rng.integers(-1, 3, size=50)
    points = [tuple(p) for p in rng.uniform((0, 0), (4, 3), size=(int(rng.integers(0, 9)), 2))]
    got = visible_labelled_nodes(points, vg, node_room, occ, blocked, 1.5)
    labelled = np.flatnonzero(node_room >= 0)
    tree = cKDTree(pos[labelled])
    for p, near in zip(points, got, strict=True):
        want = labelled[np.asarray(sorted(tree.query_ball_point(p, 1.5)), dtype=np.int64)]
        if len(want):
            want = want[line_of_sight(blocked, occ, pos[want],
                                      np.repeat(np.asarray([p]), len(want), axis=0),
                                      skip_end=0.3)]
        assert near is not None and np.array_equal(near, want)
    none = visible_labelled_nodes(points, vg, np.full(50, -1), occ, blocked, 1.5)
    assert none == [None] * len(points)


def _overlaps_one_room_at_a_time(known, room_positions, radius):  # noqa: ANN001, ANN202
    """``RoomTracker.assign``'s overlaps as they were computed: a query per new room."""
    old_ids = sorted(known)
    out = []
    if old_ids and len(room_positions):
        old_pos = np.concatenate([known[o] for o in old_ids])
        old_lab = np.concatenate([np.full(len(known[o]), o) for o in old_ids])
        tree = cKDTree(old_pos)
        for i, pos in enumerate(room_positions):
            d, j = tree.query(pos, k=1, distance_upper_bound=radius)
            hit = np.isfinite(d)
            if not hit.any():
                continue
            labs, counts = np.unique(old_lab[j[hit]], return_counts=True)
            for lab, c in zip(labs.tolist(), counts.tolist(), strict=True):
                out.append((-int(c), i, int(lab)))
    return sorted(out)


@pytest.mark.parametrize("seed", range(10))
def test_room_overlaps_in_one_query_equal_a_query_per_room(seed):
    rng = np.random.default_rng(1200 + seed)
    known = {int(o): rng.uniform(0, 10, size=(int(rng.integers(1, 30)), 2))
             for o in rng.choice(40, size=int(rng.integers(0, 8)), replace=False)}
    new = [rng.uniform(0, 10, size=(int(rng.integers(1, 30)), 2))
           for _ in range(int(rng.integers(0, 8)))]
    radius = float(rng.uniform(0.2, 1.5))
    got = sorted(room_overlaps(known, new, radius))
    assert got == _overlaps_one_room_at_a_time(known, new, radius)
    assert all(isinstance(x, int) for t in got for x in t)


def test_a_few_passable_columns_of_a_smeared_panel_do_not_make_its_opening():
    """A swung panel whose noisy voxels reach 2 free columns (of 17) is still a panel: its
    cells are those of the panel alone, not those 2 cells (an opening of 2 cells barely
    cuts the rooms apart)."""
    g = np.full((60, 60), FREE, dtype=np.int8)
    g[20, :10] = OCCUPIED
    g[20, 26:] = OCCUPIED  # the wall, a 16-cell gap at columns 10-25
    rows = 20 + np.arange(1, 16)
    g[rows, 10] = OCCUPIED  # the panel swung from the jamb at column 10
    panel = np.stack([np.full(15, 10), rows, np.zeros(15, np.int64)], axis=1)
    stray = np.array([[12, 30, 0], [13, 30, 0]])
    occ = OccupancyGrid(g, (0.0, 0.0), 0.05)
    alone = door_cells_of(occ, {1: panel.astype(np.int64)}, {})
    assert alone.sum() >= 15  # the panel's doorway, else its cells
    cells = door_cells_of(occ, {1: np.concatenate([panel, stray]).astype(np.int64)}, {})
    assert np.array_equal(cells, alone) and not cells[30, 12:14].any()
    # a fair share of passable columns (a lintel over the opening) is the opening
    lintel = np.stack([np.arange(10, 26), np.full(16, 20), np.full(16, 44)], axis=1)
    g2 = g.copy()
    g2[20, 10:26] = FREE
    opened = door_cells_of(OccupancyGrid(g2, (0.0, 0.0), 0.05),
                           {1: np.concatenate([panel, lintel]).astype(np.int64)}, {})
    assert opened[20, 10:26].all() and opened.sum() == 16


def test_thin_columns_beside_a_panel_are_not_part_of_it():
    """A swung panel (15 columns of 40 voxels) with thin columns beside it (3 voxels each:
    depth noise, drift) gives the cells of the panel alone: the panel rule looks at the
    columns holding at least CORE_SHARE of the fullest column's voxels."""
    g = np.full((60, 60), FREE, dtype=np.int8)
    g[20, :10] = OCCUPIED
    g[20, 26:] = OCCUPIED
    rows = 20 + np.arange(1, 16)
    g[rows, 10] = OCCUPIED
    g[rows, 11] = OCCUPIED  # the smear is occupied too (in the band)
    z = np.arange(40)
    panel = np.stack([np.repeat(np.full(15, 10), 40), np.repeat(rows, 40), np.tile(z, 15)],
                     axis=1)
    smear = np.stack([np.repeat(np.full(15, 11), 3), np.repeat(rows, 3), np.tile(z[:3], 15)],
                     axis=1)
    occ = OccupancyGrid(g, (0.0, 0.0), 0.05)
    alone = door_cells_of(occ, {1: panel.astype(np.int64)}, {})
    both = door_cells_of(occ, {1: np.concatenate([panel, smear]).astype(np.int64)}, {})
    assert alone.any() and np.array_equal(both, alone)


def swung_door() -> tuple[OccupancyGrid, np.ndarray]:
    """A wall along row 20 with a doorway at columns 10-25 and a door swung into the room
    below it, hinged at column 10; and the panel's voxels (i, j, k)."""
    g = np.full((60, 60), FREE, dtype=np.int8)
    g[20, :10] = OCCUPIED
    g[20, 26:] = OCCUPIED
    rows = 20 + np.arange(1, 16)
    g[rows, 10] = OCCUPIED
    panel = np.stack([np.full(15, 10), rows, np.zeros(15, np.int64)], axis=1)
    return OccupancyGrid(g, (0.0, 0.0), 0.05), panel.astype(np.int64)


def test_an_open_door_stands_at_its_doorway_not_at_its_swung_panel():
    """A door swung into a room, seen with its lintel (a fair share of passable columns) or
    as its panel alone: either way its place is the centre of the doorway (columns 10-25 of
    row 20, x = 0.9 m, y = 1.025 m at 5 cm cells), where the centroid of its voxels stands
    0.4 m inside the room."""
    occ, panel = swung_door()
    lintel = np.stack([np.arange(10, 26), np.full(16, 20), np.full(16, 44)], axis=1)
    at = doorways(occ, {7: np.concatenate([panel, lintel]).astype(np.int64)}, {}).centres
    assert at[7] == pytest.approx((0.9, 1.025))
    at = doorways(occ, {7: panel.astype(np.int64), 8: np.zeros((0, 3), np.int64)}, {}).centres
    assert set(at) == {7}  # a door without voxels has no doorway
    x, y = at[7]
    assert abs(y - 1.025) < 0.051 and 0.5 <= x <= 1.3  # in the gap (a cell), not in the room


def test_a_leaf_whose_doorway_is_not_found_marks_the_floor_around_it_unsure():
    """A leaf standing diagonally on open floor (no wall: no doorway is found) is its own
    door evidence, and the floor within UNSURE_REACH (0.9 m: 18 cells) of it is unsure,
    as far as its span (20.8 cells, 1.04 m) since that is longer; a door whose doorway
    is found (swung_door's) marks none."""
    g = np.full((80, 80), FREE, dtype=np.int8)
    t = np.arange(15)
    rows, cols = 30 + t, 30 + t  # 45 degrees, 15 cells
    g[rows, cols] = OCCUPIED
    panel = np.stack([cols, rows, np.zeros(15, np.int64)], axis=1).astype(np.int64)
    occ = OccupancyGrid(g, (0.0, 0.0), 0.05)
    got = doorways(occ, {7: panel}, {})
    cells, unsure = got.cells, got.unsure
    assert cells[rows, cols].all()  # the leaf's own cells
    dist = ndimage.distance_transform_edt(~cells)
    assert unsure[dist <= 18].all()
    reach = np.hypot(14, 14) + 1  # the leaf's span, longer than 18 cells
    assert unsure[(dist > 19) & (dist <= reach - 0.5)].all()
    assert not unsure[dist > reach + 1].any()
    swung_occ, swung = swung_door()
    none = doorways(swung_occ, {7: swung}, {}).unsure
    assert not none.any()


@pytest.mark.parametrize("seed", range(12))
def test_panel_opening_moves_with_the_grid(seed):
    """A diagonal wall with a doorway, its panel swung open and clutter: the same scene
    one, two or three cells further from the grid's corner gives a doorway (or none)
    likewise, that much further, to a cell (the search works in the grid's own cells; a
    point half-way between two cells may round the other way once moved)."""
    rng = np.random.default_rng(700 + seed)
    width = int(rng.integers(14, 30))
    d = np.array([1.0, 1.0]) / np.sqrt(2)
    t = np.array([-d[1], d[0]])
    occupied = np.zeros((200, 200), dtype=bool)
    hinge = np.array([100.0, 100.0])
    for s in np.arange(-90.0, 90.0, 0.25):
        if not 0 <= s <= width:
            c, r = np.round(hinge + t * s).astype(int)
            occupied[r, c] = True
    occupied |= rng.random(occupied.shape) < rng.uniform(0.0, 0.1)
    p = hinge[None, :] + d[None, :] * np.arange(1.0, width, 0.25)[:, None]
    cell = np.unique(np.round(p[:, ::-1]).astype(np.int64), axis=0)
    rows, cols = cell[:, 0], cell[:, 1]
    occupied[rows, cols] = True
    free = ~occupied
    want = opening_from_panel(rows, cols, occupied, min_width=8, free=free)
    for k in (1, 2, 3):
        moved = np.zeros((200 + k, 200 + k), dtype=bool)
        moved[k:, k:] = occupied
        got = opening_from_panel(rows + k, cols + k, moved, min_width=8, free=np.pad(
            free, ((k, 0), (k, 0))))
        assert (got is None) == (want is None)
        if want is not None and got is not None:
            a = np.stack([want[0], want[1]], axis=1)
            b = np.stack([got[0] - k, got[1] - k], axis=1)
            assert len(a) == len(b)
            assert np.abs(a[:, None, :] - b[None, :, :]).max(axis=2).min(axis=1).max() <= 1
