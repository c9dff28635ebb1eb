"""The closed loop's log recorder: it also feeds the scene-graph stream what it writes.

:class:`LiveRecorder` is the :class:`~sgtool.recorders.sim.recording.LogRecorder` of
``sgtool run`` (:mod:`sgtool.recorders.sim.closed_loop`): every frame, as the log holds it
(after the sensor faults), and every instance table go to a
:class:`~sgtool.scenegraph.stream.SceneGraphStream` in the order they are written, an
action record refreshes the stream as replay does, and each refresh is written as the
derived channels right after the message that caused it.

Only the ticks the map needs are frames (:class:`~sgtool.recorders.sim.keyframes.KeyframeRule`:
the camera moved or turned enough since the last frame, or a door or container changed,
or the head tilted: each tick of a deliberate look into a container is a frame);
the others are not rendered, logged or mapped, so the clock ticks on but the log, the map
and the frame count skip them. When a skill ends on a tick that was no frame, that pose is
rendered before the action is logged (:meth:`LiveRecorder.act`, at that tick's time,
within the frame budget), so the refresh at the action sees where the robot stands.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Mapping
from typing import Any

from sgtool.log.echo import as_logged
from sgtool.log.writer import LogWriter
from sgtool.recorders.sim.events import TargetInView
from sgtool.recorders.sim.keyframes import KeyframeRule
from sgtool.recorders.sim.recording import LogRecorder
from sgtool.recorders.sim.simulation import Simulation, SkillOutcome
from sgtool.scenegraph.derived_layers import write_refresh
from sgtool.scenegraph.instances import instances_from_record
from sgtool.scenegraph.stream import Refresh, SceneGraphStream


class LiveRecorder(LogRecorder):
    """The log recorder that also feeds the scene-graph stream what it writes, in the
    order it writes it, and writes the stream's refreshes."""

    def __init__(self, writer: LogWriter, sim: Simulation, stream: SceneGraphStream,
                 keyframes: KeyframeRule | None = None, **kw: Any) -> None:
        super().__init__(writer, sim, log_actions=False, **kw)
        self.stream = stream
        self.refreshes = 0
        self.last_refresh: Refresh | None = None
        # which ticks are frames (None: every tick)
        self.keyframes = keyframes or KeyframeRule(0.0, 0.0)
        self.skipped = 0  # ticks not rendered
        self._rendered: tuple[float, float, float] | None = None  # base at the last frame
        self._tilt: float | None = None  # the head's tilt at the last frame (degrees)
        self._changed = False  # a door or container changed since the last frame
        self._pending: int | None = None  # the last tick, when it was no frame
        # asked at each refresh a frame makes: True ends the skill (TargetInView)
        self.stop_when: Callable[[], bool] | None = None

    def write_instances(self, sim: Simulation) -> dict[str, Any]:
        """Write the instance table (as :class:`LogRecorder` does) and hand the stream the
        JSON form the writer checked and wrote, read once."""
        written = super().write_instances(sim)
        self.stream.instance_table(sim.time_ns(), instances_from_record(written))
        return written

    def on_state(self, sim: Simulation, spec_id: str, state: str) -> None:
        super().on_state(sim, spec_id, state)
        self._changed = True

    def on_tick(self, sim: Simulation) -> None:
        if not self.keyframes.is_frame(self._rendered, sim.base,
                                       self._changed or self._tilted(sim) > 0.0):
            self.skipped += 1
            self._pending = sim.tick_index
            return
        super().on_tick(sim)
        self._framed(sim)

    def _framed(self, sim: Simulation) -> None:
        """Bookkeeping after a frame was written: feed it to the stream."""
        self._rendered = sim.base
        self._tilt = sim.head_tilt_deg
        self._changed = False
        self._pending = None
        assert self.last_frame is not None
        r = self.stream.frame(as_logged(self.last_frame))
        self.refreshed(r)
        if r is not None and self.stop_when is not None and self.stop_when():
            raise TargetInView

    def _tilted(self, sim: Simulation) -> float:
        """Degrees the head tilted since the last frame (0 before the first)."""
        return 0.0 if self._tilt is None else abs(sim.head_tilt_deg - self._tilt)

    def flush(self, sim: Simulation) -> None:
        """Render the last tick when it was no frame and nothing ticked since (the pose a
        skill ended at), at that tick's time; nothing when the frame budget is spent or
        the robot stands as at the last frame."""
        k = self._pending
        if k is None or k != sim.tick_index - 1 or self.budget_spent \
                or (sim.base == self._rendered and not self._changed
                    and not self._tilted(sim)):
            return
        self.skipped -= 1
        self.record_frame(dataclasses.replace(sim.render(), index=k, time_ns=sim.time_ns(k)))
        self._framed(sim)

    def act(self, sim: Simulation, outcome: SkillOutcome, decision_time_s: float,
            fields: Mapping[str, Any]) -> int:
        """Log an action and refresh on it (as replay does at every action record); the
        pose the skill ended at is rendered first when it was no frame (:meth:`flush`)."""
        self.flush(sim)
        t = self.log_action(sim, outcome, decision_time_s=decision_time_s, fields=fields)
        self.refreshed(self.stream.action(t))
        return t

    def refreshed(self, r: Refresh | None) -> None:
        if r is not None:
            write_refresh(self.writer, r)
            self.refreshes += 1
            self.last_refresh = r
