"""Skills of the simulated robot (navigate, open, close, explore, look around) and the
scripted whole-house exploration, on the small two-room house and generated houses."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import ndimage
from support.small_house import small_house, small_house_dict

from sgtool.datasets.generator import generate_house
from sgtool.errors import SgtoolError
from sgtool.house.io import load_house
from sgtool.house.spec import room_at
from sgtool.mapping.occupancy import world_to_cell
from sgtool.recorders.sim import (
    CameraConfig,
    ScriptOptions,
    SimObserver,
    Simulation,
    SkillOutcome,
    explore_house,
)
from sgtool.recorders.sim.articulation import point_box_distance

SMALL = CameraConfig(width=64, height=48)


class Trace(SimObserver):
    def __init__(self) -> None:
        self.poses: list[tuple[float, float, float]] = []
        self.skills: list[SkillOutcome] = []
        self.states: list[tuple[int, str, str]] = []
        self.ticks: list[int] = []

    def on_tick(self, sim: Simulation) -> None:
        self.poses.append(sim.base)
        self.ticks.append(sim.tick_index)

    def on_state(self, sim: Simulation, spec_id: str, state: str) -> None:
        self.states.append((sim.tick_index, spec_id, state))

    def on_skill(self, sim: Simulation, outcome: SkillOutcome) -> None:
        self.skills.append(outcome)


def _sim(**kw) -> tuple[Simulation, Trace]:  # type: ignore[no-untyped-def]
    sim = Simulation(small_house(), camera=SMALL, **kw)
    tr = Trace()
    sim.observers.append(tr)
    return sim, tr


def _door_box(sim: Simulation) -> tuple[float, float, float, float, float]:
    d = sim.spec.doors[0]
    return (d.center[0], d.center[1], d.width, d.thickness, d.yaw)


def test_through_a_closed_door_navigate_open_navigate() -> None:
    sim, tr = _sim()
    with sim:
        out = sim.navigate("room_1")
        assert (out.outcome, out.ticks, out.travelled_m) == ("failure", 0, 0.0)
        assert "door_0" in out.reason and "closed" in out.reason
        assert sim.closed_doors_on_way("room_1") == ["door_0"]

        out = sim.navigate("door_0")
        assert out.success and out.ticks == len(tr.poses)
        x, y, yaw = sim.base
        d = point_box_distance(x, y, _door_box(sim))
        lo, hi = sim.robot.approach
        assert lo - 0.05 <= d <= hi + 0.05
        assert x < 4.0  # still on the living-room side
        assert abs(math.remainder(math.atan2(1.5 - y, 4.0 - x) - yaw, 2 * math.pi)) < 1e-6

        n0 = len(tr.poses)
        out = sim.open("door_0")
        assert out.success and sim.states["door_0"] == "open"
        assert tr.states == [(tr.ticks[-1], "door_0", "open")]  # on the last tick
        assert out.ticks == len(tr.poses) - n0 >= round(sim.robot.open_time * sim.fps)

        occ = sim.occupancy()
        start = len(tr.poses)
        out = sim.navigate("room_1")
        assert out.success
        assert room_at(sim.spec, *sim.base[:2]) == "room_1"
        poses = [tr.poses[start - 1], *tr.poses[start:]]
        steps = [math.dist(a[:2], b[:2]) for a, b in zip(poses, poses[1:], strict=False)]
        assert math.isclose(sum(steps), out.travelled_m, rel_tol=1e-9)
        assert max(steps) <= sim.robot.speed / sim.fps + 1e-9
        turns = [abs(math.remainder(b[2] - a[2], 2 * math.pi))
                 for a, b in zip(poses, poses[1:], strict=False)]
        assert max(turns) <= sim.robot.turn_speed / sim.fps + 1e-9
        # collision-free: every pose keeps the robot radius from obstacles (one cell slack)
        clear = ndimage.distance_transform_edt(~occ.occupied) * occ.resolution
        for p in poses[1:]:
            r, c = world_to_cell(occ, p[0], p[1])
            assert clear[r, c] >= sim.robot.radius - occ.resolution


def test_open_and_close_need_reach_and_something_openable() -> None:
    sim, tr = _sim()
    with sim:
        far = sim.open("furn_2")  # the refrigerator, in the other room
        assert far.outcome == "failure" and "out of reach" in far.reason
        assert sim.open("furn_1").reason == "furn_1 (table) cannot be opened or closed"
        assert sim.open("obj_0").outcome == "failure"
        assert sim.open("room_0").outcome == "failure"
        assert sim.navigate("room_7").outcome == "invalid"
        assert sim.open(999).outcome == "invalid"
        assert sim.navigate("furn_99").outcome == "invalid"
        assert sim.close("wall_1").outcome == "invalid"  # the building is not a target
        assert tr.poses == []  # none of these moved anything

        sim.navigate("door_0")
        assert sim.open("door_0").success
        again = sim.open("door_0")
        assert again.outcome == "failure" and "already open" in again.reason
        assert sim.close("door_0").success and sim.states["door_0"] == "closed"
        assert [s for _, _, s in tr.states] == ["open", "closed"]
        assert sim.navigate("room_1").outcome == "failure"


def test_a_piece_is_not_opened_through_the_wall_behind_it() -> None:
    """A cabinet stands in the kitchen with its back to the wall x = 4; from the living
    room, 0.4 m from its box, the arm would reach it through the wall: that fails; a walk
    up to it goes to the kitchen (its room), from where it opens."""
    d = small_house_dict()
    d["furniture"].append({"id": "furn_9", "category": "cabinet", "synset": "cabinet.n.01",
                           "room": "room_1", "center": [4.3, 0.6, 0.45],
                           "size": [0.8, 0.5, 0.9], "yaw": -math.pi / 2,  # front: +x
                           "affordances": ["container", "openable"], "state": "closed"})
    sim = Simulation(load_house(d), camera=SMALL, start=(3.65, 0.6, 0.0))
    with sim:
        behind = sim.open("furn_9")
        assert behind.outcome == "failure"
        assert behind.reason == "furn_9 is out of reach: wall_4 stands between it and the robot"
        assert sim.states["furn_9"] == "closed"
        # walking up to it with the door open: to the kitchen, round through the door,
        # though the living-room side of the wall is nearer
        assert sim.navigate("door_0").success and sim.open("door_0").success
        assert sim.navigate("furn_9").success
        assert room_at(sim.spec, *sim.base[:2]) == "room_1"
        assert sim.open("furn_9").success and sim.states["furn_9"] == "open"


def test_opening_a_container_reveals_what_is_inside() -> None:
    sim, _ = _sim()
    with sim:
        mug = sim.world.by_spec["obj_0"].id
        assert sim.navigate("furn_0").success
        cab = sim.spec.furniture_by_id()["furn_0"]
        lx, ly = cab.to_local(*sim.base[:2])
        assert ly > cab.size[1] / 2 and abs(lx) < cab.size[0] / 2  # square in front
        assert sim.open(sim.world.by_spec["furn_0"].id).success  # by instance id
        after = sim.render()
        sim.close("furn_0")
        before = sim.render()
        assert (before.ids == mug).sum() == 0
        assert (after.ids == mug).sum() >= 5


def test_look_around_and_explore() -> None:
    sim, tr = _sim(fps=7.0)
    with sim:
        yaw0 = sim.base[2]
        out = sim.look_around()
        quarter = math.ceil((math.pi / 2) / (sim.robot.turn_speed / 7.0))
        assert out.success and out.ticks == 4 * quarter == len(tr.poses)
        assert abs(math.remainder(sim.base[2] - yaw0, 2 * math.pi)) < 1e-9
        assert out.travelled_m == 0.0

        tr.skills.clear()
        out = sim.explore((1.0, 2.0))
        assert out.success and out.skill == "explore"
        assert [s.skill for s in tr.skills] == ["explore"]  # inner skills are not reported
        assert math.dist(sim.base[:2], (1.0, 2.0)) < 0.05
        assert sim.explore("room_1").outcome == "failure"  # behind the closed door


def test_log_time_is_tick_times_period() -> None:
    sim, _ = _sim(fps=30.0)
    with sim:
        assert [sim.time_ns(k) for k in (0, 1, 3, 30)] == [0, 33_333_333, 100_000_000,
                                                            1_000_000_000]
    sim, _ = _sim(fps=10.0)
    with sim:
        assert sim.time_ns(7) == 700_000_000


def test_start_pose_errors() -> None:
    with pytest.raises(SgtoolError, match="start 5"):
        Simulation(small_house(), camera=SMALL, start=5)
    with Simulation(small_house(), camera=SMALL, start=1) as sim:
        assert room_at(sim.spec, *sim.base[:2]) == "room_1"


def test_open_doors_in_the_spec_start_open_and_passable() -> None:
    with Simulation(small_house(door="open"), camera=SMALL) as sim:
        body = sim.world.panels["door_0"][0]
        assert body.fraction == 1.0
        assert sim.navigate("room_1").success


@pytest.mark.parametrize("seed", [3, 12])
def test_scripted_exploration_visits_every_room(seed: int) -> None:
    """Generated houses with closed doors: every room visited, every closed openable
    container opened, no skill failed (no rendering: nobody observes the ticks)."""
    house = generate_house(seed, rooms=(8, 12))
    sim = Simulation(house, camera=SMALL)
    tr = Trace()
    sim.observers.append(tr)
    with sim:
        rep = explore_house(sim, ScriptOptions())
    assert rep.complete and sorted(rep.visited) == sorted(r.id for r in house.rooms)
    assert all(s.success for s in rep.outcomes), [s for s in rep.outcomes if not s.success]
    openable = {f.id for f in house.furniture if f.is_openable and f.state == "closed"}
    assert openable <= set(rep.opened)
    closed = {d.id for d in house.doors if d.state == "closed"}
    assert closed and closed & set(rep.opened)  # it had to open doors on the way
    assert np.all(np.diff(tr.ticks) == 1)
