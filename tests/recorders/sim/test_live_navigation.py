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

import dataclasses
import math

import pytest
from support.scripted_planner import Scripted

from sgtool.datasets.generator import generate_house
from sgtool.log import LogReader
from sgtool.log.codec import decode_transform
from sgtool.planning.base import Action
from sgtool.planning.candidates import actionable
from sgtool.planning.registry import make_planner
from sgtool.recorders.sim import CameraConfig, Simulation
from sgtool.recorders.sim.closed_loop import (
    ClosedLoopOptions,
    list_episodes,
    pick_episode,
    run_episode,
)
from sgtool.recorders.sim.live_skills import LiveNavConfig, PrivilegedAccess, RobotBody

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
    p = Scripted([_unexplored_room] + [Action("done")] * 20)  # give-ups may hand over
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
    p2 = Scripted([_unexplored_room] + [Action("done")] * 20)
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



def _open_first_container(g):
    cands = [c for c in actionable(g) if c.skill == "open" and c.node_id.startswith("obj:")]
    return Action("open", cands[0].node_id) if cands else Action("done")


def _last_pose(path) -> tuple[float, float, float]:
    with LogReader(path) as r:
        last = [m.message for m in r.messages(["/tf"])][-1]
    t = decode_transform(last)
    return float(t[0, 3]), float(t[1, 3]), math.atan2(t[1, 0], t[0, 0])


def test_after_opening_a_container_the_robot_looks_in_from_in_front(house, tmp_path) -> None:
    """The open skill ends within reach of the container, too near for the tilted camera
    to see its lower shelves; with ``look_in`` the robot then drives to ``look_in`` metres
    from the container's node, in front of it as its map shows (``view_goal``), and faces
    it."""
    ends = {}
    for look in (0.0, 1.4):
        opts = dataclasses.replace(OPTS, live=LiveNavConfig(look_in=look), max_steps=1)
        for k in range(len(list_episodes(house))):
            idx, ep = pick_episode(house, index=k)
            p = Scripted([_open_first_container, Action("done")])
            out = tmp_path / f"open-{look}-{k}.mcap"
            run_episode(house, ep, p, out, opts, episode_index=idx)
            fb = p.feedbacks[0] if p.feedbacks else None
            if fb is not None and fb.action.skill == "open" and fb.outcome == "success":
                break
        else:
            pytest.fail("no episode of the house opens a container first")
        with LogReader(out) as r:
            started = next(r.records("episode"))[1]
        assert started["extra"]["navigation"]["look_in"] == look
        node = p.graphs[0].node(fb.action.target)
        x, y, yaw = _last_pose(out)
        ends[look] = (k, math.dist((x, y), node.position[:2]),
                      math.atan2(node.position[1] - y, node.position[0] - x) - yaw)
    k0, stand, _ = ends[0.0]
    k1, backed, off = ends[1.4]
    assert k0 == k1  # the same episode, the same container
    assert stand < 1.3 and abs(backed - 1.4) <= 0.15  # there, to a cell of its map
    assert abs(math.atan2(math.sin(off), math.cos(off))) < math.radians(10)  # facing it
