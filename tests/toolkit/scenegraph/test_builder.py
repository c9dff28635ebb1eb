"""The scene-graph builder on rendered two-room scenes (numpy ray-caster, no simulator).

The house (:func:`support.synthetic_world.two_room_house`): a kitchen [0, 4] x [0, 3] and
a bedroom [4, 8] x [0, 3] joined at x = 4 by an open door, a closed door or an open-plan
passage. The robot looks around in the kitchen, walks through the opening and looks around
in the bedroom (if it can).
"""

from __future__ import annotations

import functools

import pytest
from support.synthetic_world import (
    HouseWorld,
    look_around,
    make_frame,
    two_room_house,
    walk,
    world_of_house,
)

from sgtool.log.frame import CameraIntrinsics, Frame
from sgtool.mapping.grid import OCCUPIED
from sgtool.mapping.voxels import VoxelConfig
from sgtool.planning.candidates import actionable, door_is_entrance
from sgtool.scenegraph.builder import BuilderConfig, SceneGraphBuilder
from sgtool.scenegraph.categories import FrequencyRoomClassifier
from sgtool.scenegraph.graph import SceneGraph

K = CameraIntrinsics.from_fov(80, 60, 60)
CONFIG = BuilderConfig(voxels=VoxelConfig(min_points=5), refresh_every=8)
TABLE = {
    "kitchen": {"refrigerator": 5, "countertop": 5, "cup": 2},
    "bedroom": {"bed": 5, "wardrobe": 4},
}


@functools.cache
def scene(opening: str) -> tuple[HouseWorld, tuple[Frame, ...]]:
    hw = world_of_house(two_room_house(opening))
    poses = look_around(2.0, 1.5, 0.0, 12)
    if opening != "closed":
        poses += walk([(2.0, 1.5), (6.0, 1.5)], 0.25) + look_around(6.0, 1.0, 0.0, 12)
    frames = tuple(make_frame(hw.world, x, y, yaw, K, index=i, pitch=0.3)
                   for i, (x, y, yaw) in enumerate(poses))
    return hw, frames


def build(opening: str, with_ids: bool = True, refresh: bool = True
          ) -> tuple[SceneGraphBuilder, SceneGraph]:
    hw, frames = scene(opening)
    b = SceneGraphBuilder(hw.instances if with_ids else None,
                          FrequencyRoomClassifier(TABLE), CONFIG)
    for f in frames:
        if not with_ids:
            f = Frame(f.index, f.time_ns, f.rgb, f.depth, None, f.pose, f.intrinsics,
                      f.base_pose)
        b.integrate(f)
        if refresh and b.due():
            b.refresh(f.time_ns)
    return b, b.refresh(frames[-1].time_ns)


def room_at(sg: SceneGraph, b: SceneGraphBuilder, x: float, y: float) -> str | None:
    """Room of the Voronoi node nearest to (x, y)."""
    vg = b.layers.voronoi  # type: ignore[union-attr]
    d = (vg.positions[:, 0] - x) ** 2 + (vg.positions[:, 1] - y) ** 2
    order = d.argsort()
    for i in order:
        r = b.layers.node_rooms[int(i)]  # type: ignore[union-attr]
        if r is not None:
            return r
    return None


def test_two_rooms_joined_by_an_open_door() -> None:
    b, sg = build("open")
    explored = [r for r in sg.rooms if r.explored]
    assert len(explored) == 2
    kitchen, bedroom = room_at(sg, b, 2.0, 1.5), room_at(sg, b, 6.0, 1.5)
    assert kitchen != bedroom
    assert sg.room(kitchen).neighbours == (bedroom,)  # type: ignore[union-attr]
    (door,) = sg.doors
    assert door.state == "open" and set(door.rooms) == {kitchen, bedroom}
    assert abs(door.position[0] - 4.0) < 0.6
    # objects: furniture in its room, the cup on the countertop, hidden ones absent
    by_cat = {o.category: o for o in sg.objects}
    assert by_cat["refrigerator"].room == kitchen and by_cat["countertop"].room == kitchen
    assert by_cat["bed"].room == bedroom and by_cat["wardrobe"].room == bedroom
    assert by_cat["cup"].parent == by_cat["countertop"].id
    assert by_cat["cup"].relation == "ontop" and by_cat["cup"].room == kitchen
    assert "apple" not in by_cat and "sweater" not in by_cat  # inside closed containers
    assert by_cat["refrigerator"].state == "closed" and not by_cat["refrigerator"].explored
    assert by_cat["refrigerator"].parent.startswith(f"region:{kitchen.split(':')[1]}.")
    # categories from the contained furniture
    assert sg.room(kitchen).category == "kitchen"  # type: ignore[union-attr]
    assert sg.room(bedroom).category == "bedroom"  # type: ignore[union-attr]
    # the robot ended in the bedroom; every node it can act on has a distance
    assert sg.robot.room == bedroom
    for c in actionable(sg):
        assert c.distance >= 0
    assert sg.distances[by_cat["wardrobe"].id] < sg.distances[by_cat["refrigerator"].id]


def test_open_plan_passage_is_one_room() -> None:
    _, sg = build("passage")
    assert len(sg.rooms) == 1 and sg.rooms[0].explored
    assert sg.doors == ()
    assert {o.room for o in sg.objects} == {sg.rooms[0].id}


def test_closed_door_leads_to_an_unexplored_room() -> None:
    _, sg = build("closed")
    explored = [r for r in sg.rooms if r.explored]
    unexplored = [r for r in sg.rooms if not r.explored]
    assert len(explored) == 1 and len(unexplored) == 1
    (door,) = sg.doors
    assert door.state == "closed"
    assert set(door.rooms) == {explored[0].id, unexplored[0].id}
    assert door_is_entrance(sg, door)
    assert unexplored[0].category == "unknown" and unexplored[0].position[0] > 4.0
    assert unexplored[0].id in sg.distances and door.id in sg.distances
    assert any(c.node_id == door.id and c.skill == "open" for c in actionable(sg))


def test_geometry_only_without_instance_ids() -> None:
    b, sg = build("open", with_ids=False)
    assert sg.objects == () and sg.doors == ()
    assert len(sg.rooms) == 1  # no door evidence: nothing cuts the graph
    assert sg.rooms[0].category == "unknown" and sg.rooms[0].category_scores == ()
    assert len(b.layers.voronoi) > 5  # type: ignore[union-attr]
    assert sg.robot.room == sg.rooms[0].id


def test_replay_is_byte_identical_and_incremental_equals_rebuild() -> None:
    b1, sg1 = build("open")
    b2, sg2 = build("open")
    assert sg1.to_json() == sg2.to_json()
    scratch = b1.refresh(sg1.time_ns, from_scratch=True)
    assert scratch.to_json() == sg1.to_json()
    # the JSON form round-trips
    assert SceneGraph.from_json(sg1.to_json()).to_json() == sg1.to_json()


def test_refresh_without_new_frames_reuses_the_graph() -> None:
    b, sg = build("open")
    again = b.refresh(sg.time_ns + 5)
    assert again.time_ns == sg.time_ns + 5
    assert again.rooms == sg.rooms and again.objects == sg.objects


def test_opening_a_door_forgets_its_old_voxels() -> None:
    hw, frames = scene("closed")
    b = SceneGraphBuilder(hw.instances, None, CONFIG)
    for f in frames:
        b.integrate(f)
    door = next(i for i, v in hw.instances.items() if v.kind == "door")
    before = b.voxels.observation(door)
    assert before is not None and before.voxels > 0
    opened = dict(hw.instances)
    opened[door] = type(hw.instances[door])(**{**hw.instances[door].__dict__,
                                               "state": "open"})
    assert b.set_instances(opened) == [door]
    assert b.voxels.observation(door).voxels == 0  # type: ignore[union-attr]
    sg = b.refresh(1)
    assert sg.doors == ()  # not seen since it opened


@pytest.mark.parametrize("opening", ["open", "closed"])
def test_every_node_has_one_parent_in_the_layer_above(opening: str) -> None:
    _, sg = build(opening)
    rooms = {r.id for r in sg.rooms}
    regions = {r.id for r in sg.regions}
    objects = {o.id for o in sg.objects}
    for r in sg.regions:
        assert r.room in rooms
    for o in sg.objects:
        assert o.room in rooms
        assert o.parent in regions or o.parent in objects
        if o.parent in objects:
            assert sg.node(o.parent).room == o.room  # type: ignore[union-attr]
    if sg.robot.region is not None:
        assert sg.robot.region in regions


def test_empty_and_blank_input_never_fails() -> None:
    import numpy as np

    b = SceneGraphBuilder()
    assert b.refresh(0).rooms == ()
    blank = Frame(0, 5, None, np.full((30, 40), np.nan, dtype="float32"), None,
                  np.eye(4), CameraIntrinsics.from_fov(40, 30, 60))
    b.integrate(blank)
    sg = b.refresh(5)
    assert sg.rooms == () and sg.objects == () and sg.time_ns == 5


def test_empty_narrow_rooms_are_corridors() -> None:
    """The corridor rule on hand-made Voronoi graphs: long and narrow -> corridor; wide,
    short or without semantics (no instance table) -> no guess."""
    import numpy as np

    from sgtool.mapping.grid import OccupancyGrid
    from sgtool.mapping.voronoi import voronoi_graph
    from sgtool.scenegraph.room_nodes import corridor_like

    def walled(w: float, h: float) -> OccupancyGrid:
        g = np.full((int(h / 0.05) + 4, int(w / 0.05) + 4), 100, dtype=np.int8)
        g[2:-2, 2:-2] = 0
        return OccupancyGrid(g, (-0.1, -0.1), 0.05)

    corridor = voronoi_graph(walled(6.0, 1.4))
    room = voronoi_graph(walled(4.0, 3.0))
    short = voronoi_graph(walled(2.0, 1.4))
    assert corridor_like(corridor, np.arange(len(corridor)), CONFIG)
    assert not corridor_like(room, np.arange(len(room)), CONFIG)
    assert not corridor_like(short, np.arange(len(short)), CONFIG)
    assert not corridor_like(corridor, np.arange(len(corridor)), CONFIG, semantic=False)
    # a 2.7 m room is no longer long when the house turns (its nodes' bounding box grew to
    # a diagonal over 3 m at 45 degrees: empty, it was called a corridor)
    import dataclasses

    store = voronoi_graph(walled(2.7, 1.4))
    for deg in (0, 17, 45, 60):
        a = np.radians(deg)
        turned = dataclasses.replace(store, positions=store.positions @ np.array(
            [[np.cos(a), np.sin(a)], [-np.sin(a), np.cos(a)]]))
        assert not corridor_like(turned, np.arange(len(store)), CONFIG), deg


@pytest.mark.parametrize("doors", [1, 4])
def test_a_narrow_room_joining_four_rooms_leans_to_a_corridor(doors: int) -> None:
    """A hall with a shelf and a console table (which vote for another type) is a
    corridor once it joins four rooms (here behind four closed doors); with one door the
    objects decide, as in any room. A galley kitchen of that shape and those doors stays
    a kitchen (its stove and fridge name it clearly), and without a classifier no room is
    named (the rule weighs the classifier's answer, it does not replace it)."""
    import numpy as np

    from sgtool.datasets.room_evidence import frequency_room_classifier
    from sgtool.mapping.grid import OccupancyGrid
    from sgtool.mapping.voronoi import voronoi_graph
    from sgtool.scenegraph.door_evidence import DoorObservation
    from sgtool.scenegraph.instances import InstanceInfo
    from sgtool.scenegraph.object_placement import PlacedObject
    from sgtool.scenegraph.room_nodes import room_nodes
    from sgtool.scenegraph.room_segmentation import RoomSegmentation

    g = np.full((32, 124), 100, dtype=np.int8)
    g[2:-2, 2:-2] = 0  # 6 m x 1.4 m
    vg = voronoi_graph(OccupancyGrid(g, (-0.1, -0.1), 0.05))
    n = len(vg.positions)
    seg = RoomSegmentation(labels=np.zeros(n, dtype=np.int64),
                           cut_edges=np.zeros(len(vg.edges), dtype=bool),
                           cut_nodes=np.zeros(n, dtype=bool), rooms=(np.arange(n),),
                           centres=(0,))
    observed = [DoorObservation(10 + k, (1.0 + k, 1.4), "closed", ("room:0",),
                                f"room:{k + 1}", 0) for k in range(doors)]
    behind = {f"room:{k + 1}": (1.0 + k, 2.4) for k in range(doors)}

    def named(categories: list[str], classifier: object) -> str:
        things = {i + 1: InstanceInfo(i + 1, c, "furniture") for i, c in enumerate(categories)}
        placed = [PlacedObject(i, (1.0 + i / 2, 0.6, 0.5), i, 0, None, room="room:0")
                  for i in things]
        room = room_nodes(vg, seg, ["room:0"], placed, observed, behind, things,
                          classifier, {}, CONFIG)[0]  # type: ignore[arg-type]
        assert len(room.neighbours) == doors
        return room.category

    frequency = frequency_room_classifier()
    assert (named(["shelf", "console_table"], frequency) == "corridor") == (doors == 4)
    assert named(["stove", "refrigerator", "dishwasher", "countertop"], frequency) == \
        "kitchen"
    assert named(["shelf", "console_table"], None) == "unknown"

    class Silent:  # a classifier with nothing to say about these objects
        def classify(self, categories: list[str]) -> list[tuple[str, float]]:
            return []

    # as an empty narrow room then (it was "unknown" while an empty one was a corridor)
    assert named(["shelf"], Silent()) == ("corridor" if doors == 4 else "unknown")


def test_weighing_a_type_moves_no_other_type_up() -> None:
    """The corridor weight scales the answer back to its own total (a user classifier's
    scores need not sum to 1: renormalising raised kitchen 0.2 -> 0.29); an answer that
    does not name the type (one type at 1.0, as the LLM classifier answers) is left as it
    is."""
    from sgtool.scenegraph.room_nodes import weigh_type

    got = dict(weigh_type([("kitchen", 0.2), ("corridor", 0.05)], "corridor", 10.0))
    assert got["kitchen"] < 0.2 and sum(got.values()) == pytest.approx(0.25)
    assert weigh_type([("utility_room", 1.0)], "corridor", 10.0) == [("utility_room", 1.0)]
    assert weigh_type([("kitchen", 0.3), ("corridor", 0.0)], "corridor", 10.0) == [
        ("kitchen", 0.3), ("corridor", 0.0)]


def test_the_columns_the_camera_cannot_see_over_are_the_walls_not_the_floor() -> None:
    b, _ = build("closed")
    grid = b.layers.occupancy  # type: ignore[union-attr]
    tall = b.columns_between(grid, 1.2, 1.6)
    assert tall.shape == grid.shape and tall.any()
    # all of them are obstacles on the map, and the dividing wall (x = 4 m, 2.5 m high)
    # is among them
    assert (grid.grid[tall] == OCCUPIED).all()
    assert any(tall[grid.cell_of(x, 0.5)] for x in (3.98, 4.02))
    # nothing in the house reaches 5 m above the floor
    assert not b.columns_between(grid, 5.0, 6.0).any()
