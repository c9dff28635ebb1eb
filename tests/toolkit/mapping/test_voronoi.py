"""Generalized Voronoi graph on hand-made occupancy grids."""

from __future__ import annotations

import networkx as nx
import numpy as np
import pytest

from sgtool.mapping.esdf import distance_field
from sgtool.mapping.grid import FREE, OCCUPIED, UNKNOWN, OccupancyGrid
from sgtool.mapping.voronoi import VoronoiConfig, thin, voronoi_graph

RES = 0.05


def grid_of(width: float, height: float) -> np.ndarray:
    """A walled rectangle (walls 0.1 m thick) with unknown outside."""
    h, w = int(round(height / RES)) + 8, int(round(width / RES)) + 8
    g = np.full((h, w), UNKNOWN, dtype=np.int8)
    g[2:-2, 2:-2] = OCCUPIED
    g[4:-4, 4:-4] = FREE
    return g


def two_rooms(door: bool = True) -> OccupancyGrid:
    """Rooms [0, 4] and [4, 8] (x) by [0, 3] (y), a 0.9 m doorway at x = 4, y 1.05-1.95."""
    g = grid_of(8.0, 3.0)
    c = 4 + int(round(4.0 / RES))
    g[:, c - 1:c + 1] = np.where(g[:, c - 1:c + 1] == FREE, OCCUPIED, g[:, c - 1:c + 1])
    if door:
        r0, r1 = 4 + int(round(1.05 / RES)), 4 + int(round(1.95 / RES))
        g[r0:r1, c - 1:c + 1] = FREE
    return OccupancyGrid(g, (-4 * RES, -4 * RES), RES)


def test_graph_is_connected_clear_of_obstacles_and_crosses_the_door() -> None:
    occ = two_rooms()
    cfg = VoronoiConfig(min_clearance=0.2)
    vg = voronoi_graph(occ, cfg)
    g = vg.graph
    assert g.number_of_nodes() > 10 and nx.is_connected(g)
    dist, _ = distance_field(occ.grid != FREE, RES)
    rows, cols = vg.cells[:, 0], vg.cells[:, 1]
    assert (occ.grid[rows, cols] == FREE).all()
    assert dist[rows, cols].min() >= cfg.min_clearance - 1e-9
    np.testing.assert_allclose(vg.clearance, dist[rows, cols])
    # every ridge cell an edge runs along is free and clear too
    for cells in vg.edge_cells:
        r, c = np.divmod(cells, occ.shape[1])
        assert (occ.grid[r, c] == FREE).all() and dist[r, c].min() >= cfg.min_clearance - 1e-9
    # a path from the left room to the right room through the doorway
    left = int(np.argmin(vg.positions[:, 0]))
    right = int(np.argmax(vg.positions[:, 0]))
    assert vg.positions[left, 0] < 2.0 and vg.positions[right, 0] > 6.0
    path = nx.shortest_path(g, left, right, weight="weight")
    cells = np.concatenate([vg.edge_cells[_edge(vg, u, v)] for u, v in zip(path, path[1:],
                                                                          strict=False)])
    x, y = occ.center_of(*np.divmod(cells, occ.shape[1]))
    at_door = np.abs(x - 4.0) < 0.06
    assert at_door.any() and np.all(np.abs(y[at_door] - 1.5) < 0.1)


def _edge(vg, u: int, v: int) -> int:  # noqa: ANN001
    a, b = min(u, v), max(u, v)
    return int(np.flatnonzero((vg.edges[:, 0] == a) & (vg.edges[:, 1] == b))[0])


def test_corridor_gives_its_centre_line_sparsified() -> None:
    g = grid_of(6.0, 1.0)
    occ = OccupancyGrid(g, (-4 * RES, -4 * RES), RES)
    vg = voronoi_graph(occ, VoronoiConfig(node_spacing=0.6))
    assert nx.is_connected(vg.graph)
    inner = (vg.positions[:, 0] > 0.6) & (vg.positions[:, 0] < 5.4)
    # centre line at y = 0.5 (cell centres at 0.475/0.525)
    assert np.all(np.abs(vg.positions[inner, 1] - 0.5) <= 0.03)
    # sparsified: ~one node per 0.6 m along the line, edges ~0.6 m
    core = vg.lengths[np.isin(vg.edges, np.flatnonzero(inner)).all(axis=1)]
    assert len(core) >= 5 and np.all(core > 0.4) and np.all(core < 0.9)
    degrees = np.array([d for _, d in vg.graph.degree()])
    assert degrees.max() <= 3  # a line with two short end forks at most


def test_component_choice_follows_the_anchor() -> None:
    occ = two_rooms(door=False)
    big = voronoi_graph(occ)  # equal rooms: ties go to the component with the lowest cell
    assert big.positions[:, 0].max() < 4.0
    right = voronoi_graph(occ, anchor=(6.0, 1.5))
    assert right.positions[:, 0].min() > 4.0 and nx.is_connected(right.graph)


def test_unknown_space_bounds_the_graph() -> None:
    occ = two_rooms()
    g = occ.grid.copy()
    g[:, 4 + int(round(4.5 / RES)):] = np.where(g[:, 4 + int(round(4.5 / RES)):] == FREE,
                                                 UNKNOWN, g[:, 4 + int(round(4.5 / RES)):])
    vg = voronoi_graph(OccupancyGrid(g, occ.origin, RES), anchor=(1.0, 1.5))
    assert vg.positions[:, 0].max() < 4.5 - 0.2 + 1e-9


def test_thinning_keeps_one_cell_wide_connected_lines() -> None:
    mask = np.zeros((12, 30), dtype=bool)
    mask[4:7, 2:28] = True  # a 3-cell-thick bar
    out = thin(mask)
    assert out.sum() >= 20
    assert out.sum(axis=0).max() == 1  # one cell per column
    from scipy import ndimage

    assert ndimage.label(out, structure=np.ones((3, 3)))[1] == 1


@pytest.mark.parametrize("spacing", [0.4, 1.0])
def test_node_spacing_option(spacing: float) -> None:
    occ = OccupancyGrid(grid_of(6.0, 1.0), (-4 * RES, -4 * RES), RES)
    vg = voronoi_graph(occ, VoronoiConfig(node_spacing=spacing))
    inner = (vg.positions[:, 0] > 1.0) & (vg.positions[:, 0] < 5.0)
    core = vg.lengths[np.isin(vg.edges, np.flatnonzero(inner)).all(axis=1)]
    assert np.median(core) == pytest.approx(spacing, rel=0.3)
