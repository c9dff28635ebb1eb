"""Whether the robot gets through a door does not depend on how the house is turned
against the occupancy grid (0.05 m cells, robot radius 0.2 m).

Two 3 m x 3 m rooms joined by one door in the 0.1 m wall between them, the whole house
turned about the door's centre in 5 degree steps and shifted by parts of a cell. A door
wider than the robot's diameter by a cell's diagonal (0.4 + 0.0707 m) is passable at
every angle: on the house map (geodesics, the bench's door check) and with the door's
open panel beside it (the simulator's map). One no wider than the diameter, or a 0.1 m
slit, is closed at every angle. Walls, door frames and panels block the cells by the
exact distance from the cell centre to their boxes; grown from the cells their boxes
overlap, a 0.5 m door was closed at 15-75 degrees and a 0.55 m one at 25-35 and 55-65
(at some shifts from 5 and from 15 degrees on), both open at 0 and 90.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from sgtool.house.io import load_house
from sgtool.mapping.occupancy import geodesic_distances, house_occupancy, world_to_cell
from sgtool.recorders.sim import articulation as art
from sgtool.recorders.sim import navigation as nav
from sgtool.recorders.symbolic_environment.house import SymbolicHouse

RADIUS = nav.RobotConfig().radius  # 0.2 m
RES = nav.RobotConfig().resolution  # 0.05 m
ANGLES = range(0, 91, 5)
SHIFTS = ((0.0, 0.0), (0.5 * RES, 0.35 * RES), (0.3 * RES, 0.8 * RES))
WALL = {"thickness": 0.1, "height": 2.5}


def turned_house(width: float, deg: float, shift: tuple[float, float]) -> tuple:
    """(spec, a point in each room) of the two rooms turned by ``deg`` about the door."""
    c, s = math.cos(math.radians(deg)), math.sin(math.radians(deg))

    def at(x: float, y: float) -> list[float]:
        x, y = x - 3.0, y - 1.5
        return [10.0 + shift[0] + c * x - s * y, 10.0 + shift[1] + s * x + c * y]

    ends = [((0, 0), (6, 0)), ((0, 3), (6, 3)), ((0, 0), (0, 3)), ((6, 0), (6, 3)),
            ((3, 0), (3, 1.5 - width / 2)), ((3, 1.5 + width / 2), (3, 3))]
    house = {
        "version": "1.0", "seed": 1,
        "rooms": [{"id": "room_0", "category": "living_room",
                   "polygon": [at(0, 0), at(3, 0), at(3, 3), at(0, 3)]},
                  {"id": "room_1", "category": "kitchen",
                   "polygon": [at(3, 0), at(6, 0), at(6, 3), at(3, 3)]}],
        "walls": [dict(id=f"wall_{i}", a=at(*a), b=at(*b), **WALL)
                  for i, (a, b) in enumerate(ends)],
        "doors": [{"id": "door_0", "center": at(3, 1.5), "width": width,
                   "yaw": math.pi / 2 + math.radians(deg), "state": "open",
                   "rooms": ["room_0", "room_1"]}],
        "furniture": [{"id": "furn_0", "category": "table", "synset": "table.n.02",
                       "room": "room_1", "center": at(5.4, 2.4) + [0.375],
                       "size": [0.6, 0.6, 0.75], "yaw": math.radians(deg),
                       "affordances": ["supporter"], "state": None}],
        "objects": [{"id": "obj_0", "category": "cup", "synset": "cup.n.01",
                     "parent": "furn_0", "relation": "ontop", "room": "room_1",
                     "position": at(5.4, 2.4) + [0.8], "size": [0.08, 0.08, 0.1]}],
        "starts": [{"x": at(1, 1.5)[0], "y": at(1, 1.5)[1], "yaw": 0.0, "room": "room_0"}],
    }
    return load_house(house), at(1, 1.5), at(4.5, 1.5)


def through(occ, a, b) -> bool:
    """Whether the map joins the two points."""
    return bool(np.isfinite(geodesic_distances(occ, a)[world_to_cell(occ, *b)]))


def angles_through(width: float) -> dict[str, list[int]]:
    """Per check, the angles (deg) at which some shift leaves the door closed or open."""
    closed: dict[str, list[int]] = {"map": [], "bench": [], "panel": []}
    opened: dict[str, list[int]] = {"map": [], "bench": [], "panel": []}
    robot = nav.RobotConfig()
    for deg in ANGLES:
        for shift in SHIFTS:
            spec, a, b = turned_house(width, deg, shift)
            (door,) = spec.doors
            got = {
                "map": through(house_occupancy(spec, RES, RADIUS, closed_doors_free=True), a, b),
                "bench": not SymbolicHouse(spec, RES, RADIUS).blocked_doors,
                # the open leaf hinged at one jamb, swung into room_0
                "panel": through(nav.occupancy_with(
                    spec, {"door_0": "open"}, [art.door_panel(door, -1, 1).footprint(1.0)],
                    robot), a, b),
            }
            for name, ok in got.items():
                (opened if ok else closed)[name].append(deg)
    return {"closed at": closed, "open at": opened}


@pytest.mark.parametrize("width", [0.5, 0.55])
def test_a_door_wider_than_the_robot_is_passable_at_every_angle(width: float) -> None:
    closed = angles_through(width)["closed at"]
    assert closed == {"map": [], "bench": [], "panel": []}, closed


@pytest.mark.parametrize("width", [0.1, 0.35, 2 * RADIUS])
def test_a_gap_no_wider_than_the_robot_stays_closed_at_every_angle(width: float) -> None:
    opened = angles_through(width)["open at"]
    assert opened == {"map": [], "bench": [], "panel": []}, opened
