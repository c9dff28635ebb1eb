"""The closed-loop episode a log was run as, read back from the log (``sgtool run --again``,
:func:`sgtool.logged_run`): its house (the ``house.json`` attachment), the episode (query,
targets, start pose, index), the planner with the options the log recorded, and every
setting of :class:`~sgtool.recorders.sim.closed_loop.ClosedLoopOptions` the opening
Episode record holds, so that the episode runs again exactly as ``sgtool run`` or
``sgtool run-bench`` ran it (run-bench draws its own episodes, which ``run --episode K``
does not pick).

What cannot be carried over is said, not guessed: secrets (an LLM planner's API key,
never logged) are to be given again, and a log written by older code (settings it ran
with that today's code does not take, as run-bench's resume check reads them) comes with
notes naming each such setting; the episode then runs with today's.
"""

from __future__ import annotations

import dataclasses
import math
import os
from dataclasses import dataclass, fields
from pathlib import Path
from typing import Any

from sgtool.datasets.episodes import Episode
from sgtool.errors import SgtoolError, SpecError
from sgtool.house.spec import HouseSpec, StartPose
from sgtool.recorders.sim.camera import CameraConfig
from sgtool.recorders.sim.closed_loop_options import ClosedLoopOptions
from sgtool.recorders.sim.live_skills import LiveNavConfig
from sgtool.recorders.sim.navigation import RobotConfig
from sgtool.recorders.sim.noise import NoiseProfile
from sgtool.scenegraph.build_options import MAX_DEPTH_M, default_min_points
from sgtool.semantics.text import category_text

_POSE_TOL = 1e-5  # the opening record rounds the start pose to 1e-6
# how the robot navigated in a log that does not name these (code from before each): as
# run-bench's resume check reads such a log
_BEFORE = {"look_in": 0.0, "look_in_beyond": 0.0, "peek": False, "sight_lines": False,
           "explore_through": 0.0}


@dataclass(frozen=True)
class LoggedRun:
    """A closed-loop episode as its log recorded it: pass the fields to
    :func:`sgtool.run_closed_loop` (``house``, ``episode``, a planner, an output,
    ``options``, ``house_id=``, ``episode_index=``, ``planner_options=``) to run it again,
    with any of them replaced. ``notes``: settings of the log today's code runs otherwise."""

    house: HouseSpec
    house_id: str
    episode_index: int
    episode: Episode
    planner: str
    planner_options: dict[str, Any]
    options: ClosedLoopOptions
    notes: tuple[str, ...] = ()
    # "module:QualName" of a user's own planner object the episode ran (``planner`` is then
    # its display name, no planner sgtool builds by it): pass that object again
    planner_object: str | None = None


def logged_run(path: str | os.PathLike[str]) -> LoggedRun:
    """The episode the closed-loop log ``path`` ran (module doc); a one-line
    :class:`~sgtool.errors.SgtoolError` for a log that holds none (a recording of
    ``sgtool record``, an imported one) or whose house or settings cannot be read."""
    from sgtool.house.io import load_house_text
    from sgtool.log.reader import LogReader
    from sgtool.log.records import Episode as LoggedEpisode

    p = Path(path)
    with LogReader(p) as r:
        opened = [e for _, e in r.records(LoggedEpisode)
                  if e.kind == "search" and e.status == "started"]
        house_text = r.house_json()
    if len(opened) != 1:
        raise SgtoolError(f"{p}: {'no' if not opened else len(opened)} closed-loop "
                          "episodes in it; a log of `sgtool run` or `sgtool run-bench` holds "
                          "one (`sgtool info` shows what a log holds)")
    if house_text is None:
        raise SgtoolError(f"{p}: no house.json attachment (the house it ran in)")
    try:
        house = load_house_text(house_text)
    except SpecError as e:
        raise SgtoolError(f"{p}: its house.json is no house this sgtool reads: {e}") from None
    start = opened[0]
    x = dict(start.extras)
    try:
        episode = _episode(house, start.query, x, start.shortest_m)
        options = _options(x)
        index = int(x["episode"])
    except (KeyError, TypeError, ValueError) as e:
        raise SgtoolError(f"{p}: its opening Episode record lacks or garbles a setting "
                          f"({type(e).__name__}: {e})") from None
    planner = start.planner if isinstance(start.planner, str) and start.planner else None
    if planner is None:
        raise SgtoolError(f"{p}: its opening Episode record names no planner")
    from sgtool.planning.registry import typed_options

    obj = x.get("planner_object")
    obj = obj if isinstance(obj, str) and obj else None
    logged = x.get("planner_options") or {}
    run = LoggedRun(house=house, house_id=str(start.house_id or f"house-{house.seed}"),
                    episode_index=index, episode=episode, planner=planner,
                    # as the planner takes them (a list option: a tuple, as from -O)
                    planner_options=dict(logged) if obj else typed_options(planner, logged),
                    options=options, planner_object=obj)
    notes = () if obj else tuple(changed_settings(p, run))
    # not the log's LLM transcript: a planner made with it would write this run's
    # exchanges into the transcript of the one logged (give a new one to keep them)
    return dataclasses.replace(run, notes=notes, planner_options={
        k: v for k, v in run.planner_options.items() if k != "transcript"})


def changed_settings(path: Path, run: LoggedRun) -> list[str]:
    """The settings the log at ``path`` ran with that ``run`` (as today's code runs it)
    does not: run-bench's resume comparison, one line each."""
    from sgtool.analysis.run_bench_resume import (
        episode_identity,
        logged_settings,
        settings_differences,
        task_settings,
    )
    from sgtool.planning.registry import effective_options

    logged, _ = logged_settings(path)
    faults = {k: v for k, v in run.options.noise.to_dict().items() if k != "name" and v}
    noise = ",".join(f"{k}={v!r}" for k, v in faults.items()) or "none"
    want = task_settings(run.options, noise, episode_identity(run.episode),
                         run.planner_options)
    # compared as the planner takes them, as run-bench's resume does
    want["planner_options"] = effective_options(run.planner, want["planner_options"])
    logged["planner_options"] = effective_options(run.planner,
                                                  logged["planner_options"] or {})
    return settings_differences(logged, want)


def _episode(house: HouseSpec, query: Any, x: dict[str, Any],
             shortest: Any) -> Episode:
    """The episode of the opening record's ``extra`` ``x``, its start the house's start
    pose it names (else the logged pose)."""
    if not isinstance(query, str) or not query:
        raise ValueError("no query")
    pose = [float(v) for v in x["start_pose"]]
    room = str(x["start_room"])
    start = next((s for s in house.starts if s.room == room and all(
        abs(a - b) <= _POSE_TOL for a, b in zip((s.x, s.y, s.yaw), pose, strict=True))),
        StartPose(pose[0], pose[1], pose[2], room))
    want = category_text(query)
    synset = next((o.synset for o in house.objects if category_text(o.category) == want), "")
    return Episode(
        id=str(x["episode_id"]), query=query, synset=synset,
        targets=tuple(str(t) for t in x["targets"]),
        target_rooms=tuple(str(t) for t in x["target_rooms"]), start=start,
        hidden=bool(x.get("hidden", False)),
        shortest_path=float(shortest) if isinstance(shortest, (int, float)) else math.inf,
        description=str(x.get("description", "")))


def _known(cls: type, values: Any, skip: tuple[str, ...] = ()) -> dict[str, Any]:
    """The fields of dataclass ``cls`` that ``values`` (a dict) gives; lists as tuples."""
    if not isinstance(values, dict):
        raise TypeError(f"{cls.__name__}: not an object")
    names = {f.name for f in fields(cls)} - set(skip)
    return {k: tuple(v) if isinstance(v, list) else v for k, v in values.items()
            if k in names}


def _options(x: dict[str, Any]) -> ClosedLoopOptions:
    """The closed-loop options of the opening record's ``extra`` ``x``."""
    nav = dict(x.get("navigation") or {"mode": "house"})
    mapping = dict(x.get("mapping") or {})
    noise = NoiseProfile(**_known(NoiseProfile, x.get("noise") or {}))
    depth = mapping.get("max_depth", MAX_DEPTH_M)
    opts = ClosedLoopOptions(
        fps=float(x["fps"]), camera=CameraConfig(**_known(CameraConfig, x["camera"])),
        robot=RobotConfig(**_known(RobotConfig, x.get("robot") or {})), noise=noise,
        noise_seed=int(x.get("noise_seed", 0)), every=int(mapping.get("every", 10)),
        classifier=str(mapping.get("classifier", "containment")),
        min_points=mapping.get("min_points"),
        voxel_size=float(mapping.get("voxel_size", 0.05)),
        max_steps=int(x["max_steps"]), frames=x.get("frame_budget"),
        planner_seed=int(x.get("seed", 0)), navigation=str(nav.get("mode", "house")),
        # house navigation uses none of them (ClosedLoopOptions refuses others than the
        # defaults): an older log's missing ones are not the settings of before
        live=LiveNavConfig(**_known(LiveNavConfig, {**_BEFORE, **nav}))
        if str(nav.get("mode", "house")) != "house" else LiveNavConfig(),
        success=str(x.get("success", "observed")),
        turn_render_deg=float(x.get("turn_render_deg", 0.0)),
        render_step_m=float(x.get("render_step_m", 0.0)),
        explore_on=int(x.get("explore_on", 0)))
    # a depth or points per voxel the default rule gives stays the default (so that another
    # noise or image size changes them as it would on the command line); others are kept
    if float(depth) != opts.depth_mapped():
        opts = dataclasses.replace(opts, max_depth=float(depth))
    if opts.min_points == default_min_points(opts.camera.width, opts.camera.height):
        opts = dataclasses.replace(opts, min_points=None)
    return opts
