"""The caches of a bench worker: planners per run, also for runs in two threads."""

from __future__ import annotations

import threading

from sgtool.analysis.bench_cache import cached_planner


def test_a_run_builds_each_planner_once_and_the_next_run_afresh():
    a = cached_planner("scout", {}, "run-a")
    assert cached_planner("scout", {}, "run-a") is a
    assert cached_planner("scout", {"delta": 0.2}, "run-a") is not a
    assert cached_planner("scout", {}, "run-b") is not a


def test_runs_in_two_threads_keep_their_own_planners():
    seen: dict[str, list[object]] = {"x": [], "y": []}

    def work(run: str) -> None:
        for _ in range(50):
            seen[run].append(cached_planner("greedy", {}, run))

    threads = [threading.Thread(target=work, args=(r,)) for r in ("x", "y")]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    # each run saw one planner throughout, and not the other run's
    assert len({id(p) for p in seen["x"]}) == 1 and len({id(p) for p in seen["y"]}) == 1
    assert seen["x"][0] is not seen["y"][0]


def test_a_house_file_rewritten_between_runs_is_another_house():
    """A notebook that edits its house file and runs again benches the new house."""
    from sgtool.analysis.bench_cache import cached_house
    from sgtool.analysis.bench_houses import BenchHouse
    from sgtool.datasets.generator import generate_house

    old = BenchHouse("myhouse", "hh/myhouse.json", spec=generate_house(1, rooms=(4, 6)))
    new = BenchHouse("myhouse", "hh/myhouse.json", spec=generate_house(7, rooms=(5, 6)))
    a, b = cached_house(old, (4, 16), 3), cached_house(new, (4, 16), 3)
    assert [e.query for e in a[1]] != [e.query for e in b[1]]
    assert cached_house(old, (4, 16), 3) is a  # the same content: built once


def test_rooms_joined_by_open_floor_alone_are_a_passage_and_said():
    """Rooms that touch with no wall between them and no door or passage: the robot drives
    across, so the scene graph joins them as by a passage (every episode of such a house
    was unsolvable: the start drawn in a room the planner could not leave); the house's
    notes say so, and a house built by the generator says nothing."""
    import dataclasses

    from sgtool.analysis.bench_houses import house_notes
    from sgtool.datasets.generator import generate_house
    from sgtool.recorders.symbolic_environment.house import SymbolicHouse
    from sgtool.recorders.symbolic_environment.rollout import run_one

    spec = generate_house(2, rooms=(4, 5))
    assert SymbolicHouse(spec).open_floor == []
    bare = dataclasses.replace(spec, walls=(), doors=(), passages=())
    house = SymbolicHouse(bare)
    assert len(house.open_floor) >= len(spec.rooms) - 1
    assert all(any(o == b for o, _ in house.links[a]) for a, b in house.open_floor)
    notes = [n for n in house_notes(house) if "share open floor (no wall) but no door" in n]
    assert len(notes) == len(house.open_floor)
    # an episode started away from the target's room reaches it
    assert run_one(house, "greedy", spec.objects[0].category, max_steps=200).success


def test_a_plugin_is_built_afresh_for_each_task(tmp_path, monkeypatch):
    """What a plug-in keeps between episodes stays in one task (a house's episodes): it is
    not handed to the next task the worker runs, so results do not depend on -w."""
    (tmp_path / "keeps_state.py").write_text(
        "from sgtool.planning.planners import GreedyPlanner\n"
        "class Keeps(GreedyPlanner):\n"
        "    seen = 0\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    a = cached_planner("keeps_state:Keeps", {}, "run-p")
    b = cached_planner("keeps_state:Keeps", {}, "run-p")
    assert a is not b and a.name == b.name == "keeps_state:Keeps"


def test_a_room_the_robot_cannot_stand_in_is_said():
    """A table filling a 4 m x 4 m bedroom: the symbolic bench searches the room from
    the kitchen next to it, the closed loop cannot enter it; the notes say so (they said
    nothing of it)."""
    from support.datasets_fixtures import two_rooms

    from sgtool.analysis.bench_houses import house_notes
    from sgtool.house.io import load_house
    from sgtool.recorders.symbolic_environment.house import SymbolicHouse

    d = two_rooms()
    table = d["furniture"][1]
    table.update(center=[6.0, 2.0, 0.375], size=[3.9, 3.9, 0.75])  # a table as big
    d["objects"][1]["position"][:2] = [6.0, 2.0]
    house = SymbolicHouse(load_house(d))
    assert house.niches == (1,)
    assert any(n.startswith("room_1: no free floor the robot (radius 0.2 m) fits on")
               for n in house_notes(house))
    assert SymbolicHouse(load_house(two_rooms())).niches == ()


def test_a_door_between_rooms_that_do_not_meet_says_so():
    """Rooms 0.4 m apart with the door in the gap: the note says no floor joins them
    there (it blamed a cabinet 0.9 m away)."""
    from support.datasets_fixtures import two_rooms

    from sgtool.analysis.bench_houses import house_notes
    from sgtool.house.io import load_house
    from sgtool.recorders.symbolic_environment.house import SymbolicHouse

    d = two_rooms()
    d["rooms"][1]["polygon"] = [[4.4, 0], [8.4, 0], [8.4, 4], [4.4, 4]]
    d["walls"] = [w for w in d["walls"] if w["a"][0] != 4]
    d["doors"][0]["center"] = [4.2, 1.95]
    for x in (*d["furniture"], *d["objects"]):
        if x["room"] == "room_1":
            x["center" if "center" in x else "position"][0] += 0.4
    notes = house_notes(SymbolicHouse(load_house(d)))
    assert "door_0 (room_0 - room_1): the rooms are 0.40 m apart at the door: no floor " \
        "joins them through it; read as a wall" in " ".join(notes)
