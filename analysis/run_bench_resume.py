"""Whether an episode log already in a ``run-bench`` folder may stand for a task: it must
have been run with the task's settings (episode, planner options, steps, frames,
resolution, which ticks are frames, navigation, noise and its seed, seed, success rule, room
classifier, depth mapped, graph refreshes, voxel size and points, how far an explore goes
on) on the same house.
A log without the frame settings (``render_step_m``, ``turn_render_deg``: older code
rendered other ticks) is not reused.

The house is compared in canonical form: the spec the log carries (its ``house.json``
attachment) is parsed as any house file is and its canonical JSON compared with that of
the house to run, so a log written by older code (another key order, a 1.x attachment)
still resumes when the house is the same. A mismatch is one :class:`ResumeError` line
naming the log and what differs.
"""

from __future__ import annotations

import dataclasses
import json
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from sgtool.datasets.episodes import Episode
from sgtool.errors import SgtoolError, SpecError
from sgtool.house.spec import HouseSpec
from sgtool.mapping.voxels import VoxelConfig
from sgtool.recorders.sim.closed_loop import ClosedLoopOptions
from sgtool.recorders.sim.episode_extras import recorded_options
from sgtool.recorders.sim.noise import NoiseProfile, parse_noise
from sgtool.scenegraph.build_options import MAX_DEPTH_M, ResolvedOptions, default_min_points

_FIX = ("give a fresh -o folder (out_dir=), --force to run every episode again (from "
        "Python: a fresh out_dir), or delete the log to run the episode again")


class ResumeError(SgtoolError):
    """An episode log of the output folder was run with other settings or another house:
    :attr:`problem` says what differs, the message adds what to do."""

    problem: str = ""


def _refused(problem: str, fix: str) -> ResumeError:
    e = ResumeError(f"{problem}; {fix}")
    e.problem = problem
    return e


def episode_identity(ep: Episode) -> list[Any]:
    """What tells an episode from another drawn under the same id (the draw depends on how
    many episodes a house gets): id, query, targets, their rooms, the start room and pose
    (as :func:`logged_settings` reads them from a log)."""
    return [ep.id, ep.query, list(ep.targets), list(ep.target_rooms), ep.start.room,
            [round(float(v), 4) for v in (ep.start.x, ep.start.y, ep.start.yaw)]]


def task_settings(opts: ClosedLoopOptions, noise: str, episode: list[str] | None,
                  planner_options: Mapping[str, Any] | None = None) -> dict[str, Any]:
    """The settings a task's log must have been run with (as :func:`logged_settings`)."""
    profile = parse_noise(noise)
    ran = dataclasses.replace(opts, noise=profile)
    return {"episode": episode,
            "planner_options": recorded_options(planner_options or {}),
            "max_steps": opts.max_steps, "frame_budget": opts.frames,
            "size": [opts.camera.width, opts.camera.height],
            "render_step_m": float(opts.render_step_m),
            "turn_render_deg": float(opts.turn_render_deg),
            "navigation": opts.navigation, "noise": _faults(profile.to_dict()),
            "noise_seed": opts.noise_seed,
            "drift_model": profile.drift_model,
            "seed": opts.planner_seed, "episode_seeds": True, "success": opts.success,
            "classifier": opts.classifier, "explore_on": opts.explore_on,
            "max_depth": ran.depth_mapped(),
            **_map_settings(ran.mapping()),
            "look_in": float(opts.live.look_in) if opts.navigation == "live" else None,
            "look_in_beyond": (_beyond(opts.live.look_in, opts.live.look_in_beyond)
                               if opts.navigation == "live" else None),
            "peek": bool(opts.live.peek) if opts.navigation == "live" else None,
            "sight_lines": (bool(opts.live.sight_lines) if opts.navigation == "live"
                            else None),
            "explore_through": (float(opts.live.explore_through)
                                if opts.navigation == "live" else None)}


def _map_settings(m: ResolvedOptions) -> dict[str, Any]:
    """The mapping settings a log must share: refreshes, voxel size, points per voxel,
    whether mixed depth pixels were left out."""
    return {"every": int(m.every), "voxel_size": float(m.voxel_size),
            "min_points": int(m.min_points), "mixed_pixels": VoxelConfig().mixed_pixels}


def _beyond(look_in: float, beyond: float) -> float | None:
    """The look-in angle as a setting: none while looking in is off (it changes nothing)."""
    return float(beyond) if float(look_in) > 0.0 else None


def logged_settings(path: Path) -> tuple[dict[str, Any], str | None]:
    """The settings an episode log was run with, and the house spec text it carries."""
    from sgtool.log.reader import LogReader
    from sgtool.log.records import Episode as LoggedEpisode

    with LogReader(path) as r:
        started = next((e for _, e in r.records(LoggedEpisode) if e.status == "started"),
                       None)
        house = r.house_json()
    x = dict(started.extras) if started is not None else {}
    cam = x.get("camera") or {}
    nav = x.get("navigation") or {}
    live = nav.get("mode") == "live"
    ep = None
    if started is not None:
        pose = x.get("start_pose") or [None] * 3
        ep = [x.get("episode_id"), started.query, list(x.get("targets") or []),
              list(x.get("target_rooms") or []), x.get("start_room"),
              [None if v is None else round(float(v), 4) for v in pose]]
    return ({"episode": ep,
             # logs from before the options were recorded: the planner's defaults
             "planner_options": x.get("planner_options", {}),
             "max_steps": x.get("max_steps"),
             "frame_budget": x.get("frame_budget"),
             "size": [cam.get("width"), cam.get("height")],
             "render_step_m": x.get("render_step_m"),
             "turn_render_deg": x.get("turn_render_deg"),
             "navigation": nav.get("mode", "house"),
             # a fault added since (flying) was off in logs that do not name it
             "noise": with_new_faults(x.get("noise")), "noise_seed": x.get("noise_seed", 0),
             # logs from before drift was a random walk in the distance: model 1
             "drift_model": x.get("drift_model", 1) if _drifts(x.get("noise")) else None,
             "seed": x.get("seed"),
             # logs from before each episode drew its planner seed: all drew the run's
             "episode_seeds": "planner_seed" in x,
             "success": x.get("success", "observed"),
             # logs from before the default changed recorded no other classifier
             "classifier": (x.get("mapping") or {}).get("classifier", "containment"),
             # the depth the live map kept (recorded when not the default)
             "max_depth": float((x.get("mapping") or {}).get("max_depth", MAX_DEPTH_M)),
             # how often the graph was refreshed and what its voxels kept (logs from
             # before the mapping was recorded: the defaults)
             "every": int((x.get("mapping") or {}).get("every", 10)),
             "voxel_size": float((x.get("mapping") or {}).get("voxel_size", 0.05)),
             "min_points": int((x.get("mapping") or {}).get("min_points") or default_min_points(
                 int(cam.get("width") or 0) or 160, int(cam.get("height") or 0) or 120)),
             # logs from before the live map left mixed depth pixels out: it kept them
             "mixed_pixels": bool((x.get("mapping") or {}).get("mixed_pixels", False)),
             # logs from before explores went on: an explore ended where it was sent
             "explore_on": x.get("explore_on", 0),
             # logs from before the robot looked into what it opened: it stayed there
             "look_in": float(nav.get("look_in", 0.0)) if live else None,
             # logs from before looking in from the side only: after every open
             "look_in_beyond": (_beyond(nav.get("look_in", 0.0), nav.get("look_in_beyond", 0.0))
                                if live else None),
             # logs from before the head tilted into containers: it never did
             "peek": bool(nav.get("peek", False)) if live else None,
             # logs from before the sight lines: every unknown bearing was turned to
             "sight_lines": bool(nav.get("sight_lines", False)) if live else None,
             # logs from before explores went through: they stopped at the frontier
             "explore_through": float(nav.get("explore_through", 0.0)) if live else None},
            house)


def same_house(logged: str | None, spec: HouseSpec) -> bool:
    """Whether the house text a log carries is ``spec`` (compared in canonical form)."""
    if logged is None:
        return False
    want = spec.to_json()
    if logged == want:  # what this code attaches: no parsing needed
        return True
    from sgtool.house.io import load_house

    try:
        return load_house(json.loads(logged)).to_json() == want
    except (SpecError, ValueError, RecursionError):
        return False


# the settings by their names in messages
_LABELS = {"episode": "episode", "planner_options": "planner options (-O)",
           "max_steps": "max steps", "frame_budget": "frame budget",
           "size": "resolution", "render_step_m": "render step (m)",
           "turn_render_deg": "turn render angle (deg)", "navigation": "navigation",
           "noise": "noise", "noise_seed": "noise seed",
           "drift_model": "pose drift model (1: per frame, sgtool before 992f26a, or a log "
                          "of 992f26a that did not record it; 2: per distance)",
           "seed": "seed",
           "episode_seeds": "planner seed per episode", "success": "success rule",
           "classifier": "room classifier", "explore_on": "explore on (frontiers)",
           "max_depth": "depth mapped (m)", "every": "graph refresh (--every frames)",
           "voxel_size": "voxel size (m)", "min_points": "points per voxel",
           "mixed_pixels": "mixed depth pixels left out",
           "look_in": "look in (m)",
           "look_in_beyond": "look in beyond (deg)", "peek": "peek into containers",
           "sight_lines": "sight lines", "explore_through": "explore through (m)"}


def settings_differences(logged: dict[str, Any], want: dict[str, Any]) -> list[str]:
    """``NAME: X in the log, Y now`` for every setting that differs (planner options
    without any, ``{}``, are the planner's defaults: an option given at its default is not
    kept, so it reads so)."""
    def text(k: str, v: Any) -> str:
        return "{} (the defaults)" if k == "planner_options" and v == {} else json.dumps(v)

    return [f"{_LABELS.get(k, k)}: {text(k, logged.get(k))} in the log, {text(k, v)} now"
            for k, v in want.items() if logged.get(k) != v]


def check_resumable(path: Path, want: dict[str, Any], spec: HouseSpec, house: str,
                    planner: str = "") -> None:
    """Raise :class:`ResumeError` unless the log ``path`` was run with the settings ``want``
    (:func:`task_settings`) on the house ``spec`` (``house`` names it: a file, or a
    generated house's id); ``planner``'s options compared as it takes them (an option at
    its default is no other option: :func:`~sgtool.planning.registry.effective_options`)."""
    from sgtool.planning.registry import effective_options

    settings, logged_house = logged_settings(path)
    if settings["episode"] is None:  # no episode started in it: a recovered fragment
        # (not a ResumeError: no option given again mends it, --report-only included)
        raise SgtoolError(f"{path} holds no closed-loop episode (no started episode record: "
                          "a log recovered from a killed run, or not one run-bench wrote); "
                          "delete the log to run the episode again")
    if planner:
        want = {**want, "planner_options": effective_options(planner,
                                                             want["planner_options"])}
        settings["planner_options"] = effective_options(planner,
                                                        settings["planner_options"] or {})
    diff = settings_differences(settings, want)
    if diff:
        depth = settings.get("max_depth")
        fix = (f"--max-depth {depth:g} maps as that log did, or {_FIX}"
               if settings.get("max_depth") != want.get("max_depth") and depth is not None
               and settings.get("noise") == want.get("noise") else _FIX)
        raise _refused(f"{path} was run with other settings ({'; '.join(diff)})", fix)
    if not same_house(logged_house, spec):
        raise _refused(f"{path} was run on another house: the house of {house} changed "
                       "since", _FIX)


def with_new_faults(noise: Any) -> Any:
    """A log's recorded noise profile with the faults it does not name at 0 (off): the
    faults :class:`~sgtool.recorders.sim.noise.NoiseProfile` gained after it was written;
    its faults only (:func:`_faults`)."""
    if not isinstance(noise, dict):
        return noise
    return _faults({**NoiseProfile().to_dict(), **noise})


def _drifts(noise: Any) -> bool:
    """Whether a log's recorded noise profile drifts its poses."""
    return isinstance(noise, dict) and bool(noise.get("drift_xy") or noise.get("drift_yaw"))


def _faults(noise: dict[str, Any]) -> dict[str, Any]:
    """A profile's faults without its name: a log is taken up by faults, however the
    profile was spelled when it ran (an older spelling of the same overrides)."""
    return {k: v for k, v in noise.items() if k != "name"}
