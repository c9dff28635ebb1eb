"""The mapping parameters pinned by behaviour on small hand-made occupancy grids.

Each test builds a map whose outcome flips when a default of :class:`VoronoiConfig` moves
by 20 % (up or down), so a change of a default in the source fails here with a reason, not
only as a changed golden digest. Every test reads the default from the config class and
says in a comment where the decision boundary lies and why the default is next to it.
"""

from __future__ import annotations

import numpy as np
import pytest
from support.grids import walled

from sgtool.mapping.grid import FREE, OCCUPIED, OccupancyGrid
from sgtool.mapping.voronoi import VoronoiConfig, voronoi_graph

DEFAULT = VoronoiConfig()


# ----- Voronoi clearance (VoronoiConfig.min_clearance) ----------------------------------
RES_FINE = 0.03  # 3 cm cells: clearances come in steps of 3 cm, finer than 20 % of 0.2 m


def two_rooms_with_doorway(cells: int) -> tuple[OccupancyGrid, float]:
    """Two 1.5 m x 1.5 m rooms side by side (3 cm cells), the 2-cell wall between them
    pierced by a doorway ``cells`` cells wide in its middle; and the x of that wall."""
    n = 50  # 1.5 m
    g = walled(n, 2 * n + 2)
    c = 4 + n
    g[4:-4, c:c + 2] = OCCUPIED
    r0 = 4 + (n - cells) // 2
    g[r0:r0 + cells, c:c + 2] = FREE
    return OccupancyGrid(g, (0.0, 0.0), RES_FINE), (c + 1) * RES_FINE


def crosses(cells: int, min_clearance: float) -> bool:
    occ, wall_x = two_rooms_with_doorway(cells)
    vg = voronoi_graph(occ, VoronoiConfig(min_clearance=min_clearance), anchor=(0.5, 0.8))
    assert len(vg) > 0 and vg.positions[:, 0].min() < wall_x  # the left room's graph
    return bool(vg.positions[:, 0].max() > wall_x)


def test_min_clearance_decides_which_doorways_the_graph_crosses() -> None:
    """The Voronoi graph goes through a doorway only when its ridge there is clear by
    ``min_clearance``. In a doorway of an even number k of cells the ridge runs between
    the two middle cells, which are k/2 cells from the jambs, and a ridge needs both cells
    of the pair clear (:func:`sgtool.mapping.ridge_window.ridge_from_fields`):

    - 14 cells (0.42 m): clearance 7 x 3 cm = 0.21 m, just above the default 0.2 m: the
      graph crosses; at 1.2 x 0.2 = 0.24 m it does not;
    - 12 cells (0.36 m): clearance 0.18 m, just below 0.2 m: no crossing; at
      0.8 x 0.2 = 0.16 m it crosses.
    """
    mc = DEFAULT.min_clearance
    assert crosses(14, mc)
    assert not crosses(12, mc)
    # the boundary, spelled out: the default lies between the two doorways' clearances
    assert 0.18 < mc <= 0.21
    # what a 20 % change does (documents the sensitivity the comment claims)
    assert not crosses(14, 1.2 * mc)
    assert crosses(12, 0.8 * mc)


# ----- sparsification (VoronoiConfig.node_spacing) ---------------------------------------
RES = 0.05


def test_node_spacing_sets_how_many_edges_a_corridor_gets() -> None:
    """A 0.6 m x 3.0 m corridor (12 x 60 cells of 5 cm): its Voronoi graph is the centre
    line, 2.45 m long between the points where the corner bisectors (too close to the walls
    for ``min_clearance``) would join it. Sparsification cuts a chain of length L into
    round(L / node_spacing) edges: round(2.45 / 0.6) = round(4.08) = 4 edges of ~0.61 m.
    At 1.2 x 0.6 = 0.72 m: round(3.40) = 3 edges; at 0.8 x 0.6 = 0.48 m: round(5.10) = 5."""
    occ = OccupancyGrid(walled(12, 60), (0.0, 0.0), RES)
    vg = voronoi_graph(occ)
    assert vg.lengths.sum() == pytest.approx(2.45, abs=0.026)
    degrees = sorted(d for _, d in vg.graph.degree())
    assert degrees == [1, 1, 2, 2, 2]  # one chain, no spurs
    assert len(vg.edges) == 4
    assert round(2.45 / DEFAULT.node_spacing) == 4
    assert np.all(np.abs(vg.lengths - 2.45 / 4) <= 0.05)
    # a 20 % change either way changes the edge count
    up = voronoi_graph(occ, VoronoiConfig(node_spacing=1.2 * DEFAULT.node_spacing))
    down = voronoi_graph(occ, VoronoiConfig(node_spacing=0.8 * DEFAULT.node_spacing))
    assert (len(up.edges), len(down.edges)) == (3, 5)


# ----- spur pruning (VoronoiConfig.min_spur) ---------------------------------------------
def leaf_edge_lengths(vg) -> list[float]:  # noqa: ANN001
    deg = np.array([d for _, d in vg.graph.degree()])
    return sorted(round(float(x), 3) for (a, b), x in zip(vg.edges, vg.lengths, strict=True)
                  if deg[a] == 1 or deg[b] == 1)


def test_min_spur_drops_the_short_corner_spurs() -> None:
    """A 0.8 m x 3.0 m corridor (16 x 60 cells of 5 cm). At each end the centre line forks
    into the two corner bisectors, cut short where they come closer than ``min_clearance``
    to the walls: spurs of 4 diagonal steps (4 x 0.0707 = 0.283 m) at one end and one
    cell more (0.333 m) at the other (the even width puts the thinned centre line half a
    cell off the middle). The default 0.3 m lies between: the 0.333 m spurs stay, the
    0.283 m ones go. At 1.2 x 0.3 = 0.36 m all four go, at 0.8 x 0.3 = 0.24 m all stay."""
    occ = OccupancyGrid(walled(16, 60), (0.0, 0.0), RES)
    every = voronoi_graph(occ, VoronoiConfig(min_spur=0.0))
    assert leaf_edge_lengths(every) == pytest.approx([0.283, 0.283, 0.333, 0.333], abs=1e-3)
    assert 0.283 < DEFAULT.min_spur < 0.333
    vg = voronoi_graph(occ)
    assert leaf_edge_lengths(vg) == pytest.approx([0.333, 0.333], abs=1e-3)
    assert len(vg.edges) == 6
    up = voronoi_graph(occ, VoronoiConfig(min_spur=1.2 * DEFAULT.min_spur))
    down = voronoi_graph(occ, VoronoiConfig(min_spur=0.8 * DEFAULT.min_spur))
    assert (len(up.edges), len(down.edges)) == (4, 8)
