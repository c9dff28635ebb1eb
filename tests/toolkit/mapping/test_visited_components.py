"""The Voronoi graph spans every ridge component the robot's trajectory passed through."""

from __future__ import annotations

import numpy as np

from sgtool.mapping.grid import FREE, OCCUPIED, UNKNOWN, OccupancyGrid
from sgtool.mapping.voronoi import ridge_graph, visited_components, voronoi_graph

RES = 0.05


def three_rooms() -> OccupancyGrid:
    """Rooms [0, 3], [3, 6], [6, 9] (x) by [0, 3] (y), walled (0.1 m) and closed: each
    room's ridge is its own component (a phantom blocked every doorway)."""
    h, w = int(round(3.0 / RES)) + 8, int(round(9.0 / RES)) + 8
    g = np.full((h, w), UNKNOWN, dtype=np.int8)
    g[2:-2, 2:-2] = OCCUPIED
    g[4:-4, 4:-4] = FREE
    for x in (3.0, 6.0):
        c = 4 + int(round(x / RES))
        g[4:-4, c - 1:c + 1] = OCCUPIED
    return OccupancyGrid(g, (-4 * RES, -4 * RES), RES)


def test_rooms_the_trajectory_passed_through_are_kept() -> None:
    occ = three_rooms()
    rg = ridge_graph(occ)
    assert int(rg.component.max()) == 2  # three separate components
    track = np.array([[1.5, 1.5], [2.5, 1.5], [3.5, 1.5], [4.5, 1.5]])  # rooms 1 and 2
    comps = visited_components(occ, rg, (4.5, 1.5), track)
    assert len(comps) == 2
    vg = voronoi_graph(occ, anchor=(4.5, 1.5), ridge=rg, trajectory=track)
    x = vg.positions[:, 0]
    assert (x < 3.0).any() and ((x > 3.0) & (x < 6.0)).any() and not (x > 6.0).any()
    # without the trajectory: the anchor's room only, as before
    alone = voronoi_graph(occ, anchor=(4.5, 1.5), ridge=rg)
    assert ((alone.positions[:, 0] > 3.0) & (alone.positions[:, 0] < 6.0)).all()


def test_a_point_outside_every_free_disc_adds_nothing() -> None:
    occ = three_rooms()
    rg = ridge_graph(occ)
    # on the wall between rooms 2 and 3 (no ridge pixel's clearance reaches it) and
    # outside the house
    track = np.array([[6.0, 0.1], [12.0, 1.5]])
    assert visited_components(occ, rg, (1.5, 1.5), track) == \
        visited_components(occ, rg, (1.5, 1.5), None)
    assert len(visited_components(occ, rg, (1.5, 1.5), track)) == 1


def test_no_ridge_no_component() -> None:
    g = np.full((20, 20), OCCUPIED, dtype=np.int8)
    g[5:8, 5:8] = FREE  # too narrow for any ridge cell with 0.2 m clearance
    occ = OccupancyGrid(g, (0.0, 0.0), RES)
    rg = ridge_graph(occ)
    assert visited_components(occ, rg, (0.3, 0.3), np.array([[0.3, 0.3]])) == ()
