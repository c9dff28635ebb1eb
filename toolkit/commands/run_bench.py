"""``sgtool run-bench``: the closed-loop benchmark (:mod:`sgtool.analysis.closed_loop_bench`)."""

from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path
from typing import TYPE_CHECKING, Any

import click

from sgtool.commands.options import (
    PLANNER_OPTION_HELP,
    PLANNERS_HELP,
    PLUGIN_HELP,
    SEED,
    LlmEndpoint,
    PathParam,
    budget_options,
    executor_options,
    explore_on_option,
    explore_through_option,
    list_planners_option,
    live_max_depth_option,
    llm_endpoint_options,
    look_in_beyond_option,
    look_in_option,
    parse_resolution,
    parse_rooms,
    peek_option,
    planner_names,
    planner_options,
    reference_planner,
    render_turn_option,
    sight_lines_option,
    success_option,
)
from sgtool.datasets.presets import PRESET_NAMES
from sgtool.errors import SgtoolError

if TYPE_CHECKING:
    from sgtool.analysis.closed_loop_bench import ClosedLoopBenchConfig
    from sgtool.analysis.closed_loop_bench_run import RunBenchRequest


@click.command("run-bench")
@click.option("--planners", default=None, metavar="LIST", is_eager=True,
              help=PLANNERS_HELP + PLUGIN_HELP)
@list_planners_option()
@click.option("--houses", type=click.IntRange(min=0), default=None,
              help="Generated evaluation houses (seeds HOUSE_SEED, +1, ...). [default: 5; "
              "with --house: 0, the given houses only]")
@click.option("--house", "house_files", multiple=True, metavar="PATH",
              type=PathParam(path_type=str),
              help="A house spec JSON file or a folder of them (every *.json there is read as "
              "a house; repeatable), checked first. Generated houses join them only when "
              "--houses N is given.")
@click.option("--house-seed", default=0, show_default=True, type=SEED,
              help="Seed of the first house.")
@click.option("--rooms", default="12-16", show_default=True, metavar="MIN-MAX",
              help="Room count range of the generated houses (corridors included, 4..30).")
@click.option("--preset", type=click.Choice(list(PRESET_NAMES)), default="symsearch",
              show_default=True, help="Generator preset of the generated houses.")
@click.option("--episodes", default=6, show_default=True,
              help="Episodes per house: those `sgtool bench --episodes N` draws with the "
              "same N (the draw depends on N: a bench folder for --symbolic needs it).")
@click.option("--noise", "noise", multiple=True, metavar="PROFILE",
              help="Sensor noise profile (none, mild, strong, with overrides, or a .json "
              "file, as `sgtool record --noise`); repeatable: every profile is a run, its "
              "logs in logs/NOISE/ (NOISE: the text given, or a file's profile name). "
              "Default: none.")
@click.option("--noise-seed", type=SEED, default=0, show_default=True,
              help="Seed of the sensor faults (--noise).")
@click.option("--max-steps", default=50, show_default=True,
              help="High-level planner steps per episode.")
@click.option("--frames", type=click.IntRange(min=1), default=None,
              help="Frame budget per episode. Default: none.")
@click.option("--frames-per-room", type=click.IntRange(min=1), default=None, metavar="N",
              help="Frame budget per episode of N x the house's room count (excludes "
              "--frames).")
@click.option("--resolution", default="160x120", show_default=True,
              help="Camera image size WIDTHxHEIGHT (the default maps as 320x240 does, for "
              "less CPU: docs/experiments/issue30-efficiency.md).")
@click.option("--every", type=click.IntRange(min=1), default=10, show_default=True,
              help="Refresh the scene graph every K frames (and at every action).")
@explore_on_option()
@look_in_option()
@look_in_beyond_option()
@peek_option()
@sight_lines_option()
@explore_through_option()
@render_turn_option()
@live_max_depth_option()
@click.option("--navigation", type=click.Choice(["live", "house"]), default="live",
              show_default=True,
              help="live: skills plan on the robot's own map; house: on the ground truth "
              "(privileged, the closed loop's behaviour before live navigation; for "
              "comparison).")
@click.option("-O", "--planner-option", "planner_option", multiple=True, metavar="P.KEY=VALUE",
              help=PLANNER_OPTION_HELP)
@llm_endpoint_options("LLM planners")
@click.option("-o", "--out", "out_dir", default="run-bench", show_default=True,
              type=PathParam(file_okay=False),
              help="Output folder: logs/NOISE/PLANNER/HOUSE/ep-K.mcap, episodes.jsonl, "
              "summary.md/.json, run.md (wall-clock figures), run.json (where and how long "
              "each episode ran), efficiency curves. A run-bench "
              "folder is resumed; another "
              "non-empty folder is refused unless --force.")
@click.option("--force", is_flag=True,
              help="Start afresh: the run is built beside OUT and moved in complete, "
              "replacing what sgtool wrote there (earlier logs included); other files stay.")
@click.option("--report-only", is_flag=True,
              help="Run nothing: the tables of the episodes whose logs are there already, "
              "run as OUT/run-options.json records (the options that decide the run need "
              "not be given again; the report settings --reference, --all-pairs, "
              "--budgets, --symbolic, --with-symbolic and the budgets of AUC-E are this "
              "command's).")
@click.option("--progress/--no-progress", default=None,
              help="Progress bar on stderr (default: when stderr is a terminal).")
@click.option("--reference", default=None, metavar="PLANNER", callback=reference_planner,
              help="Paired comparisons of every other planner against this one on the same "
              "episodes, over houses and per house (SPL ratio, SR and SPL differences with "
              "bootstrap intervals, wins/losses/ties). [default: scout when run, else the "
              "first planner]")
@click.option("--all-pairs", is_flag=True,
              help="Paired comparisons of every pair of planners instead of against "
              "--reference.")
@click.option("--budgets", default=None, metavar="F1,F2,...",
              help="Frames per room of the SR-within-budget tables (e.g. 90,100): a report "
              "setting, so --report-only re-tables a finished run at other budgets. "
              "[default: quarters of the frame budget per room (--frames-per-room, or "
              "--frames over the fewest rooms of a house), else of the most frames per room "
              "an episode used]")
@click.option("--symbolic", "symbolic_dir", default=None, metavar="DIR",
              type=PathParam(path_type=str),
              help="A `sgtool bench` output folder (or its episodes.jsonl): the table adds "
              "Kendall's tau between its planner order and the closed loop's, on the "
              "episodes of the same house, episode and query when there are any.")
@click.option("--with-symbolic", is_flag=True,
              help="Run the symbolic bench (one seed) on the same houses and episodes for "
              "that Kendall tau (seconds to minutes; excludes --symbolic).")
@success_option()
@budget_options()
@executor_options("episodes (one closed-loop run each)")
def command(**given: Any) -> None:
    """Run closed-loop search episodes in PyBullet for every planner on generated and given
    houses (the houses and episodes of `sgtool bench`), under each noise profile: one
    episode log per run (what `sgtool run` writes), then the table of the symbolic bench
    (SR, SPL, steps, AUC-E) with failed skills per episode by reason, and the efficiency
    curves; the wall-clock figures (decision time, frames per second) go to run.md. SPL's
    shortest path ends within reach of the nearest target (as in MoMa-LLM's code) while an
    episode succeeds once the target is seen: a robot that sees it from afar before driving
    that far scores SPL 1, and such episodes tie whatever each planner drove.

    Resumable: an episode whose log exists is read back instead of run again (a log is
    only there once complete). Ctrl-C stops the run and leaves only complete logs (with
    --force: OUT as it was). With
    `-w N` or `--executor ray` the episodes run in parallel (the same logs and tables).

    Example: `sgtool run-bench --planners random,scout --houses 2 --episodes 3
    --resolution 160x120 -o rb`.
    """
    from sgtool.analysis.closed_loop_bench_run import RUN_OPTIONS_FILE, run_bench_into
    from sgtool.commands.run_bench_recorded import as_recorded, options_text

    args = RunBenchArgs(**given)
    if args.report_only:  # the run as it was made, whatever the defaults now
        args = as_recorded(args, Path(args.out_dir) / RUN_OPTIONS_FILE)
    request = _request(args)
    run_bench_into(replace(request, options_text=options_text(args)), show=click.echo)


@dataclass(frozen=True)
class RunBenchArgs:
    """The options of `sgtool run-bench` as given (the click parameters, by name)."""

    planners: str | None
    houses: int | None
    house_files: tuple[str, ...]
    house_seed: int
    rooms: str
    preset: str
    episodes: int
    noise: tuple[str, ...]
    max_steps: int
    frames: int | None
    frames_per_room: int | None
    resolution: str
    every: int
    navigation: str
    planner_option: tuple[str, ...]
    out_dir: str
    report_only: bool
    progress: bool | None
    force: bool = False
    success: str = "observed"
    executor: str = "local"
    workers: int = 1
    ray_address: str | None = None
    llm_base_url: str | None = None
    llm_model: str | None = None
    llm_api_key: str | None = None
    llm_timeout: float | None = None
    reference: str | None = None
    all_pairs: bool = False
    budgets: str | None = None
    symbolic_dir: str | None = None
    with_symbolic: bool = False
    explore_on: int = 0
    look_in: float = 1.4
    look_in_beyond: float = 45.0
    peek: bool = True
    sight_lines: bool = False
    explore_through: float = 0.0
    render_turn: float = 20.0
    max_depth: float | None = None
    noise_seed: int = 0
    distance_budget: float = 5000.0
    step_budget: float = 50.0


def _request(args: RunBenchArgs) -> RunBenchRequest:
    """The checks: the options and the output folder's mode, then the run's configuration
    (:meth:`ClosedLoopBenchConfig.check`) and the symbolic results to show beside it."""
    from sgtool.analysis.closed_loop_bench_run import RunBenchRequest, load_symbolic

    _check_folder(args)
    cfg = _config(args)
    if args.symbolic_dir is not None and args.with_symbolic:
        raise SgtoolError("--symbolic and --with-symbolic: give one of them")
    cfg.check(planners=not args.report_only)  # (a report imports no plug-in)
    symbolic = load_symbolic(args.symbolic_dir) if args.symbolic_dir is not None else ()
    return RunBenchRequest(
        config=cfg, out_dir=args.out_dir, force=args.force, report_only=args.report_only,
        progress=args.progress, executor=args.executor, workers=args.workers,
        ray_address=args.ray_address, symbolic_dir=args.symbolic_dir, symbolic=symbolic,
        with_symbolic=args.with_symbolic)


def _check_folder(args: RunBenchArgs) -> None:
    """``-o`` is a folder (or new); ``--report-only`` reads one as it is."""
    out_dir = args.out_dir
    if Path(out_dir).exists() and not Path(out_dir).is_dir():
        raise SgtoolError(f"-o {out_dir}: not a folder")
    if args.report_only and args.force:
        raise SgtoolError("--report-only reads the run in OUT as it is; leave out --force")
    if args.report_only and not Path(out_dir).is_dir():
        raise SgtoolError(f"no episode log of this run in {Path(out_dir) / 'logs'}")
    if args.report_only:
        from sgtool.files import read_manifest

        owner, _ = read_manifest(out_dir)
        if owner not in (None, "run-bench"):
            raise SgtoolError(f"--report-only -o {out_dir}: a folder of `sgtool {owner}`, not "
                              "of run-bench: nothing to report there")


def _config(args: RunBenchArgs) -> ClosedLoopBenchConfig:
    """The closed-loop bench configuration of the options (the planners' options
    checked)."""
    from sgtool.analysis.bench import DEFAULT_PLANNERS
    from sgtool.analysis.bench_houses import generated_count
    from sgtool.analysis.closed_loop_bench import ClosedLoopBenchConfig
    from sgtool.recorders.sim import CameraConfig
    from sgtool.recorders.sim.closed_loop import ClosedLoopOptions
    from sgtool.recorders.sim.live_skills import LiveNavConfig

    names = planner_names(args.planners) if args.planners is not None else DEFAULT_PLANNERS
    if args.max_steps < 1:
        raise SgtoolError(f"--max-steps: must be >= 1, got {args.max_steps}")
    width, height = parse_resolution(args.resolution)
    opts = ClosedLoopOptions(camera=CameraConfig(width=width, height=height),
                             every=args.every, max_steps=args.max_steps, frames=args.frames,
                             navigation=args.navigation, success=args.success,
                             explore_on=args.explore_on,
                             turn_render_deg=args.render_turn,
                             max_depth=args.max_depth, noise_seed=args.noise_seed,
                             live=LiveNavConfig(look_in=args.look_in,
                                                look_in_beyond=args.look_in_beyond,
                                                peek=args.peek,
                                                sight_lines=args.sight_lines,
                                                explore_through=args.explore_through))
    options = {k: v for k, v in planner_options(  # (a report imports no plug-in)
        args.planner_option, names, typed=not args.report_only).items()
               if k in names}  # those of planners not run: a note said they are unused
    LlmEndpoint(args.llm_base_url, args.llm_model, args.llm_api_key,
                args.llm_timeout).fill(options, names)
    return ClosedLoopBenchConfig(
        planners=names, houses=generated_count(args.houses, args.house_files, 5),
        house_seed=args.house_seed, house_files=args.house_files, episodes=args.episodes,
        rooms=parse_rooms(args.rooms), preset=args.preset,
        noise=tuple(args.noise) or ("none",), options=opts, planner_options=options,
        frames_per_room=args.frames_per_room, reference=args.reference,
        all_pairs=args.all_pairs, distance_budget=args.distance_budget,
        step_budget=args.step_budget, budgets=_budgets(args.budgets))


def _budgets(text: str | None) -> tuple[float, ...]:
    """--budgets F1,F2,...: frames per room, one line for what is not a number."""
    if text is None:
        return ()
    try:
        return tuple(float(part) for part in text.split(","))
    except ValueError:
        raise SgtoolError(f"--budgets {text or repr(text)}: comma-separated frames per "
                          "room, e.g. 90,100") from None
