"""A door leaf swung into a room closes a pocket of its floor off the room when its free
end meets a cabinet (house 907 under mild noise: the living room's door leaf and a
cabinet door opened after the robot passed, leaving 1 m^2 of floor in front of the
doorway walled off on the map: a room of its own). The leaf is a door's, not a wall:
its cells out of the doorway's wall join the floor on both its sides; its cells in that
wall (a jamb) are no leaf."""

from __future__ import annotations

import numpy as np

from sgtool.mapping.grid import FREE, OCCUPIED, OccupancyGrid
from sgtool.mapping.voronoi import voronoi_graph
from sgtool.scenegraph.door_evidence import LEAF_OFF, doorways
from sgtool.scenegraph.room_segmentation import RoomConfig, door_density, segment_rooms

RES = 0.05
WALL = (30, 32)  # rows of the wall between the corridor (below) and the room (above)
DOORWAY = (40, 58)  # its columns: 0.9 m
LEAF = (32, 50)  # rows of the leaf, hinged at the doorway's right jamb, swung up 0.9 m


def house(skin: bool = True) -> tuple[OccupancyGrid, dict[int, np.ndarray]]:
    """The map: a corridor, a wall with a doorway, a room whose door leaf stands at right
    angles to the wall and whose far end meets a cabinet (a bar across to a cabinet
    side), leaving a pocket in front of the doorway; and the door's voxels (ijk): a lintel
    over the doorway and the leaf's two labelled columns (a third, its face, is occupied
    on the map but labelled what stands behind it, when ``skin``)."""
    g = np.full((80, 100), OCCUPIED, dtype=np.int8)
    g[2:-2, 2:-2] = FREE
    g[WALL[0]:WALL[1], :] = OCCUPIED
    g[WALL[0]:WALL[1], DOORWAY[0]:DOORWAY[1]] = FREE
    g[LEAF[0]:LEAF[1], 58:61 if skin else 60] = OCCUPIED  # the leaf
    g[LEAF[1]:LEAF[1] + 3, 20:61] = OCCUPIED  # the cabinet's top, meeting the leaf's end
    g[WALL[1]:LEAF[1], 20:23] = OCCUPIED  # its side: the pocket is closed
    lintel = [(c, r, 42) for r in range(*WALL) for c in range(*DOORWAY)]
    leaf = [(c, r, k) for r in range(*LEAF) for c in (58, 59) for k in range(0, 40, 4)]
    leaf += [(58, r, k) for r in range(*WALL) for k in range(0, 40, 4)]  # the jamb
    return OccupancyGrid(g, (0.0, 0.0), RES), {7: np.array(lintel + leaf)}


def rooms(occ: OccupancyGrid, door: dict[int, np.ndarray], with_leaves: bool) -> int:
    found = doorways(occ, door, {})
    # the graph of every part the robot was in: corridor, pocket, room
    vg = voronoi_graph(occ, trajectory=np.array([[2.45, 0.8], [2.0, 2.1], [4.0, 3.4]]))
    cfg = RoomConfig()
    dens = door_density(found.cells, RES, cfg.door_bandwidth)
    leaves = found.leaves if with_leaves else None
    return segment_rooms(vg, dens, cfg, None, occ, found.unsure | found.cells,
                         leaves=leaves).count


def test_a_leaf_out_of_its_wall_joins_the_pocket_it_closes_to_its_room() -> None:
    occ, door = house()
    assert rooms(occ, door, with_leaves=False) == 3  # corridor, pocket, room
    assert rooms(occ, door, with_leaves=True) == 2


def test_the_leaf_is_its_cells_off_the_doorway_s_line_and_their_faces() -> None:
    occ, door = house()
    leaves = doorways(occ, door, {}).leaves
    rows, cols = np.nonzero(leaves)
    # off the wall's line (row 30.5) by more than LEAF_OFF: rows 38 and up of the leaf,
    # and the face beside its labelled columns (not the floor on the other side, nor the
    # cabinet past its end); never the jamb in the wall
    off = int(np.ceil(30.5 + LEAF_OFF / RES + 1e-9))
    assert set(cols.tolist()) == {58, 59, 60}
    assert (int(rows.min()), int(rows.max())) == (off, LEAF[1] - 1)  # not the cabinet
    assert not (occ.grid[leaves] == FREE).any()
    assert not leaves[WALL[0]:WALL[1]].any()


def test_without_the_face_the_leaf_s_labelled_cells_join_alone() -> None:
    occ, door = house(skin=False)
    assert rooms(occ, door, with_leaves=False) == 3
    assert rooms(occ, door, with_leaves=True) == 2


def test_a_face_two_cells_thick_is_the_leaf_s_too() -> None:
    """Under depth noise a leaf's unlabelled skin is two cells thick on the map (house 990,
    mild: its door leaf cut the corridor in two); the cells up to LEAF_SKIN across the leaf
    are its face, those beyond stay (a third cell is a wall beside it)."""
    from sgtool.scenegraph.door_evidence import LEAF_SKIN

    assert round(LEAF_SKIN / RES) == 2
    for cells, expected in ((0, 2), (1, 2), (2, 2), (3, 3)):
        occ, door = house(skin=False)
        g = occ.grid.copy()
        g[LEAF[0]:LEAF[1], 60:60 + cells] = OCCUPIED
        thick = OccupancyGrid(g, (0.0, 0.0), RES)
        assert rooms(thick, door, with_leaves=True) == expected, cells
        assert rooms(thick, door, with_leaves=False) == 3


def flush_against_a_wall(wall: tuple[int, int], labelled: tuple[int, ...]
                         ) -> tuple[OccupancyGrid, dict[int, np.ndarray]]:
    """The doorway of :func:`house`, its leaf (columns 58-59) swung flush against a wall
    (columns ``wall``) between its room and another room to the right, the door's labels
    on columns ``labelled`` (a label that reaches into the wall, when it holds 60)."""
    g = np.full((80, 100), OCCUPIED, dtype=np.int8)
    g[2:-2, 2:-2] = FREE
    g[WALL[0]:WALL[1], :] = OCCUPIED
    g[WALL[0]:WALL[1], DOORWAY[0]:DOORWAY[1]] = FREE
    g[WALL[1]:, wall[0]:wall[1]] = OCCUPIED
    g[LEAF[0]:LEAF[1], 58:60] = OCCUPIED
    lintel = [(c, r, 42) for r in range(*WALL) for c in range(*DOORWAY)]
    leaf = [(c, r, k) for r in range(*LEAF) for c in labelled for k in range(0, 40, 4)]
    return OccupancyGrid(g, (0.0, 0.0), RES), {7: np.array(lintel + leaf)}


def rooms_of(occ: OccupancyGrid, door: dict[int, np.ndarray]) -> tuple[int, int]:
    """The rooms of the nodes nearest a point left and right of the side wall."""
    found = doorways(occ, door, {})
    vg = voronoi_graph(occ, trajectory=np.array([[2.45, 0.8], [1.5, 2.5], [4.0, 2.5]]))
    cfg = RoomConfig()
    seg = segment_rooms(vg, door_density(found.cells, RES, cfg.door_bandwidth), cfg, None,
                        occ, found.unsure | found.cells, leaves=found.leaves)
    near = [int(np.argmin(np.hypot(*(vg.positions - p).T))) for p in ((1.5, 2.5), (4.0, 2.5))]
    return int(seg.labels[near[0]]), int(seg.labels[near[1]])


def test_a_leaf_flush_against_a_thin_wall_does_not_open_it() -> None:
    """The face beside a leaf is its skin only where it ends with the leaf: a wall that
    runs on past the leaf's free end is a wall (a one-cell wall on the map, or a door
    label reaching into a two-cell one, joined the rooms either side through the face)."""
    for wall, labelled in (((60, 61), (58, 59)), ((60, 62), (58, 59, 60)),
                           ((60, 62), (58, 59))):
        left, right = rooms_of(*flush_against_a_wall(wall, labelled))
        assert left != right, (wall, labelled)
