"""Recording the small house into an MCAP log and reading it back: frames, shapes, times,
poses, depth against ray tests, ids against the instances table, states and actions,
contents appearing when a container opens, byte-identical reruns."""

from __future__ import annotations

import hashlib
import math
from pathlib import Path

import numpy as np
import pytest
from support.small_house import small_house

from sgtool.log import LogReader
from sgtool.recorders.sim import (
    CameraConfig,
    RecordOptions,
    SimObserver,
    Simulation,
    parse_noise,
    record_house,
)
from sgtool.recorders.sim.camera import base_T_camera

CAM = CameraConfig(width=80, height=60)
PIXEL = (39, 29)  # (u, v) near the image centre


class CentreRays(SimObserver):
    """Ray-tests the centre pixel in the live simulation at every 10th frame."""

    def __init__(self) -> None:
        self.depth: dict[int, float] = {}

    def on_tick(self, sim: Simulation) -> None:
        if sim.tick_index % 10 == 0:
            self.depth[sim.time_ns()] = sim.ray_depth(*PIXEL)


@pytest.fixture(scope="module")
def full_log(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, CentreRays, object]:
    out = tmp_path_factory.mktemp("rec") / "small.mcap"
    rays = CentreRays()
    rep = record_house(small_house(), out, RecordOptions(camera=CAM), house_id="small",
                       observers=[rays])
    return out, rays, rep


def test_frames_shapes_times_and_poses(full_log) -> None:  # type: ignore[no-untyped-def]
    path, _, rep = full_log
    assert not rep.truncated and rep.rooms_visited == ("room_0", "room_1")
    with LogReader(path) as r:
        n = r.frame_count()
        assert n == rep.frames > 100
        assert r.frame_times() == [i * 100_000_000 for i in range(n)]  # 10 fps, exact
        ended = r.last_record("episode")
        assert ended["status"] == "ended" and ended["frames"] == n
        assert ended["house_id"] == "small" and ended["extra"]["truncated"] is False
        assert r.house_json() == small_house().to_json()
        b_t_c = base_T_camera(CAM.mount_height, CAM.tilt_deg)
        for f in r.frames():
            assert f.rgb.shape == (60, 80, 3) and f.depth.shape == (60, 80)
            assert f.ids.shape == (60, 80)
            assert f.intrinsics == CAM.intrinsics()
            assert np.allclose(np.linalg.inv(f.base_pose) @ f.pose, b_t_c, atol=1e-9)


def test_logged_depth_matches_ray_tests_at_the_centre(full_log) -> None:  # type: ignore[no-untyped-def]
    path, rays, _ = full_log
    u, v = PIXEL
    checked = 0
    with LogReader(path) as r:
        for f in r.frames():
            if f.time_ns in rays.depth and rays.depth[f.time_ns] > 0:
                assert abs(float(f.depth[v, u]) - rays.depth[f.time_ns]) < 0.01
                checked += 1
    assert checked >= 10


def test_ids_states_and_actions(full_log) -> None:  # type: ignore[no-untyped-def]
    path, _, rep = full_log
    with LogReader(path) as r:
        tables = list(r.records("instances"))
        ids = {i["id"] for i in tables[0][1]["instances"]}
        assert ids == set(range(1, 19))
        for f in r.frames():
            assert set(np.unique(f.ids).tolist()) - {0} <= ids
        # one table at the start, one per state change, with the new state
        changes = [(t, {i["spec_id"]: i["state"] for i in tab["instances"] if i["state"]})
                   for t, tab in tables]
        assert changes[0][1] == {"door_0": "closed", "furn_0": "closed", "furn_2": "closed"}
        assert changes[-1][1] == {"door_0": "open", "furn_0": "open", "furn_2": "open"}
        assert len(changes) == 4
        actions = [a for _, a in r.records("action")]
        assert [a["step"] for a in actions] == list(range(len(actions)))
        assert all(a["outcome"] == "success" and a["planner"] == "scripted" for a in actions)
        opens = [a["target"] for a in actions if a["skill"] == "open"]
        assert sorted(opens) == ["door_0", "furn_0", "furn_2"]
        total = sum(a["travelled_m"] for a in actions)
        assert math.isclose(total, r.last_record("episode")["travelled_m"], rel_tol=1e-6)
        assert len(actions) == rep.actions


def test_opening_a_container_makes_its_contents_appear(full_log) -> None:  # type: ignore[no-untyped-def]
    """Nothing inside a closed container is ever seen before the robot starts opening it
    (the action before the open ended), and it is seen once the door swings."""
    path, _, _ = full_log
    with LogReader(path) as r:
        table = r.last_record("instances")["instances"]
        inside = {i["spec_id"]: i["id"] for i in table if i["relation"] == "inside"}
        actions = list(r.records("action"))
        starts = {a["target"]: actions[k - 1][0] for k, (_, a) in enumerate(actions)
                  if a["skill"] == "open"}
        ends = {a["target"]: t for t, a in actions if a["skill"] == "open"}
        seen: dict[int, list[int]] = {k: [] for k in inside.values()}
        for f in r.frames():
            for k in np.unique(f.ids).tolist():
                if k in seen:
                    seen[k].append(f.time_ns)
    for obj, parent in (("obj_0", "furn_0"), ("obj_3", "furn_2")):  # mug, milk
        times = seen[inside[obj]]
        assert times and min(times) > starts[parent]
        assert any(starts[parent] < t <= ends[parent] for t in times)
    assert seen[inside["obj_4"]]  # the bowl in the open-fronted shelf: seen, never opened


def _sha(p: Path) -> str:
    return hashlib.sha256(p.read_bytes()).hexdigest()


def test_same_inputs_same_bytes(tmp_path: Path) -> None:
    opts = RecordOptions(camera=CameraConfig(width=48, height=36), frames=60,
                         noise=parse_noise("strong"), seed=3)
    a, b, c = tmp_path / "a.mcap", tmp_path / "b.mcap", tmp_path / "c.mcap"
    ra = record_house(small_house(), a, opts)
    record_house(small_house(), b, RecordOptions(camera=opts.camera, frames=60,
                                                 noise=opts.noise, seed=3, fps=10))
    record_house(small_house(), c, RecordOptions(camera=opts.camera, frames=60,
                                                 noise=opts.noise, seed=4))
    assert ra.frames == 60 and ra.truncated
    assert _sha(a) == _sha(b)  # fps=10 (an int) logs as the default 10.0, as --fps 10 does
    assert _sha(a) != _sha(c)  # the faults follow their seed
    with LogReader(a) as r:
        assert r.frame_count() == 60 and r.seed == 3
        assert r.last_record("episode")["extra"]["truncated"] is True
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.mcap", "b.mcap", "c.mcap"]
