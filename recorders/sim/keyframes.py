"""Which simulator ticks of the closed loop become frames (pure): the ones the map needs.

The robot moves ``speed / fps`` metres or ``turn_speed / fps`` radians a tick; neighbouring
views overlap almost entirely, so a tick is rendered, logged and mapped only when the
camera has moved enough since the last frame (:class:`KeyframeRule`):

- the first tick is a frame;
- a tick after a change of the world (a door or container opened or closed since the
  last frame) is a frame, so what the change revealed is seen;
- otherwise a tick is a frame when ``moved / step_m + turned / turn_rad >= 1`` (metres
  driven and radians turned since the last frame; a threshold of 0 makes any amount of
  its kind enough), so straight driving gives a frame every ``step_m`` metres, turning on
  the spot one every ``turn_rad`` radians, and turning while driving one sooner;
- a tick that neither moves nor turns (a door swinging) is no frame.

With both thresholds 0 every tick is a frame. The caller also renders the last pose of a
skill when it was no frame (:meth:`sgtool.recorders.sim.live_recorder.LiveRecorder.act`),
so every decision sees where the robot ended.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from sgtool.errors import SgtoolError

Pose2 = tuple[float, float, float]  # x, y, yaw
EPS = 1e-9


@dataclass(frozen=True)
class KeyframeRule:
    """When a tick is a frame (module doc): ``step_m`` metres, ``turn_rad`` radians."""

    step_m: float = 0.25
    turn_rad: float = math.radians(20.0)

    def __post_init__(self) -> None:
        if not (0.0 <= self.step_m <= 2.0 and math.isfinite(self.step_m)):
            raise SgtoolError(f"render step {self.step_m} m: must be 0..2")
        if not (0.0 <= self.turn_rad <= math.pi / 2 and math.isfinite(self.turn_rad)):
            raise SgtoolError(f"turn render angle {math.degrees(self.turn_rad):g} deg: "
                              "must be 0..90")

    @property
    def every_tick(self) -> bool:
        """Whether every tick is a frame (both thresholds 0)."""
        return self.step_m <= 0.0 and self.turn_rad <= 0.0

    def is_frame(self, last: Pose2 | None, pose: Pose2, changed: bool = False) -> bool:
        """Whether the tick at ``pose`` is a frame, ``last`` being the pose of the last
        frame (None: no frame yet) and ``changed`` whether the world changed since."""
        if last is None or changed or self.every_tick:
            return True
        moved = math.hypot(pose[0] - last[0], pose[1] - last[1])
        turned = abs(math.atan2(math.sin(pose[2] - last[2]), math.cos(pose[2] - last[2])))
        if moved <= EPS and turned <= EPS:
            return False
        return _share(moved, self.step_m) + _share(turned, self.turn_rad) >= 1.0 - EPS


def _share(amount: float, threshold: float) -> float:
    """``amount / threshold``; with threshold 0, any amount over :data:`EPS` is enough."""
    if threshold <= 0.0:
        return 1.0 if amount > EPS else 0.0
    return amount / threshold
