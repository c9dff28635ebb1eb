"""Recording a simulation into an sgtool log (MCAP).

:class:`LogRecorder` is a :class:`~sgtool.recorders.sim.simulation.SimObserver` that
writes, through :class:`sgtool.log.LogWriter`:

- every tick as one frame: rgb, depth, instance ids, calibration (first frame), and the
  transforms world -> base -> camera (with the noise profile's faults applied);
- the instances table (``sgtool.Instances``) at the start and again, whole, with the
  new states whenever a door or container opens or closes;
- one ``sgtool.Action`` per top-level skill, with its outcome, reason and distance (the
  closed loop, :mod:`sgtool.recorders.sim.closed_loop`, logs one per planner action
  instead);
- ``sgtool.Episode`` records when the run starts and ends.

:func:`record_house` runs the scripted exploration (:mod:`sgtool.recorders.sim.explore`)
of a house into a log; the closed loop builds its own run from :class:`LogRecorder`.

Log time is ``frame index * 1e9 / fps`` (integers, never the wall clock), the house spec
is attached as ``house.json``, and the same house, options and seed give a byte-identical
file. The writer writes ``OUT.XXXXXXXX.partial`` and renames it at the end; on an error
nothing is left behind (:mod:`sgtool.log.writer`).
"""

from __future__ import annotations

import dataclasses
import os
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from sgtool.arg_checks import of_type, whole
from sgtool.house.spec import HouseSpec, spec_id_key
from sgtool.log import codec
from sgtool.log import schemas as S
from sgtool.log.frame import CameraIntrinsics, Frame
from sgtool.log.records import Action, Episode, Instances
from sgtool.log.writer import LogWriter
from sgtool.progress import Progress
from sgtool.recorders.sim.body_instances import STRUCTURE
from sgtool.recorders.sim.camera import LINK_TOL, CameraConfig, base_T_camera
from sgtool.recorders.sim.explore import ExplorationReport, ScriptOptions, explore_house
from sgtool.recorders.sim.navigation import RobotConfig
from sgtool.recorders.sim.noise import PROFILES, NoiseProfile, SensorFaults
from sgtool.recorders.sim.simulation import (
    SimObserver,
    Simulation,
    SkillOutcome,
    StopSimulation,
)

SOURCE = "pybullet"
STATIC_TOL = LINK_TOL  # base -> camera this close still counts as the static link


class LogRecorder(SimObserver):
    """Writes a simulation's frames, state changes and actions to ``writer``.

    ``max_frames`` ends the run (by raising :class:`StopSimulation` from the tick that
    would exceed it). ``planner`` fills the action records' planner field. ``progress``
    is anything with ``update(n)`` (a tqdm bar). :attr:`last_frame` is the last frame as
    written (after the sensor faults) and :attr:`last_instances` the last instances
    record, for whoever builds from what the log holds (the closed loop).
    """

    def __init__(self, writer: LogWriter, sim: Simulation, *,
                 noise: NoiseProfile | None = None, seed: int = 0,
                 max_frames: int | None = None, planner: str | None = None,
                 progress: Progress | None = None, log_actions: bool = True) -> None:
        self.writer = writer
        self.max_frames = max_frames
        self.planner = planner
        self.progress = progress
        self.log_actions = log_actions
        self.frames = 0
        self.actions = 0
        self.last_time_ns = 0
        self.last_frame: Frame | None = None
        self.last_instances: Instances | None = None
        self._calibration: CameraIntrinsics | None = None  # the last one written
        self._static: np.ndarray | None = None  # base_T_camera as on /tf_static
        self._link_moved = False  # the last base -> camera on /tf is not the static one
        self._level_ns: int | None = None  # the last frame's time, while at the mounting
        profile = noise or PROFILES["none"]
        structure = [i.id for i in sim.instances if i.kind == STRUCTURE]
        self.faults = None if profile.is_clean else SensorFaults(
            profile, seed, structure,
            base_T_camera(sim.camera.mount_height, sim.camera.tilt_deg))

    def write_instances(self, sim: Simulation) -> dict[str, Any]:
        """Write the simulation's instance table; returns the JSON object written."""
        self.last_instances = Instances.of(sim.instance_records())
        return self.writer.write_record(self.last_instances, sim.time_ns())

    def on_tick(self, sim: Simulation) -> None:
        if self.budget_spent:
            raise StopSimulation(f"frame budget of {self.max_frames} reached")
        self.record_frame(sim.render())

    @property
    def budget_spent(self) -> bool:
        """Whether the frame budget is spent (the next frame would exceed it)."""
        return self.max_frames is not None and self.frames >= self.max_frames

    def record_frame(self, f: Frame) -> None:
        """Write a rendered frame (with the sensor faults applied) and count it; under pose
        drift also the true base pose (world -> ``base_truth`` on ``/tf``)."""
        truth = None
        if self.faults is not None:
            if self.faults.profile.drift_model is not None:
                truth = f.base_pose
            f = self.faults.apply(f)
        self.write_frame(f)
        if truth is not None:
            self.writer.write_transform(f.time_ns, S.WORLD_FRAME, S.TRUE_BASE_FRAME, truth)
        self.last_time_ns = f.time_ns
        self.last_frame = f
        self.frames += 1
        if self.progress is not None:
            self.progress.update(1)

    def write_frame(self, f: Frame) -> None:
        """One frame, in the order :meth:`LogWriter.write_frame` writes it (calibration when
        it changes, transforms, RGB, depth, ids), with two differences: the base -> camera
        link, which does not move, goes once to ``/tf_static`` (again on ``/tf`` only at a
        frame where it differs by more than :data:`STATIC_TOL`, e.g. under pose noise),
        and the ids are :func:`instance_image`'s. A link that moves (a tilted head) is also
        written on ``/tf`` at the mounting at the last frame before (a viewer that
        interpolates between samples, as Foxglove does, then tilts the camera between two
        frames, not over the whole run before) and again at the first frame it is back,
        since a reader takes a link also sent on ``/tf_static`` as fixed: its latest
        sample at or before a frame, not interpolated."""
        w, t = self.writer, f.time_ns
        if f.intrinsics != self._calibration:
            w.write_calibration(t, f.intrinsics)
            self._calibration = f.intrinsics
        if f.base_pose is None:
            w.write_transform(t, S.WORLD_FRAME, S.CAMERA_FRAME, f.pose)
        else:
            w.write_transform(t, S.WORLD_FRAME, S.BASE_FRAME, f.base_pose)
            base_T_cam = codec.relative(f.base_pose, f.pose)  # noqa: N806
            if self._static is None:
                self._static = base_T_cam
                w.write_proto(S.TF_STATIC, t, codec.encode_transform(
                    t, S.BASE_FRAME, S.CAMERA_FRAME, base_T_cam))
            elif not np.allclose(base_T_cam, self._static, rtol=0.0, atol=STATIC_TOL):
                if self._level_ns is not None:  # still at the mounting one frame ago
                    w.write_transform(self._level_ns, S.BASE_FRAME, S.CAMERA_FRAME,
                                      self._static)
                w.write_transform(t, S.BASE_FRAME, S.CAMERA_FRAME, base_T_cam)
                self._link_moved, self._level_ns = True, None
            elif self._link_moved:  # back to the mounting: /tf says so, as readers use it
                w.write_transform(t, S.BASE_FRAME, S.CAMERA_FRAME, self._static)
                self._link_moved = False
            if not self._link_moved:
                self._level_ns = t
        if f.rgb is not None:
            w.write_rgb(t, f.rgb)
        w.write_depth(t, f.depth)
        if f.ids is not None:
            w.write_proto(S.IDS, t, instance_image(t, f.ids))

    def on_state(self, sim: Simulation, spec_id: str, state: str) -> None:
        self.write_instances(sim)

    def on_skill(self, sim: Simulation, outcome: SkillOutcome) -> None:
        if self.log_actions:
            self.log_action(sim, outcome)

    def on_skill_of(self, sim: Simulation) -> Callable[[SkillOutcome], None]:
        """``on_skill`` for ``sim`` as a one-argument function (the robot side's log)."""
        return lambda outcome: self.on_skill(sim, outcome)

    def log_action(self, sim: Simulation, outcome: SkillOutcome, *,
                   decision_time_s: float = 0.0,
                   fields: Mapping[str, Any] | None = None) -> int:
        """Write the ``sgtool.Action`` record of ``outcome`` at the time of the last frame
        the skill took (the current time when it took none); ``fields`` are set on the
        record (e.g. ``graph_time_ns``). Returns the record's log time."""
        t = sim.time_ns(max(sim.tick_index - 1, 0)) if outcome.ticks else sim.time_ns()
        t = max(t, self.last_time_ns)
        decided = Action(outcome.skill, outcome.target, reason=outcome.reason,
                         decision_time_s=float(decision_time_s))
        record = decided.executed(outcome.outcome, outcome.travelled_m, planner=self.planner,
                                  step=self.actions)
        self.writer.write_record(dataclasses.replace(record, **(fields or {})), t)
        self.actions += 1
        return t



def instance_image(t_ns: int, ids: np.ndarray) -> Any:
    """The instance-id image of a frame (:func:`sgtool.log.codec.encode_ids`)."""
    return codec.encode_ids(t_ns, ids, S.CAMERA_FRAME)


EXPLORE = ("script", "frontier")


@dataclass(frozen=True)
class RecordOptions:
    """How :func:`record_house` records (``sgtool record``'s options): ``fps`` frames per
    second of log time, ``frames`` a budget (None: until the exploration ends), the
    camera, the robot base, sensor ``noise`` (:func:`sgtool.parse_noise`) seeded by
    ``seed``, the house's ``start`` pose, the scripted tour's ``script`` options, the
    log's ``compression`` (zstd, lz4, none), and ``explore``: "script" (the scripted tour
    of every room, with the house's knowledge) or "frontier" (frontier exploration on the
    robot's own map, refreshed every ``every`` frames). A bad value is one
    :class:`~sgtool.errors.SgtoolError` line."""

    fps: float = 10.0
    frames: int | None = None  # stop after this many frames (None: when the script ends)
    camera: CameraConfig = field(default_factory=CameraConfig)
    robot: RobotConfig = field(default_factory=RobotConfig)
    noise: NoiseProfile = field(default_factory=lambda: PROFILES["none"])
    seed: int = 0  # seeds the sensor faults
    start: int = 0  # index of the house's start pose
    script: ScriptOptions = field(default_factory=ScriptOptions)
    compression: str = "zstd"
    explore: str = "script"  # or "frontier": frontier exploration on the robot's own map
    every: int = 10  # frontier: frames between refreshes of the robot's map

    def __post_init__(self) -> None:
        from sgtool.errors import SgtoolError
        from sgtool.log.writer import COMPRESSIONS
        from sgtool.recorders.sim.noise import parse_noise
        from sgtool.recorders.sim.simulation import FPS_RANGE

        if isinstance(self.noise, str):  # a profile's text, as --noise takes it
            object.__setattr__(self, "noise", parse_noise(self.noise))
        for name, kind in (("noise", NoiseProfile), ("camera", CameraConfig),
                           ("robot", RobotConfig), ("script", ScriptOptions)):
            of_type(name, getattr(self, name), kind, f"a {kind.__name__}")
        for name in ("frames", "every", "seed", "start"):
            whole(name, getattr(self, name), optional=name == "frames")
        if isinstance(self.fps, bool) or not isinstance(self.fps, (int, float)) or \
                not FPS_RANGE[0] <= self.fps <= FPS_RANGE[1]:
            raise SgtoolError(f"fps {self.fps!r} (--fps): must be a number "
                              f"{FPS_RANGE[0]:g}..{FPS_RANGE[1]:g}")
        object.__setattr__(self, "fps", float(self.fps))  # fps=4 logs as --fps 4 does
        if self.frames is not None and self.frames < 1:
            raise SgtoolError(f"frames {self.frames} (--frames): must be >= 1")
        if self.explore not in EXPLORE:
            raise SgtoolError(f"explore {self.explore!r} (--explore): one of "
                              f"{', '.join(EXPLORE)}")
        if self.every < 1:
            raise SgtoolError(f"every {self.every}: must be >= 1")
        if self.seed < 0:
            raise SgtoolError(f"--noise-seed {self.seed}: must be >= 0")
        if self.start < 0:
            raise SgtoolError(f"--start {self.start}: must be >= 0")
        if self.compression not in COMPRESSIONS:
            raise SgtoolError(f"compression {self.compression!r} (--compression): one of "
                              f"{', '.join(COMPRESSIONS)}")


@dataclass(frozen=True)
class RecordReport:
    """What :func:`record_house` wrote: the log, its frames and actions, the metres
    driven, the rooms (or frontier goals) visited and those missed with why, the pieces
    opened, whether the frame budget cut the tour short, the wall-clock seconds, for
    a frontier exploration the share of the house's floor seen over time, and the open
    doors and pieces whose panels had no room to swing (``taken_away``, the doors among
    them ``doors_taken_away``: out of the simulation; an empty doorway in the log), and
    a room per further look-around of the scripted tour in it (``looked_again``).
    ``lines()`` is ``sgtool record``'s report."""

    output: Path
    house_id: str
    frames: int
    actions: int
    travelled_m: float
    rooms_visited: tuple[str, ...]
    rooms_missed: dict[str, str]
    opened: tuple[str, ...]
    truncated: bool
    seconds: float  # wall-clock time of the run (reported, never logged)
    coverage: tuple[tuple[float, float], ...] = ()  # frontier: (sim time s, floor share)
    taken_away: tuple[str, ...] = ()  # open doors and pieces whose panels found no room
    doors_taken_away: tuple[str, ...] = ()  # the doors among them
    looked_again: tuple[str, ...] = ()  # a room per further look-around in it (script)

    def lines(self) -> list[str]:
        fps = self.frames / self.seconds if self.seconds > 0 else 0.0
        out = [
            f"wrote {self.output} ({self.output.stat().st_size / 1e6:.1f} MB)",
            f"house {self.house_id}: {self.frames} frames, {self.actions} actions, "
            f"{self.travelled_m:.1f} m driven, {self.seconds:.1f} s ({fps:.1f} frames/s)",
            f"{'goals' if self.coverage else 'rooms'} visited: {len(self.rooms_visited)}"
            + (f" ({', '.join(self.rooms_visited)})" if self.rooms_visited else ""),
        ]
        if self.looked_again:
            rooms = dict.fromkeys(self.looked_again)
            out.append("looked around again in rooms one place does not show whole: "
                       + ", ".join(f"{r} ({self.looked_again.count(r)})" for r in rooms))
        if self.opened:
            out.append(f"opened: {', '.join(self.opened)}")
        for r, why in self.rooms_missed.items():
            out.append(f"missed {r}: {why}")
        if self.truncated:
            out.append("stopped at the frame budget before the exploration finished")
        if self.doors_taken_away:
            out.append(f"open without room to swing, so taken out of the simulation: "
                       f"{', '.join(self.doors_taken_away)} (the log shows an empty doorway "
                       "there, no door leaf: the replay finds no door there, and without a "
                       "lintel over the doorway may join its two rooms)")
        pieces = [i for i in self.taken_away if i not in self.doors_taken_away]
        if pieces:
            out.append(f"opened without room for their doors to swing, so the doors were taken "
                       f"out of the simulation: {', '.join(pieces)} (seen open, no door leaf)")
        if self.coverage:
            marks = [f"{m} min {100 * coverage_at(self.coverage, 60.0 * m):.1f} %"
                     for m in (1, 2, 5) if self.coverage[-1][0] >= 60.0 * m]
            t, c = self.coverage[-1]
            out.append("floor seen: " + ", ".join([*marks, f"end ({t:.0f} s) {100 * c:.1f} %"]))
        return out


def coverage_at(samples: Sequence[tuple[float, float]], t: float) -> float:
    """The coverage of the last sample at or before ``t`` seconds (0 before the first)."""
    best = 0.0
    for ts, c in samples:
        if ts > t + 1e-9:
            break
        best = c
    return best


def record_house(house: HouseSpec | str | os.PathLike[str], output: str | os.PathLike[str],
                 options: RecordOptions | None = None, *, house_id: str = "",
                 progress: Progress | None = None, observers: Sequence[SimObserver] = ()
                 ) -> RecordReport:
    """Record the exploration of ``house`` (a spec, or a spec file's path; ``sgtool
    record``) into the log ``output``
    (``*.mcap``, replaced when it exists; written to a temporary name and renamed at the
    end, so an error leaves nothing, and an interrupt its ``.partial`` file:
    :mod:`sgtool.log.writer`). A house without start poses needs them first
    (:func:`sgtool.datasets.start_poses.with_start_poses`, as ``sgtool record`` does).
    ``house_id`` names the house in the log (default ``house-SEED``); ``progress``
    advances by one per frame; ``observers`` also watch the simulation (after the
    recorder, so they see each frame once it is written). Needs PyBullet (``pip install
    'sgtool[sim]'``)."""
    from sgtool.arg_checks import of_type
    from sgtool.arg_checks import progress as check_progress
    from sgtool.errors import SgtoolError
    from sgtool.extras import require

    progress = check_progress("progress", progress)
    if options is not None:
        of_type("options", options, RecordOptions, "a RecordOptions")
    require("pybullet", api="sgtool.record_house")  # one line on a core install
    if isinstance(house, str | os.PathLike):  # a house spec file, as run_one takes
        from sgtool.house.io import load_house

        house = load_house(house)
    elif not isinstance(house, HouseSpec):
        raise SgtoolError(f"house: a HouseSpec or a house spec file, got "
                          f"{type(house).__name__}")
    if Path(output).suffix != ".mcap":
        raise SgtoolError(f"{output}: the output is an MCAP log; name it *.mcap")
    opts = options or RecordOptions()
    hid = house_id or f"house-{house.seed}"
    t_wall = time.perf_counter()
    rep = ExplorationReport()
    truncated = False
    with Simulation(house, camera=opts.camera, robot=opts.robot, fps=opts.fps,
                    start=opts.start) as sim, \
            LogWriter(output, seed=opts.seed, compression=opts.compression,
                      metadata={"source": SOURCE, "house_id": hid,
                                "house_seed": str(house.seed)}) as writer:
        rec = LogRecorder(writer, sim, noise=opts.noise, seed=opts.seed,
                          max_frames=opts.frames, planner="scripted", progress=progress)
        sim.observers.append(rec)
        sim.observers.extend(observers)
        writer.attach_house(house.to_json())
        writer.write_record(Episode(kind="recording", source=SOURCE, house_id=hid,
                                    status="started", extra=_episode_extra(opts, sim)), 0)
        rec.write_instances(sim)
        samples: list[tuple[float, float]] = []
        try:
            if opts.explore == "frontier":
                _explore_live(sim, rec, opts, rep, samples)
            else:
                sim.tick()  # the view at the start pose
                explore_house(sim, opts.script, rep)
        except StopSimulation:
            truncated = True
        writer.write_record(Episode(
            kind="recording", source=SOURCE, house_id=hid, status="ended",
            steps=rec.actions, frames=rec.frames, travelled_m=sim.travelled_m,
            extra={"rooms_visited": rep.visited, "rooms_missed": rep.missed,
                   "opened": rep.opened, "truncated": truncated},
        ), rec.last_time_ns)
        travelled = sim.travelled_m
        frames, actions = rec.frames, rec.actions
        taken = tuple(sid for sid, bodies in sorted(sim.world.panels.items(),
                                                    key=lambda kv: spec_id_key(kv[0]))
                      if any(b.removed for b in bodies))
        doors = {d.id for d in house.doors}
    return RecordReport(Path(output), hid, frames, actions, travelled, tuple(rep.visited),
                        dict(rep.missed), tuple(rep.opened), truncated,
                        time.perf_counter() - t_wall, tuple(samples), taken,
                        tuple(i for i in taken if i in doors), tuple(rep.looked_again))


def _explore_live(sim: Simulation, rec: LogRecorder, opts: RecordOptions,
                  rep: ExplorationReport, samples: list[tuple[float, float]]) -> None:
    """Frontier exploration on the robot's own map (:mod:`.frontier_explore`), sampling
    the floor coverage at every refresh."""
    from sgtool.recorders.sim.coverage import coverage, floor_points
    from sgtool.recorders.sim.frontier_explore import (
        FrontierReport,
        LiveMap,
        explore_frontiers,
    )
    from sgtool.recorders.sim.live_skills import LiveSkills, RobotBody, camera_sight
    from sgtool.scenegraph.build_options import ResolvedOptions, builder_config, default_min_points
    from sgtool.scenegraph.stream import Refresh, SceneGraphStream

    floor = floor_points(sim.spec)
    mapping = ResolvedOptions(every=opts.every, classifier="none",
                              min_points=default_min_points(opts.camera.width,
                                                            opts.camera.height),
                              voxel_size=0.05, max_frames=None)
    stream = SceneGraphStream(None, None, builder_config(mapping))
    assert rec.last_instances is not None, "record_house writes the instance table first"
    stream.instances(0, rec.last_instances)

    def sample(r: Refresh) -> None:
        if r.layers is not None:
            samples.append((r.time_ns / 1e9, coverage(r.layers.occupancy, floor)))

    sim.observers.insert(sim.observers.index(rec) + 1, LiveMap(rec, stream, sample))
    skills = LiveSkills(RobotBody(sim), lambda: stream.current,
                        sight=camera_sight(stream, sim.camera.mount_height))
    sim.tick()  # the view at the start pose
    fr = FrontierReport()  # filled as it goes: a frame budget stops it midway
    try:
        explore_frontiers(skills, rec.on_skill_of(sim), report=fr)
    finally:
        rep.visited.extend(fr.goals)
        rep.missed.update({g: "not reached" for g in fr.failed})
        rep.opened.extend(fr.opened)


def _episode_extra(opts: RecordOptions, sim: Simulation) -> dict[str, Any]:
    k = sim.intrinsics
    return {
        "fps": opts.fps, "seed": opts.seed, "start": opts.start,
        "start_pose": [round(v, 6) for v in sim.base],
        "camera": asdict(opts.camera),
        "intrinsics": {"width": k.width, "height": k.height, "fx": k.fx, "fy": k.fy,
                       "cx": k.cx, "cy": k.cy},
        "robot": asdict(opts.robot),
        "noise": opts.noise.to_dict(),
        **({"drift_model": opts.noise.drift_model} if opts.noise.drift_model else {}),
        "script": asdict(opts.script),
        **({"explore": opts.explore} if opts.explore != "script" else {}),
        "frame_budget": opts.frames,
    }
