"""Start poses and reachability of a hand-made house (no generator involved)."""

from __future__ import annotations

from support.foreign_house import cottage

from sgtool.datasets.episodes import list_episodes
from sgtool.datasets.start_poses import reachability, start_poses, with_start_poses
from sgtool.house.io import load_house


def test_one_start_per_room_inside_the_room() -> None:
    spec = load_house(cottage())
    rep = reachability(spec)
    assert rep.complete and rep.origin_room == "room_kitchen"
    assert [s.room for s in rep.starts] == ["room_kitchen", "room_hall", "room_bed"]
    for s in rep.starts:
        assert spec.room(s.room).contains(s.x, s.y)
    # the start nearest each centroid: the hall (4..6 x 0..4) has its centre free
    hall = rep.starts[1]
    assert abs(hall.x - 5.0) < 0.05 and abs(hall.y - 2.0) < 0.05
    assert start_poses(spec, seed=3) != start_poses(spec, seed=0)  # yaws from the seed
    assert [(s.x, s.y) for s in start_poses(spec, seed=3)] == \
        [(s.x, s.y) for s in rep.starts]


def test_walled_off_room_and_its_furniture_are_unreachable() -> None:
    d = cottage()
    d["doors"] = [x for x in d["doors"] if x["id"] != "door_bed"]
    d["walls"].append({"id": "wall_shut", "a": [6, 1.5], "b": [6, 2.5]})
    rep = reachability(load_house(d))
    assert rep.unreachable_rooms == ("room_bed",)
    assert rep.unreachable_furniture == ("furn_bed", "furn_wardrobe")
    assert not rep.complete and [s.room for s in rep.starts] == ["room_kitchen", "room_hall"]


def test_a_walled_off_room_listed_first_does_not_cut_off_the_rest() -> None:
    """The same walled-off bedroom listed first: the origin was the first room, so only the
    bedroom was reachable (every episode started in its target's room, the recorder toured
    the bedroom alone). The origin is the room that reaches the most."""
    d = cottage()
    d["doors"] = [x for x in d["doors"] if x["id"] != "door_bed"]
    d["walls"].append({"id": "wall_shut", "a": [6, 1.5], "b": [6, 2.5]})
    d["rooms"] = sorted(d["rooms"], key=lambda r: r["id"] != "room_bed")
    rep = reachability(load_house(d))
    assert rep.origin_room == "room_kitchen" and rep.unreachable_rooms == ("room_bed",)
    assert [s.room for s in rep.starts] == ["room_kitchen", "room_hall"]
    assert reachability(load_house(d), origin_room="room_bed").unreachable_rooms == (
        "room_kitchen", "room_hall")


def test_list_episodes_needs_the_start_poses_a_hand_made_house_lacks() -> None:
    spec = load_house(cottage())
    assert spec.starts == () and list_episodes(spec) == []
    eps = list_episodes(with_start_poses(spec))
    assert [e.query for e in eps] == ["milk", "mug", "pillow", "sweater", "umbrella"]
    # starts avoid the target's room when another room exists
    assert all(e.start.room not in e.target_rooms for e in eps)
    assert with_start_poses(with_start_poses(spec)) == with_start_poses(spec)
