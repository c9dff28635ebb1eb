"""A component of the Voronoi graph where the robot fits nowhere is no room (house 991: a
cabinet door opened beside a doorway leaves a 0.4 m strip of floor between itself and
the wall, whose only mouth lies in the doorway's cut zone)."""

from __future__ import annotations

import numpy as np

from sgtool.mapping.voronoi import VoronoiGraph
from sgtool.scenegraph.room_segmentation import ROBOT_RADIUS, RoomConfig, segment_rooms


def two_chains(slit_clearance: float) -> VoronoiGraph:
    """Two chains of 5 nodes 0.5 m apart (2 m of edges each): a room (clearance 0.5 m)
    and a strip of floor (``slit_clearance``)."""
    x = np.arange(5) * 0.5
    pos = np.concatenate([np.stack([x, np.zeros(5)], 1), np.stack([x, np.full(5, 3.0)], 1)])
    clearance = np.r_[np.full(5, 0.5), np.full(5, slit_clearance)]
    edges = np.array([(i, i + 1) for i in range(4)] + [(i, i + 1) for i in range(5, 9)])
    return VoronoiGraph(None, pos, clearance, np.zeros((10, 2), np.int64), edges,
                        np.full(len(edges), 0.5), (), np.zeros((1, 1), bool))


def test_a_strip_where_the_robot_fits_nowhere_is_no_room() -> None:
    seg = segment_rooms(two_chains(0.2), None, RoomConfig())
    assert seg.count == 1
    assert (seg.labels[:5] == 0).all() and (seg.labels[5:] == -1).all()
    assert segment_rooms(two_chains(ROBOT_RADIUS), None, RoomConfig()).count == 2
