"""Rooms the robot cannot stand in, and rooms it cannot get into: a closet too narrow for
the robot is searched from its doorway; a walled-off room is no start for a target
outside it (nor the house outside it for a target in it), and the bench says so."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
from support.datasets_fixtures import two_rooms, walled_off, with_closet

from sgtool.analysis.bench_houses import load_house_files
from sgtool.house.io import load_house
from sgtool.mapping.occupancy import geodesic_distances, world_to_cell
from sgtool.planning.base import Action
from sgtool.recorders.symbolic_environment import SymbolicEnv, SymbolicHouse


def test_a_closet_too_narrow_for_the_robot_is_searched_from_its_doorway() -> None:
    house = SymbolicHouse(load_house(with_closet()))
    assert house.isolated_rooms() == ()
    shelf = house.furn_place[2]
    # the shelf's place is on the bedroom's floor, in front of the closet door (y < 4)
    x, y = house.places[shelf]
    assert abs(x - 6.175) < 0.1 and 3.5 < y < 4.0
    env = SymbolicEnv(house, "hat", start_region="region:0.0")
    for target in ("room:1", "room:2", house.furn_ids[2]):  # bedroom, closet, its shelf
        assert env.step(Action("navigate", target)).feedback.outcome == "success"
    assert env.success
    assert 4.0 < env.travelled < 10.0  # across the kitchen and the door: a finite walk


def test_starts_stay_on_the_targets_side_of_a_missing_door() -> None:
    house = SymbolicHouse(load_house(walled_off(two_rooms(), "door_0")))
    assert len(house.isolated_rooms()) == 1
    for seed in range(8):
        # the apple is in the kitchen (room_0): with no way in, it is searched from there,
        # although target rooms are avoided as starts when others can reach the target
        apple = SymbolicEnv(house, "apple", seed=seed, avoid_rooms=("room_0",))
        assert apple.start_region.startswith("region:0.")
        cup = SymbolicEnv(house, "cup", seed=seed, avoid_rooms=("room_1",))
        assert cup.start_region.startswith("region:1.")
    # a query the house lacks starts anywhere, as before
    assert {SymbolicEnv(house, "piano", seed=s).start_region[:9] for s in range(16)} == \
        {"region:0.", "region:1."}


def test_the_bench_names_a_walled_off_room(tmp_path: Path) -> None:
    f = tmp_path / "cut.json"
    f.write_text(json.dumps(walled_off(two_rooms(), "door_0")))
    (h,) = load_house_files([f])
    (note,) = h.notes
    assert note.startswith("room_") and "no door or passage leads there" in note
    g = tmp_path / "closet.json"
    g.write_text(json.dumps(with_closet()))
    (note,) = load_house_files([g])[0].notes  # a closet too narrow to stand in, said
    assert note.startswith("room_2: no free floor the robot (radius 0.2 m) fits on")


def test_place_distances_are_the_grid_geodesics_of_each_place() -> None:
    """Distances between places with every door closed, searched part by part of the free
    space, are the whole-grid geodesics from each place (inf into parts it cannot reach)."""
    house = SymbolicHouse(load_house(walled_off(with_closet(), "door_0")))
    cells = tuple(zip(*(world_to_cell(house.occ, x, y) for x, y in house.places), strict=True))
    whole = np.array([geodesic_distances(house.occ, xy, max_snap=0.0)[cells]
                      for xy in house.places])
    whole = np.minimum(whole, whole.T)
    got = np.array([house.distances_from(i, frozenset()) for i in range(len(house.places))])
    assert np.array_equal(np.isfinite(got), np.isfinite(whole))
    assert np.allclose(got[np.isfinite(got)], whole[np.isfinite(whole)], rtol=0, atol=1e-9)
    # some places reach others, and the walled-off room's do not reach the rest
    assert len(house.places) < int(np.isfinite(got).sum()) < len(house.places) ** 2
