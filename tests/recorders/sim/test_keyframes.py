"""Which ticks are frames (recorders/sim/keyframes.py, live_recorder.py): the camera moved
or turned enough since the last frame, or the world changed; the pose a skill ends at is
rendered before its action is logged."""

from __future__ import annotations

import math

import pytest

from sgtool.datasets.generator import generate_house
from sgtool.errors import SgtoolError
from sgtool.log import LogReader
from sgtool.log.writer import LogWriter
from sgtool.recorders.sim import CameraConfig
from sgtool.recorders.sim.closed_loop import ClosedLoopOptions
from sgtool.recorders.sim.events import SkillOutcome
from sgtool.recorders.sim.keyframes import KeyframeRule
from sgtool.recorders.sim.live_recorder import LiveRecorder
from sgtool.recorders.sim.simulation import Simulation
from sgtool.scenegraph.build_options import builder_config
from sgtool.scenegraph.stream import SceneGraphStream

RULE = KeyframeRule(0.25, math.radians(20.0))


def frames_of(rule: KeyframeRule, poses: list[tuple[float, float, float]]) -> list[int]:
    """The indices of ``poses`` (one per tick) that are frames."""
    out, last = [], None
    for i, p in enumerate(poses):
        if rule.is_frame(last, p):
            out.append(i)
            last = p
    return out


def test_straight_driving_is_a_frame_every_step() -> None:
    # 0.05 m a tick: the first tick, then every fifth (0.25 m since the last frame)
    poses = [(0.05 * k, 0.0, 0.0) for k in range(21)]
    assert frames_of(RULE, poses) == [0, 5, 10, 15, 20]
    assert frames_of(KeyframeRule(0.0, math.radians(20.0)), poses) == list(range(21))


def test_turning_is_a_frame_every_angle_and_both_add_up() -> None:
    turn = [(0.0, 0.0, math.radians(9.0 * k)) for k in range(10)]
    assert frames_of(RULE, turn) == [0, 3, 6, 9]  # 27 degrees >= 20, 18 is not
    # 0.05 m and 9 degrees a tick: 0.2 + 0.45 per tick, a frame every second tick
    both = [(0.05 * k, 0.0, math.radians(9.0 * k)) for k in range(7)]
    assert frames_of(RULE, both) == [0, 2, 4, 6]


def test_standing_still_is_no_frame_unless_the_world_changed() -> None:
    here = (1.0, 2.0, 0.5)
    assert RULE.is_frame(None, here)
    assert not RULE.is_frame(here, here)
    assert RULE.is_frame(here, here, changed=True)
    every = KeyframeRule(0.0, 0.0)
    assert every.every_tick and every.is_frame(here, here)


@pytest.mark.parametrize("step, deg", [(-0.1, 20.0), (2.5, 20.0), (0.25, 120.0),
                                       (float("nan"), 20.0)])
def test_out_of_range_thresholds_are_one_line(step: float, deg: float) -> None:
    with pytest.raises(SgtoolError):
        ClosedLoopOptions(render_step_m=step, turn_render_deg=deg).mapping()


def test_a_skill_ending_between_frames_renders_its_last_pose(tmp_path) -> None:
    house = generate_house(6, rooms=(4, 4))
    stream = SceneGraphStream(None, None, builder_config(ClosedLoopOptions().mapping()))
    out = tmp_path / "flush.mcap"
    with Simulation(house, camera=CameraConfig(width=32, height=24), start=0) as sim, \
            LogWriter(out) as writer:
        rec = LiveRecorder(writer, sim, stream, keyframes=RULE)
        sim.observers.append(rec)
        rec.write_instances(sim)
        x, y, a = sim.base
        sim.tick()  # the first frame
        # 7 ticks straight ahead, teleported (no contacts in the way): frames at 0.25 m
        for k in range(1, 8):
            sim.teleport((x + 0.05 * k * math.cos(a), y + 0.05 * k * math.sin(a), a))
            sim.tick()
        assert rec.frames == 2 and rec.skipped == 6
        t = rec.act(sim, SkillOutcome("navigate", None, "success", "", 0.35, 7), 0.0, {})
        assert rec.frames == 3 and rec.skipped == 5  # the last tick, rendered late
        assert rec.last_frame is not None and rec.last_frame.index == 7
        assert rec.last_frame.time_ns == sim.time_ns(7) == t
        assert rec.last_refresh is not None and rec.last_refresh.frames == 3
        # nothing ticked since: a second action renders nothing more
        rec.act(sim, SkillOutcome("done", None, "success"), 0.0, {})
        assert rec.frames == 3
    with LogReader(out) as r:
        assert r.frame_count() == 3
