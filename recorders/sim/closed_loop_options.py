"""The options of a closed-loop episode (:class:`ClosedLoopOptions`), checked in one place.

:func:`sgtool.recorders.sim.closed_loop.run_episode` runs with them; ``sgtool run`` and
``sgtool run-bench`` build them from their command lines, and run-bench's resume check
compares them with what a log recorded.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, fields

from sgtool.arg_checks import of_type, typed_fields
from sgtool.errors import SgtoolError
from sgtool.mapping.bev import BevConfig
from sgtool.mapping.depth_noise import sensor_max_depth
from sgtool.planning.episode import check_success_rule
from sgtool.recorders.sim.camera import CameraConfig
from sgtool.recorders.sim.keyframes import KeyframeRule
from sgtool.recorders.sim.live_skills import LiveNavConfig
from sgtool.recorders.sim.navigation import RobotConfig
from sgtool.recorders.sim.noise import PROFILES, NoiseProfile, parse_noise
from sgtool.scenegraph.build_options import (
    CLASSIFIERS,
    MAX_DEPTH_M,
    MAX_DEPTH_RANGE,
    ResolvedOptions,
    default_min_points,
)

N_MAX = 50  # high-level steps per episode (SymSearch's N_max)
NAVIGATION = ("live", "house")
# the CLI's names of the LiveNavConfig fields it sets (``peek``'s default is on)
_LIVE_FLAGS = {"optimistic": "--optimistic", "look_in": "--look-in",
               "look_in_beyond": "--look-in-beyond", "peek": "--no-peek",
               "sight_lines": "--sight-lines", "explore_through": "--explore-through"}


@dataclass(frozen=True)
class ClosedLoopOptions:
    """How a closed-loop episode runs
    (:func:`~sgtool.recorders.sim.closed_loop.run_episode`): frame rate, camera, robot,
    sensor ``noise``; the mapping (a refresh every ``every`` frames, room ``classifier``,
    ``min_points``, ``voxel_size``, ``max_depth``: recorded in the log, so ``sgtool
    replay`` rebuilds the same graphs); ``max_steps`` high-level steps and a ``frames``
    budget; ``navigation`` ``live`` (the robot's own map) or ``house`` (ground truth);
    the ``success`` rule; ``explore_on``, how many frontiers an explore that showed nothing
    new goes on to.
    :meth:`mapping` checks them (a one-line :class:`~sgtool.errors.SgtoolError`)."""

    fps: float = 10.0
    camera: CameraConfig = field(default_factory=CameraConfig)
    robot: RobotConfig = field(default_factory=RobotConfig)
    noise: NoiseProfile = field(default_factory=lambda: PROFILES["none"])  # or its text
    noise_seed: int = 0
    every: int = 10  # frames between graph refreshes (and one at every action)
    classifier: str = "frequency"
    min_points: int | None = None  # None: MoMa-LLM's 50 at 320x240, scaled
    voxel_size: float = 0.05
    # m; depth farther is not mapped. None: the default, lowered to where the depth noise
    # of the sensor (``noise.depth_sigma``, known to the robot as a datasheet figure)
    # reaches the floor tolerance (:func:`~sgtool.mapping.depth_noise.sensor_max_depth`)
    max_depth: float | None = None
    max_steps: int = N_MAX
    frames: int | None = None  # frame budget (None: none)
    planner_seed: int = 0
    compression: str = "zstd"
    # "live": the robot plans on its own map; "house": on the ground truth (privileged)
    navigation: str = "live"
    live: LiveNavConfig = field(default_factory=LiveNavConfig)
    success: str = "observed"  # success rule (sgtool.planning.episode): observed | done
    # which ticks are frames (:mod:`.keyframes`): a frame every this many degrees turned
    # and metres driven since the last one (both 0: every tick)
    turn_render_deg: float = 20.0
    render_step_m: float = 0.25
    # an explore that showed no new object, door or room goes on to up to this many
    # frontiers the planner chooses, no steps (live navigation; 0: it does not)
    explore_on: int = 0

    def __post_init__(self) -> None:
        # a profile by name or text ("strong", "mild,holes=0.05"), as the CLI takes it
        if isinstance(self.noise, str):
            object.__setattr__(self, "noise", parse_noise(self.noise))
        else:
            of_type("noise", self.noise, NoiseProfile, "a NoiseProfile or a profile's text")
        typed_fields(self)  # max_steps="3", camera=(96, 72): one line here
        if self.max_steps < 1:
            raise SgtoolError(f"--max-steps {self.max_steps}: must be >= 1")
        if self.frames is not None and self.frames < 1:
            raise SgtoolError(f"--frames {self.frames}: must be >= 1")
        self.mapping()  # every other range, here rather than when an episode runs

    def keyframes(self) -> KeyframeRule:
        """Which ticks are frames (a one-line :class:`~sgtool.errors.SgtoolError` when
        out of range)."""
        return KeyframeRule(float(self.render_step_m), math.radians(self.turn_render_deg))

    def mapping(self) -> ResolvedOptions:
        """The replay options this run builds with (``extra.mapping`` of the log)."""
        check_success_rule(self.success)
        if self.navigation not in NAVIGATION:
            raise SgtoolError(f"navigation {self.navigation!r}: one of {', '.join(NAVIGATION)}")
        if self.every < 1:
            raise SgtoolError(f"--every {self.every}: must be >= 1")
        if self.classifier not in CLASSIFIERS:
            raise SgtoolError(f"unknown room classifier {self.classifier!r}; one of "
                              f"{', '.join(CLASSIFIERS)}")
        self.keyframes()
        if self.explore_on < 0:
            raise SgtoolError(f"--explore-on {self.explore_on}: must be >= 0")
        self._check_live_only()
        if not 0.01 <= self.voxel_size <= 0.5:
            raise SgtoolError(f"voxel size {self.voxel_size} m: must be 0.01..0.5")
        mp = self.min_points if self.min_points is not None else default_min_points(
            self.camera.width, self.camera.height)
        if mp < 1:
            raise SgtoolError(f"min points {mp}: must be >= 1")
        return ResolvedOptions(every=int(self.every), classifier=self.classifier,
                               min_points=int(mp), voxel_size=float(self.voxel_size),
                               max_frames=None, max_depth=self.depth_mapped())

    def _check_live_only(self) -> None:
        """Options of the robot's own navigation are refused with ``navigation="house"``,
        which does not use them (one line naming them as the CLI does)."""
        if self.navigation != "house":
            return
        default = LiveNavConfig()
        changed = [_LIVE_FLAGS.get(f.name, f.name) for f in fields(LiveNavConfig)
                   if getattr(self.live, f.name) != getattr(default, f.name)]
        if self.explore_on:
            changed.append("--explore-on")
        if changed:
            raise SgtoolError(f"{', '.join(changed)}: for --navigation live (the robot's own "
                              "navigation); --navigation house does not use "
                              f"{'them' if len(changed) > 1 else 'it'}")

    def depth_mapped(self) -> float:
        """``max_depth``, checked, or the default cut to the sensor's depth noise."""
        lo, hi = MAX_DEPTH_RANGE
        if self.max_depth is not None:
            if not (math.isfinite(self.max_depth) and lo <= self.max_depth <= hi):
                raise SgtoolError(f"--max-depth {self.max_depth:g} m: must be {lo:g}..{hi:g}")
            floor = self.camera.nearest_floor_depth()
            if floor is not None and self.max_depth <= floor:
                raise SgtoolError(
                    f"--max-depth {self.max_depth:g} m: the camera ({self.camera.mount_height:g}"
                    f" m high, tilted {self.camera.tilt_deg:g} deg) sees no floor nearer than "
                    f"{floor:.2f} m, so the live map would hold no floor; give more")
            return float(self.max_depth)
        cut = sensor_max_depth(self.noise.depth_sigma, self.camera.mount_height,
                               BevConfig().floor_tolerance, ceiling=MAX_DEPTH_M)
        return MAX_DEPTH_M if cut is None else max(lo, cut)
