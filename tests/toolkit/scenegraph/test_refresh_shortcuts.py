"""Shortcuts of the refresh equal the plain computation exactly, on randomised inputs:
the door voxels kept from new keys (vs the voxel map's scan), the robot footprint stamped
for new trajectory points only (vs all points), the room sub-graphs (vs scipy's fancy
indexing), room neighbours from a memoised climb of the shortest-path tree (vs one walk
per pair), room edge lengths and edge cuts in one pass (vs one per room / edge)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.sparse import random as sparse_random
from scipy.sparse.csgraph import dijkstra
from support.synthetic_world import look_around, make_frame, two_room_house, walk, world_of_house

from sgtool.log.frame import CameraIntrinsics
from sgtool.mapping.bev import BevConfig, ColumnGrid, footprint
from sgtool.mapping.voronoi import VoronoiGraph, submatrix
from sgtool.mapping.voxels import VoxelConfig
from sgtool.scenegraph.builder import BuilderConfig, SceneGraphBuilder
from sgtool.scenegraph.door_evidence import open_doors
from sgtool.scenegraph.regions import RegionConfig
from sgtool.scenegraph.room_nodes import room_edge_lengths, room_regions
from sgtool.scenegraph.room_segmentation import (
    RoomConfig,
    RoomSegmentation,
    room_neighbours,
    segment_rooms,
)

RES = 0.05


def as_set(ijk: np.ndarray) -> set[tuple[int, int, int]]:
    return {tuple(int(v) for v in row) for row in ijk}


@pytest.mark.parametrize("opening", ["open", "closed"])
def test_door_voxels_kept_from_new_keys_equal_the_map_scan(opening: str) -> None:
    hw = world_of_house(two_room_house(opening))
    k = CameraIntrinsics.from_fov(80, 60, 60)
    poses = look_around(2.0, 1.5, 0.0, 8) + walk([(2.0, 1.5), (6.0, 1.5)], 0.5)
    b = SceneGraphBuilder(hw.instances, None,
                          BuilderConfig(voxels=VoxelConfig(min_points=5), refresh_every=3))
    doors = [i for i, v in hw.instances.items() if v.kind == "door"]
    checked = 0
    for i, (x, y, yaw) in enumerate(poses):
        b.integrate(make_frame(hw.world, x, y, yaw, k, index=i, pitch=0.3))
        if b.due():
            b.refresh(i)
            kept, scan = b._door_voxels.of(doors), b.voxels.voxels_of(doors)
            assert kept.keys() == scan.keys()
            for d in doors:
                assert as_set(kept[d]) == as_set(scan[d])
                assert len(kept[d]) == len(scan[d])  # each voxel once
            checked += sum(len(v) for v in scan.values())
    assert checked > 0  # the doors were seen
    # a door that changes state loses its voxels: the kept ones follow
    opened = {i: type(v)(**{**v.__dict__, "state": "open" if v.kind == "door" else v.state})
              for i, v in hw.instances.items()}
    b.set_instances(opened)
    b.refresh(len(poses))
    assert open_doors(b.instances) == doors
    scan = b.voxels.voxels_of(doors)
    assert {d: as_set(v) for d, v in b._door_voxels.of(doors).items()} == \
        {d: as_set(v) for d, v in scan.items()}


@pytest.mark.parametrize("seed", range(8))
def test_footprint_of_new_points_only_equals_all_points(seed: int) -> None:
    rng = np.random.default_rng(seed)
    cg = ColumnGrid(RES, BevConfig())
    traj: list[tuple[float, float]] = []
    for step in range(12):
        x0, y0 = traj[-1] if traj else (0.0, 0.0)
        for _ in range(int(rng.integers(0, 6))):
            x0, y0 = x0 + float(rng.normal(0, 0.4)), y0 + float(rng.normal(0, 0.4))
            traj.append((x0, y0))
        if step % 4 == 3:  # the map grows: a new extent
            cols = rng.integers(-200, 200, (3, 2))
            cg.add(type("C", (), {"occupied": cols, "floor": cols[:0]})(), traj)
        occ = cg.occupancy(traj)
        assert cg.extent is not None
        ref = footprint(traj, cg.extent, cg.flags.shape, RES, BevConfig().robot_radius) \
            if traj else np.zeros(cg.flags.shape, dtype=bool)
        assert np.array_equal(cg._footprint[2], ref)  # type: ignore[index]
        assert (occ.grid[ref] != -1).all()  # stamped cells are free (or occupied)
    assert len(traj) > 10


@pytest.mark.parametrize("seed", range(20))
def test_submatrix_equals_scipy_fancy_indexing(seed: int) -> None:
    rng = np.random.default_rng(seed)
    n = int(rng.integers(1, 60))
    m = sparse_random(n, n, density=float(rng.random()), random_state=seed, format="csr")
    m = (m + m.T).tocsr()
    m.sort_indices()
    nodes = np.sort(rng.choice(n, size=int(rng.integers(1, n + 1)), replace=False))
    where = np.full(n, -1, dtype=np.int64)
    got, ref = submatrix(m, nodes, where), m[nodes][:, nodes]
    assert (where == -1).all()
    for a in ("indptr", "indices", "data"):
        assert np.array_equal(getattr(got, a), getattr(ref, a))
    assert np.array_equal(dijkstra(got, directed=False), dijkstra(ref, directed=False))


def random_graph(seed: int) -> VoronoiGraph:
    """A random planar-ish graph: a grid of nodes with random edges and edge cells."""
    rng = np.random.default_rng(seed)
    side = int(rng.integers(3, 9))
    n = side * side
    pos = np.stack([np.arange(n) % side, np.arange(n) // side], axis=1).astype(float)
    edges = set()
    for u in range(n):
        for v in (u + 1, u + side):
            if v < n and (v != u + 1 or v % side) and rng.random() < 0.75:
                edges.add((u, v))
    e = np.asarray(sorted(edges), dtype=np.int64).reshape(-1, 2)
    lengths = rng.uniform(0.5, 1.5, len(e))
    h, w = 4 * side, 4 * side
    cells = np.stack([pos[:, 1] * 4, pos[:, 0] * 4], axis=1).astype(np.int64)
    mid = (cells[e[:, 0]] + cells[e[:, 1]]) // 2  # one ridge cell between the two nodes
    edge_cells = tuple(np.asarray([cells[u, 0] * w + cells[u, 1], mid[i, 0] * w + mid[i, 1],
                                   cells[v, 0] * w + cells[v, 1]]) for i, (u, v) in enumerate(e))
    return VoronoiGraph(None, pos, np.ones(n), cells, e, lengths, edge_cells,
                        np.zeros((h, w), bool), (h, w))


def neighbours_by_walking(vg: VoronoiGraph, seg: RoomSegmentation) -> list[tuple[int, int]]:
    """The plain form: walk every pair's path."""
    out = []
    if seg.count < 2:
        return out
    centres = np.asarray(seg.centres, dtype=np.int64)
    dist, pred = dijkstra(vg.csgraph(), directed=False, indices=centres,
                          return_predecessors=True)
    for a in range(seg.count):
        for b in range(a + 1, seg.count):
            t = int(centres[b])
            if not np.isfinite(dist[a, t]):
                continue
            seen, node = set(), t
            while node >= 0:
                if seg.labels[node] >= 0:
                    seen.add(int(seg.labels[node]))
                node = int(pred[a, node])
            if seen == {a, b}:
                out.append((a, b))
    return out


def check_room_stage(seed: int) -> tuple[int, int]:
    """Compare on one random graph; (rooms, neighbour pairs)."""
    vg = random_graph(seed)
    rng = np.random.default_rng(seed + 100)
    density = np.zeros(vg.shape)
    w = vg.shape[1]
    for _ in range(int(rng.integers(2, 14))):  # door evidence on some edges and nodes
        if rng.random() < 0.5:
            r, c = vg.cells[int(rng.integers(len(vg)))]
        else:
            r, c = divmod(int(vg.edge_cells[int(rng.integers(len(vg.edges)))][1]), w)
        density[r, c] = 1.0
    seg = segment_rooms(vg, density, RoomConfig(min_room_length=0.5))
    flat = density.ravel()
    plain_cut = np.asarray([flat[c].max() >= RoomConfig().door_threshold
                            for c in vg.edge_cells], dtype=bool)
    assert np.array_equal(seg.cut_edges, plain_cut)
    keep = ~seg.cut_edges & ~seg.cut_nodes[vg.edges[:, 0]] & ~seg.cut_nodes[vg.edges[:, 1]]
    graph = vg.csgraph(keep)
    for nodes, centre in zip(seg.rooms, seg.centres, strict=True):
        if len(nodes) > 1:
            d = dijkstra(graph[nodes][:, nodes], directed=False)
            assert centre == int(nodes[int(np.argmin(d.max(axis=1)))])
    assert room_neighbours(vg, seg) == neighbours_by_walking(vg, seg)
    for i, got in enumerate(room_edge_lengths(vg, seg)):
        inside = np.isin(vg.edges, seg.rooms[i]).all(axis=1)
        assert float(got.sum()) == float(vg.lengths[inside].sum())
    return seg.count, len(room_neighbours(vg, seg))


def test_room_stage_shortcuts_equal_the_plain_forms() -> None:
    got = [check_room_stage(seed) for seed in range(40)]
    # the random door evidence does cut the graphs into rooms with neighbours
    assert sum(c > 2 for c, _ in got) >= 10 and sum(n for _, n in got) >= 20


def test_networkx_view_is_built_from_the_arrays() -> None:
    vg = random_graph(3)
    assert vg.built is None
    g = vg.graph
    assert vg.graph is g and g.number_of_nodes() == len(vg)
    u, v = (int(x) for x in vg.edges[0])
    assert g[u][v]["weight"] == vg.lengths[0]
    assert g.nodes[u]["cell"] == tuple(int(x) for x in vg.cells[u])



def test_memoised_room_centres_and_regions_equal_fresh_ones() -> None:
    centre_memo: dict[bytes, int] = {}
    region_memo: dict = {}
    hits = 0
    for seed in list(range(12)) * 2:  # every graph twice: the second time from the memos
        vg = random_graph(seed)
        density = np.zeros(vg.shape)
        r, c = vg.cells[len(vg) // 2]
        density[r, c] = 1.0
        before = len(centre_memo)
        seg = segment_rooms(vg, density, RoomConfig(min_room_length=0.5), centre_memo)
        hits += len(centre_memo) == before and seg.count > 0
        fresh = segment_rooms(vg, density, RoomConfig(min_room_length=0.5))
        assert seg.centres == fresh.centres
        ids = [f"room:{i}" for i in range(seg.count)]
        got = room_regions(vg, seg, ids, RegionConfig(region_length=2.0), region_memo)
        assert got == room_regions(vg, seg, ids, RegionConfig(region_length=2.0))
    assert hits >= 10 and centre_memo and region_memo


def test_room_centres_from_one_memo_along_changing_graphs_equal_fresh_ones() -> None:
    """One centre memo carried along graphs that change a little at a time (a few edge
    lengths, by as little as one ulp, an edge dropped, the door evidence moved): every
    centre equals the one computed without the memo, and rooms left as they were are
    answered from it."""
    memo: dict[bytes, int] = {}
    hits = 0
    for seed in range(6):
        rng = np.random.default_rng(700 + seed)
        vg = random_graph(seed)
        density = np.zeros(vg.shape)
        for _ in range(3):
            r, c = vg.cells[int(rng.integers(len(vg)))]
            density[r, c] = 1.0
        for _step in range(8):
            before = len(memo)
            seg = segment_rooms(vg, density, RoomConfig(min_room_length=0.5), memo)
            fresh = segment_rooms(vg, density, RoomConfig(min_room_length=0.5))
            assert seg.centres == fresh.centres
            assert all(np.array_equal(a, b) for a, b in zip(seg.rooms, fresh.rooms, strict=True))
            hits += len(memo) - before < sum(len(r) > 1 for r in seg.rooms)
            lengths, edges, cells = vg.lengths.copy(), vg.edges, vg.edge_cells
            pick = rng.integers(0, len(lengths), size=2)
            if rng.random() < 0.5:
                lengths[pick] = np.nextafter(lengths[pick], np.inf)
            else:
                lengths[pick] *= rng.uniform(0.2, 3.0)
            if rng.random() < 0.3 and len(edges) > 4:
                drop = int(rng.integers(len(edges)))
                keep = np.arange(len(edges)) != drop
                edges, lengths = edges[keep], lengths[keep]
                cells = tuple(c for i, c in enumerate(cells) if i != drop)
            if rng.random() < 0.3:
                density = np.zeros(vg.shape)
                r, c = vg.cells[int(rng.integers(len(vg)))]
                density[r, c] = 1.0
            vg = VoronoiGraph(None, vg.positions, vg.clearance, vg.cells, edges, lengths,
                              cells, vg.ridge, vg.shape)
    assert hits >= 10
