"""``sgtool run``: one closed-loop object search in PyBullet, logged to MCAP.

The work is done in :mod:`sgtool.recorders.sim.closed_loop`; this module parses options,
picks the house and the episode, checks the output, shows a progress bar of frames and
prints the report.
"""

from __future__ import annotations

import sys
from pathlib import Path

import click

from sgtool.commands.options import (
    PLUGIN_HELP,
    LlmEndpoint,
    house_options,
    list_planners_option,
    llm_endpoint_options,
    llm_log_options,
    run_planner_options,
    success_option,
)
from sgtool.errors import SgtoolError


@click.command("run")
@click.option("--planner", "-p", required=True,
              help="The planner: random, greedy, sbert, sbert-noroom, scout, scout-noroom, "
              "scout-delta0, godhs, esc, bayes-search, moma-llm, unstructured-llm or "
              "godhs-llm. " + PLUGIN_HELP)
@list_planners_option()
@house_options(
    seed_help="Search a generated evaluation house (`sgtool scenes generate`) of this seed "
    "instead of --house.",
    rooms_help="Room count range of a house generated with --seed.")
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
@click.option("--fps", type=float, default=10.0, show_default=True,
              help="Frames per second of log time (the robot drives 0.5 m/s, turns 90 deg/s).")
@click.option("--every", type=click.IntRange(min=1), default=10, show_default=True,
              help="Refresh the scene graph every K frames (and always at every action).")
@click.option("--classifier", type=click.Choice(["containment", "frequency", "none"]),
              default="containment", show_default=True,
              help="Room categories from contents: the distilled containment model, the "
              "naive-Bayes frequency model of the training knowledge, or none.")
@click.option("--min-points", type=click.IntRange(min=1), default=None,
              help="Points an instance needs in one frame to count as seen. Default: "
              "MoMa-LLM's 50 at 320x240 scaled by the image size.")
@click.option("--navigation", type=click.Choice(["live", "house"]), default="live",
              show_default=True,
              help="live: the robot plans every motion on its own map (unknown space is not "
              "driven through; a goal the map cannot reach fails with the reason); house: "
              "the simulator plans on the house's ground truth (the privileged behaviour "
              "before, for comparison).")
@click.option("--optimistic", type=float, default=0.25, show_default=True, metavar="M",
              help="live navigation: how far (m) past known free floor a path may run into "
              "unknown space (at frontiers).")
@click.option("--noise", default="none", show_default=True,
              help="Sensor faults, as `sgtool record --noise` (none, mild, strong, overrides).")
@click.option("-O", "--planner-option", "planner_option", multiple=True,
              metavar="P.KEY=VALUE",
              help="Planner option, e.g. -O scout.delta=0.2 or -O moma-llm.model=gpt-4o-mini "
              "(repeatable; --list-planners lists them). The bare KEY=VALUE of before still "
              "sets the planner's option, with a note that it is deprecated.")
@llm_endpoint_options("LLM planners")
@success_option()
@click.option("--planner-seed", type=click.IntRange(min=0), default=0, show_default=True,
              help="Seed of the planner's randomness (random planner, tie-breaks).")
@llm_log_options(
    transcript_help="moma-llm: append every LLM exchange to this JSONL transcript (replay it "
    "later with --llm-replay).")
@click.option("-o", "--output", required=True, type=click.Path(dir_okay=False),
              help="The episode log to write (OUT.mcap).")
@click.option("--force", is_flag=True, help="Overwrite the output log.")
@click.option("--quiet", is_flag=True, help="No progress bar, no report.")
@click.option("--rerun", "rerun_to", default=None, metavar="spawn|connect[:URL]|serve[:PORT]",
              help="Stream every decision (scene graph, robot, action) to Rerun while the "
              "episode runs: spawn a viewer, connect to one, or serve a web viewer (headless "
              "machines; waits for Ctrl-C at the end).")
def command(planner: str, house_path: str | None, seed: int | None, rooms: str,
            query: str | None, episode: int | None, max_steps: int, frames: int | None,
            frames_per_room: int | None,
            resolution: str, fps: float, every: int, classifier: str, min_points: int | None,
            navigation: str, optimistic: float, noise: str, planner_option: tuple[str, ...],
            planner_seed: int, llm_replay: str | None, llm_transcript: str | None, output: str,
            force: bool, quiet: bool, success: str = "observed",
            llm_base_url: str | None = None, llm_model: str | None = None,
            llm_api_key: str | None = None, llm_timeout: float | None = None,
            rerun_to: str | None = None) -> None:
    """Search a house for an object in closed loop: PyBullet renders the camera, the scene
    graph is built live from the frames (the same refresh schedule as `sgtool replay`:
    every K frames and at every action), the planner chooses an action on it, the
    simulator's skills execute it (navigate, explore = go there and look around, open /
    close = go there and open / close), and the outcome goes back to the planner.

    The episode starts with a look around; it succeeds as soon as the scene graph holds an
    object of the query category (as in the symbolic benchmark, no done() needed; with
    `--success done` the planner must then call done() on it), and fails on done(), after
    --max-steps steps or when the --frames budget is spent.

    Everything goes into one log: sensors, instance tables, the derived map layers and
    scene graphs, every action (outcome, reason, distance, decision time, the graph it was
    decided on), the LLM exchanges of moma-llm and the episode's figures. `sgtool view`
    shows it, `sgtool replay OUT.mcap` rebuilds the very same scene graphs, `sgtool eval
    OUT.mcap` recomputes SR, SPL and steps. The same inputs give the same log except the
    measured decision times (and LLM latencies).

    Example: `sgtool run --planner scout --query bowl -o bowl.mcap`.
    """
    from sgtool.commands.options import house_from_options, parse_resolution, with_starts
    from sgtool.recorders.sim import CameraConfig, parse_noise
    from sgtool.recorders.sim.closed_loop import ClosedLoopOptions, pick_episode, run_episode
    from sgtool.recorders.sim.frame_budget import frame_budget
    from sgtool.recorders.sim.live_skills import LiveNavConfig

    out = Path(output)
    if out.suffix != ".mcap":
        raise SgtoolError(f"-o {out}: the output is an MCAP log; name it *.mcap")
    if out.exists() and not force:
        raise SgtoolError(f"{out} exists; not overwriting it (use --force)")
    if out.is_dir():
        raise SgtoolError(f"-o {out} is a folder; name the log file")
    if not out.parent.exists():
        raise SgtoolError(f"-o {out}: folder {out.parent} does not exist")
    frame_budget(frames, frames_per_room, 1)  # both given: one line, before the house is built
    if query is not None and episode is not None:
        raise SgtoolError("give either --query or --episode, not both")
    if not 0.1 <= fps <= 1000:
        raise SgtoolError(f"--fps {fps}: must be 0.1..1000")
    from sgtool.planning.registry import PLANNER_NAMES, check_planner_name, is_llm_planner

    name = planner.strip()
    name = name.lower() if name.lower() in PLANNER_NAMES else name
    check_planner_name(name)
    options = run_planner_options(planner_option, name)
    endpoint = LlmEndpoint(llm_base_url, llm_model, llm_api_key, llm_timeout)
    if endpoint.given() and not is_llm_planner(name):
        raise SgtoolError("--llm-base-url, --llm-model, --llm-api-key and --llm-timeout are "
                          "for an LLM planner (moma-llm, unstructured-llm, godhs-llm)")
    for k, v in endpoint.given().items():
        options.setdefault(k, v)
    if (llm_replay or llm_transcript) and not is_llm_planner(name):
        raise SgtoolError("--llm-replay and --llm-transcript are for --planner moma-llm "
                          "(or another LLM planner)")
    if llm_replay:
        if not Path(llm_replay).is_file():
            raise SgtoolError(f"--llm-replay {llm_replay}: no such file")
        options["replay"] = llm_replay
    if llm_transcript:
        options["transcript"] = llm_transcript
    width, height = parse_resolution(resolution)
    camera = CameraConfig(width=width, height=height)
    house, house_id = house_from_options(house_path, seed, rooms)
    house = with_starts(house, house_path or house_id)  # a hand-made house: as bench does
    index, ep = pick_episode(house, query=query, index=episode)
    frames = frame_budget(frames, frames_per_room, len(house.rooms))
    opts = ClosedLoopOptions(fps=fps, camera=camera, every=every, classifier=classifier,
                             min_points=min_points, max_steps=max_steps, frames=frames,
                             planner_seed=planner_seed, navigation=navigation, success=success,
                             noise=parse_noise(noise), live=LiveNavConfig(optimistic=optimistic))
    from tqdm import tqdm

    bar = tqdm(total=frames, unit="frame", desc=f"run {name}", file=sys.stderr, leave=False,
               disable=quiet or not sys.stderr.isatty(), dynamic_ncols=True)
    from sgtool.planning.registry import make_planner

    live = None
    if rerun_to is not None:
        from sgtool.analysis.rerun_live import LiveReplay

        live = LiveReplay.start(rerun_to, f"run {house_id} {index} {name} {out}",
                                lambda m: click.echo(m, err=True))
    try:
        report = run_episode(house, ep, make_planner(name, **options), out, opts,
                             house_id=house_id, episode_index=index, overwrite=force,
                             progress=bar, on_decision=live.decision if live else None)
    finally:
        bar.close()
    if not quiet:
        for line in report.lines():
            click.echo(line)
    if live is not None:  # after the report: serve keeps the recording up until Ctrl-C
        live.finish(lambda m: click.echo(m, err=True))
