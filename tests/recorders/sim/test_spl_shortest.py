"""SPL's shortest path in the closed loop: the episode's grid route string-pulled as the
robot pulls its own paths. On the demo house every route is the episode's own geodesic,
the pulled one no longer and no shorter than the straight line to its goal, and shorter
than the grid's wherever the way runs diagonally (an 8-connected path is up to 8 % long)."""

from __future__ import annotations

import math

import sgtool.datasets as ds
from sgtool.datasets.episodes import EpisodeGeometry, list_episodes
from sgtool.recorders.sim.navigation import lines_are_free
from sgtool.recorders.sim.spl_shortest import driven_shortest


def _length(points) -> float:
    return sum(math.dist(a, b) for a, b in zip(points, points[1:], strict=False))


def test_the_driven_shortest_path_is_the_grid_route_pulled_taut() -> None:
    spec = ds.demo_house()
    geo = EpisodeGeometry(spec)
    ratios = []
    for e in list_episodes(spec, geometry=geo):
        route = geo.shortest_route(e.start, list(e.targets))
        assert route is not None and route[0] == (e.start.x, e.start.y)
        assert abs(_length(route) - e.shortest_path) < 0.05 + 1e-9  # (snapped start cell)
        pulled = driven_shortest(spec, e, geo)
        assert pulled is not None
        assert math.dist(route[0], route[-1]) - 1e-4 <= pulled <= e.shortest_path + 1e-4
        ratios.append(pulled / e.shortest_path)
        if lines_are_free(geo.occ, route[0], [route[-1]])[0]:  # in sight: straight there
            assert abs(pulled - math.dist(route[0], route[-1])) <= 1e-4  # (0.1 mm records)
    assert min(ratios) < 0.95 and max(ratios) <= 1.0
