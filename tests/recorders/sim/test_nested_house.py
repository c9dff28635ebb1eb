"""PyBullet loads a house-spec-2 house (tests/support/nested_house.py): objects nested in
objects get their parent's instance and are boxes at their positions, turned like their
furniture; a piece with shelf levels is hollow with a board under each level, so a ray
from above onto the bookcase's lowest shelf hits the mug standing there."""

from __future__ import annotations

import pytest
from support.nested_house import nested_house

from sgtool.house.io import load_house
from sgtool.recorders.sim.body_instances import OBJECT, instance_table
from sgtool.recorders.sim.build import build_world, pybullet, shelf_boards


@pytest.fixture(scope="module")
def world():
    spec = load_house(nested_house())
    pb = pybullet()
    client = pb.connect(pb.DIRECT)
    try:
        yield pb, client, spec, build_world(pb, client, spec)
    finally:
        pb.disconnect(client)


def hit_from_above(world, x: float, y: float, z0: float) -> tuple[str | None, float]:
    """Spec id of the first body straight down from (x, y, z0), and the hit's z."""
    pb, client, _, w = world
    hit = pb.rayTest((x, y, z0), (x, y, 0.0), physicsClientId=client)[0]
    return w.by_id[w.body_instance[hit[0]]].spec_id, hit[3][2]


def test_instance_parents_follow_the_nesting():
    spec = load_house(nested_house())
    table = instance_table(spec)
    by_spec = {i.spec_id: i for i in table if i.spec_id}
    assert by_spec["obj_candy"].parent == by_spec["obj_tin"].id
    assert by_spec["obj_tin"].parent == by_spec["obj_box"].id  # listed after the tin
    assert by_spec["obj_box"].parent == by_spec["furn_cabinet"].id
    assert by_spec["obj_book"].relation == "ontop"
    assert [i.kind for i in table].count(OBJECT) == len(spec.objects)


def test_nested_objects_are_built_at_their_positions(world):
    pb, client, spec, w = world
    bodies = {}
    for uid, iid in w.body_instance.items():
        bodies.setdefault(iid, []).append(uid)
    for o in spec.objects:
        (uid,) = bodies[w.by_spec[o.id].id]
        pos, _ = pb.getBasePositionAndOrientation(uid, physicsClientId=client)
        assert pos == pytest.approx(o.position, abs=1e-6), o.id


def test_a_lower_shelf_is_a_board_the_mug_stands_on(world):
    spec = world[2]
    bookcase = spec.furniture_by_id()["furn_bookcase"]
    boards = shelf_boards(bookcase)
    assert [round(c[2] + s[2] / 2 + bookcase.size[2] / 2, 6) for c, s in boards] == [0.3, 0.8]
    # straight down from between the shelves at the mug's centre: the mug (top 0.4);
    # beside it, the lowest shelf
    for x, (sid, z) in ((6.0, ("obj_mug", 0.4)), (6.2, ("furn_bookcase", 0.3))):
        got = hit_from_above(world, x, 3.75, 0.7)
        assert got[0] == sid and got[1] == pytest.approx(z, abs=1e-4)


def test_a_small_container_is_hollow_so_its_contents_show(world):
    # straight down into the bowl on the counter: the apple (top 0.97), not a solid bowl;
    # beside the apple, inside the rim: the bowl's bottom board (0.90 + 0.01)
    for x, (sid, z) in ((3.0, ("obj_apple", 0.97)), (3.06, ("obj_bowl", 0.91))):
        got = hit_from_above(world, x, 3.6, 1.5)
        assert got[0] == sid and got[1] == pytest.approx(z, abs=1e-4)
