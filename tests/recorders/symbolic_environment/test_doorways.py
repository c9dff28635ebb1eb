"""A door the robot cannot get through (furniture in its doorway, or a pocket cut off from
the room's floor) is a wall in the symbolic house: not offered, no travel through it, and
the bench and ``scenes check`` say so; ``scenes episodes`` agrees that the far side
cannot be reached."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
from support.datasets_fixtures import two_rooms

from sgtool.analysis.bench_houses import load_house_files
from sgtool.datasets.episodes import list_episodes
from sgtool.house.io import load_house
from sgtool.planning.base import Action
from sgtool.recorders.symbolic_environment import SymbolicEnv, SymbolicHouse


def _with_piece(d: dict, pid: str, center: list[float], size: list[float]) -> dict:
    d["furniture"].append({"id": pid, "category": "bookshelf", "synset": "bookshelf.n.01",
                           "room": "room_1", "center": center, "size": size, "yaw": 0,
                           "affordances": ["supporter"], "state": None})
    return d


def _spec(d: dict, tmp_path: Path, name: str):  # noqa: ANN202 - a HouseSpec
    f = tmp_path / f"{name}.json"
    f.write_text(json.dumps(d))
    return load_house(f), f


def test_a_bookshelf_in_the_doorway_makes_the_door_a_wall(tmp_path: Path) -> None:
    # the door is at x = 4, y 1.5-2.4; a 0.4 m deep shelf stands 0.05 m in front of it
    spec, f = _spec(_with_piece(two_rooms(), "furn_9", [4.25, 1.95, 0.9], [0.4, 1.2, 1.8]),
                    tmp_path, "shelf")
    house = SymbolicHouse(spec)
    assert house.blocked_doors == frozenset({0})
    assert len(house.isolated_rooms()) == 1  # two parts: one of them is named
    env = SymbolicEnv(house, "apple", start_region="region:0.0")
    assert "door:0" not in {n.id for n in env.observe().doors}
    assert env.step(Action("explore", "room:1")).feedback.outcome != "success"
    (h,) = load_house_files([f])
    assert h.notes[0].startswith("door_0 (room_0 - room_1): the robot")
    assert "furn_9" in h.notes[0] and h.notes[0].endswith("read as a wall")
    # the episode list's path lengths agree: the cup beyond the door cannot be reached
    cup = [e for e in list_episodes(spec, seed=0) if e.query == "cup"]
    assert cup and all(math.isinf(e.shortest_path) for e in cup
                       if e.start.room == "room_0")


def test_a_door_into_a_pocket_of_the_room_is_a_wall(tmp_path: Path) -> None:
    # a shelf from wall to wall (y 0-4 at x 4.9-5.3) but for a 0.2 m gap: the door opens
    # into a 0.9 m strip of the bedroom that the robot (0.4 m wide) cannot leave
    d = _with_piece(two_rooms(), "furn_9", [5.1, 1.9, 0.9], [0.4, 3.8, 1.8])
    spec, _ = _spec(d, tmp_path, "pocket")
    assert SymbolicHouse(spec).blocked_doors == frozenset({0})


def test_a_clear_doorway_is_a_door(tmp_path: Path) -> None:
    # a shelf 1.3 m into the room from the north wall, leaving 0.8 m below it: passable
    spec, f = _spec(_with_piece(two_rooms(), "furn_9", [5.5, 2.4, 0.9], [0.4, 3.2, 1.8]),
                    tmp_path, "clear")
    house = SymbolicHouse(spec)
    assert house.blocked_doors == frozenset()
    env = SymbolicEnv(house, "cup", start_region="region:0.0")
    assert "door:0" in {n.id for n in env.observe().doors}
    assert env.step(Action("explore", "room:1")).feedback.outcome == "success"
    assert load_house_files([f])[0].notes == ()


def test_a_check_computes_no_geodesics_and_finds_the_same_parts(tmp_path: Path,
                                                                monkeypatch) -> None:
    """Checking a house file asks no travel question (the per-place geodesics are the
    costly part, computed at the first one), and the parts it finds are those of the
    place graph with every door open."""
    from sgtool.recorders.symbolic_environment import house as symbolic

    d = _with_piece(two_rooms(), "furn_9", [4.25, 1.95, 0.9], [0.4, 1.2, 1.8])
    f = tmp_path / "blocked.json"
    f.write_text(json.dumps(d))

    def refuse(*a, **k):
        raise AssertionError("a geodesic during the check")

    with monkeypatch.context() as m:
        m.setattr(symbolic, "dijkstra", refuse)
        (h,) = load_house_files([f])
        assert "read as a wall" in h.notes[0]
    house = SymbolicHouse(load_house(f))
    labels = house.place_component
    for i in range(len(house.places)):  # same part <=> a finite walk with every door open
        reach = np.isfinite(house.distances_from(i, house.all_doors()))
        assert (reach == (labels == labels[i])).all()
    assert len(set(labels.tolist())) == 2  # the blocked door leaves two parts
