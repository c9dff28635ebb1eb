"""The symbolic benchmark run: houses x episodes x seeds x planners -> records, table, curves.

Protocol (SCOUT sec. VI, Table VII; MoMa-LLM's AUC-E):

- houses ``generate_house(house_seed + i, rooms=rooms, split="eval")`` for i < ``houses``:
  furnished from the evaluation part of the knowledge only (``rooms`` defaults to
  :data:`DEFAULT_ROOMS`, chosen for scene size, see there), ids ``house-<seed>``; then the
  house spec files of ``house_files`` (files or folders of ``*.json``), ids from the spec
  or the file name, every file checked before anything runs
  (:mod:`sgtool.analysis.bench_houses`);
- per house, ``episodes`` search episodes from :func:`sgtool.datasets.episodes.list_episodes`
  (seeded by the house seed, so the episode set is the same for every bench seed; a house
  file without start poses gets one per reachable room first);
- per bench seed (0 .. ``seeds`` - 1): the start region of every episode and the planner's
  own seed are drawn from (seed, house seed, episode index)
  (:class:`sgtool.recorders.symbolic_environment.SymbolicEnv`,
  :func:`~sgtool.recorders.symbolic_environment.planner_seed`);
- every planner runs every (seed, house, episode) with at most ``max_steps`` actions;
- a query is "seen" when its :func:`~sgtool.semantics.text.category_text` is one of the
  training queries of the relational priors (the shipped ones, or those in ``priors_dir``,
  which the scout planners then also load): :func:`sgtool.semantics.priors.training_queries`,
  the vocabulary ``sgtool distill`` writes into the weights' metadata; "unseen" otherwise.

Outputs (in ``out_dir``): ``episodes.jsonl`` (one :class:`EpisodeResult` per line, ordered
by planner, then house id (plain string order), episode index, seed), ``summary.md`` (Table
VII-shaped table, the same next to the rows quoted from SCOUT Table VII, seen/unseen table,
SR and SPL with bootstrap intervals over houses and the paired comparisons of
:mod:`sgtool.analysis.intervals` (every planner against ``reference``, or every pair),
per-house and per-query tables, AUC-E budgets, settings, digest), ``summary.json``
(both hold no wall-clock figure: the same arguments give the same bytes on any executor and
any number of workers), ``run.md``/``run.json`` (the table with the decision time and
episodes per second, the run time, workers, executor and command: wall-clock figures),
``per_house.md``/``per_house.jsonl`` and ``per_query.md``/``per_query.jsonl`` (SR, SPL,
steps per planner, pooled over seeds), and the efficiency curves
``efficiency_distance.png`` and ``efficiency_steps.png``, each written atomically. Records
are identical between runs except their ``wall`` figures; the summary's digest leaves them out.

Tasks are grouped by house (:func:`bench_tasks`): one task runs every planner on one
house, so the house is built once in the whole run; when there are fewer houses than
workers, a house's planners are split over several tasks. The tasks run on
:mod:`sgtool.analysis.executor`'s local executor (``workers`` spawned processes, each keeping
its last houses and its planners) or on Ray (``executor="ray"``, ``ray_address``); results
are put back in the fixed order, so the output does not depend on the executor or N. A task
that still fails after one retry stops the run with a :class:`BenchError` naming it; with
``partial`` the run goes on, the task is listed in the summary (``failed_tasks``) with its
error, and its episodes are missing from every table.
"""

from __future__ import annotations

import functools
import json
import math
import os
import sys
import time
from collections.abc import Mapping, Sequence
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

from sgtool.analysis.bench_cache import cached_house, cached_planner
from sgtool.analysis.bench_houses import (
    BenchHouse,
    generated_houses,
    load_house_files,
    output_path,
)
from sgtool.analysis.bench_planner_checks import (
    BenchError,
    check_budgets,
    check_house_seeds,
    check_planner_list,
    check_planner_options,
    check_reference,
    config_names,
    config_planner_options,
    config_rooms,
    recorded_planner_options,
)
from sgtool.analysis.bench_priors import (
    planner_options_for,
    priors_fingerprint,
    training_vocabulary,
)
from sgtool.analysis.executor import Task, chunks, failure_lines, make_executor, retry_lines
from sgtool.analysis.interval_report import IntervalReport, interval_report
from sgtool.analysis.intervals import (
    DEFAULT_BOOTSTRAP,
    Bootstrap,
    PairedComparison,
    PlannerIntervals,
)
from sgtool.analysis.paper_tables import TABLE_IX_SYMSEARCH
from sgtool.analysis.report import (
    breakdown_records,
    format_breakdown,
    format_seen_unseen,
    format_side_by_side,
    format_table,
    invalid_action_notes,
    llm_answer_lines,
    llm_answer_totals,
    summary_dict,
)
from sgtool.analysis.search_metrics import CostModel, breakdown, cost_models, seen_unseen, summarize
from sgtool.arg_checks import of_type, whole
from sgtool.canonical import strict_json
from sgtool.files import atomic_write, note_written, output_dir, output_folder
from sgtool.planning.episode import SUCCESS_RULES
from sgtool.redact import redact_text, secret_values
from sgtool.results import EpisodeResult, results_digest, write_jsonl
from sgtool.version import __version__

DEFAULT_PLANNERS: tuple[str, ...] = (
    "random", "greedy", "sbert-noroom", "sbert", "scout-noroom", "scout-delta0", "scout",
    "godhs", "esc", "bayes-search",
)
BENCH_VERSION = "1.0"
# Room-count range and generator preset of the benchmark houses: with the symsearch preset,
# 12-16 rooms come close to the object and first-level counts of SCOUT's InteriorGS houses
# (SCOUT Table I: 408 objects, ~250 first-level) and the random planner's success rate to
# SymSearch's; the sparse default houses let random succeed too often to separate planners
# (the counts and rates: docs/experiments/moved-from-docstrings.md).
DEFAULT_ROOMS: tuple[int, int] = (12, 16)


@dataclass(frozen=True)
class BenchConfig:
    """The settings of a symbolic benchmark run (module doc): the planners (names for
    :func:`sgtool.planning.registry.make_planner`), generated houses and their room range
    and preset, house files, episodes per house, seeds, ``max_steps`` per episode, the
    AUC-E budgets, options per planner, the success rule and where the tasks run.
    :meth:`check` raises a one-line :class:`BenchError` for a setting that cannot work;
    :meth:`settings` are the ones that can change results (written to summary.json)."""

    planners: tuple[str, ...] | str = DEFAULT_PLANNERS  # a tuple once made (a name alone: one)
    houses: int = 10
    episodes: int = 20  # per house
    seeds: int = 5
    rooms: tuple[int, int] = DEFAULT_ROOMS
    preset: str = "symsearch"  # generator preset of the generated houses (DEFAULT_ROOMS)
    house_seed: int = 0  # first house seed
    max_steps: int = 50  # SymSearch's N_max
    workers: int = 1
    distance_budget: float = 5000.0  # MoMa-LLM low-level budget (0.1 m steps + 30 per open)
    step_budget: float = 50.0  # MoMa-LLM high-level budget
    planner_options: Mapping[str, Mapping[str, Any]] = field(default_factory=dict, repr=False)
    log_dir: str | None = None  # also record every episode as an MCAP log here
    house_files: tuple[str, ...] | str = ()  # house spec files or folders, after the generated
    priors_dir: str | None = None  # relational priors (vocabulary, scout weights)
    success: str = "observed"  # success rule: observed | done (sgtool.planning.episode)
    executor: str = "local"  # local | ray (sgtool.analysis.executor)
    ray_address: str | None = None  # a Ray cluster; None: RAY_ADDRESS, else a local Ray
    reference: str | None = None  # paired comparisons against it (None: scout, else first)
    all_pairs: bool = False  # paired comparisons of every pair of planners instead

    def __post_init__(self) -> None:
        object.__setattr__(self, "planner_options",
                           config_planner_options(self.planner_options))
        object.__setattr__(self, "planners", config_names(self.planners, "planners"))
        object.__setattr__(self, "house_files",
                           config_names(self.house_files, "house_files", paths=True))
        object.__setattr__(self, "rooms", config_rooms(self.rooms))

    def check(self) -> None:
        for name in ("houses", "episodes", "seeds", "max_steps", "workers"):
            whole(name, getattr(self, name))  # "2" or 2.5 from Python: one line
        check_planner_list(self.planners)
        if len(set(self.planners)) != len(self.planners):
            raise BenchError("--planners: a planner is named twice")
        for name, value in (("--episodes", self.episodes), ("--seeds", self.seeds),
                            ("--max-steps", self.max_steps), ("--workers", self.workers)):
            if value < 1:
                raise BenchError(f"{name}: must be >= 1, got {value}")
        if self.houses < 0 or (self.houses == 0 and not self.house_files):
            raise BenchError(f"--houses: must be >= 1, or >= 0 with --house (house_files=), got "
                             f"{self.houses}")
        check_house_seeds(self.house_seed, self.houses)
        check_budgets(self.distance_budget, self.step_budget)
        if self.house_seed < 0:
            raise BenchError(f"--house-seed: must be >= 0, got {self.house_seed}")
        from sgtool.datasets.presets import PRESET_NAMES

        if self.preset not in PRESET_NAMES:
            raise BenchError(f"--preset: one of {', '.join(PRESET_NAMES)}, got {self.preset!r}")
        from sgtool.datasets.generator import MAX_ROOMS

        lo, hi = self.rooms
        if not 4 <= lo <= hi <= MAX_ROOMS:
            raise BenchError(f"--rooms: need 4 <= MIN <= MAX <= {MAX_ROOMS}, got {lo}-{hi}")
        check_reference(self.reference, self.all_pairs, self.planners)
        if self.success not in SUCCESS_RULES:
            raise BenchError(f"--success: one of {', '.join(SUCCESS_RULES)}, got "
                             f"{self.success!r}")
        check_planner_options(self.planners, self.planner_options,
                              one_writer=self.workers == 1 and self.executor == "local")
        here = [p for p in self.planners if p.startswith("__main__:")]
        if here and (self.workers > 1 or self.executor != "local"):
            raise BenchError(f"planner {here[0]!r} is defined in __main__ (a notebook or "
                             "script), which worker processes cannot import: run it with "
                             "workers=1, or put it in a module on sys.path")

    def models(self) -> tuple[CostModel, CostModel]:
        return cost_models(self.distance_budget, self.step_budget)

    def settings(self) -> dict[str, Any]:
        d = asdict(self)
        d["planners"] = list(self.planners)
        d["rooms"] = list(self.rooms)
        d["planner_options"] = recorded_planner_options(self.planner_options)
        for key in ("workers", "executor", "ray_address",  # do not change the results
                    "reference", "all_pairs"):
            d.pop(key)
        d.pop("log_dir")
        if self.success == "observed":  # the default: settings as before the option
            d.pop("success")
        return d


@dataclass(frozen=True)
class BenchResult:
    """What :func:`run_benchmark` returns: its ``config``, every episode's
    :class:`~sgtool.results.EpisodeResult` (by planner, house, episode, seed), episodes per
    second per planner (wall clock), the ``table`` and ``seen_table`` text, the
    ``digest`` of the results without wall-clock figures, the run's ``wall_s``, its
    houses, the number of training queries of the priors and one line per task that
    ``failed``; :func:`write_outputs` (``sgtool.write_bench_outputs``) writes it into a
    folder."""

    config: BenchConfig
    # every episode with its trace: kilobytes each, left out of repr (a notebook prints it)
    results: tuple[EpisodeResult, ...] = field(repr=False)
    throughput: dict[str, float]  # planner -> episodes per second of one core (wall-clock)
    table: str = field(repr=False)
    seen_table: str = field(repr=False)
    digest: str
    wall_s: float
    houses: tuple[BenchHouse, ...] = ()
    vocabulary_size: int = 0  # training queries of the priors
    failed: tuple[str, ...] = ()  # one line per task that failed after its retry
    retried: tuple[str, ...] = ()  # one line per task that succeeded after an error

    @property
    def side_by_side(self) -> str:
        return self._side_by_side(timing=True)

    @property
    def results_table(self) -> str:
        """:attr:`table` without its wall-clock columns: a function of the results alone."""
        models = self.config.models()
        return format_table(summarize(self.results, models, self.config.planners),
                            models=models, title=_title(self.config), timing=False)

    @property
    def results_side_by_side(self) -> str:
        return self._side_by_side(timing=False)

    def _side_by_side(self, timing: bool) -> str:
        return format_side_by_side(
            summarize(self.results, self.config.models(), self.config.planners),
            title="Ours next to SCOUT Table VII (SymSearch rows quoted from the paper)",
            timing=timing)

    def interval_report(self, boot: Bootstrap = DEFAULT_BOOTSTRAP) -> IntervalReport:
        """SR and SPL per planner with bootstrap intervals over houses, and the paired
        comparisons of the config's pairs (:func:`~sgtool.analysis.intervals.
        comparison_pairs`) on all, seen and unseen queries (with the default bootstrap,
        computed once)."""
        if boot == DEFAULT_BOOTSTRAP:
            return self._default_report
        cfg = self.config
        return interval_report(self.results, cfg.planners, cfg.reference, cfg.all_pairs, boot)

    @functools.cached_property
    def _default_report(self) -> IntervalReport:
        cfg = self.config
        return interval_report(self.results, cfg.planners, cfg.reference, cfg.all_pairs)

    def intervals(self, boot: Bootstrap = DEFAULT_BOOTSTRAP) -> list[PlannerIntervals]:
        """SR and SPL per planner with cluster-bootstrap intervals over houses."""
        return list(self.interval_report(boot).planners)

    def comparisons(self, boot: Bootstrap = DEFAULT_BOOTSTRAP,
                    seen: bool | None = None) -> list[PairedComparison]:
        """The paired comparisons of the config's pairs, intervals over houses; ``seen``
        True / False: on the episodes of seen / unseen queries only."""
        rep = self.interval_report(boot)
        return list(rep.paired if seen is None else rep.paired_seen if seen
                    else rep.paired_unseen)

    def interval_tables(self) -> str:
        """The intervals per planner, then the paired comparisons (text)."""
        return self.interval_report().text()

    def interval_dict(self) -> dict[str, Any]:
        """The same as :meth:`interval_tables`, JSON-ready (summary.json)."""
        return self.interval_report().to_dict()

    def breakdown_table(self, by: str) -> str:
        rows = breakdown(self.results, by, self.config.planners)
        what = "house" if by == "house" else "query (seen: in the priors' training queries)"
        return format_breakdown(rows, by, self.config.planners,
                                title=f"Per {what}: SR / SPL per planner, episodes pooled "
                                      "over seeds")


# ----------------------------------------------------------------------------------------
# one worker task: one house, one planner, every seed and episode
# ----------------------------------------------------------------------------------------
def run_task(args: tuple[BenchConfig, BenchHouse, tuple[str, ...]]
             | tuple[BenchConfig, BenchHouse, tuple[str, ...], str]) -> list[EpisodeResult]:
    """Every episode and seed of one house for each of the given planners (the ``args`` of a
    :func:`bench_tasks` task, with the run's token), in planner, seed, episode order. The
    results depend on the task alone: not on what the process ran before, nor on the
    machine's core count."""
    from sgtool.blas import single_blas_thread
    from sgtool.heap import frozen_heap
    from sgtool.semantics.priors import forget_default_scores

    cfg, ref, names = args[:3]
    run = str(args[3]) if len(args) > 3 else ""
    # A task's results depend on the task alone, not on what its worker ran before nor on
    # the machine's core count: the shared priors start from an empty score memo (their
    # batches, and so the last bits of their scores, are the task's own), and the small
    # products of the priors' MLP run on one BLAS thread (OpenBLAS splits them over every
    # core, which changes bits and, on a busy machine, costs several times the work).
    # What the worker holds already (modules, models) stays out of the collector's full
    # scans (sgtool.heap.frozen_heap).
    forget_default_scores()
    with single_blas_thread(), frozen_heap():
        return _task_episodes(cfg, ref, names, run)


def _task_episodes(cfg: BenchConfig, ref: BenchHouse, names: tuple[str, ...],
                   run: str = "") -> list[EpisodeResult]:
    from sgtool.errors import SgtoolError
    from sgtool.planning.moma.planner import replay_miss_of
    from sgtool.planning.registry import planner_file_name
    from sgtool.recorders.symbolic_environment.rollout import run_episode
    from sgtool.semantics.text import category_text

    house, episodes = cached_house(ref, cfg.rooms, cfg.episodes, cfg.preset)
    vocabulary = training_vocabulary(cfg.priors_dir)
    out = []
    for name in names:
        planner = cached_planner(name, planner_options_for(cfg, name), run)
        for seed in range(cfg.seeds):
            for i, ep in enumerate(episodes):
                kw = dict(seed=seed, episode_index=i, avoid_rooms=ep.target_rooms,
                          max_steps=cfg.max_steps, seen=category_text(ep.query) in vocabulary,
                          house_id=ref.id, planner_name=name, success=cfg.success,
                          planner_options=planner_options_for(cfg, name))
                if cfg.log_dir is None:
                    out.append(run_episode(house, planner, ep.query, ep.targets, **kw))
                else:
                    from sgtool.log.writer import LogWriter

                    path = output_path(cfg.log_dir, planner_file_name(name), ref.id,
                                       f"seed{seed}-ep{i}.mcap")
                    path.parent.mkdir(parents=True, exist_ok=True)
                    with LogWriter(path, seed=seed) as log:
                        out.append(run_episode(house, planner, ep.query, ep.targets, log=log,
                                               **kw))
                if miss := replay_miss_of(planner):  # --llm-replay of another run
                    raise SgtoolError(f"{name}: {miss} ({ref.id}, episode {i}, seed {seed})")
    return out


def bench_tasks(cfg: BenchConfig, houses: Sequence[BenchHouse], run: str = "") -> list[Task]:
    """The run's tasks, grouped by house: all planners of a house in one task, or, when
    there are fewer houses than workers, the house's planners cut into that many runs;
    ``run``: the run's token (:func:`~sgtool.analysis.bench_cache.cached_planner`)."""
    groups = -(-cfg.workers // max(1, len(houses)))  # ceil(workers / houses)
    return [Task(f"{h.id}/{'+'.join(names)}", (cfg, h, names, run))
            for h in houses for names in chunks(cfg.planners, groups)]


# ----------------------------------------------------------------------------------------
# the run
# ----------------------------------------------------------------------------------------
def run_benchmark(cfg: BenchConfig, progress: bool | None = None,
                  partial: bool = False) -> BenchResult:
    """Run every planner on every episode (module doc) and return the results and their
    tables; nothing is written (:func:`write_outputs`, ``sgtool.write_bench_outputs``,
    does). A setting that cannot work is
    a one-line :class:`~sgtool.errors.SgtoolError` (:class:`BenchError`, a planner option)
    before any episode runs. A task (one house's planners) that failed twice (a plug-in
    that raises) is a :class:`BenchError` naming the first failure, unless ``partial``:
    then the result holds the other tasks' episodes and says which failed (``failed``)."""
    import uuid

    of_type("cfg", cfg, BenchConfig, "a BenchConfig")
    cfg.check()
    run = uuid.uuid4().hex  # planners are built afresh for each run (cached_planner)
    executor = make_executor(cfg.executor, cfg.workers, cfg.ray_address)
    houses = prepare_houses(cfg)
    vocabulary = training_vocabulary(cfg.priors_dir)  # a bad --priors fails before any episode
    for name in cfg.planners:  # and so does a bad planner option (built-ins kept for the tasks)
        cached_planner(name, planner_options_for(cfg, name), run)
    show = sys.stderr.isatty() if progress is None else progress
    t0 = time.perf_counter()
    outcomes = executor.run(run_task, bench_tasks(cfg, houses, run), progress=show,
                            desc="bench")
    chunks = [o.value for o in outcomes if o.ok]
    failed = failure_lines(outcomes)
    retried = retry_lines(outcomes)
    if failed and not partial:  # tables without some houses' episodes would pass for a result
        raise BenchError(f"{len(failed)} of {len(outcomes)} bench task(s) failed after a "
                         f"retry; the first: {failed[0]}")
    wall = time.perf_counter() - t0
    order = {p: i for i, p in enumerate(cfg.planners)}
    # through the JSONL form, so the summary is exactly what `sgtool eval` recomputes from
    # episodes.jsonl (figures rounded as written)
    results = sorted((EpisodeResult.from_dict(r.to_dict()) for c in chunks for r in c),
                     key=lambda r: (order[r.planner], r.house, r.episode, r.seed))
    spent: dict[str, float] = {}
    count: dict[str, int] = {}
    for r in results:
        spent[r.planner] = spent.get(r.planner, 0.0) + float(r.wall.get("episode_s", 0.0))
        count[r.planner] = count.get(r.planner, 0) + 1
    throughput = {p: (count[p] / spent[p] if spent.get(p) else math.nan) for p in count}
    models = cfg.models()
    sums = summarize(results, models, planners=cfg.planners)
    table = format_table(sums, throughput=throughput, models=models, title=_title(cfg))
    priors = cfg.priors_dir or "the shipped priors"
    seen_table = format_seen_unseen(
        seen_unseen(results, cfg.planners), quoted=TABLE_IX_SYMSEARCH,
        title=f"Seen vs unseen queries (SCOUT Table IX), episodes pooled over seeds; seen = "
              f"one of the {len(vocabulary)} training queries of {priors}")
    return BenchResult(cfg, tuple(results), throughput, table, seen_table,
                       results_digest(results), wall, houses, len(vocabulary),
                       tuple(failed), tuple(retried))


def prepare_houses(cfg: BenchConfig) -> tuple[BenchHouse, ...]:
    """The run's houses: the generated ones, then every house file, all checked first
    (:func:`sgtool.analysis.bench_houses.load_house_files`)."""
    made = generated_houses(cfg.houses, cfg.house_seed)
    given = load_house_files(cfg.house_files, taken=[h.id for h in made]) \
        if cfg.house_files else ()
    return made + given


def _title(cfg: BenchConfig) -> str:
    parts = []
    if cfg.houses:
        parts.append(f"{cfg.houses} generated houses (rooms {cfg.rooms[0]}-{cfg.rooms[1]})")
    if cfg.house_files:
        parts.append(f"houses from {', '.join(cfg.house_files)}")
    return (f"Symbolic benchmark (SymSearch roll-out): {' + '.join(parts)}; {cfg.episodes} "
            f"episodes per house x {cfg.seeds} seeds, N_max = {cfg.max_steps}"
            f"{'; success only on done() (MoMa-LLM)' if cfg.success == 'done' else ''}")


# the names write_outputs gives its files (what ``--force`` may replace in a folder without
# a manifest: :func:`sgtool.files.output_folder`)
OUTPUT_NAMES: tuple[str, ...] = (
    "episodes.jsonl", "summary.md", "summary.json", "run.md", "run.json", "per_house.md",
    "per_house.jsonl", "per_query.md", "per_query.jsonl", "efficiency_*.png",
)


def write_outputs(res: BenchResult, out_dir: str | os.PathLike[str],
                  command: str = "") -> list[Path]:
    """episodes.jsonl, summary.md, summary.json (no wall-clock figure), run.md, run.json
    (timing, command), per_house.md/.jsonl, per_query.md/.jsonl and the two efficiency
    PNGs (:data:`OUTPUT_NAMES`), each written atomically into ``out_dir`` (created when
    missing) and listed in its manifest as ``sgtool bench``'s
    (:func:`sgtool.files.note_written`); the commands write into the folder of
    :func:`sgtool.files.output_folder`, so that the set appears complete."""
    from sgtool.analysis.curves import plot_efficiency

    of_type("res", res, BenchResult, "a BenchResult (of run_benchmark)")
    out = output_dir(out_dir)
    cfg = res.config
    paths = [write_jsonl(res.results, out / "episodes.jsonl")]
    by_planner = [(p, [r for r in res.results if r.planner == p]) for p in cfg.planners]
    for model in cfg.models():
        paths.append(plot_efficiency(by_planner, model, out / f"efficiency_{model.name}.png"))
    for by in ("house", "query"):
        rows = breakdown(res.results, by, cfg.planners)
        paths.append(atomic_write(out / f"per_{by}.md", res.breakdown_table(by)))
        paths.append(atomic_write(out / f"per_{by}.jsonl", "".join(
            json.dumps(d, sort_keys=True, allow_nan=False) + "\n"
            for d in breakdown_records(rows, by))))
    md = [res.results_table, res.results_side_by_side, res.seen_table,
          res.interval_tables(), res.breakdown_table("house"), res.breakdown_table("query"),
          *([f"Failed tasks (retried once; their episodes are in no table): "
             f"{len(res.failed)}", *(f"- {line}" for line in res.failed)]
            if res.failed else []),
          *llm_answer_lines(res.results, cfg.planners),
          *invalid_action_notes(res.results, cfg.planners),
          *[f"Note on {h.id} ({h.source}): {line}" for h in res.houses for line in h.notes],
          f"Digest of episodes.jsonl without wall-clock fields: {res.digest}",
          f"sgtool {__version__}; relational priors "
          f"{priors_fingerprint(cfg.priors_dir)}; wall-clock figures and the command in "
          f"run.md"]
    paths.append(atomic_write(out / "summary.md", "\n".join(md) + "\n"))
    # secrets given as options (-O moma-llm.api_key=...) never reach a file
    shown = redact_text(command, secret_values(cfg.planner_options)) if command else ""
    run_md = [res.table,
              f"Episodes per second: one core, episode roll-outs only (house preparation "
              f"excluded); whole run {res.wall_s:.1f} s with {cfg.workers} worker(s) on the "
              f"{cfg.executor} executor.", *([f"Command: `{shown}`"] if shown else []),
              *([f"Tasks that succeeded after an error (retried; their episodes are in the "
                 f"tables): {len(res.retried)}", *(f"- {line}" for line in res.retried)]
                if res.retried else [])]
    paths.append(atomic_write(out / "run.md", "\n".join(run_md) + "\n"))
    sums = summarize(res.results, cfg.models(), cfg.planners)
    summary = {
        "version": BENCH_VERSION,
        "settings": cfg.settings(),
        "budgets": {m.name: {"max": m.max_cost, "cost": m.label} for m in cfg.models()},
        "planners": summary_dict(sums, timing=False),
        "seen_unseen": [asdict(s) for s in seen_unseen(res.results, cfg.planners)],
        "intervals": res.interval_dict(),
        "vocabulary": {"priors": cfg.priors_dir, "training_queries": res.vocabulary_size},
        "houses": [{"id": h.id, "source": h.source, **({"notes": list(h.notes)} if h.notes
                                                       else {})} for h in res.houses],
        "digest": res.digest,
        "failed_tasks": list(res.failed),
        "sgtool_version": __version__,
        "priors_sha256_16": priors_fingerprint(cfg.priors_dir),
    }
    if answers := llm_answer_totals(res.results, cfg.planners):
        summary["llm_answers"] = answers  # only for runs with an LLM planner
    paths.append(atomic_write(
        out / "summary.json",
        json.dumps(strict_json(summary), indent=1, sort_keys=True, allow_nan=False) + "\n"))
    run = {"wall": {"seconds": round(res.wall_s, 3), "workers": cfg.workers,
                    "executor": cfg.executor,
                    "episodes_per_s": {k: float(f"{v:.3g}") for k, v in res.throughput.items()},
                    "decision_s": {p: d["decision_s"]
                                   for p, d in summary_dict(sums).items()}},
           "command": shown, "retried_tasks": list(res.retried)}
    paths.append(atomic_write(
        out / "run.json",
        json.dumps(strict_json(run), indent=1, sort_keys=True, allow_nan=False) + "\n"))
    note_written(out, "bench", [p.name for p in paths])  # (sgtool's, for --force later)
    return paths


def run_bench(planners: Sequence[str] = DEFAULT_PLANNERS, houses: int = 10, episodes: int = 20,
              seeds: int = 5, workers: int = 1, out_dir: str | os.PathLike[str] | None = None,
              rooms: tuple[int, int] = DEFAULT_ROOMS, max_steps: int = 50, house_seed: int = 0,
              planner_options: Mapping[str, Mapping[str, Any]] | None = None,
              progress: bool | None = None, house_files: Sequence[str] = (),
              priors_dir: str | None = None, force: bool = True) -> str:
    """Run the benchmark and return its table text (Table VII shape, then Table IX);
    with ``out_dir``, also write the outputs there (see :func:`write_outputs`), built
    beside it and moved in complete (:func:`sgtool.files.output_folder`): with ``force``
    they replace the outputs of an earlier run there (other files stay), without it a
    non-empty ``out_dir`` is refused."""
    cfg = BenchConfig(planners=tuple(planners), houses=houses, episodes=episodes, seeds=seeds,
                      rooms=(int(rooms[0]), int(rooms[1])), house_seed=house_seed,
                      max_steps=max_steps, workers=workers,
                      planner_options=dict(planner_options or {}),
                      house_files=tuple(map(str, house_files)), priors_dir=priors_dir)
    if out_dir is None:
        res = run_benchmark(cfg, progress=progress)
    else:
        with output_folder(out_dir, force=force, command="bench", known=OUTPUT_NAMES) as out:
            res = run_benchmark(cfg, progress=progress)
            write_outputs(res, out)
    return res.table + "\n" + res.seen_table
