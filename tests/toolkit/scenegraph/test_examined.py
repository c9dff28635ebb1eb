"""Which pieces count as looked at from close by (:mod:`sgtool.scenegraph.examined`), and the
rule shared with the symbolic environment."""

from __future__ import annotations

import numpy as np
import pytest

from sgtool.scenegraph.examined import (
    EXAMINE,
    EXAMINE_RANGE_M,
    INNER_SHARE,
    close_views,
    examinable,
)


def _frame(patches: list[tuple[int, int, float]], shape=(12, 16)) -> tuple[np.ndarray, np.ndarray]:
    """ids and depth images: each patch (instance, pixels, depth) fills the next pixels."""
    ids = np.zeros(shape, dtype=np.int32)
    depth = np.full(shape, 4.0, dtype=np.float32)
    flat_i, flat_d = ids.reshape(-1), depth.reshape(-1)
    at = 0
    for iid, n, d in patches:
        flat_i[at:at + n] = iid
        flat_d[at:at + n] = d
        at += n
    return ids, depth


def test_near_enough_pixels_count_and_far_or_few_do_not() -> None:
    ids, depth = _frame([(5, 20, 1.5), (6, 20, 3.0), (7, 3, 1.0), (9, 12, EXAMINE_RANGE_M)])
    assert close_views(ids, depth, min_points=10) == [5, 9]  # 9: exactly at the range
    assert close_views(ids, depth, min_points=3) == [5, 7, 9]
    assert close_views(ids, depth, min_points=10, max_depth=3.0) == [5, 6, 9]
    big = ids.astype(np.int64) << 24  # ids too large to count by index: the sorted path
    assert close_views(big, depth, min_points=10) == [5 << 24, 9 << 24]


def test_the_mean_depth_decides_and_invalid_depth_is_ignored() -> None:
    ids, depth = _frame([(4, 10, 1.0), (4, 10, 3.5)])  # mean 2.25 m: too far
    assert close_views(ids, depth, min_points=5) == []
    ids, depth = _frame([(4, 10, 1.0), (4, 10, np.nan), (4, 5, 0.0)])  # 10 valid pixels at 1 m
    assert close_views(ids, depth, min_points=10) == [4]
    assert close_views(ids, depth, min_points=11) == []
    background, _ = _frame([])
    assert close_views(background, depth, min_points=1) == []  # id 0 is no instance


@pytest.mark.parametrize("affordances,small,expected", [
    (("supporter",), False, True), (("container", "openable"), False, True),
    (("Supporter",), False, True), ((), False, False), (("openable",), False, False),
    (("supporter",), True, False), (("container",), True, True),
])
def test_examinable_pieces(affordances, small, expected) -> None:
    assert examinable(affordances, small_object=small) is expected
    assert EXAMINE == "examine"


# ----- seeing into a piece (look_into), rendered in PyBullet -------------------------------
def _room_with_a_bucket_and_a_table() -> dict:
    """One 5 m x 5 m room: a bucket (a container open at its front, local +y, which faces
    +y here) on the floor at (2.5, 2.5) with a ball inside, and a table (a supporter,
    0.75 m high) at (1.0, 4.2) with a cup on it."""
    def obj(oid, cat, parent, rel, pos, size):  # type: ignore[no-untyped-def]
        return {"id": oid, "category": cat, "synset": f"{cat}.n.01", "parent": parent,
                "relation": rel, "room": "room_a", "position": pos, "size": size}
    walls = [((0, 0), (5, 0)), ((0, 5), (5, 5)), ((0, 0), (0, 5)), ((5, 0), (5, 5))]
    return {
        "version": "2.0", "seed": 1,
        "rooms": [{"id": "room_a", "category": "utility_room",
                   "polygon": [[0, 0], [5, 0], [5, 5], [0, 5]]}],
        "walls": [{"id": f"wall_{i}", "a": list(a), "b": list(b)}
                  for i, (a, b) in enumerate(walls)],
        "doors": [],
        "furniture": [
            {"id": "furn_bucket", "category": "bucket", "synset": "bucket.n.01",
             "room": "room_a", "center": [2.5, 2.5, 0.2], "size": [0.4, 0.4, 0.4],
             "affordances": ["container"]},
            {"id": "furn_table", "category": "table", "synset": "table.n.02",
             "room": "room_a", "center": [1.0, 4.2, 0.375], "size": [1.0, 0.6, 0.75],
             "affordances": ["supporter"]},
        ],
        "objects": [obj("obj_ball", "tennis_ball", "furn_bucket", "inside",
                        [2.5, 2.5, 0.07], [0.07, 0.07, 0.07]),
                    obj("obj_cup", "cup", "furn_table", "ontop", [1.0, 4.2, 0.8],
                        [0.08, 0.08, 0.1])],
        "starts": [{"x": 2.5, "y": 1.0, "yaw": 1.5708, "room": "room_a"}],
    }


def _views(poses):  # type: ignore[no-untyped-def]
    """For each (x, y) of ``poses``: the robot there facing the bucket; the bucket's
    PieceView after that one frame, and whether the ball was in view (pixels)."""
    import math

    pytest.importorskip("pybullet")
    from sgtool.house.io import load_house
    from sgtool.recorders.sim import CameraConfig
    from sgtool.recorders.sim.simulation import Simulation
    from sgtool.scenegraph.examined import FramePoints, PieceView, look_into

    spec = load_house(_room_with_a_bucket_and_a_table())
    out = []
    with Simulation(spec, camera=CameraConfig(width=160, height=120)) as sim:
        ids_of = {i.spec_id: i.id for i in sim.instances if i.spec_id}
        bucket, ball = ids_of["furn_bucket"], ids_of["obj_ball"]
        for x, y in poses:
            sim.teleport((x, y, math.atan2(2.5 - y, 2.5 - x)))
            fr = sim.render()
            ids, depth = np.asarray(fr.ids), np.asarray(fr.depth)
            v = PieceView()
            look_into(v, bucket, FramePoints.of(ids, depth, fr.pose, fr.intrinsics, 0.05))
            out.append((v, int((ids == ball).sum()), bucket in close_views(ids, depth, 50)))
    return out


def test_a_container_is_seen_into_from_its_open_front_not_past_its_side_board() -> None:
    front, side = _views([(2.5, 3.4), (3.4, 2.5)])  # 0.9 m in front; 0.9 m to its side
    v, ball_px, close = front
    assert close and ball_px > 0  # the ball is in view from the front
    assert v.searched(container=True, supporter=False)
    # from 1.2 m up the top board hides the back half of the inside: part of it is seen
    assert INNER_SHARE <= v.shares()[0] < 0.6 and v.eye == pytest.approx(1.2, abs=0.05)
    v, ball_px, close = side
    assert close and ball_px == 0  # a close view, the side board hides the ball
    assert not v.searched(container=True, supporter=False)  # the old rule said searched
    assert v.shares()[0] == 0.0


def test_what_a_piece_needs_depends_on_its_kind_and_height() -> None:
    from sgtool.scenegraph.examined import PieceView

    v = PieceView(cells={(i, j) for i in range(4) for j in range(4)}, bottom=0.0, top=0.7,
                  eye=1.2)
    inner = v.inner()
    assert inner == [(1, 1), (1, 2), (2, 1), (2, 2)]
    v.seen_in.update(inner[:2])
    assert v.searched(True, False) and not v.searched(False, True)
    assert not v.searched(True, True)  # both: the top too
    v.seen_on.update(inner[2:])
    assert v.searched(True, True) and v.searched(False, True)
    assert not v.searched(False, False)  # not a carrier
    tall = PieceView(cells=v.cells, bottom=0.0, top=1.8, eye=1.2, seen_on=set(inner))
    assert not tall.searched(False, True)  # a tall shelf: its top is out of sight,
    tall.seen_in.update(inner)  # what it holds is on the shelves inside it
    assert tall.searched(False, True)
    assert PieceView(cells={(0, 0), (0, 1)}).shares() == (0.0, 0.0)  # no inner column


@pytest.mark.parametrize("look_inside", [True, False])
def test_the_builder_counts_the_bucket_searched_only_once_seen_into(look_inside) -> None:
    """Frames past the bucket's side leave it unsearched (the older rule, ``look_inside``
    off, counted the first close view); frames from its front search it."""
    import math

    pytest.importorskip("pybullet")
    from sgtool.house.io import load_house
    from sgtool.recorders.sim import CameraConfig
    from sgtool.recorders.sim.simulation import Simulation
    from sgtool.scenegraph.builder import SceneGraphBuilder
    from sgtool.scenegraph.builder_config import BuilderConfig
    from sgtool.scenegraph.instances import instances_from_record

    spec = load_house(_room_with_a_bucket_and_a_table())
    with Simulation(spec, camera=CameraConfig(width=160, height=120)) as sim:
        table = instances_from_record({"instances": sim.instance_records()})
        bucket = next(i for i, info in table.items() if info.spec_id == "furn_bucket")
        b = SceneGraphBuilder(table, None, BuilderConfig(look_inside=look_inside))
        searched = []
        for x, y in [(3.4, 2.5), (3.5, 2.5), (3.6, 2.5), (2.5, 3.4), (2.5, 3.5)]:
            sim.teleport((x, y, math.atan2(2.5 - y, 2.5 - x)))
            b.integrate(sim.render())
            searched.append(bucket in b.examined)
    assert searched == ([False, False, False, True, True] if look_inside else [True] * 5)
