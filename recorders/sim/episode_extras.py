"""What the Episode records of a closed-loop episode carry in ``extra``
(:func:`sgtool.recorders.sim.closed_loop.run_episode`): the settings it ran with, read by
``sgtool replay``, ``eval``, ``golden`` and run-bench's resume, and the options its planner
was built with.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import asdict
from typing import Any

from sgtool.datasets.episodes import Episode
from sgtool.planning.episode import planner_seed
from sgtool.recorders.sim.closed_loop_options import ClosedLoopOptions
from sgtool.recorders.sim.simulation import Simulation
from sgtool.scenegraph.build_options import ResolvedOptions, mapping_record


def recorded_options(options: Mapping[str, Any]) -> dict[str, Any]:
    """A planner's options as an episode record keeps them: JSON values only (a Python
    object set from Python, an encoder, is left out), keys named like secrets left out
    (:func:`sgtool.redact.is_secret_name`) and URL passwords redacted, sorted."""
    from sgtool.redact import is_secret_name, redact_options

    plain = (str, int, float, bool, type(None))
    return {k: redact_options(v) for k, v in sorted(options.items())
            if not is_secret_name(str(k)) and (isinstance(v, plain) or (
                isinstance(v, list | tuple) and all(isinstance(x, plain) for x in v)))}


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
        "turn_render_deg": opts.turn_render_deg, "render_step_m": opts.render_step_m,
        "explore_on": opts.explore_on,
        **success_rule(opts),
    }


def success_rule(opts: ClosedLoopOptions) -> dict[str, str]:
    """``{"success": "done"}`` under MoMa-LLM's rule; nothing under the default (logs of
    the default rule stay as they were)."""
    return {} if opts.success == "observed" else {"success": opts.success}
