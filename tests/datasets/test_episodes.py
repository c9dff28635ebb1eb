"""Search episodes: targets, hidden flag, and shortest paths checked against the grid and
against a hand-built two-room house."""

from __future__ import annotations

import math

import numpy as np
import pytest
from support.datasets_fixtures import two_rooms, walled_off
from support.path_lengths import path_length

import sgtool
import sgtool.datasets as ds
from sgtool.datasets.episodes import EpisodeGeometry, list_episodes
from sgtool.house.io import load_house
from sgtool.mapping.occupancy import astar, world_to_cell


def test_demo_episodes_are_consistent():
    spec = ds.demo_house()
    eps = list_episodes(spec)
    objs = spec.object_by_id()
    furn = spec.furniture_by_id()
    assert [e.query for e in eps] == sorted({o.category for o in spec.objects})
    assert [e.id for e in eps] == [f"ep_{i}" for i in range(len(eps))]
    geo = EpisodeGeometry(spec)
    for e in eps:
        assert set(e.targets) == {o.id for o in spec.objects if o.category == e.query}
        assert e.hidden == all(objs[t].relation == "inside"
                               and furn[objs[t].parent].state == "closed" for t in e.targets)
        assert set(e.target_rooms) == {objs[t].room for t in e.targets}
        # starts outside the target rooms when the house has such a start
        assert e.start.room not in e.target_rooms
        assert math.isfinite(e.shortest_path) and e.shortest_path > 0
        # the figure is the grid geodesic to the nearest goal cell
        d = geo.distances(e.start)
        goal = np.zeros_like(d, bool)
        for t in e.targets:
            goal |= geo.goal_mask(t)
        assert e.shortest_path == pytest.approx(float(d[goal].min()))
        # and never shorter than the straight line to the nearest goal cell
        ys, xs = np.nonzero(goal)
        gx = geo.occ.origin[0] + (xs + 0.5) * geo.occ.resolution
        gy = geo.occ.origin[1] + (ys + 0.5) * geo.occ.resolution
        straight = np.hypot(gx - e.start.x, gy - e.start.y).min()
        assert e.shortest_path >= straight - 0.05
    assert any(e.hidden for e in eps) and not all(e.hidden for e in eps)
    # deterministic, and n episodes with a seed
    assert list_episodes(spec) == eps
    some = list_episodes(spec, n=40, seed=3)
    assert len(some) == 40 and some == list_episodes(spec, n=40, seed=3)
    assert len({e.query for e in some[:len(eps)]}) == min(40, len(eps))


def test_two_room_episode_by_hand():
    """The apple is in the (closed) fridge at x 0.1-0.9, y 3.15-3.85 of room_0; the robot
    starts in room_1 at (7, 1). The goal region is the free part of room_0 within 1 m of the
    fridge; the path must cross the door, so its length lies between the straight-line
    detour through the door band and an A* path to the region's nearest cell."""
    d = two_rooms()
    d["starts"] = [{"x": 7.0, "y": 1.0, "yaw": 0.0, "room": "room_1"},
                   {"x": 1.0, "y": 1.0, "yaw": 0.0, "room": "room_0"}]
    spec = load_house(d)
    eps = {e.query: e for e in list_episodes(spec)}
    apple = eps["apple"]
    assert apple.hidden and apple.targets == ("obj_0",) and apple.start.room == "room_1"
    assert apple.description == "inside a closed refrigerator in the kitchen"
    cup = eps["cup"]
    assert not cup.hidden and cup.start.room == "room_0"
    geo = EpisodeGeometry(spec)
    goal = geo.goal_mask("obj_0")
    # goal cells: room_0, free, within 1 m of the fridge footprint
    ys, xs = np.nonzero(goal)
    gx = geo.occ.origin[0] + (xs + 0.5) * 0.05
    gy = geo.occ.origin[1] + (ys + 0.5) * 0.05
    assert (gx < 4.0).all()
    dx = np.maximum(np.maximum(0.1 - gx, gx - 0.9), 0)
    dy = np.maximum(np.maximum(3.15 - gy, gy - 3.85), 0)
    assert (np.hypot(dx, dy) <= 1.0 + 1e-9).all()
    # lower bound: through the door's free band (x = 4, y in [1.775, 2.125]) to the region
    lb = min(math.dist((7, 1), (4, yb)) + np.hypot(gx - 4, gy - yb).min()
             for yb in np.linspace(1.775, 2.125, 8))
    assert apple.shortest_path >= lb - 0.05
    # upper bound: an actual A* path to the goal cell the episode's figure ends at
    dist = geo.distances(apple.start)
    i = int(np.argmin(np.where(goal, dist, np.inf)))
    end = (float(gx[np.flatnonzero(goal.ravel()) == i][0]),
           float(gy[np.flatnonzero(goal.ravel()) == i][0]))
    path = astar(geo.occ, (7.0, 1.0), end)
    assert path is not None
    assert path_length(path) == pytest.approx(apple.shortest_path, abs=1e-6)
    assert world_to_cell(geo.occ, *path[-1]) == world_to_cell(geo.occ, *end)


def test_spellings_of_one_category_are_one_episode():
    """"Cup" on the bedroom table and "cup" in a second spelling in the kitchen are one
    query with both instances as targets (the environments find either), so the start
    avoids both rooms' instances the way it avoids one."""
    d = two_rooms()
    d["objects"][0]["category"] = "Cup"  # the apple in the fridge, renamed
    d["objects"][1]["category"] = "cup"
    d["starts"] = [{"x": 1, "y": 1, "yaw": 0, "room": "room_0"}]
    eps = list_episodes(load_house(d))
    assert [(e.query, e.targets) for e in eps] == [("cup", ("obj_0", "obj_1"))]
    assert set(eps[0].target_rooms) == {"room_0", "room_1"}


def test_a_start_that_cannot_reach_the_target_is_drawn_again() -> None:
    """Two rooms and no door between them, a start in each: every episode starts on its
    target's side (the start outside the target room cannot reach it), with a finite path;
    a house whose starts all reach keeps its draws."""
    d = walled_off(two_rooms(), "door_0")
    d["starts"].append({"x": 7.0, "y": 1.0, "yaw": 0.0, "room": "room_1"})
    eps = {e.query: e for e in list_episodes(load_house(d), seed=0)}
    assert eps["apple"].start.room == "room_0" and eps["cup"].start.room == "room_1"
    assert all(math.isfinite(e.shortest_path) for e in eps.values())
    open_house = two_rooms()
    open_house["starts"].append({"x": 7.0, "y": 1.0, "yaw": 0.0, "room": "room_1"})
    for e in list_episodes(load_house(open_house), seed=0):  # outside its target room
        assert e.start.room not in e.target_rooms and math.isfinite(e.shortest_path)


def test_with_no_start_that_reaches_it_a_search_starts_inside() -> None:
    """Two rooms and no door between them, the only start in the kitchen: the cup's search
    (in the bedroom) starts inside the bedroom, on its reachable floor, with a finite path,
    as the symbolic bench searches a walled-off room from inside."""
    eps = {e.query: e for e in list_episodes(load_house(walled_off(two_rooms(), "door_0")))}
    cup = eps["cup"]
    assert cup.start.room == "room_1" and math.isfinite(cup.shortest_path)
    assert 4.0 < cup.start.x < 8.0 and 0.0 < cup.start.y < 4.0
    assert eps["apple"].start.room == "room_0"  # the file's start reaches the apple


def test_a_furniture_target_no_start_reaches_is_searched_from_inside() -> None:
    """The SymSearch mix's furniture episodes draw their start as the small objects' do:
    the table behind the walled-off door is searched from inside its room."""
    from sgtool.datasets.episode_mix import furniture_episodes

    house = load_house(walled_off(two_rooms(), "door_0"))
    eps = {e.query: e for e in furniture_episodes(house, 4, seed=0)}
    assert eps["table"].start.room == "room_1" and math.isfinite(eps["table"].shortest_path)
    assert all(math.isfinite(e.shortest_path) for e in eps.values())


def test_a_reach_the_robot_cannot_stand_within_is_refused() -> None:
    """The robot's centre stays 0.2 m from furniture: a reach under 0.3 m made every
    episode unreachable without a word; it is one line now."""
    from sgtool.errors import SgtoolError

    spec = sgtool.generate_house(3, rooms=(4, 4))
    with pytest.raises(SgtoolError, match="reach 0.2 m: at least 0.3 m"):
        list_episodes(spec, 2, reach=0.2)
    assert all(math.isfinite(e.shortest_path) for e in list_episodes(spec, 3, reach=0.3))


def test_run_episode_k_is_the_listings_k() -> None:
    """`sgtool run --episode K` (pick_episode) draws the start poses the listing of
    `sgtool scenes episodes`, bench and run-bench draw: with the house's own seed."""
    from sgtool.datasets.episodes import pick_episode

    spec = sgtool.generate_house(7, rooms=(5, 6))
    assert spec.seed == 7
    listed = list_episodes(spec, seed=spec.seed)
    assert listed != list_episodes(spec, seed=0)  # the seed moves the starts
    for k, ep in enumerate(listed):
        assert pick_episode(spec, index=k) == (k, ep)
        assert pick_episode(spec, query=ep.query) == (k, ep)
