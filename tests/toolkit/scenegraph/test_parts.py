"""Scene-graph stages on hand-made inputs: rooms, assignment, frontiers, regions, categories."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.sparse import csr_matrix

from sgtool.datasets.room_evidence import frequency_room_classifier
from sgtool.mapping.grid import FREE, OCCUPIED, UNKNOWN, OccupancyGrid
from sgtool.mapping.voronoi import voronoi_graph
from sgtool.scenegraph.assign import AssignConfig, assign_objects
from sgtool.scenegraph.categories import FrequencyRoomClassifier, RoomClassifier
from sgtool.scenegraph.door_evidence import panel_cells
from sgtool.scenegraph.door_panel import opening_from_panel
from sgtool.scenegraph.frontiers import FrontierConfig, find_frontiers
from sgtool.scenegraph.regions import cluster_room
from sgtool.scenegraph.room_segmentation import (
    RoomTracker,
    door_density,
    room_neighbours,
    segment_rooms,
)

RES = 0.05


def cell(v: float) -> int:
    return 4 + int(round(v / RES))


def two_rooms() -> tuple[OccupancyGrid, np.ndarray]:
    """Rooms [0, 4] x [0, 3] and [4, 8] x [0, 3], a doorway at x = 4, y 1.05-1.95; and the
    doorway's cells (door evidence)."""
    h, w = cell(3.0) + 4, cell(8.0) + 4
    g = np.full((h, w), UNKNOWN, dtype=np.int8)
    g[2:-2, 2:-2] = OCCUPIED
    g[4:-4, 4:-4] = FREE
    c = cell(4.0)
    g[4:-4, c - 1:c + 1] = OCCUPIED
    g[cell(1.05):cell(1.95), c - 1:c + 1] = FREE
    door = np.zeros_like(g, dtype=bool)
    door[cell(1.05):cell(1.95), c - 1:c + 1] = True
    return OccupancyGrid(g, (-4 * RES, -4 * RES), RES), door


# ----- rooms --------------------------------------------------------------------------
def test_door_density_cuts_the_graph_into_two_rooms() -> None:
    occ, door = two_rooms()
    vg = voronoi_graph(occ)
    one = segment_rooms(vg, None)
    assert one.count == 1
    dens = door_density(door, RES, 0.15)
    # next to a two-cell-thick line of door cells: about 2 x 0.133
    assert dens[cell(1.5), cell(4.0)] == pytest.approx(0.26, abs=0.03)
    seg = segment_rooms(vg, dens)
    assert seg.count == 2
    xs = [vg.positions[nodes, 0] for nodes in seg.rooms]
    assert xs[0].max() < 4.0 < xs[1].min()
    assert seg.cut_edges.any()
    assert room_neighbours(vg, seg) == [(0, 1)]
    for nodes, c in zip(seg.rooms, seg.centres, strict=True):
        assert c in nodes


def test_room_ids_are_stable_and_unexplored_rooms_pass_theirs_on() -> None:
    tr = RoomTracker()
    a = np.array([[1.0, 1.0], [1.5, 1.0], [2.0, 1.0]])
    b = np.array([[6.0, 1.0], [6.5, 1.0]])
    assert tr.assign([a, b], 0.6) == [0, 1]
    # next refresh: listed in the other order, shifted a little, a third room appears
    c = np.array([[10.0, 1.0], [10.5, 1.0]])
    assert tr.assign([b + 0.1, c, a - 0.1], 0.6) == [1, 2, 0]
    # a closed door at x = 12 hides a room: it gets a number now...
    assert tr.unexplored_room(door=77, position=(13.0, 1.0)) == 3
    assert tr.unexplored_room(door=77, position=(13.0, 1.1)) == 3
    # ...that the room found there later inherits
    d = np.array([[13.2, 1.0], [14.0, 1.0]])
    assert tr.assign([a, b, c, d], 0.6) == [0, 1, 2, 3]
    assert 77 not in tr.unexplored


def test_swung_panel_gives_its_doorway() -> None:
    occupied = np.zeros((60, 100), dtype=bool)
    occupied[20, :] = True  # a wall along x at row 20 ...
    occupied[20, 40:58] = False  # ... with an 18-cell gap
    rows = np.arange(21, 39)  # the panel, hinged at (20, 40), swung into +row
    cols = np.full(len(rows), 40)
    occupied[rows, cols] = True
    got = opening_from_panel(rows, cols, occupied, min_width=8)
    assert got is not None
    r, c = got
    assert np.all(np.abs(r - 20) <= 1)
    assert c.min() <= 41 and 56 <= c.max() <= 59
    assert opening_from_panel(rows[:4], cols[:4], occupied, min_width=8) is None



def test_smeared_panel_beside_a_cupboard_still_gives_its_doorway() -> None:
    """Depth noise smears the wall to 7 cells and the panel to 26 cells (doorway 18), its
    hinge end inside the wall: the opening ray from the hinge reaches the far wall (share
    0.27, sum score 1.46); a cupboard where the far-jamb ray of the free end looks scores
    that end 1.0. Within 0.5 of each other, the sum rule alone gave up (the panel's own
    cells then cut the room); the wall line (min of wall and jamb, minus the opening: 0.73
    against 0.0) finds the hinge."""
    occupied = np.zeros((80, 100), dtype=bool)
    occupied[14:21, :] = True  # the smeared wall ...
    occupied[14:21, 40:58] = False  # ... with an 18-cell doorway
    rows = np.arange(18, 44)  # the panel, hinged at (18, 40), swung into +row
    cols = np.full(len(rows), 40)
    occupied[rows, cols] = True
    occupied[40:50, 64:76] = True  # the cupboard
    got = opening_from_panel(rows, cols, occupied, min_width=8)
    assert got is not None
    r, c = got
    assert np.all((r >= 14) & (r <= 20))  # along the wall ...
    assert c.min() <= 41 and c.max() >= 57  # ... across the whole doorway

def test_panel_of_a_door_at_a_rooms_corner_gives_its_doorway() -> None:
    """A door whose opening ends at a room's corner (the wall across it at row 20, the
    door's own wall along column 40 from row 39 up), hinged at its other end and swung
    into +column: no wall continues past the opening for the far-jamb ray (beyond the
    wall across it lies unseen space), and a panel smeared 2 cells longer than its
    doorway puts the jamb ray past that thin wall. The wall across the doorway's line
    is its jamb; the doorway ends there."""
    occupied = np.zeros((70, 100), dtype=bool)
    occupied[19:21, :] = True  # the wall across the doorway (the room's corner)
    occupied[39:, 39:42] = True  # the door's own wall, from the hinge up
    rows = np.full(20, 39)  # the panel: 20 cells (doorway 18), hinged at (39, 40)
    cols = np.arange(42, 62)
    occupied[rows, cols] = True
    free = ~occupied
    free[:19] = False  # unseen past the wall across
    got = opening_from_panel(rows, cols, occupied, min_width=8, free=free)
    assert got is not None
    r, c = got
    assert np.all(np.abs(c - 41) <= 1)  # along the door's wall line ...
    assert r.max() >= 38 and 20 <= r.min() <= 22  # ... from the hinge to the corner


def test_a_wall_across_is_a_jamb_only_when_nothing_else_decides() -> None:
    """A door mid-wall with a side wall 0.2 m past its far jamb and a cabinet just past the
    leaf's free end: counting the side wall as the free end's far jamb made both ends of
    the leaf score as hinges, and the doorway was lost (the rooms merged). The wall across
    is asked only when the usual jambs decide nothing."""
    occupied = np.zeros((80, 110), dtype=bool)
    occupied[20:22, :] = True
    occupied[20:22, 40:58] = False  # the doorway, columns 40-57
    occupied[22:61, 62:64] = True  # a side wall past the far jamb
    occupied[42:53, 33:52] = True  # a cabinet past the leaf's free end
    rows = np.arange(22, 41)  # the leaf, hinged at (21, 40), swung into +row
    cols = np.full(len(rows), 40)
    occupied[rows, cols] = True
    got = opening_from_panel(rows, cols, occupied, min_width=8, free=~occupied)
    assert got is not None
    r, c = got
    assert np.all((r >= 19) & (r <= 22))
    assert c.min() <= 41 and c.max() >= 56


def _wall_with_doorway() -> tuple[np.ndarray, np.ndarray]:
    """A wall along x at row 20 with an 18-cell doorway (columns 40-57); floor seen free
    everywhere else."""
    occupied = np.zeros((70, 100), dtype=bool)
    occupied[20, :] = True
    occupied[20, 40:58] = False
    return occupied, ~occupied


def test_panel_seen_only_far_from_its_hinge_still_gives_its_doorway() -> None:
    """Near its hinge a swung panel stands in the corner and may go unseen: the seen part
    (rows 27-38) ends 7 cells short of the wall, unseen cells between. The wall line is
    looked for that far out, and the doorway spans the whole door (panel and unseen
    part); floor seen free in that gap says the panel ends there: no doorway."""
    occupied, free = _wall_with_doorway()
    rows = np.arange(27, 39)  # hinged at (20, 40), swung into +row
    cols = np.full(len(rows), 40)
    occupied[rows, cols], free[rows, cols] = True, False
    free[21:27, 39:42] = False  # never seen
    got = opening_from_panel(rows, cols, occupied, min_width=8, free=free)
    assert got is not None
    r, c = got
    assert np.all(np.abs(r - 20) <= 1)
    assert c.min() <= 41 and 56 <= c.max() <= 59
    free[21:27, 39:42] = True  # floor seen where the panel would have to be
    assert opening_from_panel(rows, cols, occupied, min_width=8, free=free) is None


def test_counter_past_a_panels_free_end_is_no_wall_line() -> None:
    """A counter 3 cells past a whole panel's free end, floor seen between, looks like a
    wall line with the panel's gap in it (wall and jamb rays both hit it), as close as
    the true hinge: without what was seen free neither wins; with it the free end's line
    is ruled out and the doorway is found at the hinge."""
    occupied, _ = _wall_with_doorway()
    rows = np.arange(21, 39)  # hinged at (20, 57), swung into +row
    cols = np.full(len(rows), 57)
    occupied[rows, cols] = True
    occupied[42:50, 30:75] = True  # the counter
    occupied[22:34, 64:80] = True  # a cupboard beside the hinge
    assert opening_from_panel(rows, cols, occupied, min_width=8) is None
    got = opening_from_panel(rows, cols, occupied, min_width=8, free=~occupied)
    assert got is not None
    r, c = got
    assert np.all(np.abs(r - 20) <= 1)
    assert c.max() >= 56 and 39 <= c.min() <= 41


def test_panel_line_takes_thin_columns_in_line_not_beside_or_in_the_wall() -> None:
    """Core columns (10 voxels) at rows 30-38; thin columns (2 voxels) continue it down to
    row 25 with a 1-row gap, stand beside it (column 41), lie beyond a 4-row gap (rows
    10-14), and sit in the wall's row 23 beside occupied cells on both sides."""
    occupied = np.zeros((60, 60), dtype=bool)
    occupied[23, :] = True
    core_rows = np.arange(30, 39)
    thin_rows = np.array([25, 26, 27, 29])
    rows = np.concatenate([core_rows, thin_rows, [33, 34], [10, 11, 12, 13, 14], [23]])
    cols = np.concatenate([np.full(len(core_rows) + len(thin_rows), 40), [41, 41],
                           np.full(5, 40), [40]])
    counts = np.concatenate([np.full(len(core_rows), 10), np.full(len(rows) - 9, 2)])
    (cr, cc), (lr, lc) = panel_cells(rows, cols, counts, occupied)
    assert sorted(zip(cr.tolist(), cc.tolist(), strict=True)) == [(r, 40) for r in range(30, 39)]
    assert sorted(zip(lr.tolist(), lc.tolist(), strict=True)) == [
        (r, 40) for r in (25, 26, 27, 29)] + [
        (r, 40) for r in range(30, 39)]


# ----- assignment -----------------------------------------------------------------------
def test_assignment_goes_around_the_wall_not_through_it() -> None:
    """A wall at x = 4 with a doorway at y 2.6-3.0. The object stands against the wall in
    the left room, seen from (2, 0.5); the nearest node (0.4 m) is in the right room."""
    h, w = 80, 180
    g = np.full((h, w), FREE, dtype=np.int8)
    g[:, 80] = OCCUPIED
    g[52:60, 80] = FREE
    occ = OccupancyGrid(g, (0.0, 0.0), RES)
    left = [(x, 1.5) for x in (0.5, 1.0, 1.5, 2.0, 2.5, 3.0, 3.5)] + [(3.5, 2.8)]
    right = [(4.5, 2.8), (4.3, 1.5), (4.3, 0.5), (5.0, 1.5), (6.0, 1.5)]
    pos = np.array(left + right)
    room = np.array([0] * len(left) + [1] * len(right))
    edges = [(i, i + 1) for i in range(6)] + [(6, 7), (7, 8), (8, 9), (9, 10), (9, 11),
                                              (11, 12)]
    e = np.array(edges)
    wts = np.hypot(*(pos[e[:, 0]] - pos[e[:, 1]]).T)
    graph = csr_matrix((np.r_[wts, wts], (np.r_[e[:, 0], e[:, 1]], np.r_[e[:, 1], e[:, 0]])),
                       shape=(len(pos),) * 2)
    obj = np.array([[3.9, 0.5]])
    vp = np.array([[2.0, 0.5]])
    asg = assign_objects(pos, room, graph, obj, vp, occ, g == OCCUPIED)
    assert room[asg.node[0]] == 0
    # without a viewpoint only the Euclidean term is left: the wrong room
    blind = assign_objects(pos, room, graph, obj, np.full((1, 2), np.nan), occ, g == OCCUPIED)
    assert room[blind.node[0]] == 1
    # the cost is MoMa-LLM's: path / u + (|o - n| / u) ** 1.3 + |vp - v| / u
    cfg = AssignConfig()
    n = asg.node[0]
    euc = (np.hypot(*(obj[0] - pos[n])) / cfg.unit) ** cfg.exponent
    assert asg.cost[0] > euc


# ----- frontiers ------------------------------------------------------------------------
def test_frontier_types() -> None:
    """A 4 m x 3 m room whose left wall has a 1 m gap to the unknown outside, an enclosed
    1 m x 1 m unseen pocket inside, and a tiny 0.1 m x 0.1 m one."""
    h, w = cell(3.0) + 4, cell(4.0) + 4
    g = np.full((h, w), UNKNOWN, dtype=np.int8)
    g[2:-2, 2:-2] = OCCUPIED
    g[4:-4, 4:-4] = FREE
    g[cell(1.0):cell(2.0), 2:4] = FREE  # the gap in the left wall
    g[cell(1.0):cell(2.0), cell(2.5):cell(3.5)] = UNKNOWN  # pocket
    g[cell(0.4):cell(0.5), cell(1.5):cell(1.6)] = UNKNOWN  # tiny pocket
    occ = OccupancyGrid(g, (-4 * RES, -4 * RES), RES)
    fr = find_frontiers(occ, (1.0, 2.5), FrontierConfig(max_size=10.0))
    kinds = sorted((f.type, round(f.medoid[0])) for f in fr)
    assert kinds == [("leading out", 0), ("unexplored area", 3)]
    out = next(f for f in fr if f.leading_out)
    assert out.size == pytest.approx(1.0, abs=0.15)
    # nothing reachable from a start outside the room's free space component
    assert all(f.cells.shape[1] == 2 for f in fr)


def test_long_frontiers_are_split() -> None:
    h, w = 60, 200
    g = np.full((h, w), FREE, dtype=np.int8)
    g[30:, :] = UNKNOWN
    g[:30, 0] = g[:30, -1] = g[0, :] = OCCUPIED  # walls on three sides
    occ = OccupancyGrid(g, (0.0, 0.0), RES)
    fr = find_frontiers(occ, (1.0, 0.5), FrontierConfig(max_size=2.5))
    # 196 cells (the two next to the side walls excluded) in pieces of at most 2.5 m
    assert len(fr) == 4
    assert sum(f.size for f in fr) == pytest.approx(196 * RES)
    assert all(f.leading_out for f in fr)


# ----- regions --------------------------------------------------------------------------
def test_regions_split_long_rooms_deterministically() -> None:
    pos = np.array([[x, 0.0] for x in np.arange(0.0, 12.0, 0.5)])
    reg = cluster_room(pos, length=11.5, centre=12)
    assert len(reg.centres) == 3  # round(11.5 / 4)
    # contiguous clusters along the line (labels change twice), numbered by centre node
    assert np.count_nonzero(np.diff(reg.labels)) == 2
    assert list(reg.labels) == sorted(reg.labels)
    assert list(reg.centres) == sorted(reg.centres)
    again = cluster_room(pos, length=11.5, centre=12)
    assert np.array_equal(reg.labels, again.labels)
    one = cluster_room(pos[:3], length=1.0, centre=1)
    assert len(one.centres) == 1 and set(one.labels) == {0}


# ----- categories -----------------------------------------------------------------------
def test_frequency_classifier_is_naive_bayes() -> None:
    table = {"kitchen": {"Refrigerator": 8, "cup": 2}, "bedroom": {"bed": 9, "cup": 1}}
    clf = FrequencyRoomClassifier(table, alpha=1.0)
    assert isinstance(clf, RoomClassifier)
    ranked = clf.classify(["refrigerator", "cup", "spaceship"])
    assert [r for r, _ in ranked] == ["kitchen", "bedroom"]
    # P(kitchen) / P(bedroom) = (9/13 * 3/13) / (1/13 * 2/13)  (V = 3, N = 10 each)
    p = dict(ranked)
    assert p["kitchen"] / p["bedroom"] == pytest.approx((9 * 3) / (1 * 2))
    assert sum(p.values()) == pytest.approx(1.0)
    assert clf.classify(["spaceship"]) == [] and clf.classify([]) == []
    with pytest.raises(ValueError):
        FrequencyRoomClassifier({})


@pytest.mark.parametrize("objects,room", [
    (["bed", "nightstand"], "bedroom"),
    (["toilet", "bathtub"], "bathroom"),
    (["refrigerator", "stove", "dishwasher"], "kitchen"),
    (["sofa", "coffee table", "television"], "living_room"),
])
def test_classifier_from_training_knowledge(objects: list[str], room: str) -> None:
    clf = _trained()
    assert clf.classify(objects)[0][0] == room


_CLF: list[FrequencyRoomClassifier] = []


def _trained() -> FrequencyRoomClassifier:
    if not _CLF:
        _CLF.append(frequency_room_classifier())
    return _CLF[0]
