"""``sgtool study``: studies over many recordings; ``sgtool study noise`` is the
perception-noise study (:mod:`sgtool.analysis.noise_study`)."""

from __future__ import annotations

import os
import sys
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import click

from sgtool.commands.options import (
    FINITE_FLOAT,
    SEED,
    PathParam,
    executor_options,
    parse_resolution,
    parse_rooms,
    planner_names,
)
from sgtool.errors import SgtoolError

if TYPE_CHECKING:
    from sgtool.analysis.noise_study_run import NoiseStudyRequest

CONTEXT = {"help_option_names": ["-h", "--help"], "max_content_width": 100}


def default_cache() -> Path:
    """``$XDG_CACHE_HOME/sgtool/study-noise``, else ``~/.cache/sgtool/study-noise``."""
    base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(base) / "sgtool" / "study-noise"


@click.group("study", context_settings=CONTEXT)
def command() -> None:
    """Studies over many recordings: `sgtool study noise` measures scene-graph quality
    against sensor noise."""


@command.command("noise", context_settings=CONTEXT)
@click.option("--houses", default=5, show_default=True, type=click.IntRange(min=0),
              help="Generated houses (seeds HOUSE_SEED, +1, ...; the houses of `sgtool "
              "record --seed`); 0 with --house studies the given houses only.")
@click.option("--house-seed", default=0, show_default=True,
              type=SEED,
              help="Seed of the first generated house.")
@click.option("--house", "house_files", multiple=True, metavar="FILE",
              type=PathParam(path_type=str),
              help="A house spec JSON file or a folder of them (repeatable), studied after "
              "the generated houses.")
@click.option("--rooms", default="8-8", show_default=True, metavar="MIN-MAX",
              help="Room count range of the generated houses (corridors included, 4..30).")
@click.option("--factor", "factors", multiple=True, metavar="NAME=L1,L2,...",
              help="A noise factor and its levels (repeatable): depth_sigma, holes, "
              "label_swap, label_dropout, drift_xy, drift_yaw, flying (fields and units of `sgtool "
              "record --noise`); each level is recorded with that fault alone. Default: "
              "every factor at levels including mild's and strong's values.")
@click.option("--profile", "profiles", multiple=True, metavar="NAME",
              help="A whole noise profile to study as well (repeatable; mild, strong, or a "
              "JSON profile's file as `record --noise` takes it). Default: mild and strong, "
              "unless --factor is given.")
@click.option("--resolution", default="160x120", show_default=True,
              help="Camera image size WIDTHxHEIGHT of the recordings.")
@click.option("--fps", default=4.0, show_default=True, type=FINITE_FLOAT,
              help="Frames per second of log time of the recordings.")
@click.option("--frames", default=None, type=click.IntRange(min=1),
              help="Stop each recording after this many frames. Default: when the scripted "
              "tour has visited every room.")
@click.option("--noise-seed", default=0, show_default=True,
              type=SEED,
              help="Seed of the sensor faults.")
@click.option("--cache", "cache_dir", default=None, type=PathParam(file_okay=False),
              help="Folder of recorded logs, keyed by house, noise and recording settings: "
              "a log recorded once is reused by every later study [default: "
              "$XDG_CACHE_HOME/sgtool/study-noise, else ~/.cache/sgtool/study-noise].")
@click.option("--closed-loop", "closed_loop", default=None, metavar="PLANNERS",
              help="Also run closed-loop search episodes (`sgtool run-bench`) of these "
              "comma-separated planners on the first --closed-loop-houses houses, under "
              "each --closed-loop-noise profile, and report SR/SPL.")
@click.option("--closed-loop-noise", default="none,mild", show_default=True, metavar="LIST",
              help="Comma-separated noise profiles of the closed-loop runs (the first is the "
              "reference of the SR differences).")
@click.option("--episodes", default=3, show_default=True, type=click.IntRange(min=1),
              help="Closed-loop episodes per house (the first of `sgtool bench`'s).")
@click.option("--closed-loop-houses", default=0, show_default=True, type=click.IntRange(min=0),
              help="Houses of the closed-loop runs: the first N of the study (0: all).")
@click.option("--frames-per-room", default=60, show_default=True, type=click.IntRange(min=1),
              help="Closed-loop frame budget per episode: N x the house's room count.")
@click.option("--max-steps", default=50, show_default=True, type=click.IntRange(min=1),
              help="Closed-loop high-level planner steps per episode.")
@click.option("-o", "--out", "out_dir", required=True, type=PathParam(file_okay=False),
              help="Output folder: summary.md, results.json, results.csv (one row per "
              "house x condition), plots/FACTOR.png, closed_loop/ (episode logs and tables).")
@click.option("--force", is_flag=True,
              help="Write into a non-empty -o folder, replacing what sgtool wrote there.")
@click.option("--progress/--no-progress", default=None,
              help="Progress bar on stderr (default: when stderr is a terminal).")
@executor_options("recordings and replays (one per house and noise setting)")
def noise(**given: Any) -> None:
    """Scene-graph quality against perception noise: for each noise factor at each level
    (and each whole profile), record the scripted tour of every house with that noise
    (`sgtool record --noise`), or reuse the log of --cache, replay it and score the final
    graph (`sgtool replay --score`, merged scores: rooms found vs true, Voronoi purity,
    ARI, objects in the right room). With --closed-loop, the SR/SPL of those planners under
    --closed-loop-noise on the same episodes (`sgtool run-bench --noise`).

    Writes summary.md, results.json, results.csv and plots/ (quality vs noise level per
    factor: a point per house, the median line). The same inputs give byte-identical
    tables on any executor and worker count.

    Example: `sgtool study noise --houses 5 --rooms 8-8 --factor label_dropout=0.01,0.05
    --profile mild -w 2 -o study`.
    """
    from sgtool.analysis.noise_study_run import study_into

    study_into(_request(NoiseArgs(**given)), show=click.echo)


@dataclass(frozen=True)
class NoiseArgs:
    """The options of `sgtool study noise` as given (the click parameters, by name)."""

    houses: int
    house_seed: int
    house_files: tuple[str, ...]
    rooms: str
    factors: tuple[str, ...]
    profiles: tuple[str, ...]
    resolution: str
    fps: float
    frames: int | None
    noise_seed: int
    cache_dir: str | None
    closed_loop: str | None
    closed_loop_noise: str
    episodes: int
    closed_loop_houses: int
    frames_per_room: int
    max_steps: int
    out_dir: str
    force: bool
    progress: bool | None
    executor: str = "local"
    workers: int = 1
    ray_address: str | None = None


def _request(args: NoiseArgs) -> NoiseStudyRequest:
    """The input check: the conditions, the recording settings, the houses, the
    closed-loop part (names and profiles before any work) and the cache folder."""
    from sgtool.analysis.bench_houses import generated_houses, load_house_files
    from sgtool.analysis.noise_study import RecordingSettings, StudyConfig
    from sgtool.analysis.noise_study_run import NoiseStudyRequest
    from sgtool.files import refuse_input_folder

    refuse_input_folder(args.out_dir, args.house_files, what="--house")
    conditions = _conditions(args.factors, args.profiles)
    width, height = parse_resolution(args.resolution)
    settings = RecordingSettings(width, height, args.fps, args.frames, args.noise_seed)
    settings.check()
    room_range = parse_rooms(args.rooms)
    gen = generated_houses(args.houses, args.house_seed)
    all_houses = gen + (load_house_files(args.house_files, taken=[h.id for h in gen])
                        if args.house_files else ())
    cfg = StudyConfig(all_houses, conditions, room_range, settings, _closed_loop(args))
    cfg.check()
    if cfg.closed_loop.planners:
        from sgtool.analysis.closed_loop_bench import ClosedLoopBenchConfig

        try:  # names, profiles: before any work, named by this command's options
            ClosedLoopBenchConfig(planners=cfg.closed_loop.planners, houses=1,
                                  episodes=args.episodes, noise=cfg.closed_loop.noise
                                  ).check()
        except SgtoolError as e:
            raise _renamed(e, "--planners", "--closed-loop") from None
        _check_llm_planners(cfg.closed_loop.planners)
    cache = Path(args.cache_dir) if args.cache_dir else default_cache()
    _check_cache(cache)
    return NoiseStudyRequest(
        config=cfg, cache=cache, out_dir=args.out_dir, force=args.force,
        progress=sys.stderr.isatty() if args.progress is None else args.progress,
        executor=args.executor, workers=args.workers, ray_address=args.ray_address)


def _conditions(factors: tuple[str, ...], profiles: tuple[str, ...]) -> Any:
    """The study's conditions: ``--factor`` levels (each factor once; none: the default
    levels) and ``--profile`` profiles (none: the defaults unless factors are given)."""
    from sgtool.analysis.noise_study import (
        DEFAULT_LEVELS,
        DEFAULT_PROFILES,
        conditions_of,
        parse_factor,
    )

    chosen: dict[str, tuple[float, ...]] = {}
    for text in factors:
        name, levels = parse_factor(text)
        if name in chosen:
            raise SgtoolError(f"--factor {name}: given twice; list its levels once")
        chosen[name] = levels
    if not factors:
        chosen = dict(DEFAULT_LEVELS)
    twice = sorted({p for p in profiles if profiles.count(p) > 1})
    if twice:
        raise SgtoolError(f"--profile {twice[0]}: given twice")
    profile_list = tuple(profiles) if profiles else (() if factors else DEFAULT_PROFILES)
    return conditions_of(chosen, profile_list)


_CLOSED_LOOP_ONLY = ("closed_loop_noise", "episodes", "closed_loop_houses",
                     "frames_per_room", "max_steps")


def _refuse_closed_loop_options() -> None:
    """The options of the closed-loop part, given without --closed-loop, are refused
    (they would do nothing)."""
    from click.core import ParameterSource

    ctx = click.get_current_context(silent=True)
    if ctx is None:
        return
    given = [f"--{n.replace('_', '-')}" for n in _CLOSED_LOOP_ONLY
             if ctx.get_parameter_source(n) is ParameterSource.COMMANDLINE]
    if given:
        raise SgtoolError(f"{', '.join(given)}: for the closed-loop part; give "
                          "--closed-loop PLANNERS too")


def _renamed(e: SgtoolError, theirs: str, ours: str) -> SgtoolError:
    """``e`` with the option its message starts with (another command's, ``theirs``)
    named as this command calls it (``ours``; run-bench's ``--noise`` is
    ``--closed-loop-noise`` here)."""
    text = str(e)
    text = ours + text[len(theirs):] if text.startswith(theirs) else text
    return SgtoolError(text.replace(f"{ours}/--noise", f"{ours}/--closed-loop-noise", 1))


def _check_llm_planners(planners: Sequence[str]) -> None:
    """An LLM planner of the closed-loop part needs an endpoint before any recording (the
    study takes it from SGTOOL_LLM_BASE_URL; it has no option for one)."""
    from sgtool.planning.registry import is_llm_planner, make_planner

    for name in planners:
        if is_llm_planner(name):
            try:
                make_planner(name)
            except SgtoolError as e:
                why = str(e)
                if why.startswith("no LLM endpoint configured"):
                    why = ("no LLM endpoint configured: set SGTOOL_LLM_BASE_URL (and "
                           "SGTOOL_LLM_API_KEY if it needs one); study noise has no option "
                           "for it")
                raise SgtoolError(f"--closed-loop {name}: {why}") from None


def _check_cache(cache: Path) -> None:
    """``--cache`` is a folder, or can be made one (its nearest existing ancestor is a
    folder), before any work."""
    near = next((p for p in (cache, *cache.parents) if p.exists()), None)
    if near is not None and not near.is_dir():
        what = "is a file, not a folder" if near == cache else \
            f"lies under {near}, which is no folder"
        raise SgtoolError(f"--cache {cache}: {what}")


def _closed_loop(args: NoiseArgs) -> Any:
    """The closed-loop settings: ``--closed-loop`` planners under each
    ``--closed-loop-noise`` profile (each parsed)."""
    from sgtool.analysis.noise_study import ClosedLoopSettings
    from sgtool.recorders.sim.noise import parse_noise

    planners = planner_names(args.closed_loop) if args.closed_loop else ()
    cl_noise = tuple(n.strip() for n in args.closed_loop_noise.split(",") if n.strip())
    for n in cl_noise:
        try:
            parse_noise(n)
        except SgtoolError as e:  # its message names `record`'s --noise
            raise _renamed(e, "--noise", "--closed-loop-noise") from None
    if args.closed_loop is not None and not planners:
        raise SgtoolError("--closed-loop: give at least one planner")
    if args.closed_loop is None:
        _refuse_closed_loop_options()
    if planners and not cl_noise:
        raise SgtoolError("--closed-loop-noise: give at least one profile")
    return ClosedLoopSettings(planners, cl_noise, args.episodes, args.closed_loop_houses,
                              args.frames_per_room, args.max_steps)
