"""What the Episode records of a closed-loop episode carry in ``extra``
(:func:`sgtool.recorders.sim.closed_loop.run_episode`): the settings it ran with, read by
``sgtool replay``, ``eval``, ``golden`` and run-bench's resume, and the options its planner
was built with.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import asdict
from typing import Any

from sgtool.canonical import canonical_float
from sgtool.datasets.episodes import Episode
from sgtool.planning.episode import planner_seed
from sgtool.recorders.sim.closed_loop_options import ClosedLoopOptions
from sgtool.recorders.sim.simulation import Simulation
from sgtool.redact import recorded_options  # noqa: F401 (re-exported)
from sgtool.scenegraph.build_options import ResolvedOptions, mapping_record
from sgtool.scenegraph.graph import SceneGraph


def options_record(planner: object, given: Mapping[str, Any] | None) -> dict[str, Any]:
    """``{"planner_options": ...}`` for the episode records (empty: none): the options
    ``given`` (None: those :func:`sgtool.planning.registry.make_planner` built ``planner``
    with), as :func:`sgtool.redact.recorded_options` keeps them; and ``"planner_object":
    "module:QualName"`` for a user's own planner object (neither made by ``make_planner``
    nor sgtool's): the log's planner name is then its display name, from which no planner
    is rebuilt (``golden`` pins no decisions of it, ``run --again`` asks for ``-p``)."""
    from sgtool.planning.timing import TimedPlanner

    options = getattr(planner, "given_options", None) if given is None else given
    out: dict[str, Any] = {"planner_options": recorded_options(options)} \
        if isinstance(options, Mapping) and options else {}
    # make_planner's planners are rebuilt by name: a plug-in's wrapper, a built-in with its
    # options recorded; a TimedPlanner of one's own is its planner, and a built-in made
    # without make_planner (options unknown) is one's own object too
    obj = planner.inner if isinstance(planner, TimedPlanner) and not planner.plugin \
        else planner
    cls = type(obj)
    made = isinstance(obj, TimedPlanner) or (
        cls.__module__.startswith("sgtool.")
        and isinstance(getattr(planner, "given_options", None), Mapping))
    if not made:
        out["planner_object"] = f"{cls.__module__}:{cls.__qualname__}"
    return out


def started_extra(opts: ClosedLoopOptions, sim: Simulation, mapping: ResolvedOptions,
                  episode: Episode, index: int) -> dict[str, Any]:
    """The opening record's ``extra``: the episode, seeds, budgets, camera, robot,
    navigation, noise and frame settings, the mapping, the success rule."""
    k = sim.intrinsics
    return {
        "mapping": mapping_record(mapping),
        "episode": int(index), "episode_id": episode.id,
        "targets": list(episode.targets), "target_rooms": list(episode.target_rooms),
        "hidden": episode.hidden, "description": episode.description,
        "seed": opts.planner_seed,
        "planner_seed": planner_seed(opts.planner_seed, sim.spec.seed, index),
        "max_steps": opts.max_steps, "frame_budget": opts.frames, "fps": opts.fps,
        "start_pose": [round(v, 6) for v in sim.base],
        "start_room": episode.start.room,
        "camera": asdict(opts.camera),
        "intrinsics": {"width": k.width, "height": k.height, "fx": k.fx, "fy": k.fy,
                       "cx": k.cx, "cy": k.cy},
        "robot": asdict(opts.robot),
        "navigation": {"mode": opts.navigation, **opts.live.to_dict()},
        "noise": opts.noise.to_dict(), "noise_seed": opts.noise_seed,
        **({"drift_model": opts.noise.drift_model} if opts.noise.drift_model else {}),
        "turn_render_deg": opts.turn_render_deg, "render_step_m": opts.render_step_m,
        "explore_on": opts.explore_on,
        **success_rule(opts),
    }


def success_rule(opts: ClosedLoopOptions) -> dict[str, str]:
    """``{"success": "done"}`` under MoMa-LLM's rule; nothing under the default (logs of
    the default rule stay as they were)."""
    return {} if opts.success == "observed" else {"success": opts.success}


def shown_distances(view: SceneGraph, logged: SceneGraph) -> dict[str, Any]:
    """``{"view_distances": ...}`` when the planner was shown ``view`` with other distances
    than the ``logged`` graph's (the Action record's field: an offline replay shows a planner
    the same graph); empty when they are the same."""
    if view.distances == {k: canonical_float(v) for k, v in logged.distances.items()}:
        return {}
    return {"view_distances": dict(view.distances)}


def withheld_extra(withheld: Mapping[str, int], forgot_bumps: int) -> dict[str, Any]:
    """``{"withheld": {reason: count}}``: goals not offered to the planner, summed over
    its decisions (live navigation; nothing when none was withheld), and
    ``{"bumps_forgotten": n}`` when the robot's bump marks were dropped n times because
    they walled off every goal or withheld goals the map without them reaches."""
    out: dict[str, Any] = {}
    if withheld:
        out["withheld"] = dict(sorted(withheld.items()))
    if forgot_bumps:
        out["bumps_forgotten"] = forgot_bumps
    return out
