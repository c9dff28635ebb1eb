"""``sgtool run``: one closed-loop object search in PyBullet, logged to MCAP.

The work is done in :mod:`sgtool.recorders.sim.closed_loop` (through
:func:`sgtool.analysis.sim_session.run_search`: progress bar, live viewer, report); this
module parses the options into :class:`RunArgs`, checks the output and the inputs (planner,
house, episode) and hands a :class:`~sgtool.analysis.sim_session.SearchRequest` over.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace
from pathlib import Path
from typing import TYPE_CHECKING, Any

import click
from click.core import ParameterSource

from sgtool.commands.llm_replay_options import replay_sampling_note
from sgtool.commands.options import (
    FINITE_FLOAT,
    PLUGIN_HELP_ONE,
    SEED,
    LlmEndpoint,
    PathParam,
    check_log_output,
    explore_on_option,
    explore_through_option,
    house_options,
    list_planners_option,
    live_max_depth_option,
    llm_endpoint_options,
    llm_log_options,
    look_in_beyond_option,
    look_in_option,
    peek_option,
    render_turn_option,
    run_planner_options,
    sight_lines_option,
    success_option,
)
from sgtool.errors import SgtoolError

if TYPE_CHECKING:
    from sgtool.analysis.logged_run import LoggedRun
    from sgtool.analysis.sim_session import SearchRequest
    from sgtool.recorders.sim.closed_loop import ClosedLoopOptions


@click.command("run")
@click.option("--planner", "-p", default=None, is_eager=True,
              help="The planner: a built-in (--list-planners shows them all with their "
              "options: scout, voi, bayes-search, moma-llm, ...). " + PLUGIN_HELP_ONE +
              " Required, unless --again names a log (then: the log's planner).")
@list_planners_option("--planner")
@click.option("--again", type=PathParam(exists=True, dir_okay=False), default=None,
              metavar="LOG",
              help="Run the episode of this closed-loop log again (a log of `sgtool run` or "
              "of a `run-bench` folder, whose episodes `--episode K` does not pick): its "
              "house, start, query, planner with its -O options and every setting it "
              "recorded. Options given beside it change that setting only (--planner voi "
              "to compare a planner on the episode, --rerun spawn to watch it, --noise "
              "strong); --house, --seed, --rooms, --query and --episode pick another "
              "episode and are refused. A log of older code: notes name what runs "
              "otherwise today.")
@house_options(
    seed_help="Search a generated evaluation house (`sgtool scenes generate`) of this seed "
    "instead of --house.",
    rooms_help="Room count range of a house generated with --seed (corridors included, "
    "4..30).")
@click.option("--query", default=None, metavar="CATEGORY",
              help="The object category to find (a small object of the house, e.g. 'bowl'); "
              "the start pose is that of its episode in `sgtool scenes episodes`.")
@click.option("--episode", type=click.IntRange(min=0), default=None, metavar="K",
              help="Run the K-th episode of `sgtool scenes episodes HOUSE` (query and start "
              "pose). Default: 0, unless --query is given.")
@click.option("--max-steps", type=click.IntRange(min=1), default=50, show_default=True,
              help="High-level planner steps before the episode fails (SymSearch's N_max).")
@click.option("--frames", type=click.IntRange(min=1), default=None,
              help="Frame budget: the episode fails when it is spent. Default: none.")
@click.option("--frames-per-room", type=click.IntRange(min=1), default=None, metavar="N",
              help="Frame budget of N x the house's room count (excludes --frames).")
@click.option("--resolution", default="320x240", show_default=True,
              help="Camera image size WIDTHxHEIGHT.")
@click.option("--fps", type=FINITE_FLOAT, default=10.0, show_default=True,
              help="Simulator ticks per second of log time (the robot drives 0.5 m/s, turns "
              "90 deg/s); a tick becomes a frame once the camera turned --render-turn "
              "degrees or drove 0.25 m, so the log holds fewer frames than ticks.")
@click.option("--every", type=click.IntRange(min=1), default=10, show_default=True,
              help="Refresh the scene graph every K frames (and always at every action).")
@click.option("--classifier", type=click.Choice(["containment", "frequency", "none"]),
              default="frequency", show_default=True,
              help="Room categories from contents: the naive-Bayes frequency model of the "
              "training knowledge (the containment model for a room none of whose "
              "objects it knows), the distilled containment model alone, or none.")
@click.option("--min-points", type=click.IntRange(min=1), default=None,
              help="Points an instance needs in one frame to count as seen. Default: "
              "MoMa-LLM's 50 at 320x240 scaled by the image size.")
@click.option("--navigation", type=click.Choice(["live", "house"]), default="live",
              show_default=True,
              help="live: the robot plans every motion on its own map (unknown space is not "
              "driven through; a goal the map cannot reach fails with the reason); house: "
              "the simulator plans on the house's ground truth (the privileged behaviour "
              "before, for comparison).")
@explore_on_option()
@look_in_option()
@look_in_beyond_option()
@peek_option()
@sight_lines_option()
@explore_through_option()
@render_turn_option()
@live_max_depth_option()
@click.option("--optimistic", type=FINITE_FLOAT, default=0.25, show_default=True, metavar="M",
              help="live navigation: how far (m) past known free floor a path may run into "
              "unknown space (at frontiers).")
@click.option("--noise", default="none", show_default=True,
              help="Sensor faults, as `sgtool record --noise` (none, mild, strong, overrides).")
@click.option("--noise-seed", type=SEED, default=0, show_default=True,
              help="Seed of the sensor faults (--noise).")
@click.option("-O", "--planner-option", "planner_option", multiple=True,
              metavar="P.KEY=VALUE",
              help="Planner option, e.g. -O scout.delta=0.2 or -O moma-llm.model=gpt-4o-mini "
              "(repeatable; --list-planners lists them). The bare KEY=VALUE of before still "
              "sets the planner's option, with a note that it is deprecated.")
@llm_endpoint_options("LLM planners")
@success_option()
@click.option("--planner-seed", type=SEED, default=0,
              show_default=True,
              help="Seed of the planner's randomness (the random planner): the episode's "
                   "planner draws from a seed made of it, the house seed and the episode "
                   "index, as in `sgtool bench`.")
@llm_log_options(
    transcript_help="moma-llm: write every LLM exchange to this JSONL transcript, emptied "
    "when the run starts (an interrupted run puts the previous one back; replay "
    "it later with --llm-replay).")
@click.option("-o", "--output", required=True, type=PathParam(dir_okay=False),
              help="The episode log to write (OUT.mcap).")
@click.option("--force", is_flag=True, help="Overwrite the output log.")
@click.option("--quiet", is_flag=True, help="No progress bar, no report.")
@click.option("--rerun", "rerun_to", default=None,
              metavar="spawn|connect[:URL]|serve[:WEB_PORT[:GRPC_PORT]]",
              help="Stream every decision (scene graph, robot, action) to Rerun while the "
              "episode runs: spawn a viewer, connect to one, or serve a web viewer (headless "
              "machines; waits for Ctrl-C at the end).")
def command(**given: Any) -> None:
    """Search a house for an object in closed loop: PyBullet renders the camera, the scene
    graph is built live from the frames (the same refresh schedule as `sgtool replay`:
    every K frames and at every action), the planner chooses an action on it, the
    simulator's skills execute it (navigate, explore = go there and look around, open /
    close = go there and open / close), and the outcome goes back to the planner.

    The episode starts with a look around; it succeeds as soon as the scene graph holds an
    object of the query category (as in the symbolic benchmark, no done() needed; with
    `--success done` the planner must then call done() on it), and fails on done(), after
    --max-steps steps or when the --frames budget is spent. (When the graph offers
    nothing, or the planner gives up after every goal on offer failed, the robot explores
    its map's frontiers on its own, logged as fallback actions, until the graph offers
    something new.)

    Everything goes into one log: sensors, instance tables, the derived map layers and
    scene graphs, every action (outcome, reason, distance, decision time, the graph it was
    decided on), the LLM exchanges of moma-llm and the episode's figures. `sgtool view`
    shows it, `sgtool replay OUT.mcap` rebuilds the very same scene graphs, `sgtool eval
    OUT.mcap` recomputes SR, SPL and steps. The same inputs give the same log except the
    measured decision times (and LLM latencies).

    Example: `sgtool run --planner scout --query bowl -o bowl.mcap`.
    """
    from sgtool.analysis.sim_session import run_search

    args = RunArgs(**given)
    if args.again is None and args.planner is None:
        raise click.UsageError("Missing option '-p' / '--planner' (or --again LOG).")
    out = check_log_output(args.output, force=args.force,
                           inputs=(args.house_path, args.noise, args.again))
    ctx = click.get_current_context()
    given_here = frozenset(k for k in given if ctx.get_parameter_source(k) in (
        ParameterSource.COMMANDLINE, ParameterSource.ENVIRONMENT))
    request = _request(args, out) if args.again is None else \
        again_request(args, given_here, out, note=lambda m: click.echo(m, err=True))
    run_search(request, show=click.echo, note=lambda m: click.echo(m, err=True))


@dataclass(frozen=True)
class RunArgs:
    """The options of `sgtool run` as given (the click parameters, by name)."""

    planner: str | None
    house_path: str | None
    seed: int | None
    rooms: str
    preset: str
    query: str | None
    episode: int | None
    max_steps: int
    frames: int | None
    frames_per_room: int | None
    resolution: str
    fps: float
    every: int
    classifier: str
    min_points: int | None
    navigation: str
    optimistic: float
    noise: str
    planner_option: tuple[str, ...]
    planner_seed: int
    llm_replay: str | None
    llm_transcript: str | None
    output: str
    force: bool
    quiet: bool
    success: str = "observed"
    llm_base_url: str | None = None
    llm_model: str | None = None
    llm_api_key: str | None = None
    llm_timeout: float | None = None
    rerun_to: str | None = None
    explore_on: int = 0
    look_in: float = 1.4
    look_in_beyond: float = 45.0
    peek: bool = True
    sight_lines: bool = False
    explore_through: float = 0.0
    render_turn: float = 20.0
    max_depth: float | None = None
    noise_seed: int = 0
    again: str | None = None


def _planner(args: RunArgs) -> tuple[str, dict[str, Any]]:
    """The planner's name and its checked options (-O, the LLM endpoint, --llm-replay and
    --llm-transcript)."""
    from sgtool.planning.registry import PLANNER_NAMES, check_planner_name, is_llm_planner

    name = (args.planner or "").strip()
    name = name.lower() if name.lower() in PLANNER_NAMES else name
    check_planner_name(name)
    options = run_planner_options(args.planner_option, name)
    endpoint = LlmEndpoint(args.llm_base_url, args.llm_model, args.llm_api_key,
                           args.llm_timeout)
    if endpoint.given() and not is_llm_planner(name):
        raise SgtoolError("--llm-base-url, --llm-model, --llm-api-key and --llm-timeout are "
                          "for an LLM planner (moma-llm, unstructured-llm, godhs-llm)")
    for k, v in endpoint.given().items():
        options.setdefault(k, v)
    if (args.llm_replay or args.llm_transcript) and not is_llm_planner(name):
        raise SgtoolError("--llm-replay and --llm-transcript are for --planner moma-llm "
                          "(or another LLM planner)")
    if args.llm_replay:
        if not Path(args.llm_replay).is_file():
            raise SgtoolError(f"--llm-replay {args.llm_replay}: no such file")
        options["replay"] = args.llm_replay
    if note := replay_sampling_note(name, options):
        click.echo(note, err=True)
    if args.llm_transcript:
        if args.llm_replay and Path(args.llm_replay).resolve() == \
                Path(args.llm_transcript).resolve():
            raise SgtoolError(f"--llm-transcript {args.llm_transcript}: it is the "
                              "--llm-replay transcript (a run's transcript is emptied when "
                              "it starts)")
        options["transcript"] = args.llm_transcript
    t, r = options.get("transcript"), options.get("replay")
    if t and Path(str(t)).resolve() == Path(args.output).resolve():
        raise SgtoolError(f"transcript {t}: it is the output log (-o)")
    if t and r and Path(str(t)).resolve() == Path(str(r)).resolve():
        raise SgtoolError(f"transcript {t}: it is the replay transcript (a run's transcript "
                          "is emptied when it starts)")
    return name, options


def _request(args: RunArgs, out: Path) -> SearchRequest:
    """The input check: options, planner, house and episode, in the order a user's mistake
    is best reported (before the house is built where possible)."""
    from sgtool.analysis.sim_session import SearchRequest
    from sgtool.commands.options import house_from_options, parse_resolution, with_starts
    from sgtool.recorders.sim import CameraConfig, parse_noise
    from sgtool.recorders.sim.closed_loop import ClosedLoopOptions, pick_episode
    from sgtool.recorders.sim.frame_budget import frame_budget
    from sgtool.recorders.sim.live_skills import LiveNavConfig

    frame_budget(args.frames, args.frames_per_room, 1)  # both given: before the house
    if args.query is not None and args.episode is not None:
        raise SgtoolError("give either --query or --episode, not both")
    from sgtool.recorders.sim.simulation import FPS_RANGE

    if not FPS_RANGE[0] <= args.fps <= FPS_RANGE[1]:
        raise SgtoolError(f"--fps {args.fps}: must be {FPS_RANGE[0]:g}..{FPS_RANGE[1]:g}")
    name, options = _planner(args)
    width, height = parse_resolution(args.resolution)
    house, house_id = house_from_options(args.house_path, args.seed, args.rooms, args.preset)
    house = with_starts(house, args.house_path or house_id)  # a hand-made house: as bench
    index, ep = pick_episode(house, query=args.query, index=args.episode)
    opts = ClosedLoopOptions(
        fps=args.fps, camera=CameraConfig(width=width, height=height), every=args.every,
        classifier=args.classifier, min_points=args.min_points, max_steps=args.max_steps,
        frames=frame_budget(args.frames, args.frames_per_room, len(house.rooms)),
        planner_seed=args.planner_seed, navigation=args.navigation, success=args.success,
        noise=parse_noise(args.noise), noise_seed=args.noise_seed,
        live=LiveNavConfig(optimistic=args.optimistic, look_in=args.look_in,
                           look_in_beyond=args.look_in_beyond, peek=args.peek,
                           sight_lines=args.sight_lines,
                           explore_through=args.explore_through),
        explore_on=args.explore_on, turn_render_deg=args.render_turn,
        max_depth=args.max_depth)
    return SearchRequest(house=house, house_id=house_id, episode_index=index, episode=ep,
                         planner=name, output=out, options=opts, planner_options=options,
                         force=args.force, quiet=args.quiet, rerun_to=args.rerun_to)


# options that pick another episode than the log's
_OTHER_EPISODE = {"house_path": "--house", "seed": "--seed", "rooms": "--rooms",
                  "preset": "--preset", "query": "--query", "episode": "--episode"}
# RunArgs fields given beside --again -> the ClosedLoopOptions field each sets
_SAME_NAME = {"fps": "fps", "every": "every", "classifier": "classifier",
              "min_points": "min_points", "max_steps": "max_steps",
              "navigation": "navigation", "noise_seed": "noise_seed", "success": "success",
              "planner_seed": "planner_seed", "explore_on": "explore_on",
              "render_turn": "turn_render_deg", "max_depth": "max_depth"}
_LIVE = ("optimistic", "look_in", "look_in_beyond", "peek", "sight_lines", "explore_through")


def again_request(args: RunArgs, given: frozenset[str], out: Path,
                  note: Callable[[str], None]) -> SearchRequest:
    """The request of ``--again LOG``: the log's episode and settings
    (:func:`sgtool.analysis.logged_run.logged_run`), each option in ``given`` (the names of
    the options the user gave) changing its own setting."""
    from sgtool.analysis.logged_run import logged_run
    from sgtool.analysis.sim_session import SearchRequest
    from sgtool.recorders.sim.frame_budget import frame_budget

    other = [flag for name, flag in _OTHER_EPISODE.items() if name in given]
    if other:
        raise SgtoolError(f"{', '.join(other)}: --again runs the episode of its log; give "
                          f"{'them' if len(other) > 1 else 'it'} without --again to pick "
                          "another")
    frame_budget(args.frames, args.frames_per_room, 1)  # both given: before the log is read
    assert args.again is not None
    run = logged_run(args.again)
    if run.planner_object and not args.planner:
        raise _own_object(args.again, run.planner, run.planner_object)
    for n in run.notes:
        note(f"note: {args.again} was run by older sgtool with a setting it runs otherwise "
             f"today: {n}")
    name, options = _planner(replace(args, planner=args.planner or run.planner))
    if name == run.planner:  # the log's options, -O given beside changing them; not its
        # transcript, which a run empties when it starts (--llm-transcript names a new one)
        # (an endpoint given beside a replayed log asks it: the log's replay goes)
        drop = {"transcript", *(("replay",) if "base_url" in options else ())}
        logged = {k: v for k, v in run.planner_options.items() if k not in drop}
        options = {**logged, **options}
    return SearchRequest(house=run.house, house_id=run.house_id,
                         episode_index=run.episode_index, episode=run.episode, planner=name,
                         output=out, options=_changed(args, given, run),
                         planner_options=options, force=args.force, quiet=args.quiet,
                         rerun_to=args.rerun_to)


def _own_object(log: str, planner: str, cls: str) -> SgtoolError:
    """The one line for ``--again`` of a log whose planner was a user's object of class
    ``cls`` (``module:QualName``), which no name builds."""
    module, _, qual = cls.partition(":")
    hint = (f"e.g. -p {cls}, with its -O options" if module != "__main__"
            and "<locals>" not in qual else
            f"its class was defined in {'a script' if module == '__main__' else 'a function'}"
            f": put it in a module on PYTHONPATH and give -p MODULE:"
            f"{qual.rsplit('.', 1)[-1]}, with its -O options")
    return SgtoolError(f"{log}: its planner {planner!r} was a Python object ({cls}) given to "
                       f"sgtool.run_closed_loop, which its name does not build; give -p "
                       f"({hint})")


def _changed(args: RunArgs, given: frozenset[str], run: LoggedRun) -> ClosedLoopOptions:
    """The options ``run`` ran with, each option in ``given`` changing its own setting."""
    from sgtool.commands.options import parse_resolution
    from sgtool.recorders.sim import parse_noise
    from sgtool.recorders.sim.frame_budget import frame_budget
    from sgtool.recorders.sim.live_skills import LiveNavConfig

    o = run.options
    changes: dict[str, Any] = {field: getattr(args, name)
                               for name, field in _SAME_NAME.items() if name in given}
    if "resolution" in given:
        width, height = parse_resolution(args.resolution)
        changes["camera"] = replace(o.camera, width=width, height=height)
    if "noise" in given:
        changes["noise"] = parse_noise(args.noise)
    if {"frames", "frames_per_room"} & given:
        changes["frames"] = frame_budget(args.frames, args.frames_per_room,
                                         len(run.house.rooms))
    live = {f: getattr(args, f) for f in _LIVE if f in given}
    if changes.get("navigation", o.navigation) == "house" and o.navigation != "house":
        base, changes["explore_on"] = LiveNavConfig(), changes.get("explore_on", 0)
    else:  # (the robot's own navigation settings do not go to house navigation)
        base = o.live
    if live or base is not o.live:
        changes["live"] = replace(base, **live)
    return replace(o, **changes)
