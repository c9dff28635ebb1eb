"""Frames at the rate the map needs (recorders/sim/live_recorder.py): a tick that only
turns the robot on the spot by less than ``turn_render_deg`` since the last frame is not
rendered, logged nor mapped; driving ticks always are."""

from __future__ import annotations

import pytest
from support.scripted_planner import Scripted

from sgtool.datasets.generator import generate_house
from sgtool.errors import SgtoolError
from sgtool.log import LogReader
from sgtool.planning.base import Action
from sgtool.recorders.sim import CameraConfig
from sgtool.recorders.sim.closed_loop import ClosedLoopOptions, pick_episode, run_episode

CAM = CameraConfig(width=96, height=72)


def test_turning_ticks_are_frames_every_20_degrees(tmp_path) -> None:
    house = generate_house(6, rooms=(4, 4))
    idx, ep = pick_episode(house, index=0)
    reps = {}
    for deg in (0.0, 20.0):
        out = tmp_path / f"turn{deg:.0f}.mcap"
        reps[deg] = run_episode(house, ep, Scripted([Action("done")]), out,
                                ClosedLoopOptions(camera=CAM, max_steps=1,
                                                  turn_render_deg=deg),
                                episode_index=idx)
        with LogReader(out) as r:
            times = [t for t, _ in r.records("action")]
            started = next(iter(r.records("episode")))[1]
            # the frames of the opening look-around (a give-up may hand over to the
            # robot's own exploration after it)
            look = sum(1 for m in r.messages(["/camera/rgb"]) if m.log_time_ns <= times[0])
        assert started["extra"]["turn_render_deg"] == deg
        assert times
        reps[deg] = look
    # the opening look-around turns on the spot at 9 degrees a tick: every frame at 0,
    # about every third tick (18 degrees is under 20, 27 is not) at 20
    every, sparse = reps[0.0], reps[20.0]
    assert every > 20
    assert sparse <= every // 3 + 2
    with pytest.raises(SgtoolError, match="turn render"):
        ClosedLoopOptions(turn_render_deg=120.0).mapping()
