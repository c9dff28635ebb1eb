"""Imported real RGB-D data replayed through the scene-graph builder: the occupancy map
and the Voronoi graph of one room must come out plausible, and the missing semantics
(no instance ids) must give geometry only, not a failure.

Stated ranges and why:
- ICL-NUIM livingroom1 (211 frames, 3.7 m of camera path, every 2nd frame replayed) and
  7-Scenes redkitchen (100 frames, 6.8 m): a hand-held Kinect in one room sees a few
  square metres of floor; free area 2-15 m^2 (measured 4.4 and 4.7 m^2), obstacles
  (walls, sofa, counters) 0.5-20 m^2 (1.8 and 7.8 m^2), and everything occupied within a
  room-sized box of 1.5-8 m a side;
- the camera's path is mostly free: a hand-held camera is carried by someone standing on
  the floor, but reaches over counters and tables (7-Scenes frames 74-88 are 0.7 m above a
  0.75 m high counter top): at least 75 % of its positions are on free cells (measured:
  ICL 100 %, 7-Scenes 84 %);
- the Voronoi graph is connected and no node is in or near an obstacle: every node on a
  free cell at least ``min_clearance`` (0.2 m) minus one cell from any occupied or
  unknown cell, checked with an independent distance transform. In the living room it
  has edges (measured: 10 nodes); in the kitchen the free floor is an aisle between
  counters too narrow for more than one node at 0.2 m clearance (measured: 1 node).
"""

from __future__ import annotations

from pathlib import Path

import networkx as nx
import numpy as np
from scipy import ndimage

from sgtool.log import LogReader
from sgtool.mapping import bev
from sgtool.recorders.importers.rgbd import RgbdOptions, import_rgbd
from sgtool.scenegraph import builder as builder_mod


def replay(log: Path):  # type: ignore[no-untyped-def]
    b = builder_mod.SceneGraphBuilder()
    cams = []
    with LogReader(log) as r:
        for f in r.frames():
            assert f.ids is None
            b.integrate(f)
            cams.append(f.pose[:2, 3].copy())
    sg = b.refresh()
    return b, sg, np.array(cams)


def check_room(b, sg, cams: np.ndarray, free_m2: tuple[float, float], min_nodes: int  # type: ignore[no-untyped-def]
               ) -> dict[str, float]:
    occ = b.layers.occupancy
    vg = b.layers.voronoi
    res = occ.resolution
    grid = occ.grid
    free = float((grid == bev.FREE).sum() * res * res)
    occupied = float((grid == bev.OCCUPIED).sum() * res * res)
    assert free_m2[0] < free < free_m2[1], free
    assert 0.5 < occupied < 20.0, occupied
    rows, cols = np.nonzero(grid == bev.OCCUPIED)
    size = np.array([np.ptp(cols), np.ptp(rows)]) * res
    assert np.all((1.5 < size) & (size < 8.0)), size
    r, c = occ.cell_of(cams[:, 0], cams[:, 1])
    assert np.mean(grid[r, c] == bev.FREE) >= 0.75
    # the Voronoi graph: connected, every node well inside free space
    assert len(vg) >= min_nodes
    assert nx.is_connected(vg.graph)
    clearance = ndimage.distance_transform_edt(grid == bev.FREE) * res
    min_clear = b.config.voronoi.min_clearance
    for (row, col) in vg.cells:
        assert grid[row, col] == bev.FREE
        assert clearance[row, col] >= min_clear - res
    # geometry only: no objects, no room categories, and the graph says where to explore
    assert sg.objects == () and sg.doors == ()
    assert all(room.category == "unknown" and not room.category_scores for room in sg.rooms)
    assert len(b.layers.frontiers) >= 1
    return {"free": free, "occupied": occupied, "nodes": len(vg)}


def test_replay_icl_livingroom(shared_data_dir, tmp_path):
    out = tmp_path / "icl.mcap"
    import_rgbd(shared_data_dir / "rgbd" / "icl-livingroom1-micro", out,
                RgbdOptions(every=2, progress=False))
    b, sg, cams = replay(out)
    check_room(b, sg, cams, (2.0, 15.0), min_nodes=4)


def test_replay_7scenes_kitchen(shared_data_dir, tmp_path):
    out = tmp_path / "kitchen.mcap"
    import_rgbd(shared_data_dir / "rgbd" / "7scenes-redkitchen-every10", out,
                RgbdOptions(progress=False))
    b, sg, cams = replay(out)
    check_room(b, sg, cams, (2.0, 15.0), min_nodes=1)
