"""Reveal rules of the symbolic environment on a house-spec-2 house
(tests/support/nested_house.py): walking up to a piece shows what is on its top even when
it is closed; opening shows what is inside and on its lower shelves; nested containers
open one at a time; the episode list's "hidden" flag agrees; furniture of the query
category counts for the shortest path."""

from __future__ import annotations

import pytest
from support.nested_house import nested_house
from support.symbolic_fixtures import three_rooms

from sgtool.datasets.episodes import list_episodes
from sgtool.house.io import load_house
from sgtool.planning.base import Action
from sgtool.recorders.symbolic_environment import SymbolicEnv, SymbolicHouse

CABINET, COUNTER, BOOKCASE = "obj:1", "obj:2", "obj:3"
# small objects: node obj:<3 + 1 + index in spec.objects>
VASE, BOOK, TIN, BOX, CANDY, BOWL, APPLE, MUG = (f"obj:{4 + j}" for j in range(8))


@pytest.fixture(scope="module")
def house() -> SymbolicHouse:
    return SymbolicHouse(load_house(nested_house()))


def seen(env: SymbolicEnv) -> set[str]:
    return {o.id for o in env.observe().objects}


def in_kitchen(house: SymbolicHouse, query: str = "umbrella") -> SymbolicEnv:
    """An episode that starts in the den and has walked into the kitchen: its one region
    (cabinet and counter) is in view, nothing on or in them yet."""
    env = SymbolicEnv(house, query, start_region="region:1.0")
    assert env.step(Action("explore", "room:0")).feedback.outcome == "success"
    assert seen(env) == {CABINET, COUNTER, BOOKCASE}
    return env


def test_walking_up_reveals_the_top_of_a_closed_piece_opening_its_inside(house):
    env = in_kitchen(house)
    out = env.step(Action("navigate", CABINET)).feedback
    assert out.outcome == "success" and out.message == "at the cabinet; found vase"
    assert seen(env) == {CABINET, COUNTER, BOOKCASE, VASE}  # not the book on the shelf
    node = next(o for o in env.observe().objects if o.id == CABINET)
    assert node.state == "closed" and not node.explored
    out = env.step(Action("open", CABINET))
    assert out.opened and out.feedback.message == "found book, box"
    assert seen(env) - {CABINET, COUNTER, BOOKCASE} == {VASE, BOOK, BOX}


def test_nested_containers_open_one_at_a_time(house):
    env = in_kitchen(house)
    env.step(Action("open", CABINET))
    assert TIN not in seen(env)
    box = next(o for o in env.observe().objects if o.id == BOX)
    assert (box.parent, box.relation, box.state) == (CABINET, "inside", "closed")
    assert "openable" in box.affordances and not box.explored
    # an object that is not openable cannot be opened; the tin is not in view yet
    assert env.step(Action("open", VASE)).feedback.outcome == "invalid"
    assert env.step(Action("open", TIN)).feedback.outcome == "invalid"
    out = env.step(Action("open", BOX))
    assert out.opened and out.feedback.message == "found tin"
    assert TIN in seen(env) and CANDY not in seen(env)
    assert env.step(Action("open", BOX)).feedback.outcome == "failure"  # already open
    assert env.step(Action("open", TIN)).feedback.message == "found candy"
    candy = next(o for o in env.observe().objects if o.id == CANDY)
    assert candy.parent == TIN and candy.state is None and candy.affordances == ()
    assert env.n_open == 3


def test_an_open_container_on_top_shows_its_contents_with_it(house):
    env = in_kitchen(house)
    assert env.step(Action("navigate", COUNTER)).feedback.message == "found apple, bowl"
    bowl = next(o for o in env.observe().objects if o.id == BOWL)
    assert bowl.explored and "examine" in bowl.affordances
    assert env.step(Action("explore", BOWL)).feedback.outcome == "failure"  # nothing left


def test_the_target_is_found_when_its_last_container_opens(house):
    env = in_kitchen(house, query="candy")
    for target in (CABINET, BOX):
        env.step(Action("open", target))
        assert not env.ended
    env.step(Action("open", TIN))
    assert env.ended and env.success and env.end_reason == "found"


def test_a_lower_shelf_of_an_open_piece_is_seen_by_walking_up(house):
    env = SymbolicEnv(house, "umbrella", start_region="region:1.0")
    assert env.step(Action("navigate", BOOKCASE)).feedback.message == "found mug"


def test_the_hidden_flag_agrees_with_the_reveal_rules(house):
    eps = {e.query: e for e in list_episodes(house.spec)}
    assert {q for q, e in eps.items() if e.hidden} == {"book", "box", "tin", "candy"}
    assert eps["candy"].description == ("inside a closed tin inside a closed box inside a "
                                        "closed cabinet in the kitchen")
    # each not hidden object is seen by walking up to its furniture, no opening
    for q, e in eps.items():
        env = in_kitchen(house) if e.target_rooms == ("room_kitchen",) else \
            SymbolicEnv(house, "umbrella", start_region="region:1.0")
        piece = {"vase": CABINET, "book": CABINET, "box": CABINET, "tin": CABINET,
                 "candy": CABINET, "bowl": COUNTER, "apple": COUNTER, "mug": BOOKCASE}[q]
        env.step(Action("navigate", piece))
        node = f"obj:{4 + house.obj_index[e.targets[0]]}"
        assert (node in seen(env)) == (not e.hidden), q


def test_furniture_of_the_query_category_counts_for_the_shortest_path():
    """A toy refrigerator on the bedroom table of the three-room house: the kitchen's
    refrigerator is nearer, and the environment counts it as found, so both the episode
    and the environment measure the path to it."""
    d = three_rooms(door1="open")
    d["objects"].append({"id": "obj_6", "category": "refrigerator", "synset": "toy.n.01",
                         "parent": "furn_5", "relation": "ontop", "room": "room_1",
                         "position": [6.2, 0.8, 0.44], "size": [0.08, 0.08, 0.08]})
    d["starts"] = [{"x": 1.0, "y": 2.0, "yaw": 0, "room": "room_0"}]
    spec = load_house(d)
    ep = next(e for e in list_episodes(spec) if e.query == "refrigerator")
    assert ep.targets == ("obj_6", "furn_0")
    assert ep.target_rooms == ("room_0", "room_1") and not ep.hidden
    from sgtool.datasets.episodes import EpisodeGeometry

    geo = EpisodeGeometry(spec)
    to_toy = geo.shortest_path(ep.start, ["obj_6"])
    to_fridge = geo.shortest_path(ep.start, ["furn_0"])
    assert to_fridge < to_toy and ep.shortest_path == pytest.approx(to_fridge)
    h = SymbolicHouse(spec)
    env = SymbolicEnv(h, "refrigerator", start_region="region:0.1")
    toy_only = h.distances_from(env.start_place, h.all_doors())[h.furn_place[5]]
    assert env.shortest_path(["obj_6"]) < toy_only  # the refrigerator, not the toy
