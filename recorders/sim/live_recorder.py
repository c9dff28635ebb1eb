"""The closed loop's log recorder: it also feeds the scene-graph stream what it writes.

:class:`LiveRecorder` is the :class:`~sgtool.recorders.sim.recording.LogRecorder` of
``sgtool run`` (:mod:`sgtool.recorders.sim.closed_loop`): every frame, as the log holds it
(after the sensor faults), and every instance table go to a
:class:`~sgtool.scenegraph.stream.SceneGraphStream` in the order they are written, an
action record refreshes the stream as replay does, and each refresh is written as the
derived channels right after the message that caused it. A tick that only turns the
robot on the spot by less than ``turn_render`` radians since the last frame is no frame
(not rendered, logged or mapped: the views of a turn overlap), so the clock ticks on but
the log, the map and the frame count skip it.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

from sgtool.log.echo import as_logged
from sgtool.log.writer import LogWriter
from sgtool.recorders.sim.recording import LogRecorder
from sgtool.recorders.sim.simulation import Simulation, SkillOutcome
from sgtool.scenegraph.derived_layers import write_refresh
from sgtool.scenegraph.stream import Refresh, SceneGraphStream


class LiveRecorder(LogRecorder):
    """The log recorder that also feeds the scene-graph stream what it writes, in the
    order it writes it, and writes the stream's refreshes."""

    def __init__(self, writer: LogWriter, sim: Simulation, stream: SceneGraphStream,
                 turn_render: float = 0.0, **kw: Any) -> None:
        super().__init__(writer, sim, log_actions=False, **kw)
        self.stream = stream
        self.refreshes = 0
        self.last_refresh: Refresh | None = None
        # a tick that only turns the base less than this (radians) from the last frame's
        # heading is not rendered, logged nor mapped (0: every tick is a frame)
        self.turn_render = float(turn_render)
        self.skipped = 0  # ticks not rendered
        self._rendered: tuple[float, float, float] | None = None  # base at the last frame

    def write_instances(self, sim: Simulation) -> None:
        super().write_instances(sim)
        assert self.last_instances is not None
        self.stream.instances(sim.time_ns(), self.last_instances)

    def on_tick(self, sim: Simulation) -> None:
        if self._turn_only(sim.base):
            self.skipped += 1
            return
        super().on_tick(sim)
        self._rendered = sim.base
        assert self.last_frame is not None
        self.refreshed(self.stream.frame(as_logged(self.last_frame)))

    def _turn_only(self, base: tuple[float, float, float]) -> bool:
        """Whether a tick at ``base`` only turned the robot on the spot by less than
        :attr:`turn_render` since the last frame (so it is not a frame)."""
        last = self._rendered
        if self.turn_render <= 0 or last is None:
            return False
        if abs(base[0] - last[0]) > 1e-9 or abs(base[1] - last[1]) > 1e-9:
            return False
        turned = abs(math.atan2(math.sin(base[2] - last[2]), math.cos(base[2] - last[2])))
        return turned < self.turn_render - 1e-9

    def act(self, sim: Simulation, outcome: SkillOutcome, decision_time_s: float,
            fields: Mapping[str, Any]) -> int:
        """Log an action and refresh on it (as replay does at every action record)."""
        t = self.log_action(sim, outcome, decision_time_s=decision_time_s, fields=fields)
        self.refreshed(self.stream.action(t))
        return t

    def refreshed(self, r: Refresh | None) -> None:
        if r is not None:
            write_refresh(self.writer, r)
            self.refreshes += 1
            self.last_refresh = r
