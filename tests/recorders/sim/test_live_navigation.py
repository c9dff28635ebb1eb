"""The closed loop without privileged information (issue 17), on the small 4-room house of
test_closed_loop at 160x120.

Checked: a skill to a goal the robot's map cannot reach (an unexplored room behind a
closed door) fails, with its reason in the log and in the planner's feedback; an episode
runs with the ground truth made unavailable to the robot side (the simulator's planning
occupancy, its privileged skills and the room look-up raise), and the robot's view of the
simulator refuses the spec; the contact check stops a drive into a wall. (That a
closed-loop log replays into the same graphs byte for byte is checked by
test_closed_loop.py's replay test, whose episode runs with the live navigation, the
default.)
"""

from __future__ import annotations

import math

import pytest
from support.scripted_planner import Scripted

from sgtool.datasets.generator import generate_house
from sgtool.log import LogReader
from sgtool.planning.base import Action
from sgtool.planning.registry import make_planner
from sgtool.recorders.sim import CameraConfig, Simulation
from sgtool.recorders.sim.closed_loop import ClosedLoopOptions, pick_episode, run_episode
from sgtool.recorders.sim.live_skills import PrivilegedAccess, RobotBody

OPTS = ClosedLoopOptions(camera=CameraConfig(width=160, height=120))


@pytest.fixture(scope="module")
def house():
    return generate_house(6, rooms=(4, 4))


def _unexplored_room(g):
    (room,) = [r for r in g.rooms if not r.explored]
    return Action("navigate", room.id)


def test_unreachable_goal_fails_with_its_reason_in_the_log(house, tmp_path) -> None:
    # episode 0 starts in a room whose only door to room:1 is closed: after the look
    # around the graph knows room:1 through that door, but the map holds no way there
    idx, ep = pick_episode(house, index=0)
    p = Scripted([_unexplored_room, Action("done")])
    out = tmp_path / "unreachable.mcap"
    run_episode(house, ep, p, out, OPTS, episode_index=idx)
    fb = p.feedbacks[0]
    assert fb.outcome == "failure" and fb.travelled_m == 0.0
    assert "room:1 is unreachable on the robot's map" in fb.message
    with LogReader(out) as r:
        acts = [a for _, a in r.records("action")]
        started = r.records("episode").__next__()[1]
    assert (acts[1]["skill"], acts[1]["target"], acts[1]["outcome"]) == (
        "navigate", "room:1", "failure")
    assert acts[1]["reason"] == fb.message
    assert started["extra"]["navigation"]["mode"] == "live"
    # the privileged simulator planned on the whole house and knew why
    p2 = Scripted([_unexplored_room, Action("done")])
    run_episode(house, ep, p2, tmp_path / "house.mcap",
                ClosedLoopOptions(camera=OPTS.camera, navigation="house"), episode_index=idx)
    assert "behind closed door" in p2.feedbacks[0].message


def test_the_robot_side_never_reads_the_house(house, tmp_path, monkeypatch) -> None:
    def forbidden(*a, **k):
        raise AssertionError("the robot side used the ground truth")

    for name in ("occupancy", "navigate", "explore", "closed_doors_on_way", "room_of_base"):
        monkeypatch.setattr(Simulation, name, forbidden)
    idx, ep = pick_episode(house, index=3)
    rep = run_episode(house, ep, make_planner("random"), tmp_path / "guarded.mcap",
                      ClosedLoopOptions(camera=OPTS.camera, max_steps=3, frames=300),
                      episode_index=idx)
    assert rep.steps >= 1 and rep.travelled_m > 0  # it drove, on its own map
    with LogReader(tmp_path / "guarded.mcap") as r:
        acts = [a for _, a in r.records("action")]
    assert all("ground truth" not in a["reason"] for a in acts)


def test_the_robot_body_has_no_house_and_contacts_stop_it(house) -> None:
    with Simulation(house, start=0) as sim:
        body = RobotBody(sim)
        for name in ("spec", "world", "occupancy", "resolve", "navigate"):
            with pytest.raises(PrivilegedAccess, match=name):
                getattr(body, name)
        # drive straight along the heading until something is in the way
        x, y, yaw = sim.base
        poses = [(x + k * 0.05 * math.cos(yaw), y + k * 0.05 * math.sin(yaw), yaw)
                 for k in range(1, 400)]
        driven, hit = body.drive(poses)
        assert hit and 0 < driven < 20.0
        assert not sim.in_contact() and sim.in_contact(poses[round(driven / 0.05)])
        assert math.isclose(sim.travelled_m, driven)
