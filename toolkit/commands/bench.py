"""``sgtool bench``: the symbolic object-search benchmark over planners."""

from __future__ import annotations

import shlex
import sys
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import click

from sgtool.commands.llm_replay_options import replay_files, replay_sampling_note
from sgtool.commands.options import (
    PLANNER_OPTION_HELP,
    PLANNERS_HELP,
    PLUGIN_HELP,
    SEED,
    LlmEndpoint,
    PathParam,
    budget_options,
    executor_options,
    list_planners_option,
    llm_endpoint_options,
    llm_log_options,
    parse_rooms,
    planner_names,
    planner_options,
    reference_planner,
    shown_command,
    success_option,
)
from sgtool.datasets.presets import PRESET_NAMES

if TYPE_CHECKING:
    from sgtool.analysis.bench_run import BenchRunRequest


@click.command("bench")
@click.option("--planners", default=None, metavar="LIST", is_eager=True,
              help=PLANNERS_HELP + PLUGIN_HELP)
@list_planners_option()
@click.option("--houses", type=click.IntRange(min=0), default=None,
              help="Number of generated evaluation-split houses (house seeds HOUSE_SEED, +1, "
                   "...). [default: 10; with --house: 0, the given houses only]")
@click.option("--house", "house_files", multiple=True, metavar="PATH",
              type=PathParam(path_type=str),
              help="A house spec JSON file, or a folder of them (every *.json there is read "
                   "as a house), to bench (repeatable); named by the spec's id or the file "
                   "name. Generated houses join them only when --houses N is given. Every "
                   "file is checked first (`sgtool scenes check` runs the same checks); a "
                   "bad one stops the run before any episode, naming file and field. "
                   "Episodes start as SymSearch's do, in a random region of a random room "
                   "that can reach the target; the file's `starts` are for the closed "
                   "loop.")
@click.option("--priors", "priors_dir", default=None, metavar="DIR",
              type=PathParam(file_okay=False, path_type=str),
              help="Relational priors (a folder written by `sgtool distill`, or `blend` for "
                   "the shipped priors with the room blend): the planners "
                   "of the learned priors (scout*, godhs, esc, bayes-search, and a plug-in "
                   "whose options have weights_dir) load them, and a "
                   "query is 'seen' when it is one of their training queries [default: the "
                   "shipped priors].")
@click.option("--episodes", default=20, show_default=True,
              help="Search episodes per house (the same for every seed).")
@click.option("--seeds", default=5, show_default=True,
              help="Seeds 0..N-1; each draws the start regions and the planners' randomness; "
                   "metrics are reported as mean ± std over seeds.")
@executor_options("tasks (one house, its planners)")
@click.option("-o", "--out", "out_dir", default="results", show_default=True,
              type=PathParam(file_okay=False),
              help="Output folder: episodes.jsonl, summary.md, summary.json (the same bytes "
                   "on any executor and worker count), run.md, run.json (wall-clock figures "
                   "and the command), per_house.md, "
                   "per_house.jsonl, per_query.md, per_query.jsonl, efficiency_distance.png, "
                   "efficiency_steps.png. Built beside OUT and moved in complete; a "
                   "non-empty OUT is refused unless --force.")
@click.option("--force", is_flag=True,
              help="Write into a non-empty OUT: replaces what sgtool wrote there (an earlier "
                   "bench's files), keeps other files.")
@click.option("--rooms", default="12-16", show_default=True, metavar="MIN-MAX",
              help="Room count range of the generated houses (corridors included, 4..30); "
                   "the default gives about as many first-level objects per house as "
                   "SymSearch's scenes.")
@click.option("--preset", type=click.Choice(list(PRESET_NAMES)), default="symsearch",
              show_default=True,
              help="Generator preset of the generated houses: 'symsearch' furnishes them as "
                   "densely as SymSearch's InteriorGS scenes (~380 objects and ~230 "
                   "explorable first-level pieces per house at 12-16 rooms, long-tail small "
                   "objects) and makes about a third of the episodes furniture-level "
                   "(non-interactive) targets; 'default' is the sparse generator of "
                   "`sgtool scenes generate` (random reaches SR ~0.85 there).")
@click.option("--house-seed", default=0, show_default=True, type=SEED,
              help="Seed of the first house.")
@click.option("--max-steps", default=50, show_default=True,
              help="High-level actions per episode (SymSearch's N_max).")
@budget_options()
@llm_log_options(
    transcript_help="moma-llm: write every LLM exchange to this JSONL transcript, emptied "
    "when the run starts (an interrupted run puts the previous one back; "
    "needs --workers 1).", many=True)
@llm_endpoint_options("LLM planners")
@click.option("-O", "--planner-option", "planner_option", multiple=True, metavar="P.KEY=VALUE",
              help=PLANNER_OPTION_HELP)
@click.option("--log-dir", type=PathParam(file_okay=False), default=None,
              help="Also record every episode as an MCAP log (scene graph and action per "
                   "step) under LOG_DIR/PLANNER/HOUSE/, readable by `sgtool eval`; built "
                   "beside LOG_DIR and moved in complete, as OUT (--force likewise).")
@click.option("--progress/--no-progress", default=None,
              help="Progress bar on stderr (default: when stderr is a terminal).")
@click.option("--reference", default=None, metavar="PLANNER", callback=reference_planner,
              help="Paired comparisons (summary.md, summary.json) of every other planner "
                   "against this one on the same episodes: SPL ratio, SR and SPL "
                   "differences with bootstrap intervals over houses, wins/losses/ties per "
                   "house. [default: scout when benched, else the first planner]")
@click.option("--all-pairs", is_flag=True,
              help="Paired comparisons of every pair of planners instead of against "
                   "--reference.")
@success_option()
def command(**given: Any) -> None:
    """Run the symbolic object-search benchmark (SCOUT's SymSearch roll-out) on generated
    evaluation houses and/or house spec files and print a table in the shape of SCOUT's
    Table VII: success rate, SPL, high-level steps, decision time, and MoMa-LLM's AUC-E with
    a distance-plus-open budget and a step budget (mean ± std over seeds), the same next to
    the SymSearch rows quoted from SCOUT Table VII, then the seen/unseen query breakdown
    (SCOUT Table IX; seen = a training query of the priors). Writes per-episode JSONL, the
    summary, per-house and per-query tables and the efficiency curves to OUT. The same
    command gives the same episodes.jsonl except its wall-clock fields."""
    from sgtool.analysis.bench_run import bench_into

    bench_into(_request(BenchArgs(**given)), show=click.echo)


@dataclass(frozen=True)
class BenchArgs:
    """The options of `sgtool bench` as given (the click parameters, by name)."""

    planners: str | None
    houses: int | None
    house_files: tuple[str, ...]
    priors_dir: str | None
    episodes: int
    seeds: int
    workers: int
    out_dir: str
    force: bool
    rooms: str
    preset: str
    house_seed: int
    max_steps: int
    distance_budget: float
    step_budget: float
    llm_replay: tuple[str, ...]
    llm_transcript: str | None
    planner_option: tuple[str, ...]
    log_dir: str | None
    progress: bool | None
    success: str = "observed"
    executor: str = "local"
    ray_address: str | None = None
    llm_base_url: str | None = None
    llm_model: str | None = None
    llm_api_key: str | None = None
    llm_timeout: float | None = None
    reference: str | None = None
    all_pairs: bool = False


def _request(args: BenchArgs) -> BenchRunRequest:
    """The input check: the budgets, the planners and their options; the house files are
    checked by the run before any episode, the folders by the run's output check."""
    from sgtool.analysis.bench import BenchConfig
    from sgtool.analysis.bench_houses import generated_count
    from sgtool.analysis.bench_run import BenchRunRequest

    names, options = _planners(args)
    cfg = BenchConfig(planners=names, houses=generated_count(args.houses, args.house_files, 10),
                      episodes=args.episodes, seeds=args.seeds,
                      rooms=parse_rooms(args.rooms), preset=args.preset,
                      house_seed=args.house_seed, max_steps=args.max_steps,
                      workers=args.workers, distance_budget=args.distance_budget,
                      step_budget=args.step_budget, planner_options=options,
                      log_dir=args.log_dir, house_files=args.house_files,
                      priors_dir=args.priors_dir, success=args.success,
                      executor=args.executor, ray_address=args.ray_address,
                      reference=args.reference, all_pairs=args.all_pairs)
    command_line = shlex.join(shown_command(["sgtool", *sys.argv[1:]]))
    return BenchRunRequest(config=cfg, out_dir=args.out_dir, command_line=command_line,
                           force=args.force, progress=args.progress)


def _planners(args: BenchArgs) -> tuple[tuple[str, ...], dict[str, dict[str, Any]]]:
    """The planners run and their checked options (``-O``, the LLM endpoint, the
    moma-llm transcripts)."""
    from sgtool.analysis.bench import DEFAULT_PLANNERS
    from sgtool.semantics.priors import weights_folder

    names = planner_names(args.planners) if args.planners is not None else DEFAULT_PLANNERS
    options = {k: v for k, v in planner_options(args.planner_option, names).items()
               if k in names}  # those of planners not run: a note said they are unused
    LlmEndpoint(args.llm_base_url, args.llm_model, args.llm_api_key,
                args.llm_timeout).fill(options, names)
    for name, given in options.items():  # priors of their own: the tables do not say so
        if "weights_dir" in given and str(given["weights_dir"]) != str(args.priors_dir) \
                and weights_folder(given["weights_dir"]).is_dir():  # (else: an error)
            bench_priors = f"--priors {args.priors_dir}" if args.priors_dir else \
                "the shipped priors"
            click.echo(f"sgtool: note: -O {name}.weights_dir={given['weights_dir']}: {name} "
                       "loads those priors, but the summary's priors id and seen/unseen "
                       f"split are those of {bench_priors}; give --priors DIR to label the "
                       "tables by the priors the planners load", err=True)
    if args.llm_replay or args.llm_transcript:
        moma = options.setdefault("moma-llm", {})
        if args.llm_replay:
            moma["replay"] = replay_files(args.llm_replay)
        if args.llm_transcript:
            moma["transcript"] = args.llm_transcript
    for name, given in options.items():
        if note := replay_sampling_note(name, given):
            click.echo(note, err=True)
    return names, options
