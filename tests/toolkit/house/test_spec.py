"""House spec: validation messages, canonical JSON, room look-up; occupancy and paths on a
hand-built two-room house whose distances can be worked out by hand."""

from __future__ import annotations

import copy
import json
import math

import numpy as np
import pytest
from support.datasets_fixtures import two_rooms
from support.path_lengths import path_length, shortest_path_length

from sgtool.errors import SpecError
from sgtool.house.io import load_house, save_house
from sgtool.house.spec import HouseSpec, room_at
from sgtool.mapping.occupancy import (
    astar,
    cell_to_world,
    geodesic_distances,
    house_occupancy,
    world_to_cell,
)


def test_round_trip_is_canonical(tmp_path):
    spec = load_house(two_rooms())
    assert isinstance(spec, HouseSpec)
    text = spec.to_json()
    again = load_house(text)
    assert again == spec
    assert again.to_json() == text
    p = save_house(spec, tmp_path / "h.json")
    assert p.read_bytes() == text.encode()
    assert load_house(p) == spec
    assert [f.name for f in tmp_path.iterdir()] == ["h.json"]  # no temp file left behind
    # key order of the input does not matter
    d = two_rooms()
    shuffled = {k: d[k] for k in reversed(list(d))}
    assert load_house(shuffled).to_json() == text


def test_lookups():
    spec = load_house(two_rooms())
    assert room_at(spec, 1, 1) == "room_0"
    assert room_at(spec, 5, 1) == "room_1"
    assert room_at(spec, 9, 1) is None
    assert room_at(spec, 4, 3) == "room_0"  # shared border: first room in id order
    assert spec.room_graph() == {"room_0": ("room_1",), "room_1": ("room_0",)}
    assert spec.containers()[0].id == "furn_0"
    f = spec.furniture_by_id()["furn_1"]
    assert f.top == pytest.approx(0.75)
    assert spec.room("room_1").area == pytest.approx(16.0)
    assert spec.room("room_0").centroid == pytest.approx((2.0, 2.0))


@pytest.mark.parametrize("mutate, message", [
    (lambda d: d["rooms"][1].__setitem__("polygon", [[0, 0], [1, 1]]),
     "rooms[1].polygon: needs at least 3 points"),
    (lambda d: d["rooms"][0].__setitem__("polygon", [[0, 0], [1, 1], [2, 2]]),
     "rooms[0].polygon: has zero area"),
    (lambda d: d.__setitem__("version", "3.0"), "version: '3.0' is not supported"),
    (lambda d: d.pop("rooms"), "rooms: missing"),
    (lambda d: d["doors"][0].__setitem__("state", "ajar"),
     "doors[0].state: expected 'open' or 'closed'"),
    (lambda d: d["doors"][0].__setitem__("rooms", ["room_0", "room_9"]),
     "doors[0].rooms: unknown room 'room_9'"),
    (lambda d: d["furniture"][1].__setitem__("size", [1, 0, 1]),
     "furniture[1].size: every side must be > 0"),
    (lambda d: d["furniture"][0].__setitem__("state", None),
     "furniture[0].state: expected 'open' or 'closed'"),
    (lambda d: d["furniture"][1].__setitem__("affordances", ["edible"]),
     "furniture[1].affordances: unknown affordance 'edible'"),
    (lambda d: d["furniture"][1].__setitem__("center", [12, 3.4, 0.375]),
     "furniture[1].center: (12.0, 3.4) is outside its room room_1"),
    (lambda d: d["objects"][1].__setitem__("relation", "inside"),
     "objects[1].parent: furn_1 (table) is not a container"),
    (lambda d: d["objects"][0].__setitem__("parent", "furn_9"),
     "objects[0].parent: 'furn_9' is not a furniture or object id"),
    (lambda d: d["objects"][0].__setitem__("position", [0.5, 3.5, 2.5]),
     "objects[0].position: obj_0 sticks out of furn_0 vertically"),
    (lambda d: d["objects"][1].__setitem__("position", [6.0, 3.4, 1.2]),
     "objects[1].position: obj_1 bottom z=1.150 is not on furn_1's top z=0.750"),
    (lambda d: d["objects"][1].__setitem__("room", "room_0"),
     "objects[1].room: 'room_0' differs from its parent's room 'room_1'"),
    (lambda d: d["furniture"][1].__setitem__("id", "furn_0"),
     "furniture[1].id: duplicate id 'furn_0'"),
    (lambda d: d["walls"][2].__setitem__("thickness", -1),
     "walls[2].thickness: must be > 0"),
    (lambda d: d["starts"][0].__setitem__("x", "one"), "starts[0].x: expected a finite number"),
    (lambda d: d["starts"][0].__setitem__("x", 6.0), "starts[0]: (6.0, 1.0) is outside its room"),
])
def test_validation_names_the_field(mutate, message):
    d = copy.deepcopy(two_rooms())
    mutate(d)
    with pytest.raises(SpecError) as e:
        load_house(d)
    assert str(e.value).startswith(message), str(e.value)


def test_a_file_with_a_byte_order_mark_loads(tmp_path):
    """Editors on Windows save UTF-8 with a byte-order mark; it is no part of the JSON."""
    p = tmp_path / "bom.json"
    p.write_bytes(b"\xef\xbb\xbf" + json.dumps(two_rooms()).encode())
    assert load_house(p) == load_house(two_rooms())


def test_file_errors_name_the_file(tmp_path):
    bad = tmp_path / "bad.json"
    bad.write_text("{not json")
    with pytest.raises(SpecError, match="bad.json: not valid JSON"):
        load_house(bad)
    with pytest.raises(SpecError, match="nope.json: no such house spec file"):
        load_house(tmp_path / "nope.json")
    d = two_rooms()
    d["rooms"][0]["polygon"] = [[0, 0]]
    p = tmp_path / "h.json"
    p.write_text(json.dumps(d))
    with pytest.raises(SpecError, match=r"h.json: rooms\[0\].polygon: needs at least 3 points"):
        load_house(p)


def test_occupancy_cells_and_coordinates():
    occ = house_occupancy(load_house(two_rooms()), resolution=0.05, robot_radius=0.2)
    assert occ.origin == (-0.5, -0.5)
    assert occ.shape == (100, 180)
    r, c = world_to_cell(occ, 1.0, 1.0)
    assert cell_to_world(occ, r, c) == pytest.approx((1.025, 1.025))
    # a wall of 0.1 m at x = 0 covers exactly the two columns either side of the line
    row = world_to_cell(occ, 0.0, 1.0)[0]
    cols = np.nonzero(occ.occupied[row, world_to_cell(occ, -0.2, 0)[1]:
                                   world_to_cell(occ, 0.3, 0)[1]])[0]
    xs = [cell_to_world(occ, row, world_to_cell(occ, -0.2, 0)[1] + k)[0] for k in cols]
    assert xs == pytest.approx([-0.175, -0.125, -0.075, -0.025, 0.025])  # outside + wall
    # the fridge footprint is an obstacle, the free floor is not
    assert occ.occupied[world_to_cell(occ, 0.5, 3.5)]
    assert not occ.occupied[world_to_cell(occ, 2.0, 2.0)]
    # inflation by 0.2 m: 0.025 + 4 cells from the wall's inner face blocked, 5th free
    r = world_to_cell(occ, 2.0, 2.0)[0]
    blocked_cols = [c for c in range(world_to_cell(occ, 0.0, 0)[1], world_to_cell(occ, 0.5, 0)[1])
                    if occ.blocked[r, c]]
    assert cell_to_world(occ, r, max(blocked_cols))[0] == pytest.approx(0.225)
    # the door opening (0.9 m = 18 cells) leaves 10 free cells for the robot's centre
    col = world_to_cell(occ, 4.0 + 0.001, 0)[1]
    door_rows = [rr for rr in range(occ.shape[0]) if not occ.blocked[rr, col]]
    assert len(door_rows) == 10


def test_geodesics_by_hand():
    spec = load_house(two_rooms())
    occ = house_occupancy(spec)
    # inside one room with nothing between: straight line (on the 8-connected grid)
    d = shortest_path_length(occ, (1.0, 1.0), (3.0, 1.0))
    assert d == pytest.approx(2.0)
    d = shortest_path_length(occ, (1.0, 1.0), (3.0, 3.0))
    assert d == pytest.approx(2 * math.sqrt(2))
    # through the door: from (1, 1) the path must pass the door's free band x=4, y in
    # [1.75, 2.2] (0.2 m + half a cell from each jamb); a lower bound is the Euclidean
    # detour via the band's lowest point, an upper bound that plus octile slack
    lb = math.dist((1, 1), (4, 1.775)) + math.dist((4, 1.775), (7, 1))
    d = shortest_path_length(occ, (1.0, 1.0), (7.0, 1.0))
    assert lb <= d <= lb * 1.09
    # A* agrees with Dijkstra and its path only uses free cells
    path = astar(occ, (1.0, 1.0), (7.0, 1.0))
    assert path is not None and path_length(path) == pytest.approx(d)
    for x, y in path:
        assert not occ.blocked[world_to_cell(occ, x, y)]
    # a closed door disconnects the rooms, unless closed doors count as passable
    closed = load_house(two_rooms("closed"))
    occ_c = house_occupancy(closed)
    assert math.isinf(shortest_path_length(occ_c, (1.0, 1.0), (7.0, 1.0)))
    assert astar(occ_c, (1.0, 1.0), (7.0, 1.0)) is None
    occ_o = house_occupancy(closed, closed_doors_free=True)
    assert shortest_path_length(occ_o, (1.0, 1.0), (7.0, 1.0)) == pytest.approx(d)
    # several sources: distance to the nearest one
    dd = geodesic_distances(occ, [(1.0, 1.0), (3.0, 1.0)])
    assert dd[world_to_cell(occ, 3.0, 1.0)] == 0.0
    # a start inside furniture snaps to the nearest free cell; far outside gives inf
    assert np.isfinite(geodesic_distances(occ, (0.5, 3.5), max_snap=1.0)).any()
    assert np.isinf(geodesic_distances(occ, (20.0, 20.0))).all()


def test_a_house_without_a_starts_key_loads_with_none():
    """``starts`` may be left out, as the commands that need starts add their own."""
    d = two_rooms()
    del d["starts"]
    assert load_house(d).starts == ()
