"""The scripted tour looks around again where one look-around does not show a room whole:
a U-shaped living room wrapped round a closet, with a table and a desk at the tips of its
arms, out of sight of the room's viewpoint at the foot of the U."""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pytest

from sgtool.recorders.sim.room_views import best_view, places, visible

W = {"thickness": 0.1, "height": 2.5}


def _piece(name: str, room: str, center: tuple[float, float, float]) -> dict:
    return {"id": f"furn_{name}", "category": name, "synset": f"{name}.n.01", "room": room,
            "center": list(center), "size": [0.8, 0.8, 2 * center[2]], "yaw": 0.0,
            "affordances": ["supporter"], "state": None}


def _on(name: str, piece: str, room: str, xy: tuple[float, float], top: float) -> dict:
    return {"id": f"obj_{name}", "category": name, "synset": f"{name}.n.01",
            "parent": f"furn_{piece}", "relation": "ontop", "room": room,
            "position": [xy[0], xy[1], top + 0.06], "size": [0.12, 0.12, 0.12]}


def u_house() -> dict:
    """Living room: x 0-9, y 0-7 less the closet x 3-6, y 3-7 (door at x 4-5 of its south
    wall); the robot starts at the foot of the U, (4.5, 1.5)."""
    walls = [((0, 0), (9, 0)), ((9, 0), (9, 7)), ((9, 7), (6, 7)), ((6, 7), (6, 3)),
             ((6, 3), (5, 3)), ((4, 3), (3, 3)), ((3, 3), (3, 7)), ((3, 7), (0, 7)),
             ((0, 7), (0, 0)), ((3, 7), (6, 7))]
    return {
        "version": "1.0", "seed": 3,
        "rooms": [
            {"id": "room_living", "category": "living_room",
             "polygon": [[0, 0], [9, 0], [9, 7], [6, 7], [6, 3], [3, 3], [3, 7], [0, 7]]},
            {"id": "room_closet", "category": "closet",
             "polygon": [[3, 3], [6, 3], [6, 7], [3, 7]]}],
        "walls": [dict(id=f"wall_{i}", a=list(a), b=list(b), **W)
                  for i, (a, b) in enumerate(walls)],
        "doors": [{"id": "door_closet", "center": [4.5, 3], "width": 0.9, "yaw": 0.0,
                   "state": "open", "rooms": ["room_living", "room_closet"]}],
        "furniture": [_piece("table", "room_living", (0.6, 6.4, 0.4)),
                      _piece("desk", "room_living", (8.4, 6.4, 0.4)),
                      _piece("sofa", "room_living", (4.5, 0.5, 0.4))],
        "objects": [_on("mug", "table", "room_living", (0.6, 6.4), 0.8),
                    _on("pillow", "sofa", "room_living", (4.5, 0.5), 0.8)],
        "starts": [{"x": 4.5, "y": 1.5, "yaw": 0.0, "room": "room_living"}],
    }


def test_a_wall_hides_what_is_behind_it() -> None:
    """A 2 x 2 m box split by a wall with a gap: from the left half, the right half is seen
    only through the gap, and nothing beyond ``reach``."""
    blocked = np.zeros((40, 40), bool)  # 5 cm cells, origin (0, 0)
    blocked[:, 20] = True
    blocked[18:22, 20] = False  # a 20 cm gap at y 0.9-1.1
    seen = visible(blocked, (0.0, 0.0), 0.05, (0.5, 1.0), reach=5.0)
    assert seen[20, 10] and seen[20, 30]  # through the gap, straight on
    assert not seen[2, 30] and not seen[38, 30]  # the right half's corners
    assert seen[2, 20]  # the wall itself is seen
    near = visible(blocked, (0.0, 0.0), 0.05, (0.5, 1.0), reach=0.3)
    assert near[20, 15] and not near[20, 17]  # 0.275 m away: in; 0.375 m: out


def test_the_best_view_shows_the_most_floor_not_seen() -> None:
    blocked = np.zeros((40, 40), bool)
    blocked[:, 20] = True
    blocked[18:22, 20] = False
    floor = ~blocked
    seen = visible(blocked, (0.0, 0.0), 0.05, (0.5, 1.0), reach=5.0)
    (point, gain) = best_view(blocked, (0.0, 0.0), 0.05, floor, seen,
                              [(0.2, 0.2), (1.5, 1.0)], reach=5.0)
    assert point == (1.5, 1.0) and gain > 200


@pytest.mark.parametrize("first_row", [0, 3, 7])
def test_a_strip_narrower_than_the_stride_gets_places_wherever_the_grid_falls(
        first_row: int) -> None:
    """A corridor's reachable band 0.2 m wide (4 cells) and 3 m long, at three offsets
    against the 0.5 m blocks: one place per block it crosses, on the band (a lattice of
    block centres missed it at two of the three)."""
    mask = np.zeros((20, 80), bool)
    mask[first_row:first_row + 4, 10:70] = True
    got = places(mask, (0.0, 0.0), 0.05, 0.5)
    rows = {int(y / 0.05) for _, y in got}
    assert len(got) == 6 * len({r // 10 for r in range(first_row, first_row + 4)})
    assert rows <= set(range(first_row, first_row + 4))


def test_the_bound_on_a_view_gives_the_answer_of_weighing_every_place() -> None:
    """best_view stops weighing where what a place could see at most falls below the
    best: the same place and gain as weighing all of them, on rooms with walls across."""
    rng = np.random.default_rng(5)
    for _ in range(4):
        blocked = np.zeros((90, 120), bool)
        blocked[[0, -1], :] = blocked[:, [0, -1]] = True
        for _ in range(4):
            r, c = rng.integers(5, 85), rng.integers(5, 115)
            if rng.random() < 0.5:
                blocked[r:r + 40, c:c + 2] = True
            else:
                blocked[r:r + 2, c:c + 50] = True
        cands = places(~blocked, (0.0, 0.0), 0.05, 0.5)
        reach = float(rng.uniform(1.0, 4.0))
        seen = visible(blocked, (0.0, 0.0), 0.05, cands[0], reach)
        todo = ~blocked & ~seen
        gains = [int(np.count_nonzero(visible(blocked, (0.0, 0.0), 0.05, p, reach) & todo))
                 for p in cands]
        i = int(np.argmax(gains))
        assert best_view(blocked, (0.0, 0.0), 0.05, ~blocked, seen, cands, reach) == \
            (cands[i], gains[i])


def test_a_u_shaped_room_is_seen_to_the_tips_of_its_arms(tmp_path: Path) -> None:
    pytest.importorskip("pybullet")
    import sgtool

    rep = sgtool.record_house(sgtool.load_house(u_house()), tmp_path / "u.mcap",
                              sgtool.RecordOptions(camera=sgtool.CameraConfig(
                                  width=96, height=72)))
    graphs: list[sgtool.SceneGraph] = []
    sgtool.replay(tmp_path / "u.mcap", on_refresh=lambda r, s: graphs.append(r.graph))
    assert {"table", "desk", "mug"} <= {o.category for o in graphs[-1].objects}
    # two further look-arounds, one where each arm (x < 3, x > 6) opens off the foot
    stands = sorted(_points_driven_to(tmp_path / "u.mcap"))
    assert len(stands) == 2 and stands[0][0] < 3.0 < 6.0 < stands[1][0]
    assert rep.rooms_visited == ("room_living", "room_closet")
    assert rep.looked_again == ("room_living", "room_living")
    assert "looked around again in rooms one place does not show whole: room_living (2)" \
        in rep.lines()


def _points_driven_to(log: Path) -> list[tuple[float, float]]:
    """The (x, y) of the log's navigate actions to a point."""
    import sgtool

    out = []
    with sgtool.LogReader(log) as reader:
        for _, action in reader.records(sgtool.ActionRecord):
            if action.skill == "navigate" and str(action.target).startswith("("):
                x, y = (float(v) for v in str(action.target).strip("()").split(","))
                out.append((x, y))
    assert all(math.isfinite(v) for p in out for v in p)
    return out


@pytest.mark.parametrize(("given", "expect"), [
    ({"views": -1}, "views=-1: a whole number >= 0"),
    ({"view_gain_m2": float("nan")}, "view_gain_m2=nan: a finite number"),
    ({"open_doors": "yes"}, "open_doors='yes': a bool"),
])
def test_a_bad_script_option_is_one_line(given: dict, expect: str) -> None:
    from sgtool.errors import SgtoolError
    from sgtool.recorders.sim import ScriptOptions

    with pytest.raises(SgtoolError, match="^" + re.escape(expect)):
        ScriptOptions(**given)
