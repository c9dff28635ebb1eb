"""A door's swung panel whose free end stops just short of a counter: the counter reads as a
wall line at the free end, so that end looked as much like a hinge as the real one, its
"opening" running over floor behind the panel that no frame saw. Neither hinge won,
the doorway was not found, and the panel's own cells, at right angles to the doorway,
did not cut it: house 901 (generated, 10 rooms, no noise) had its bathroom merged with
the corridor. The map around that door, at 0.05 m a cell, as the replay had it."""

from __future__ import annotations

import numpy as np

from sgtool.scenegraph.door_panel import opening_from_panel

# '#' occupied, '.' seen free, ' ' never seen, 'D' the door's panel (occupied)
HOUSE_901_BATHROOM_DOOR = [
    *["." * 60] * 20,  # the corridor: rows 0-19 seen free
    "###############################................#############",
    "###############################................#############",
    "########                     #D................#############",
    "########                      D................#############",
    "......##                      D................... . .......",
    "......##                      D....................   ......",
    "......##                      D.............................",
    "......##                      D.............................",
    "......##                      D.............................",
    "......##                      D.............................",
    "......##                      D.............................",
    "......##                      D.............................",
    "......##                      D.............................",
    "......##                      D.............................",
    "......##                      D.............................",
    "......##                      D.............................",
    "......##                      D.............................",
    "......##                      D.............................",
    "......##                      D.............................",
    "......##                      D.............................",
    "......##                     .#.............................",
    "......##                  ..................................",
    "......##               ###############......................",
    "......##               # #############..............########",
    "......##                            ................########",
    "......##                          ..................########",
    "......##                          ..................########",
    "......##                         ...................########",
    "......##                         ...................###.. ##",
    "......####                      ....................####..##",
    "......####                     .....................#####. #",
    "......####                    ......................######. ",
    "......####                   .......................######..",
    "......####                  ........................#######.",
    "......####                  ........................########",
    "......####                 .........................########",
    "##########                ..........................########",
    "#..     ##               ...........................########",
    "......  ##        #################################.########",
    "......# ##         ################################.###. ###",
]


def grids() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    cells = np.array([list(row) for row in HOUSE_901_BATHROOM_DOOR])
    return cells == "D", np.isin(cells, ["#", "D"]), cells == "."


def test_unseen_floor_behind_a_panel_is_no_opening() -> None:
    """The wall runs along rows 20-21 with a doorway at columns 31-46; the panel stands at
    column 30 from row 22 to 39, hinged at its top end; a counter crosses its line two
    rows past its free end. The doorway found is the panel turned about its hinge:
    row 22, columns 30 to 48 (the panel's 18 cells and the hinge's)."""
    panel, occupied, free = grids()
    rows, cols = np.nonzero(panel)
    got = opening_from_panel(rows, cols, occupied, min_width=8, free=free)
    assert got is not None
    r, c = got
    assert set(r.tolist()) == {22}
    assert (int(c.min()), int(c.max())) == (30, 48)


def test_without_knowing_what_was_seen_the_panel_stays_unplaced() -> None:
    """Without the seen-free grid nothing says the free end's opening was never seen:
    both ends score alike and no doorway is claimed (the caller then keeps the panel's
    cells and marks the floor near it unsure)."""
    panel, occupied, _ = grids()
    rows, cols = np.nonzero(panel)
    assert opening_from_panel(rows, cols, occupied, min_width=8) is None


def test_a_free_end_that_opens_over_unseen_floor_is_no_hinge() -> None:
    """House 1117 (generated, 12 rooms, strong noise, 160x120): a panel swung into a room
    the robot never entered, its free end beside a cabinet (a wall line) with a wall 1.2
    door widths beyond it (a far jamb), and between them floor no frame saw. Counting only
    occupied cells as closed, that end scored as the hinge and the doorway was put there,
    its centre 1.56 m (31 cells) from the real one, and the room merged with the corridor.
    Unseen floor is no opening: the doorway is found at the hinge end, its centre within
    0.6 m of the real doorway's (the panel, smeared by noise, reaches 0.5 m past the wall
    line). ``data/door_panel_h1117.npz``: the replay's map window around that door at
    0.05 m a cell (occupied and seen-free grids, bit-packed), the panel's cells and the
    true doorway's ends in the map's cells (row, col)."""
    from pathlib import Path

    z = np.load(Path(__file__).parent / "data" / "door_panel_h1117.npz")
    shape = tuple(int(v) for v in z["shape"])
    n = shape[0] * shape[1]
    occupied = np.unpackbits(z["occupied"])[:n].reshape(shape).astype(bool)
    free = np.unpackbits(z["free"])[:n].reshape(shape).astype(bool)
    got = opening_from_panel(z["rows"], z["cols"], occupied, min_width=8, free=free)
    assert got is not None
    centre = np.array([got[0].mean(), got[1].mean()])
    assert np.hypot(*(centre - z["doorway"].mean(axis=0))) < 12.0
