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

import numpy as np
import pytest
from click.testing import CliRunner
from support.bag_read import read_bag
from support.pinned_houses import pinned_house
from support.scripted_planner import Scripted
from support.seed0_episodes import seed0_episode

from sgtool.cli import cli
from sgtool.datasets.episodes import list_episodes
from sgtool.datasets.generator import generate_house
from sgtool.errors import SgtoolError
from sgtool.log import LogReader
from sgtool.log import schemas as S
from sgtool.log.codec import decode_transform
from sgtool.planning.base import Action
from sgtool.planning.candidates import actionable
from sgtool.planning.registry import make_planner
from sgtool.recorders.sim import CameraConfig, Simulation
from sgtool.recorders.sim.closed_loop import ClosedLoopOptions, run_episode
from sgtool.recorders.sim.live_skills import (
    LiveNavConfig,
    PrivilegedAccess,
    RobotBody,
    off_bearing,
)
from sgtool.recorders.sim.motion import head_tilts, peek_tilt

OPTS = ClosedLoopOptions(camera=CameraConfig(width=160, height=120))
GRAPH_TOPIC = S.RECORDS["scene_graph"].topic


@pytest.fixture(scope="module")
def house():
    return pinned_house("generated-6-rooms-4")  # its closed door (support.pinned_houses)


def _unexplored_room(g):
    (room,) = [r for r in g.rooms if not r.explored]
    return Action("navigate", room.id)


def test_unreachable_goal_fails_with_its_reason_in_the_log(house, tmp_path) -> None:
    # episode 0 starts in a room whose only door to room:1 is closed: after the look
    # around the graph knows room:1 through that door, but the map holds no way there
    idx, ep = seed0_episode(house, 0)
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
    assert acts[1]["message"] == fb.message  # the planner's own reason beside it
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
    idx, ep = seed0_episode(house, 3)
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


def _first_open(house, opts, stem):
    """(episode index, log, planner, feedback) of the first episode of ``house`` whose
    first action opens a container successfully (logs ``STEM-K.mcap``)."""
    for k in range(len(list_episodes(house, seed=0))):
        idx, ep = seed0_episode(house, k)
        p = Scripted([_open_first_container, Action("done")])
        out = stem.with_name(f"{stem.name}-{k}.mcap")
        run_episode(house, ep, p, out, opts, episode_index=idx)
        fb = p.feedbacks[0] if p.feedbacks else None
        if fb is not None and fb.action.skill == "open" and fb.outcome == "success":
            return k, out, p, fb
    pytest.fail("no episode of the house opens a container first")


def _last_pose(path) -> tuple[float, float, float]:
    """The base's last pose on ``/tf`` (not a base -> camera link of a tilted head)."""
    with LogReader(path) as r:
        last = [m.message for m in r.messages(["/tf"])
                if m.message.child_frame_id == S.BASE_FRAME][-1]
    t = decode_transform(last)
    return float(t[0, 3]), float(t[1, 3]), math.atan2(t[1, 0], t[0, 0])


def test_after_opening_a_container_the_robot_looks_in_from_in_front(house, tmp_path) -> None:
    """The open skill ends within reach of the container, too near for the tilted camera
    to see its lower shelves; with ``look_in`` the robot then drives to ``look_in`` metres
    from the container's node, in front of it as its map shows (``view_goal``), and faces
    it."""
    ends = {}
    for look in (0.0, 1.4):
        opts = dataclasses.replace(OPTS, live=LiveNavConfig(look_in=look, look_in_beyond=0.0,
                                                            peek=False),
                                   max_steps=1)
        k, out, p, fb = _first_open(house, opts, tmp_path / f"open-{look}")
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


def test_a_container_is_opened_from_in_front_of_it(tmp_path) -> None:
    """The open skill stands in front of the container's opening as the robot's map shows
    it (``front_goal``), within reach: checked against the house's own placement of the
    piece (its front is local +y), which the robot never reads. In this episode (house 1
    of 4 rooms, episode 1) the nearest stand within reach is 64 degrees off the front,
    where the side board hides the inside; the front stand is 31 degrees off."""
    house = generate_house(1, rooms=(4, 4))
    idx, ep = seed0_episode(house, 1)
    p = Scripted([_open_first_container, Action("done")])
    out = tmp_path / "front.mcap"
    run_episode(house, ep, p, out,
                dataclasses.replace(OPTS, live=LiveNavConfig(peek=False), max_steps=1),
                episode_index=idx)
    fb = p.feedbacks[0]
    assert (fb.action.skill, fb.outcome) == ("open", "success")
    node = p.graphs[0].node(fb.action.target)
    piece = min(house.furniture, key=lambda f: math.dist(f.center[:2], node.position[:2]))
    assert math.dist(piece.center[:2], node.position[:2]) < 0.3
    x, y, _ = _last_pose(out)
    front = piece.yaw + math.pi / 2
    bearing = math.atan2(y - piece.center[1], x - piece.center[0])
    off = abs(math.remainder(bearing - front, 2 * math.pi))
    assert off < math.radians(40) and math.dist((x, y), node.position[:2]) < 1.0


@pytest.mark.parametrize("beyond", [60.0, 10.0])
def test_looking_in_only_after_an_open_from_the_side(tmp_path, beyond) -> None:
    """With ``look_in_beyond`` the robot looks in only when it opened the container from
    more than that many degrees off the container's open fan on its map. Here (the episode
    of the test above) it opens from 31 degrees off the piece's front: within 60 degrees
    it stays where it opened, beyond 10 degrees it backs off to 1.4 m in front."""
    house = generate_house(1, rooms=(4, 4))
    idx, ep = seed0_episode(house, 1)
    p = Scripted([_open_first_container, Action("done")])
    out = tmp_path / "side.mcap"
    live = LiveNavConfig(peek=False, look_in=1.4, look_in_beyond=beyond)
    run_episode(house, ep, p, out, dataclasses.replace(OPTS, live=live, max_steps=1),
                episode_index=idx)
    fb = p.feedbacks[0]
    assert (fb.action.skill, fb.outcome) == ("open", "success")
    with LogReader(out) as r:
        started = next(r.records("episode"))[1]
    assert started["extra"]["navigation"]["look_in_beyond"] == beyond
    node = p.graphs[0].node(fb.action.target)
    x, y, _ = _last_pose(out)
    d = math.dist((x, y), node.position[:2])
    if beyond == 60.0:
        assert d < 1.0  # where it opened (the test above)
    else:
        assert abs(d - 1.4) <= 0.15


def test_a_look_in_angle_is_checked() -> None:
    with pytest.raises(SgtoolError, match="must be 0..180"):
        LiveNavConfig(look_in=1.4, look_in_beyond=200.0)
    assert LiveNavConfig(look_in=1.4, look_in_beyond=45.0).to_dict()["look_in_beyond"] == 45.0


def test_off_bearing_is_the_angle_from_the_fan_bisector() -> None:
    assert off_bearing((0.0, 0.0), (1.0, 0.0), 0.0) == pytest.approx(0.0)
    assert off_bearing((0.0, 0.0), (0.0, 2.0), 0.0) == pytest.approx(90.0)
    assert off_bearing((1.0, 1.0), (0.0, 1.0), math.radians(170.0)) == pytest.approx(10.0)
    assert off_bearing((0.0, 0.0), (-1.0, -0.01), math.radians(179.0)) == \
        pytest.approx(1.0 + math.degrees(math.atan(0.01)), abs=1e-6)


def _tilt(base_T_cam) -> float:
    """The camera's downward tilt (degrees) of a base -> camera link: the optical z axis
    is (cos t, 0, -sin t) in the base frame."""
    return math.degrees(math.asin(-float(base_T_cam[2, 2])))


def test_the_head_peek_shows_a_cabinet_bottom_the_mast_tilt_misses(house) -> None:
    """Standing 0.75 m in front of an opened container, the camera at its configured 15
    degrees leaves the bottom shelf below the view; tilted by ``peek_tilt`` it shows what
    stands there (pixel counts of the objects inside, by the simulator's ids)."""
    inside: dict[str, list[str]] = {}
    for o in house.objects:
        if o.relation == "inside":
            inside.setdefault(o.parent, []).append(o.id)
    fixed = peeked = hidden = 0
    with Simulation(house, camera=CameraConfig(width=160, height=120)) as sim:
        by = {i.spec_id: i.id for i in sim.instances if i.spec_id}
        t0 = sim.tick_index
        with pytest.raises(SgtoolError, match="head tilt"):
            sim.tilt_head([95.0])
        for f in house.furniture:
            if f.id not in inside or f.id not in sim.world.panels:
                continue
            cx, cy, cz = f.center
            x, y = cx - math.sin(f.yaw) * 0.75, cy + math.cos(f.yaw) * 0.75  # front: +y
            pose = (x, y, math.atan2(cy - y, cx - x))
            if sim.in_contact(pose):
                continue
            sim.teleport(pose)
            sim._set_open(f.id, 1.0, sim._layout_for_opening(f.id))
            before = sim.render().ids
            tilt = peek_tilt(1.2, 15.0, pose[:2], (cx, cy, cz))
            assert tilt is not None and tilt > 40.0
            ticks = sim.tick_index
            sim.tilt_head([tilt])
            assert sim.tick_index == ticks + 1
            link = np.linalg.inv(sim.base_matrix()) @ sim.camera_matrix()
            assert _tilt(link) == pytest.approx(tilt)
            after = sim.render().ids
            sim.tilt_head([15.0])
            for i in (by[o] for o in inside[f.id]):
                a, b = int((before == i).sum()), int((after == i).sum())
                fixed += a >= 12
                peeked += b >= 12
                hidden += a == 0 and b >= 12
        assert sim.tick_index > t0
    assert hidden >= 1 and peeked > fixed


def test_after_opening_a_container_the_robot_peeks_in_and_back(house, tmp_path) -> None:
    """With ``peek`` the open is followed by the head's tilt down to ``peek_tilt`` of the
    container's node and back, every tick a frame, no metres; the log's base -> camera
    link follows the head (and is back at the mounting on ``/tf`` after), so the replay
    builds the same graphs."""
    runs = {}
    for peek in (False, True):
        opts = dataclasses.replace(OPTS, live=LiveNavConfig(peek=peek), max_steps=1)
        k, out, p, fb = _first_open(house, opts, tmp_path / f"peek-{peek}")
        with LogReader(out) as r:
            frames = list(r.frames())
            started = next(r.records("episode"))[1]
        assert started["extra"]["navigation"]["peek"] is peek
        tilts = [_tilt(np.linalg.inv(f.base_pose) @ f.pose) for f in frames]
        runs[peek] = (k, out, fb, tilts, p.graphs[0].node(fb.action.target), frames)
    k0, _, fb0, flat, _, frames0 = runs[False]
    k1, out, fb1, tilts, node, frames1 = runs[True]
    assert k0 == k1 and fb1.travelled_m == fb0.travelled_m  # the same stand, no metres
    assert max(flat) == pytest.approx(15.0) and tilts[-1] == pytest.approx(15.0)
    low = [i for i, t in enumerate(tilts) if t > 15.0 + 1e-6]
    stand = frames1[low[0]].base_pose
    goal = peek_tilt(1.2, 15.0, (stand[0, 3], stand[1, 3]), node.position)
    # (the planner's graph is the log's, positions to 0.1 mm; the skill aims at the raw one)
    assert goal is not None and max(tilts) == pytest.approx(goal, abs=0.01)
    # one frame a tick down and back up, the base standing still
    assert low == list(range(low[0], low[-1] + 1))
    assert len(low) == 2 * len(head_tilts(15.0, goal, 9.0)) - 1
    assert len(frames1) == len(frames0) + len(low) + 1
    assert all(np.array_equal(frames1[i].base_pose, stand) for i in low)
    # the link on /tf: at the mounting at the last frame before the tilt (a viewer that
    # interpolates tilts the camera between two frames only), tilted, and back after
    with LogReader(out) as r:
        links = [(d.log_time_ns, _tilt(decode_transform(d.message)))
                 for d in r.messages([S.TF]) if d.message.child_frame_id == S.CAMERA_FRAME]
    before, after = frames1[low[0] - 1].time_ns, frames1[low[-1] + 1].time_ns
    assert links[0] == (before, pytest.approx(15.0)) and links[-1] == (after,
                                                                       pytest.approx(15.0))
    assert [t for t, _ in links[1:-1]] == [frames1[i].time_ns for i in low]
    derived = tmp_path / "peek-replayed.mcap"
    r = CliRunner().invoke(cli, ["replay", str(out), "-o", str(derived)])
    assert r.exit_code == 0, r.output
    assert _graphs(out) == _graphs(derived) and len(_graphs(out)) >= 2
    # as a ROS bag: every image has the camera's link on /tf at its stamp (tf2 neither
    # extrapolates nor keeps old samples), tilted where the log's is
    bag = tmp_path / "peek_bag"
    r = CliRunner().invoke(cli, ["export", "bag", str(out), "-o", str(bag), "--no-progress"])
    assert r.exit_code == 0, r.output
    got = read_bag(bag)
    stamps = {_stamp(m.header.stamp) for _, m in got["/camera/depth/image_raw"]}
    written = [tr for _, m in got["/tf"] for tr in m.transforms
               if tr.child_frame_id == "camera_optical_frame"]
    links_at = {_stamp(tr.header.stamp): tr for tr in written}
    assert stamps and stamps <= set(links_at)
    assert len(links_at) == len(written)  # one sample a stamp (tf2 warns of repeated data)
    assert all(tr.child_frame_id != "camera_optical_frame"
               for _, m in got.get("/tf_static", []) for tr in m.transforms)
    tilted = [tr for tr in links_at.values() if abs(tr.transform.rotation.x) > 0.0]
    assert len({round(tr.transform.rotation.x, 6) for tr in tilted}) == len(low) // 2 + 2


def _stamp(stamp) -> int:
    return int(stamp.sec) * 1_000_000_000 + int(stamp.nanosec)


def _graphs(path) -> list[bytes]:
    with LogReader(path) as r:
        return [bytes(m.data) for _, _, m in r.raw_messages([GRAPH_TOPIC])]


def _open_containers(g) -> list[str]:
    """Navigate candidates of ``g`` that are containers standing open."""
    out = []
    for c in actionable(g):
        node = g.node(c.node_id)
        if c.skill == "navigate" and "container" in getattr(node, "affordances", ()) \
                and node.state != "closed":
            out.append(c.node_id)
    return out


def _examine_or_explore(g):
    """Examine an open container once one is on offer, else open the first door on offer,
    else explore the first frontier."""
    found = _open_containers(g)
    if found:
        return Action("navigate", found[0])
    doors = [c.node_id for c in actionable(g) if c.kind == "door"]
    if doors:
        return Action("open", doors[0])
    frontiers = [c.node_id for c in actionable(g) if c.kind == "frontier"]
    return Action("explore", frontiers[0]) if frontiers else Action("done")


def test_examining_an_open_container_peeks_into_it(house, tmp_path) -> None:
    """A navigate to a container that stands open (a bookcase, a sink) examines it; with
    ``peek`` the head then tilts into it and back, as after an open; driving elsewhere
    or opening a door does not tilt it."""
    idx, ep = seed0_episode(house, 3)  # its fifth action examines a bookcase
    p = Scripted([_examine_or_explore] * 8)
    out = tmp_path / "examine.mcap"
    opts = dataclasses.replace(OPTS, live=LiveNavConfig(peek=True), max_steps=8)
    run_episode(house, ep, p, out, opts, episode_index=idx)
    steps = [k for k, fb in enumerate(p.feedbacks) if fb.action.skill == "navigate"]
    assert steps, "the episode never examined an open container"
    k = steps[0]
    fb = p.feedbacks[k]
    node = p.graphs[k].node(fb.action.target)
    assert fb.outcome == "success" and node.state != "closed"
    with LogReader(out) as r:
        acts = [t for t, a in r.records("action")]
        frames = list(r.frames())
    t0, t1 = acts[k], acts[k + 1]  # the look-around is action 0
    tilt = [(f.time_ns, _tilt(np.linalg.inv(f.base_pose) @ f.pose)) for f in frames]
    assert all(t == pytest.approx(15.0) for ns, t in tilt if ns <= t0)  # before: none
    assert max(t for ns, t in tilt if t0 < ns <= t1) > 20.0
    assert tilt[-1][1] == pytest.approx(15.0)


def _explore_farthest_frontier(g):
    """Explore the frontier on offer farthest along the floor (the robot sets out toward
    it, so there is a direction to go on in)."""
    cands = [c for c in actionable(g) if c.skill == "explore" and
             c.node_id.startswith("frontier:") and c.node_id in g.distances]
    if not cands:
        return Action("done")
    return Action("explore", max(cands, key=lambda c: (g.distances[c.node_id], c.node_id)
                                 ).node_id)


def test_an_explore_goes_on_through_its_frontier(house, tmp_path) -> None:
    """With ``explore_through`` the robot drives that far on past the frontier it
    reached, straight on from where it set out, before it looks around: the same first
    explore of the same episode travels farther and ends farther from the start than
    without (by at most the extra metres, snapped to a reachable cell). Episode 1 starts
    where six frontiers are on offer after the look-around."""
    idx, ep = seed0_episode(house, 1)
    runs = {}
    for through in (0.0, 1.5):
        p = Scripted([_explore_farthest_frontier, Action("done")])
        out = tmp_path / f"through-{through}.mcap"
        live = LiveNavConfig(explore_through=through)
        run_episode(house, ep, p, out, dataclasses.replace(OPTS, live=live, max_steps=1),
                    episode_index=idx)
        fb = p.feedbacks[0]
        assert (fb.action.skill, fb.outcome) == ("explore", "success")
        with LogReader(out) as r:
            started = next(r.records("episode"))[1]
            first = [m.message for m in r.messages(["/tf"])
                     if m.message.child_frame_id == S.BASE_FRAME][0]
        assert started["extra"]["navigation"]["explore_through"] == through
        t0 = decode_transform(first)
        x, y, _ = _last_pose(out)
        runs[through] = (fb.action.target, fb.travelled_m,
                         math.dist((x, y), (t0[0, 3], t0[1, 3])))
    (f0, m0, d0), (f1, m1, d1) = runs[0.0], runs[1.5]
    assert f0 == f1  # the same frontier
    assert m0 + 0.5 < m1 <= m0 + 1.5 + 1.0 + 0.5  # on by up to 1.5 m (+ snap, + turns)
    assert d1 > d0 + 0.5


def test_an_explore_through_distance_is_checked() -> None:
    with pytest.raises(SgtoolError, match="must be 0..5"):
        LiveNavConfig(explore_through=6.0)
    assert LiveNavConfig(explore_through=1.5).to_dict()["explore_through"] == 1.5
