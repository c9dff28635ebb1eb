"""The scene-graph parameters pinned by behaviour on small synthetic maps and graphs.

Each test builds a map (or graph) whose outcome flips when a default of the stage's config
(:class:`RoomConfig`, :class:`AssignConfig`, :class:`FrontierConfig`) moves by 20 % (up or
down), so a change of a default in the source fails here with a reason, not only as a
changed golden digest. Every test reads the default from the config class and says in a
comment where the decision boundary lies and why the default is next to it.
"""

from __future__ import annotations

import dataclasses

import networkx as nx
import numpy as np
import pytest
from scipy import ndimage
from scipy.sparse import csr_matrix
from support.grids import walled

from sgtool.mapping.grid import FREE, OCCUPIED, UNKNOWN, OccupancyGrid
from sgtool.mapping.voronoi import VoronoiGraph, voronoi_graph
from sgtool.scenegraph.assign import AssignConfig, assign_objects
from sgtool.scenegraph.door_evidence import UNSURE_REACH
from sgtool.scenegraph.frontiers import FrontierConfig, find_frontiers
from sgtool.scenegraph.room_segmentation import RoomConfig, door_density, segment_rooms

RES = 0.05
ROOMS = RoomConfig()


# ----- door threshold and door KDE bandwidth (RoomConfig) --------------------------------
# A corridor runs past door evidence lying against its wall (an open door panel swung flat
# against the wall: its cells are the door's evidence). Whether the corridor is cut there
# is the question "how close to a door does the cut reach", which the threshold and the
# bandwidth decide together. Next to a long line of door cells one cell thick the density is
# cell / (sqrt(2 pi) sigma) * exp(-d^2 / (2 sigma^2)) = 0.133 * exp(-d^2 / 0.045) at
# sigma = 0.15 m (room_segmentation's module doc).
#
# - NEAR: a 0.5 m corridor (10 cells) past a 0.9 m panel one cell (5 cm) thick in its wall:
#   the centre line is 5 cells = 0.25 m from the panel, density 0.133 * exp(-1.39) = 0.033
#   = 1.10 x the default threshold 0.03: cut into two rooms. At 1.2 x (or 1.33 x) the
#   threshold, or with a bandwidth 20 % smaller (0.12 m: 0.166 * exp(-2.17) = 0.019), it is
#   not cut.
# - FAR: a 0.55 m corridor (11 cells) past a panel two cells (0.1 m) thick: the centre line
#   is 0.30 and 0.35 m from its two rows, density 0.133 * (exp(-2) + exp(-2.72)) = 0.027
#   = 0.89 x the threshold: not cut. At 0.8 x the threshold, or with a bandwidth 20 %
#   larger (0.18 m: 0.111 * (exp(-1.39) + exp(-1.89)) = 0.044), it is cut.


def corridor_past_door(width_cells: int, panel_cells: int) -> tuple[VoronoiGraph, np.ndarray]:
    """A corridor ``width_cells`` wide and 5 m long; the door evidence: ``panel_cells``
    rows of the wall next to its middle 0.9 m (18 cells)."""
    g = walled(width_cells, 100)
    occ = OccupancyGrid(g, (0.0, 0.0), RES)
    door = np.zeros(g.shape, dtype=bool)
    door[4 - panel_cells:4, 4 + 41:4 + 59] = True  # x 2.05-2.95 m of the corridor
    return voronoi_graph(occ), door


NEAR = (10, 1)
FAR = (11, 2)


def rooms_past_door(case: tuple[int, int], threshold: float, bandwidth: float) -> int:
    vg, door = corridor_past_door(*case)
    dens = door_density(door, RES, bandwidth)
    cfg = dataclasses.replace(ROOMS, door_threshold=threshold, door_bandwidth=bandwidth)
    return segment_rooms(vg, dens, cfg).count


def peak_on_ridge(case: tuple[int, int], bandwidth: float) -> float:
    vg, door = corridor_past_door(*case)
    dens = door_density(door, RES, bandwidth).ravel()
    return float(max(dens[cells].max() for cells in vg.edge_cells))


def test_door_density_next_to_the_corridors() -> None:
    """The densities the comment above computes (they depend on the bandwidth only)."""
    bw = ROOMS.door_bandwidth
    assert peak_on_ridge(NEAR, bw) == pytest.approx(0.033, abs=0.001)
    assert peak_on_ridge(FAR, bw) == pytest.approx(0.0267, abs=0.001)


def test_door_threshold_decides_how_close_a_corridor_may_pass_a_door() -> None:
    t, bw = ROOMS.door_threshold, ROOMS.door_bandwidth
    # the default sits between the two corridors' densities
    assert peak_on_ridge(FAR, bw) < t <= peak_on_ridge(NEAR, bw)
    assert rooms_past_door(NEAR, t, bw) == 2  # cut at the door: two rooms
    assert rooms_past_door(FAR, t, bw) == 1  # passes the door uncut
    # the default is within 20 % of both: a higher threshold keeps NEAR whole,
    # a lower one cuts FAR
    assert rooms_past_door(NEAR, 1.2 * t, bw) == 1
    assert rooms_past_door(NEAR, 1.33 * t, bw) == 1
    assert rooms_past_door(FAR, 0.8 * t, bw) == 2


def test_door_bandwidth_decides_how_far_the_door_reaches() -> None:
    t, bw = ROOMS.door_threshold, ROOMS.door_bandwidth
    assert rooms_past_door(NEAR, t, bw) == 2
    assert rooms_past_door(FAR, t, bw) == 1
    assert rooms_past_door(NEAR, t, 0.8 * bw) == 1  # narrower kernel: no longer reaches
    assert rooms_past_door(FAR, t, 1.2 * bw) == 2  # wider kernel: reaches the far one


def test_a_door_in_the_passage_cuts_whatever_the_parameters() -> None:
    """Sanity: door evidence across the corridor (a doorway) cuts it at 0.5 x .. 2 x the
    defaults; the tests above probe the fringe, not the doorway itself."""
    g = walled(10, 100)
    occ = OccupancyGrid(g, (0.0, 0.0), RES)
    vg = voronoi_graph(occ)
    door = np.zeros(g.shape, dtype=bool)
    door[4:14, 4 + 49:4 + 51] = True
    for f in (0.5, 1.0, 2.0):
        dens = door_density(door, RES, ROOMS.door_bandwidth)
        cfg = dataclasses.replace(ROOMS, door_threshold=f * ROOMS.door_threshold)
        assert segment_rooms(vg, dens, cfg).count == 2


def test_a_corridor_cut_beside_a_door_is_joined_by_its_floor() -> None:
    """NEAR's graph is cut beside the door (two rooms), but the door's cut zone reaches
    only 0.3 m into the 0.5 m corridor: its floor joins up past the zone, so with the
    free cells it is one room. The doorway across the corridor still makes two (its cut
    zone spans the floor), at every threshold of the test above."""
    g = walled(NEAR[0], 100)
    vg, door = corridor_past_door(*NEAR)
    dens = door_density(door, RES, ROOMS.door_bandwidth)
    assert segment_rooms(vg, dens, ROOMS).count == 2
    occ = OccupancyGrid(g, (0.0, 0.0), RES)
    joined = segment_rooms(vg, dens, ROOMS, occ=occ)
    assert joined.count == 1
    assert joined.rooms[0].tolist() == np.flatnonzero(joined.labels == 0).tolist()
    assert joined.centres[0] in joined.rooms[0]
    across = np.zeros(g.shape, dtype=bool)
    across[4:4 + NEAR[0], 4 + 49:4 + 51] = True
    for f in (0.5, 1.0, 2.0):
        cfg = dataclasses.replace(ROOMS, door_threshold=f * ROOMS.door_threshold)
        assert segment_rooms(vg, door_density(across, RES, ROOMS.door_bandwidth), cfg,
                             occ=occ).count == 2


def floor(free: np.ndarray) -> OccupancyGrid:
    """A grid of ``free`` cells (else occupied), 5 cm cells, for a hand-made graph (whose
    node n sits in cell (0, n))."""
    return OccupancyGrid(np.where(free, FREE, OCCUPIED).astype(np.int8), (0.0, 0.0), RES)


def test_pieces_of_one_floor_are_one_room_centred_on_the_larger() -> None:
    """Two pieces of graph, 7 nodes (2.4 m of edges) and 5 (1.2 m), with no door between
    them: apart they are two rooms; on one free floor they are one, whose centre is the
    larger piece's (node 3 of its 0..6 chain; the smaller's middle node is nearer its
    ends). A wall of one cell between their floors keeps them apart, and so does a gap
    in that wall narrower than JOIN_WIDTH (0.15 m: 3 cells); a gap of 3 cells joins."""
    a_pts, a_e = chain(0.0, 0.0, 6, 0.4)
    b_pts, b_e = chain(0.0, 3.0, 4, 0.3)
    k = len(a_pts)
    vg = hand_graph(a_pts + b_pts, a_e + [(i + k, j + k) for i, j in b_e])
    assert segment_rooms(vg, None).count == 2
    one_floor = np.ones((12, k + 5), dtype=bool)
    seg = segment_rooms(vg, None, occ=floor(one_floor))
    assert seg.count == 1 and seg.rooms[0].tolist() == list(range(k + 5))
    assert seg.centres == (3,)
    walled = one_floor.copy()
    walled[:, k] = False  # node k stands in the wall; the pieces' floors either side
    assert segment_rooms(vg, None, occ=floor(walled)).count == 2
    for gap, rooms in ((1, 2), (2, 2), (3, 1)):
        gapped = walled.copy()
        gapped[6:6 + gap, k] = True
        assert segment_rooms(vg, None, occ=floor(gapped)).count == rooms, gap


def two_pieces(steps: int = 4, step: float = 0.3) -> VoronoiGraph:
    """Two pieces of graph for a 40 x 60 grid with a wall at column 30: their nodes on
    row 20, the first piece (2.4 m of edges) at columns 5-11, the second (``steps`` of
    ``step`` m) from column 45 on."""
    a_pts, a_e = chain(0.0, 0.0, 6, 0.4)
    b_pts, b_e = chain(0.0, 3.0, steps, step)
    k = len(a_pts)
    vg = hand_graph(a_pts + b_pts, a_e + [(i + k, j + k) for i, j in b_e])
    cells = np.stack([np.full(k + steps + 1, 20),
                      np.r_[np.arange(5, 5 + k), np.arange(45, 46 + steps)]], axis=1)
    return dataclasses.replace(vg, cells=cells, shape=(40, 60))


@pytest.mark.parametrize(("resolution", "joins_from"), [(0.1, 3), (0.05, 3), (0.04, 5),
                                                       (0.025, 7), (0.02, 9)])
def test_a_passage_joins_from_join_width_at_any_cell_size(resolution: float,
                                                          joins_from: int) -> None:
    """Two pieces of graph on floors either side of a one-cell wall with a gap: the gap
    joins them from the fewest odd number of cells at least JOIN_WIDTH (0.15 m) wide
    (erosion keeps passages of 2k + 1 cells), a cell narrower it does not, even where
    that is 0.15 m or more (4 cells of 4 cm; at 0.1 m cells 3 cells, 0.3 m)."""
    vg = two_pieces()
    assert joins_from % 2 == 1
    assert (joins_from - 2) * resolution < 0.15 <= joins_from * resolution + 1e-9
    for gap, rooms in ((joins_from - 1, 2), (joins_from, 1)):
        free = np.ones((40, 60), dtype=bool)
        free[:, 30] = False
        free[15:15 + gap, 30] = True
        occ = OccupancyGrid(np.where(free, FREE, OCCUPIED).astype(np.int8), (0.0, 0.0),
                            resolution)
        assert segment_rooms(vg, None, occ=occ).count == rooms, gap


def test_the_robots_path_joins_the_floor_it_crossed_but_not_through_a_door() -> None:
    """Two pieces of graph on floors either side of a one-cell wall (two rooms): the
    robot's path from one floor to the other across that wall (a phantom obstacle, a
    leaf or a container's door opened after it passed) makes them one room; the same
    path through door evidence on the wall (its cut zone) does not, nor does a path that
    stays on one side."""
    vg = two_pieces()
    free = np.ones((40, 60), dtype=bool)
    free[:, 30] = False
    occ = OccupancyGrid(np.where(free, FREE, OCCUPIED).astype(np.int8), (0.0, 0.0), RES)
    across = np.array([[0.5, 1.0], [1.2, 1.0], [1.8, 1.05], [2.4, 1.0]])  # x 0.5 -> 2.4 m
    assert segment_rooms(vg, None, occ=occ).count == 2
    assert segment_rooms(vg, None, occ=occ, trajectory=across).count == 1
    assert segment_rooms(vg, None, occ=occ, trajectory=across[:2]).count == 2
    door = np.zeros((40, 60), dtype=bool)
    door[12:28, 30] = True  # a doorway in the wall where the path crosses it
    dens = door_density(door, RES, ROOMS.door_bandwidth)
    assert segment_rooms(vg, dens, ROOMS, occ=occ, trajectory=across).count == 2
    assert segment_rooms(vg, None, occ=occ, unsure=door, trajectory=across).count == 2
    # drift: the path crosses the wall beside the doorway's evidence, 0.45 m from its end
    # (the doorway filled in the final map, the door seen 0.45 m off its passes)
    beside = np.zeros((40, 60), dtype=bool)
    beside[2:12, 30] = True
    dens = door_density(beside, RES, ROOMS.door_bandwidth)
    assert segment_rooms(vg, dens, ROOMS, occ=occ, unsure=beside, trajectory=across).count == 2


def test_a_short_piece_on_floor_of_its_own_is_a_room() -> None:
    """A room glimpsed through a door: its graph is a 0.6 m piece (under min_room_length),
    dropped on its own. On floor of its own of at least half min_room_length squared
    (0.5 m^2: 200 cells of 5 cm; a closet's) it is a room; on less floor, or on floor a
    long piece stands on, it is none (its nodes keep no room)."""
    a_pts, a_e = chain(0.0, 0.0, 6, 0.4)  # 2.4 m: a room
    b_pts, b_e = chain(0.0, 3.0, 3, 0.2)  # 0.6 m: short
    k = len(a_pts)
    vg = hand_graph(a_pts + b_pts, a_e + [(i + k, j + k) for i, j in b_e])
    assert segment_rooms(vg, None).count == 1

    def grid(rows: int, wall: bool = True) -> OccupancyGrid:
        free = np.zeros((rows, 40), dtype=bool)
        free[:3, :k] = True  # the long piece's floor
        free[:, k + 1:] = True  # the short piece's floor: rows x 40 - k - 1 cells ...
        free[:, k] = not wall  # ... behind a wall of one cell
        return floor(free)

    assert 32 * 6 < 200 <= 32 * 7  # 40 - 7 - 1 = 32 columns
    big = segment_rooms(vg, None, occ=grid(7))
    assert big.count == 2 and big.rooms[1].tolist() == list(range(k, k + 4))
    assert big.labels[k:].tolist() == [1] * 4
    assert segment_rooms(vg, None, occ=grid(6)).count == 1  # under 0.5 m^2
    seg = segment_rooms(vg, None, occ=grid(7, wall=False))  # one floor for both
    assert seg.count == 1 and seg.rooms[0].tolist() == list(range(k))


def test_a_pocket_beside_a_doorway_is_no_room_of_its_own() -> None:
    """A 0.6 m piece of graph (short) on floor right of a wall at column 30, a 2.4 m one
    left of it; the wall has a 0.8 m gap (rows 10-25) whose rows 10-19 hold door
    evidence. Within JOIN_SEAL (6 cells) of the evidence the floor joins nothing, so the
    right floor has no long piece on it and was a room of its own (a pocket at a
    corridor's end whose mouth runs past a doorway, house 1105). Its floor joins the left
    one beside the evidence (rows 21-25, off a cell's margin): no room. With the whole gap
    door evidence (a closet's doorway), it is one."""
    vg = two_pieces(3, 0.2)  # 0.6 m: short
    free = np.ones((40, 60), dtype=bool)
    free[:, 30] = False
    free[10:26, 30] = True
    occ = floor(free)
    for evidence, rooms in ((slice(10, 20), 1), (slice(10, 26), 2)):
        door = np.zeros((40, 60), dtype=bool)
        door[evidence, 30] = True
        assert segment_rooms(vg, None, occ=occ, unsure=door).count == 2  # as before
        assert segment_rooms(vg, None, occ=occ, unsure=door, doors=door).count == rooms


# ----- hand-made Voronoi graphs ----------------------------------------------------------
def hand_graph(positions: list[tuple[float, float]], edges: list[tuple[int, int]],
               lengths: list[float] | None = None) -> VoronoiGraph:
    """A VoronoiGraph from node positions and edges (lengths: Euclidean unless given);
    its grid is a dummy (no door density is used with it)."""
    pos = np.asarray(positions, dtype=np.float64)
    e = np.asarray(sorted((min(a, b), max(a, b)) for a, b in edges), dtype=np.int64)
    if lengths is None:
        ln = np.hypot(*(pos[e[:, 0]] - pos[e[:, 1]]).T)
    else:
        by = {(min(a, b), max(a, b)): x for (a, b), x in zip(edges, lengths, strict=True)}
        ln = np.asarray([by[(int(a), int(b))] for a, b in e], dtype=np.float64)
    g = nx.Graph()
    for i, p in enumerate(pos):
        g.add_node(i, pos=(float(p[0]), float(p[1])), clearance=1.0, cell=(0, i))
    for (a, b), x in zip(e.tolist(), ln.tolist(), strict=True):
        g.add_edge(a, b, weight=x)
    n = len(pos)
    return VoronoiGraph(g, pos, np.ones(n), np.stack([np.zeros(n, np.int64),
                                                       np.arange(n)], axis=1),
                        e, ln, tuple(np.zeros(1, np.int64) for _ in e),
                        np.zeros((1, n), dtype=bool), (1, n))


def chain(x0: float, y: float, steps: int, step: float) -> tuple[list, list]:
    pts = [(x0 + i * step, y) for i in range(steps + 1)]
    return pts, [(i, i + 1) for i in range(steps)]


# ----- min room size (RoomConfig.min_room_length) ----------------------------------------
def test_min_room_length_drops_short_pieces_of_graph() -> None:
    """Two separate pieces of graph (say, two alcoves cut off by doors): 1.1 m and 0.9 m
    of edges (chains of 0.22 m and 0.18 m steps). With the default minimum of 1.0 m the
    first is a room and the second is not; at 1.2 m neither is, at 0.8 m both are."""
    a_pts, a_e = chain(0.0, 0.0, 5, 0.22)  # 1.1 m
    b_pts, b_e = chain(0.0, 3.0, 5, 0.18)  # 0.9 m
    k = len(a_pts)
    vg = hand_graph(a_pts + b_pts, a_e + [(i + k, j + k) for i, j in b_e])
    m = ROOMS.min_room_length
    assert 0.9 < m <= 1.1
    seg = segment_rooms(vg, None)
    assert seg.count == 1 and seg.rooms[0].tolist() == list(range(k))
    assert (seg.labels[k:] == -1).all()  # the short piece's nodes keep no room
    big = dataclasses.replace(ROOMS, min_room_length=1.2 * m)
    small = dataclasses.replace(ROOMS, min_room_length=0.8 * m)
    assert segment_rooms(vg, None, big).count == 0
    assert segment_rooms(vg, None, small).count == 2


# ----- room centre rule (room_segmentation._graph_centre) --------------------------------
def test_room_centre_is_the_node_of_minimum_eccentricity() -> None:
    """A room whose graph is a 6 m corridor (nodes 0..6 at x = 0..6, 1 m apart) with six
    0.5 m spurs hanging off node 1 (a cluttered corner). The centre is the node whose
    farthest node is nearest (graph centre, MoMa-LLM): node 3, 3 m from both ends. Other
    rules pick other nodes: the medoid (least summed distance) is node 1 (sum 19 m vs 22 m
    for node 2 and 27 m for node 3), the node nearest the mean position is node 2
    (mean x = 2.1)."""
    pts, edges = chain(0.0, 0.0, 6, 1.0)
    for j in range(6):  # spurs around node 1
        ang = np.pi * (j + 0.5) / 6
        pts.append((1.0 + 0.5 * np.cos(ang), 0.5 * np.sin(ang)))
        edges.append((1, 7 + j))
    vg = hand_graph(pts, edges)
    seg = segment_rooms(vg, None)
    assert seg.count == 1
    assert seg.centres == (3,)
    # the alternatives named above really differ
    d = nx.floyd_warshall_numpy(vg.graph, weight="weight")
    assert int(np.argmin(d.sum(axis=1))) == 1
    mean = vg.positions.mean(axis=0)
    assert int(np.argmin(np.hypot(*(vg.positions - mean).T))) == 2
    # ties go to the lowest node id: a 4-node chain has two middle nodes
    p4, e4 = chain(0.0, 0.0, 3, 1.0)
    assert segment_rooms(hand_graph(p4, e4), None).centres == (1,)


# ----- assignment exponent and unit (AssignConfig) ---------------------------------------
# MoMa-LLM's cost: path / u + (|o - n| / u) ** p (+ |vp - v| / u, 0 here). The object lies
# on node A (room 0); node B (room 1) is 0.75 m from it. From the viewpoint (node V), B is
# 6 m along the graph and A 6 m + detour. A wins while
#     detour / u < (0.75 / u) ** p,  i.e.  detour < u * (0.75 / u) ** p = 0.75^p * u^(1-p),
# which at the defaults (u = 0.075 m, p = 1.3) is 10 ** 1.3 * 0.075 = 1.496 m. Two
# objects with detours 1.46 m (-2.4 %) and 1.53 m (+2.3 %) sit on either side:
# - p up 20 % (1.56): the boundary moves to 10^1.56 * 0.075 = 2.72 m: both go to A;
# - p down 20 % (1.04): 0.82 m: both go to B;
# - u up 20 % (0.09 m): 0.75^1.3 * 0.09^-0.3 = 1.417 m: both go to B;
# - u down 20 % (0.06 m): 1.600 m: both go to A.
D_B = 0.75
DETOURS = (1.46, 1.53)


def assigned_rooms(cfg: AssignConfig) -> list[int]:
    out = []
    for detour in DETOURS:
        pos = np.array([[0.0, 0.0], [6.0, 0.0], [6.0, D_B]])  # V, B, A
        room = np.array([-1, 1, 0])
        e = np.array([[0, 1], [0, 2]])
        w = np.array([6.0, 6.0 + detour])
        graph = csr_matrix((np.r_[w, w], (np.r_[e[:, 0], e[:, 1]], np.r_[e[:, 1], e[:, 0]])),
                           shape=(3, 3))
        # no occupancy grid: no line-of-sight test; A and B are > 5 m from the viewpoint,
        # so the viewpoint's only node is V itself
        asg = assign_objects(pos, room, graph, pos[2:3], pos[0:1], config=cfg)
        out.append(int(room[asg.node[0]]))
    return out


def test_assignment_balance_of_path_and_distance() -> None:
    cfg = AssignConfig()
    boundary = cfg.unit * (D_B / cfg.unit) ** cfg.exponent
    assert DETOURS[0] < boundary < DETOURS[1]
    assert boundary == pytest.approx(1.496, abs=0.001)
    assert assigned_rooms(cfg) == [0, 1]
    # 20 % either way of either parameter moves the boundary past one of the detours
    rep = dataclasses.replace
    assert assigned_rooms(rep(cfg, exponent=1.2 * cfg.exponent)) == [0, 0]
    assert assigned_rooms(rep(cfg, exponent=0.8 * cfg.exponent)) == [1, 1]
    assert assigned_rooms(rep(cfg, unit=1.2 * cfg.unit)) == [1, 1]
    assert assigned_rooms(rep(cfg, unit=0.8 * cfg.unit)) == [0, 0]


# ----- frontier size (FrontierConfig.min_size) -------------------------------------------
def test_frontier_min_size_drops_small_gaps() -> None:
    """A 4 m x 2 m room (5 cm cells) whose top wall, one cell thick, has two gaps to the
    unknown outside: 8 and 7 cells wide. Their frontiers are the gap cells not next to an
    occupied cell: 6 and 5 cells, 0.30 m and 0.25 m. The default minimum 0.3 m is
    round(0.3 / 0.05) = 6 cells: only the first counts. At 1.2 x 0.3 = 0.36 m (7 cells)
    neither does, at 0.8 x 0.3 = 0.24 m (5 cells) both do."""
    h, w = 40, 80
    g = np.full((h + 4, w + 2), UNKNOWN, dtype=np.int8)
    g[0:h + 2, 0:w + 2] = OCCUPIED
    g[1:h + 1, 1:w + 1] = FREE
    top = h + 1
    g[top, 10:18] = FREE  # 8-cell gap
    g[top, 50:57] = FREE  # 7-cell gap
    occ = OccupancyGrid(g, (0.0, 0.0), RES)
    start = (2.0, 1.0)
    cfg = FrontierConfig()
    assert round(cfg.min_size / RES) == 6
    sizes = [f.size for f in find_frontiers(occ, start, cfg)]
    assert sizes == pytest.approx([0.30])
    big = dataclasses.replace(cfg, min_size=1.2 * cfg.min_size)
    small = dataclasses.replace(cfg, min_size=0.8 * cfg.min_size)
    assert find_frontiers(occ, start, big) == []
    assert sorted(f.size for f in find_frontiers(occ, start, small)) == pytest.approx(
        [0.25, 0.30])


def room_with_gaps(width: int, gaps: list[tuple[int, int]]) -> OccupancyGrid:
    """A ``width`` x 40-cell room (5 cm cells) in a one-cell wall, unknown beyond its top
    wall, which has gaps (first column, cells wide)."""
    g = np.full((44, width + 2), UNKNOWN, dtype=np.int8)
    g[0:42, :] = OCCUPIED
    g[1:41, 1:width + 1] = FREE
    for c0, n in gaps:
        g[41, c0:c0 + n] = FREE
    return OccupancyGrid(g, (0.0, 0.0), RES)


# ----- frontier splitting (FrontierConfig.max_size) --------------------------------------
def test_frontier_max_size_splits_long_gaps() -> None:
    """Gaps of 57 and 47 cells in the top wall give frontiers of 55 and 45 cells (2.75 m,
    2.25 m). The default maximum 2.5 m (50 cells) splits the first in two pieces and keeps
    the second whole: 3 frontiers. At 1.2 x 2.5 = 3.0 m (60 cells) neither is split (2);
    at 0.8 x 2.5 = 2.0 m (40 cells) both are (4)."""
    occ = room_with_gaps(120, [(3, 57), (65, 47)])
    cfg = FrontierConfig()
    assert round(cfg.max_size / RES) == 50
    got = find_frontiers(occ, (2.0, 1.0), cfg)
    assert sorted(round(f.size, 3) for f in got) == pytest.approx([1.35, 1.4, 2.25])
    rep = dataclasses.replace
    assert len(find_frontiers(occ, (2.0, 1.0), rep(cfg, max_size=1.2 * cfg.max_size))) == 2
    assert len(find_frontiers(occ, (2.0, 1.0), rep(cfg, max_size=0.8 * cfg.max_size))) == 4


# ----- unseen pockets (FrontierConfig.min_pocket) ----------------------------------------
def test_frontier_min_pocket_ignores_small_unseen_pockets() -> None:
    """A closed 6 m x 2 m room (5 cm cells, 0.0025 m^2 each) with two unseen pockets
    inside: 14 x 15 cells (0.525 m^2) and 13 x 14 cells (0.455 m^2). The default minimum
    0.5 m^2 (200 cells) keeps the first as an "unexplored area" frontier and ignores the
    second. At 1.2 x 0.5 = 0.6 m^2 both are ignored, at 0.8 x 0.5 = 0.4 m^2 both count."""
    g = np.full((44, 124), OCCUPIED, dtype=np.int8)
    g[2:42, 2:122] = FREE
    g[12:26, 20:35] = UNKNOWN  # 14 x 15
    g[12:25, 80:94] = UNKNOWN  # 13 x 14
    occ = OccupancyGrid(g, (0.0, 0.0), RES)
    cfg = FrontierConfig()
    assert 182 < cfg.min_pocket / RES**2 <= 210

    def pockets(c: FrontierConfig) -> list[int]:
        fr = find_frontiers(occ, (0.5, 0.5), c)
        assert not any(f.leading_out for f in fr)
        return sorted({1 if f.medoid[0] < 2.5 else 2 for f in fr})

    assert pockets(cfg) == [1]
    assert pockets(dataclasses.replace(cfg, min_pocket=1.2 * cfg.min_pocket)) == []
    assert pockets(dataclasses.replace(cfg, min_pocket=0.8 * cfg.min_pocket)) == [1, 2]


# ----- assignment candidates (AssignConfig.candidate_radius) -----------------------------
def test_candidate_radius_decides_which_nodes_may_take_the_object() -> None:
    """An object with three labelled nodes around it: B (room 1) 2.3 m away, A (room 0)
    2.45 m away, D (room 2) 2.7 m away; along the graph from the viewpoint node V they are
    10 m, 8 m and 6 m away (2 m = 27 cost units apart, more than the Euclidean terms differ:
    (2.3 / 0.075)^1.3 = 86, (2.45 / 0.075)^1.3 = 93, (2.7 / 0.075)^1.3 = 106). The
    candidates are the labelled nodes within ``candidate_radius`` and the shortest path
    wins among them: at the default 2.5 m {B, A} -> A; at 1.2 x 2.5 = 3.0 m {B, A, D} -> D;
    at 0.8 x 2.5 = 2.0 m none, so the nearest labelled node B."""
    obj = np.array([[0.0, 0.0]])
    pos = np.array([[-12.0, 0.0], [2.3, 0.0], [0.0, 2.45], [-2.7, 0.0]])  # V, B, A, D
    room = np.array([-1, 1, 0, 2])
    e = np.array([[0, 1], [0, 2], [0, 3]])
    w = np.array([10.0, 8.0, 6.0])
    graph = csr_matrix((np.r_[w, w], (np.r_[e[:, 0], e[:, 1]], np.r_[e[:, 1], e[:, 0]])),
                       shape=(4, 4))
    vp = pos[0:1]  # the others are > 5 m away: V is the viewpoint's only node

    def room_of(cfg: AssignConfig) -> int:
        return int(room[assign_objects(pos, room, graph, obj, vp, config=cfg).node[0]])

    cfg = AssignConfig()
    assert 2.45 <= cfg.candidate_radius < 2.7
    assert room_of(cfg) == 0
    assert room_of(dataclasses.replace(cfg, candidate_radius=1.2 * cfg.candidate_radius)) == 2
    assert room_of(dataclasses.replace(cfg, candidate_radius=0.8 * cfg.candidate_radius)) == 1


def partly_open_door(degrees: float) -> tuple[OccupancyGrid, np.ndarray]:
    """Two rooms either side of a 2-cell wall at row 60 with an 18-cell (0.9 m) doorway
    at columns 70-87, its leaf hinged at (62, 70) and standing ``degrees`` open into the
    lower room; the leaf's cells are the door evidence (its doorway not found)."""
    g = walled(112, 152)
    g[60:62, 4:-4] = OCCUPIED
    g[60:62, 70:88] = FREE
    door = np.zeros(g.shape, dtype=bool)
    a = np.radians(degrees)
    for t in np.linspace(0.0, 17.0, 72):
        r, c = int(round(62 + t * np.sin(a))), int(round(70 + t * np.cos(a)))
        g[r, c] = OCCUPIED
        door[r, c] = True
    return OccupancyGrid(g, (0.0, 0.0), RES), door


def test_floor_near_unsure_door_evidence_joins_nothing() -> None:
    """A leaf standing 30 degrees open cuts the doorway's ridge (two rooms), but its cut
    zone leaves the far part of the opening open: the floor joins the rooms there, even
    0.3 m (JOIN_SEAL) from the leaf. The floor within a leaf's width (UNSURE_REACH, what
    door_evidence marks unsure around a leaf whose doorway it did not find) joins
    nothing, so they stay two. Doorway cells covering 60 % of an opening from one jamb
    leave a gap narrower than JOIN_SEAL and JOIN_WIDTH together: two rooms as well."""
    occ, door = partly_open_door(30)
    vg = voronoi_graph(occ)
    dens = door_density(door, RES, ROOMS.door_bandwidth)
    assert segment_rooms(vg, dens, ROOMS).count == 2
    assert segment_rooms(vg, dens, ROOMS, occ=occ).count == 1  # the leak
    assert segment_rooms(vg, dens, ROOMS, occ=occ, unsure=door).count == 1
    unsure = ndimage.distance_transform_edt(~door) <= UNSURE_REACH / RES
    assert segment_rooms(vg, dens, ROOMS, occ=occ, unsure=unsure).count == 2
    g = walled(60, 120)
    g[30:32, 4:-4] = OCCUPIED
    g[30:32, 60:78] = FREE
    part = np.zeros(g.shape, dtype=bool)
    part[30:32, 60:71] = True  # 11 of the 18 cells, from one jamb
    grid = OccupancyGrid(g, (0.0, 0.0), RES)
    vg = voronoi_graph(grid)
    dens = door_density(part, RES, ROOMS.door_bandwidth)
    assert segment_rooms(vg, dens, ROOMS, occ=grid).count == 1  # without the seal
    assert segment_rooms(vg, dens, ROOMS, occ=grid, unsure=part).count == 2
