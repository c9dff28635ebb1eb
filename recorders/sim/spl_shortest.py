"""SPL's shortest path in the closed loop: the distance a robot driving straight to the
nearest place a target is seen from travels.

The episode's ``shortest_path`` (:mod:`sgtool.datasets.episodes`) is the 8-connected grid
geodesic, SCOUT's A* on the dilated map, against which the symbolic bench, travelling on
the same grid, is measured. The closed-loop robot drives its A* paths string-pulled
(:func:`~sgtool.recorders.sim.navigation.smooth_path`), up to 8 % shorter than the grid
path on diagonals, so SPL's shortest there is the episode's route pulled the same way: a
robot that drives straight to the nearest goal scores 1, not more than its grid path
allows for.
"""

from __future__ import annotations

import math

from sgtool.canonical import canonical_float
from sgtool.datasets.episodes import Episode, EpisodeGeometry
from sgtool.house.spec import HouseSpec
from sgtool.recorders.sim.navigation import smooth_path


def driven_shortest(spec: HouseSpec, episode: Episode,
                    geometry: EpisodeGeometry | None = None) -> float | None:
    """The episode's shortest route (:meth:`EpisodeGeometry.shortest_route`, on
    ``geometry`` or the house's default one) string-pulled on that geometry's occupancy,
    its length in m as episode records keep it (:func:`sgtool.canonical.canonical_float`);
    None when no target is reached."""
    geo = geometry or EpisodeGeometry(spec)
    route = geo.shortest_route(episode.start, list(episode.targets))
    if route is None:
        return None
    pulled = smooth_path(geo.occ, route)
    return canonical_float(sum(math.dist(a, b) for a, b in zip(pulled, pulled[1:],
                                                               strict=False)))
