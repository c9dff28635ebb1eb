"""Doorways seen by their lintel (sgtool.scenegraph.lintels) on hand-made grids: a beam over
a gap in a wall, with floor seen under it and on both sides, is a doorway; a wall whose
foot is hidden, a shelf along a wall, a beam across a room, a duct across a corridor and
a lamp are not."""

from __future__ import annotations

import numpy as np

from sgtool.mapping.grid import FREE, OCCUPIED, UNKNOWN, OccupancyGrid
from sgtool.scenegraph.lintels import lintel_doorways

RES = 0.05


def two_rooms() -> tuple[np.ndarray, np.ndarray]:
    """A 3 x 6 m floor seen free, split at x = 3 m (columns 60-61) by a wall with an
    18-cell gap (rows 20-37, 0.9 m); and the overhead mask of the gap's lintel."""
    g = np.full((60, 120), FREE, dtype=np.int8)
    g[[0, -1], :] = OCCUPIED
    g[:, [0, -1]] = OCCUPIED
    g[:, 60:62] = OCCUPIED
    g[20:38, 60:62] = FREE
    overhead = np.zeros(g.shape, dtype=bool)
    overhead[20:38, 60:62] = True
    return g, overhead


def grid(g: np.ndarray) -> OccupancyGrid:
    return OccupancyGrid(g, (0.0, 0.0), RES)


def test_a_beam_over_a_gap_in_a_wall_is_a_doorway() -> None:
    g, overhead = two_rooms()
    got = lintel_doorways(grid(g), overhead)
    assert np.array_equal(got, overhead)
    # the ceiling-height band of a wall seen whole is no lintel: its cells are occupied
    overhead[:, 60:62] = True
    assert np.array_equal(lintel_doorways(grid(g), overhead), got)


def test_no_doorway_without_floor_under_it_and_on_both_sides() -> None:
    g, overhead = two_rooms()
    hidden = g.copy()
    hidden[20:38, 60:62] = UNKNOWN  # the wall's foot hidden by furniture: no floor seen
    assert not lintel_doorways(grid(hidden), overhead).any()
    one_side = g.copy()
    one_side[15:43, 62:66] = OCCUPIED  # a cupboard filling one side of the gap
    assert not lintel_doorways(grid(one_side), overhead).any()


def test_shelf_beam_and_lamp_are_no_doorways() -> None:
    g, _ = two_rooms()
    g[20:38, 60:62] = OCCUPIED  # a wall without a gap
    shelf = np.zeros(g.shape, dtype=bool)
    shelf[10:30, 62:68] = True  # 1 m along the wall, 0.3 m deep, above the floor
    assert not lintel_doorways(grid(g), shelf).any()
    beam = np.zeros(g.shape, dtype=bool)
    beam[1:59, 30:32] = True  # 2.9 m across the room, wall to wall: longer than a door
    assert not lintel_doorways(grid(g), beam).any()
    lamp = np.zeros(g.shape, dtype=bool)
    lamp[28:32, 28:34] = True  # over the middle of the room, no wall at either end
    assert not lintel_doorways(grid(g), lamp).any()


def test_a_duct_across_a_corridor_is_no_doorway() -> None:
    """A 1.2 m corridor (rows 20-43) between walls along it; a duct overhead across it
    (columns 30-31) runs into the walls past both ends, with floor on both sides, as a
    lintel does, but those walls run across its line: they are no jambs. A wider bar
    smeared by noise (0.5 m deep) in a doorway is still its lintel."""
    g = np.full((64, 120), FREE, dtype=np.int8)
    g[[0, 19, 44, 63], :] = OCCUPIED
    duct = np.zeros(g.shape, dtype=bool)
    duct[20:44, 30:32] = True
    assert not lintel_doorways(grid(g), duct).any()
    d, overhead = two_rooms()
    d[20:38, 56:66] = FREE
    overhead[20:38, 56:66] = True  # 10 cells deep: the doorway's lintel, smeared
    d[:20, 56:60] = d[38:, 56:60] = OCCUPIED  # the wall smeared as deep
    d[:20, 62:66] = d[38:, 62:66] = OCCUPIED
    assert np.array_equal(lintel_doorways(grid(d), overhead), overhead)


def test_a_lintel_with_a_thin_tail_along_its_wall_is_measured_by_its_body() -> None:
    """Noise smears a wall into two copies with a line of floor between them, under the
    wall's top: the lintel's piece runs on along the wall's line in a thin tail (here
    1 m past a 0.9 m doorway: 1.9 m in all, longer than a doorway). The bar's body is the
    doorway's lintel; the tail is no doorway."""
    g, overhead = two_rooms()
    g[:, 59:64] = OCCUPIED
    g[20:38, 59:64] = FREE
    overhead[20:38, 59:64] = True  # the smeared lintel, 5 cells deep
    g[38:58, 61] = FREE
    overhead[38:58, 61] = True  # the tail: between the wall's two copies
    got = lintel_doorways(grid(g), overhead)
    assert np.array_equal(got, overhead & (np.arange(60) < 38)[:, None])
    # a bar as deep all along, as long, is no doorway's
    g[38:58, 59:64] = FREE
    overhead[38:58, 59:64] = True
    assert not lintel_doorways(grid(g), overhead).any()


def test_a_bar_cut_from_its_tails_beside_a_seen_doors_evidence_adds_nothing() -> None:
    """A bar measured by its body (its thin tails cut) beside a seen door's evidence is
    left out: that doorway has its evidence (house 990 under mild noise: such bars made
    the evidence of three seen doors deeper, and objects beside them lost their room). A
    whole bar beside a seen door is found as before, and a cut one apart from it."""
    g, overhead = two_rooms()
    doors = np.zeros(g.shape, dtype=bool)
    doors[20:38, 62] = True  # the seen door's opening, beside the lintel's bar
    assert np.array_equal(lintel_doorways(grid(g), overhead, doors), overhead)
    g[:, 59:64] = OCCUPIED  # the tailed bar of the test above
    g[20:38, 59:64] = FREE
    overhead[20:38, 59:64] = True
    g[38:58, 61] = FREE
    overhead[38:58, 61] = True
    doors[20:38, 62] = False
    doors[20:38, 64] = True
    assert not lintel_doorways(grid(g), overhead, doors).any()
    doors[:] = False
    doors[45:50, 90:92] = True  # a door elsewhere
    assert lintel_doorways(grid(g), overhead, doors).any()
