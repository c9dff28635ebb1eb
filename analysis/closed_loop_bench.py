"""The closed-loop benchmark (``sgtool run-bench``): N episodes x planners x noise profiles
in PyBullet, one episode log per run, and the table of the symbolic bench.

Houses are those of ``sgtool bench`` (:mod:`sgtool.analysis.bench_houses`): generated ones
(``house-<seed>``, the generator ``preset``) and given files; episodes are the bench's
(:func:`~sgtool.analysis.bench_houses.bench_episodes`: the first ``episodes`` of the same
draw, so a house's episodes are those of the symbolic bench). Every (noise, planner,
house, episode) is one :class:`RunTask`; :func:`run_task` runs it into its own log,
``LOGS/NOISE/PLANNER/HOUSE/ep-K.mcap``, and returns a :class:`RunRow` read back from that
log (:func:`sgtool.analysis.offline.read_log_episodes`), so a fresh run and a resumed one
give the same row (a resumed log's SPL shortest path measured as a new run measures it,
:mod:`sgtool.recorders.sim.spl_shortest`). A log that exists is complete (the writer renames
its partial file only at the end), so a task whose log exists is not run again: the
benchmark resumes. Ctrl-C stops the run and removes the interrupted episode's partial file.

:func:`run_task` takes everything it needs and returns a plain row, so executors can
spread tasks over processes or machines (:func:`run_closed_loop_bench` takes a ``runner``,
``map`` by default, that maps ``run_task`` over the tasks in order).

The outputs (:func:`write_outputs`): ``episodes.jsonl`` (the
:class:`~sgtool.results.EpisodeResult` of every run, its ``source`` the log relative to the
folder: :func:`log_source`), ``summary.md`` (per noise profile: SR / SPL / steps / AUC-E
as the symbolic bench, then failed skills per episode by reason; then the statistics that
separate planners, :mod:`sgtool.analysis.closed_loop_tables`: SR and SPL with bootstrap
intervals over houses, paired comparisons over houses and per house, SR against the frame
budget per room with AUC-E on frames, and, with symbolic bench results, Kendall's tau
between the two planner orders), ``summary.json`` (the same statistics as numbers),
``run.md`` (wall-clock figures: decision time, frames per second) and the efficiency curves
per noise profile (distance, steps and frames per room).
"""

from __future__ import annotations

import json
import math
import re
import statistics
from collections import Counter
from collections.abc import Callable, Iterable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

from sgtool.analysis.bench_houses import (
    BenchHouse,
    HouseFilesError,
    bench_episodes,
    generated_houses,
    load_house_files,
)
from sgtool.analysis.bench_planner_checks import (
    check_budgets,
    check_house_seeds,
    check_planner_options,
    check_plugins_build,
    config_names,
    config_planner_options,
    config_rooms,
    recorded_planner_options,
)
from sgtool.analysis.closed_loop_tables import (
    budget_comparisons,
    format_agreement,
    format_frame_curves,
    frame_curves,
    frames_model,
    interval_tables,
    reason_class,
    symbolic_agreement,
)
from sgtool.analysis.offline import executor_message, log_exchanges, read_log_episodes, with_seen
from sgtool.analysis.report import format_table, llm_answer_lines, pipe_table
from sgtool.analysis.run_bench_paths import log_path, log_source, noise_folder
from sgtool.analysis.run_bench_resume import (
    ResumeError,
    check_resumable,
    episode_identity,
    task_settings,
)
from sgtool.analysis.search_metrics import CostModel, cost_models, summarize
from sgtool.arg_checks import of_type, whole
from sgtool.arg_checks import progress as check_progress
from sgtool.canonical import strict_json
from sgtool.errors import SgtoolError
from sgtool.extras import require
from sgtool.files import atomic_write, output_dir, remove_empty_folders
from sgtool.llm.stats import answer_counts
from sgtool.log.writer import partial_files
from sgtool.progress import Progress
from sgtool.recorders.sim.closed_loop import WENT_ON, ClosedLoopOptions, run_episode
from sgtool.recorders.sim.fallback_explore import is_fallback
from sgtool.recorders.sim.frame_budget import frame_budget
from sgtool.recorders.sim.noise import NoiseProfile, names_file, parse_noise
from sgtool.recorders.sim.spl_shortest import driven_shortest
from sgtool.results import EpisodeResult, write_jsonl

# what maps run_task over the tasks: map (in order, here) or an executor's runner
Runner = Callable[[Callable[["RunTask"], "RunRow"], Iterable["RunTask"]], Iterable["RunRow"]]


@dataclass(frozen=True)
class ClosedLoopBenchConfig:
    """What ``sgtool run-bench`` runs: ``episodes`` per house of ``planners`` in closed loop
    (PyBullet), on ``houses`` generated houses (seeds from ``house_seed``, ``rooms`` (MIN,
    MAX), ``preset``) and the ``house_files`` after them, once per sensor ``noise`` profile,
    each with the closed-loop ``options`` and its ``planner_options``; the tables price
    ``frames_per_room`` (None: the most any episode used), ``distance_budget`` and
    ``step_budget``, and compare planners against ``reference`` (or every pair). A planner
    name, a house file or a noise profile given alone is a list of one; :meth:`check` says
    in one line what cannot work."""

    planners: tuple[str, ...] | str  # a tuple once made (a name alone: a list of one)
    houses: int = 5  # generated houses, seeds house_seed, +1, ...
    house_seed: int = 0
    house_files: tuple[str, ...] | str = ()
    episodes: int = 6  # per house
    rooms: tuple[int, int] = (12, 16)
    preset: str = "symsearch"
    noise: tuple[str, ...] | str = ("none",)  # noise profiles (`sgtool record --noise` syntax)
    options: ClosedLoopOptions = field(default_factory=ClosedLoopOptions)
    planner_options: Mapping[str, Mapping[str, Any]] = field(default_factory=dict, repr=False)
    frames_per_room: int | None = None  # frame budget per room (excludes options.frames)
    distance_budget: float = 5000.0
    step_budget: float = 50.0
    reference: str | None = None  # paired comparisons against it (None: scout, else first)
    all_pairs: bool = False  # paired comparisons of every pair of planners instead
    budgets: tuple[float, ...] = ()  # f/room of the SR tables (empty: quarters of the most used)

    def __post_init__(self) -> None:
        object.__setattr__(self, "planner_options",
                           config_planner_options(self.planner_options))
        for name in ("planners", "noise"):
            object.__setattr__(self, name, config_names(getattr(self, name), name))
        try:  # (a list from Python, numbers as text)
            object.__setattr__(self, "budgets", tuple(float(b) for b in self.budgets))
        except (TypeError, ValueError):
            raise SgtoolError(f"budgets: frames per room, numbers; got {self.budgets!r}") from None
        object.__setattr__(self, "house_files",
                           config_names(self.house_files, "house_files", paths=True))
        object.__setattr__(self, "rooms", config_rooms(self.rooms))

    def check(self, *, planners: bool = True) -> None:
        """One line for what is wrong; ``planners=False`` leaves the planners and their
        options unasked (a report of logs run already: a plug-in need not import)."""
        from sgtool.analysis.bench_planner_checks import check_planner_list, check_reference

        for name in ("houses", "episodes", "frames_per_room"):  # "2" or 2.5: one line
            whole(name, getattr(self, name), optional=name == "frames_per_room")
        if planners:
            check_planner_list(self.planners)
        if len(set(self.planners)) != len(self.planners) or \
                len(set(self.noise)) != len(self.noise):
            raise SgtoolError("--planners/--noise: a name is given twice")
        if any(not (math.isfinite(b) and b > 0) for b in self.budgets):
            raise SgtoolError(f"--budgets: frames per room, finite numbers > 0, got "
                              f"{', '.join(f'{b:g}' for b in self.budgets)}")
        if len(set(self.budgets)) != len(self.budgets):
            raise SgtoolError(f"--budgets: a budget is given twice "
                              f"({', '.join(f'{b:g}' for b in self.budgets)})")
        check_reference(self.reference, self.all_pairs, self.planners)
        if planners:
            check_planner_options(self.planners, self.planner_options, one_writer=True)
        if self.episodes < 1:
            raise SgtoolError(f"--episodes: must be >= 1, got {self.episodes}")
        if self.houses < 0 or (self.houses == 0 and not self.house_files):
            raise SgtoolError(f"--houses: must be >= 1, or >= 0 with --house (house_files=), got "
                              f"{self.houses}")
        check_house_seeds(self.house_seed, self.houses)
        check_budgets(self.distance_budget, self.step_budget)
        of_type("options", self.options, ClosedLoopOptions, "a ClosedLoopOptions")
        folders, faults = dict[str, str](), dict[NoiseProfile, str]()
        for n in self.noise:
            profile = replace(parse_noise(n), name="")
            folder = noise_folder(n)
            if not re.fullmatch(r"[A-Za-z0-9_.=,+-]+", folder) or set(folder) == {"."}:
                what = "the profile's name" if names_file(n) else "a profile name with overrides"
                raise SgtoolError(f"--noise {n!r}: {what} (letters, digits, _ . = , + -) "
                                  f"names a log folder, not {folder!r}")
            if folder in folders:
                raise SgtoolError(f"--noise {folders[folder]!r} and {n!r}: both name the log "
                                  f"folder {folder!r}")
            folders[folder] = n
            same = faults.setdefault(profile, n)
            if same != n:  # two spellings of one profile would run it twice, apart
                raise SgtoolError(f"--noise {same!r} and {n!r}: the same faults; give one")
        self.options.mapping()
        frame_budget(self.options.frames, self.frames_per_room, 1)


@dataclass(frozen=True)
class RunTask:
    """One closed-loop episode to run: everything :func:`run_task` needs."""

    house: BenchHouse
    episode: int
    planner: str
    noise: str
    output: Path
    options: ClosedLoopOptions
    planner_options: Mapping[str, Any]
    rooms: tuple[int, int]
    preset: str
    episodes: int  # the house's episodes in the run: the draw ``episode`` is taken from
    frames_per_room: int | None = None  # the frame budget per room of the house (or none)


@dataclass(frozen=True)
class RunRow:
    """The result of one task: the episode's result, read back from its log, plus the
    frames, the wall seconds of the run (None when the log was already there), the
    failed skills by reason class, the goals of the robot's own exploration when the
    graph offered the planner nothing (:mod:`sgtool.recorders.sim.fallback_explore`) and
    the frontiers an explore that showed nothing new went on to (``went_on``)."""

    task: RunTask
    result: EpisodeResult
    frames: int
    seconds: float | None
    failures: Mapping[str, int]
    fallbacks: int = 0
    went_on: int = 0


# the house and its episodes per house and draw, per process: houses a worker keeps (a
# house is rebuilt when a run of more houses comes back to it, a small cost beside its
# closed-loop episode)
DRAWS_KEPT = 16
_DRAWS: dict[tuple[Any, ...], tuple[Any, list[Any]]] = {}


def house_episodes(task: RunTask) -> tuple[Any, list[Any]]:
    """The house's spec and its episodes of the run: the bench's draw of ``task.episodes``
    (the draw depends on its size, so this is what makes them the symbolic bench's
    episodes)."""
    key = (task.house, task.rooms, task.preset, task.episodes)  # a file's spec, too
    if key not in _DRAWS:
        spec = task.house.load(task.rooms, task.preset)
        mix = task.preset if task.house.spec is None else "default"
        if len(_DRAWS) >= DRAWS_KEPT:  # the oldest goes: tasks come episode by episode,
            del _DRAWS[next(iter(_DRAWS))]  # cycling through the run's houses
        _DRAWS[key] = (spec, bench_episodes(spec, task.episodes, mix))
    return _DRAWS[key]


def task_options(task: RunTask) -> ClosedLoopOptions:
    """The task's options with its frame budget resolved (per room of its house)."""
    if task.frames_per_room is None:
        return task.options
    rooms = len(house_episodes(task)[0].rooms)
    return replace(task.options, frames=frame_budget(task.options.frames,
                                                     task.frames_per_room, rooms))


def run_task(task: RunTask) -> RunRow:
    """Run one task into its log (unless the log is there already) and read its row back.
    Ctrl-C removes the partial log and re-raises."""
    from sgtool.planning.registry import make_planner
    from sgtool.planning.timing import PlannerContractError

    seconds: float | None = None
    if not task.output.exists():
        spec, eps = house_episodes(task)
        if task.episode >= len(eps):
            raise SgtoolError(f"{task.house.id}: has {len(eps)} episodes, not {task.episode + 1}")
        opts = replace(task_options(task), noise=parse_noise(task.noise))
        task.output.parent.mkdir(parents=True, exist_ok=True)
        try:
            rep = run_episode(spec, eps[task.episode],
                              make_planner(task.planner, **dict(task.planner_options)),
                              task.output, opts, house_id=task.house.id,
                              episode_index=task.episode,
                              planner_options=dict(task.planner_options))
        except KeyboardInterrupt:
            for p in partial_files(task.output):
                p.unlink(missing_ok=True)
            raise
        except PlannerContractError as e:  # a plug-in's fault: where, and that it resumes
            raise PlannerContractError(f"{e} ({task.house.id}, episode {task.episode}; the "
                                       "logs written are kept: run again, it resumes)") from None
        seconds = rep.seconds
    return _row(task, seconds)


def _row(task: RunTask, seconds: float | None) -> RunRow:
    if seconds is None:  # a log that was there: run with these settings, on this house?
        spec, eps = house_episodes(task)
        want = episode_identity(eps[task.episode]) if task.episode < len(eps) else None
        check_resumable(task.output, task_settings(task_options(task), task.noise, want,
                                                    dict(task.planner_options)),
                        spec, task.house.source if task.house.spec is not None
                        else task.house.id, task.planner)
    logged = read_log_episodes(task.output)
    if len(logged) != 1 or not logged[0].closed:  # (closed: not `doctor --recover`ed)
        what = (f"holds {len(logged)} episodes, not one" if len(logged) != 1 else "its "
                "episode has no closing record (a log recovered from a killed run?)")
        raise SgtoolError(f"{task.output}: {what}; delete it to run the episode again")
    ep = logged[0]
    res = replace(with_seen(ep.result()), seed=task.options.planner_seed,
                  source=log_source(task.output),
                  llm_answers=answer_counts(rec for _, rec in log_exchanges([task.output])))
    if seconds is None and task.episode < len(eps):  # SPL's shortest as it is measured now
        res = replace(res, shortest_m=driven_shortest(spec, eps[task.episode]))
    fails = Counter(reason_class(executor_message(d.action)) for d in ep.decisions
                    if d.action.outcome == "failure")
    reasons = [d.action.reason or "" for d in ep.decisions]
    went_on = sum(1 for r in reasons if r.startswith(WENT_ON))
    fallbacks = sum(1 for r in reasons if is_fallback(r))
    return RunRow(task, res, int(ep.episode.frames or 0), seconds, dict(sorted(fails.items())),
                  fallbacks, went_on)


def bench_houses(cfg: ClosedLoopBenchConfig) -> tuple[BenchHouse, ...]:
    gen = generated_houses(cfg.houses, cfg.house_seed)
    return gen + load_house_files(cfg.house_files, taken=[h.id for h in gen])


def tasks_of(cfg: ClosedLoopBenchConfig, logs: Path) -> list[RunTask]:
    """Every (noise, episode, house, planner) of the run, in that nesting order: episode k
    of every house before episode k + 1, each with all planners, so a run cut short has
    compared the planners on the same episodes, spread over all houses. The outputs list
    them house by house (:func:`report_order`)."""
    houses = bench_houses(cfg)
    out = []
    for noise in cfg.noise:
        for k in range(cfg.episodes):
            for h in houses:
                for planner in cfg.planners:
                    out.append(RunTask(h, k, planner, noise,
                                       log_path(logs, noise, planner, h.id, k), cfg.options,
                                       dict(cfg.planner_options.get(planner, {})),
                                       cfg.rooms, cfg.preset, cfg.episodes,
                                       cfg.frames_per_room))
    return out


@dataclass(frozen=True)
class ClosedLoopBenchResult:
    """The rows of a run, and optionally the episodes of a symbolic bench to compare the
    planner order with (``symbolic``, from ``symbolic_source``); ``missing``: the episodes
    of the config without a log (a report of a run cut short)."""

    config: ClosedLoopBenchConfig
    rows: tuple[RunRow, ...]
    symbolic: tuple[EpisodeResult, ...] = ()
    symbolic_source: str = ""
    missing: int = 0

    def results(self, noise: str | None = None) -> list[EpisodeResult]:
        return [r.result for r in self.rows if noise is None or r.task.noise == noise]

    def frames_model(self, noise: str) -> CostModel:
        """Frames per room of the house, per episode of ``noise``
        (:func:`~sgtool.analysis.closed_loop_tables.frames_model`)."""
        rooms: dict[str, int] = {}
        per_room = {}
        for r in self.rows:
            if r.task.noise != noise:
                continue
            if r.task.house.id not in rooms:
                rooms[r.task.house.id] = max(1, len(house_episodes(r.task)[0].rooms))
            per_room[r.result.key()] = r.frames / rooms[r.task.house.id]
        budget: float | None = self.config.frames_per_room
        frames = self.config.options.frames
        if budget is None and frames is not None and rooms:  # --frames F: F / rooms at most
            budget = max(frames / n for n in rooms.values())
        return frames_model(per_room, None if budget is None else float(budget))

    def statistics(self, noise: str) -> tuple[str, dict[str, Any]]:
        """The tables that separate planners under ``noise`` (module doc): text, dict."""
        cfg = self.config
        results = self.results(noise)
        text, data = interval_tables(results, cfg.planners, cfg.reference, cfg.all_pairs)
        model = self.frames_model(noise)
        budgets, curves = frame_curves(results, cfg.planners, model, sorted(cfg.budgets))
        within, within_data = budget_comparisons(results, cfg.planners, model, budgets,
                                                 cfg.reference, cfg.all_pairs)
        parts = [text, format_frame_curves(
            budgets, curves, title="SR against the frame budget (frames per room)",
            max_cost=model.max_cost), within]
        data["frames"] = {"max_per_room": model.max_cost,
                          "budgets_per_room": list(budgets),
                          "planners": {c.planner: {"auc_e": round(c.auc_e, 6),
                                                   "sr_within": [round(v, 6)
                                                                 for v in c.sr_within]}
                                       for c in curves},
                          "paired_sr_diff": within_data}
        if self.symbolic:
            matched, taus = symbolic_agreement(results, self.symbolic, cfg.planners)
            parts.append(format_agreement(matched, len(self.symbolic), taus,
                                          self.symbolic_source))
            data["symbolic_agreement"] = {"source": self.symbolic_source,
                                          "matched_episodes": matched,
                                          "kendall": [t.to_dict() for t in taus]}
        return "\n".join(parts), data

    def table(self) -> str:
        """summary.md, per noise profile: the bench table, failed skills by reason and the
        statistics that separate planners; no wall-clock figure (:meth:`timings`)."""
        cfg = self.config
        models = cost_models(cfg.distance_budget, cfg.step_budget)
        parts = []
        rule = "; success only on done() (MoMa-LLM)" if cfg.options.success == "done" else ""
        if self.missing:
            parts.append(f"**Incomplete: {self.missing} of {self.missing + len(self.rows)} "
                         "episodes have no log** (a run cut short?): the planners' rows may "
                         "cover different episodes; `sgtool run-bench` with the same options "
                         "finishes the run.\n")
        for noise in cfg.noise:
            rows = [r for r in self.rows if r.task.noise == noise]
            parts.append(format_table(summarize([r.result for r in rows], models,
                                                cfg.planners), models=models, timing=False,
                                      title=f"## Closed loop, noise "
                                            f"{noise_folder(noise)!r}{rule}"))
            parts.append(_run_table(rows, cfg.planners))
            parts.append(self.statistics(noise)[0])
            if answers := llm_answer_lines([r.result for r in rows], cfg.planners):
                parts.append("\n".join(answers) + "\n")
        return "\n".join(parts)

    def timings(self) -> str:
        """run.md, per noise profile: the wall-clock figures, which differ between two
        runs: the decision times as the logs recorded them, and the frames per second of
        the episodes run now."""
        cfg = self.config
        models = cost_models(cfg.distance_budget, cfg.step_budget)
        parts = []
        for noise in cfg.noise:
            rows = [r for r in self.rows if r.task.noise == noise]
            parts.append(format_table(summarize([r.result for r in rows], models,
                                                cfg.planners), models=models,
                                      title=f"## Closed loop, noise {noise_folder(noise)!r}"))
            parts.append(_frame_rates(rows, cfg.planners))
        return "\n".join(parts)

    def summary(self) -> dict[str, Any]:
        """summary.json: per noise profile the statistics of :meth:`statistics`, and the
        settings ``sgtool eval`` re-scores and compares runs by (:mod:`.eval_settings`)."""
        cfg = self.config
        settings = {"planners": list(cfg.planners), "max_steps": cfg.options.max_steps,
                    "distance_budget": cfg.distance_budget, "step_budget": cfg.step_budget,
                    "planner_options": recorded_planner_options(cfg.planner_options)}
        return {"planners": list(cfg.planners), "settings": settings,
                "noise": {noise_folder(n): self.statistics(n)[1] for n in cfg.noise},
                **({"missing_episodes": self.missing} if self.missing else {})}


def _run_table(rows: Sequence[RunRow], planners: Sequence[str]) -> str:
    classes = sorted({k for r in rows for k in r.failures})
    header = ["Planner", "Episodes", "Frames/ep", "Ended", "Fallback/ep", "Went on/ep",
              "Failed skills/ep", *classes]
    table = []
    for p in planners:
        rs = [r for r in rows if r.task.planner == p]
        if not rs:
            continue
        n = len(rs)
        ends = Counter(r.result.end for r in rs)
        total = sum(sum(r.failures.values()) for r in rs)
        table.append([p, str(n), f"{statistics.mean(r.frames for r in rs):.0f}",
                      ", ".join(f"{k} {v}" for k, v in sorted(ends.items())),
                      f"{sum(r.fallbacks for r in rs) / n:.2f}",
                      f"{sum(r.went_on for r in rs) / n:.2f}", f"{total / n:.2f}",
                      *(f"{sum(r.failures.get(c, 0) for r in rs) / n:.2f}" for c in classes)])
    return (pipe_table(header, table) + "\nFallback/ep: goals per episode of the robot's own "
            "exploration when the graph offered the planner nothing; Went on/ep: frontiers "
            "per episode an explore that showed no new object, door or room went on to; "
            "failed skills per episode by reason.\n")


def _frame_rates(rows: Sequence[RunRow], planners: Sequence[str]) -> str:
    table = []
    for p in planners:
        if not any(r.task.planner == p for r in rows):
            continue
        timed = [r for r in rows if r.task.planner == p and r.seconds]
        seconds = sum(r.seconds or 0 for r in timed)
        fps = f"{sum(r.frames for r in timed) / seconds:.1f}" if timed else "-"
        table.append([p, str(len(timed)), fps])
    return (pipe_table(["Planner", "Episodes run now", "Frames/s"], table)
            + "\nFrames/s: wall clock of the episodes run now (resumed ones excluded).\n")


def iter_rows(tasks: Iterable[RunTask], runner: Runner = map) -> Iterator[RunRow]:
    return iter(runner(run_task, tasks))


def run_closed_loop_bench(cfg: ClosedLoopBenchConfig, out_dir: str | Path,
                          progress: Progress | None = None, runner: Runner = map,
                          report_only: bool = False) -> ClosedLoopBenchResult:
    """Run (or resume) the benchmark into ``out_dir``/logs; ``progress`` is advanced per
    episode (a tqdm bar's ``total`` is set to the episodes). ``runner`` maps
    :func:`run_task` over the tasks (``map``: one after the other, here). ``report_only``:
    run nothing, read back the episodes whose logs are there (a run cut short too)."""
    cfg.check(planners=not report_only)  # a report imports no plug-in
    progress = check_progress("progress", progress)
    if not report_only:  # one line on a core install, before any folder is made
        require("pybullet", api="sgtool.run_closed_loop_bench")
        check_plugins_build(cfg.planners, cfg.planner_options)
    logs = (Path(out_dir) if report_only else output_dir(out_dir)) / "logs"
    try:
        tasks = tasks_of(cfg, logs)
    except HouseFilesError as e:
        if not report_only or all(Path(p).exists() for p in cfg.house_files):
            raise
        raise HouseFilesError(f"{e}\n--report-only: the run's house files are not where "
                              "it read them; give --house with their place now") from None
    expected = len(tasks)
    if report_only:
        tasks = [t for t in tasks if t.output.exists()]
        if not tasks:
            raise SgtoolError(f"no episode log of these planners, houses and episodes in "
                              f"{logs}: give the options the run was made with")
    if progress is not None and hasattr(progress, "total"):
        progress.total = len(tasks)
    rows = []
    try:
        for row in iter_rows(tasks, runner):
            rows.append(row)
            if progress is not None:
                progress.update(1)
    except BaseException as e:
        if report_only and isinstance(e, ResumeError):  # nothing to run again
            how = ("it needs the sgtool it was run with (the per-frame drift model: "
                   "before 992f26a)" if "pose drift model" in e.problem
                   else "give the options the run was made with")
            raise ResumeError(f"{e.problem}; --report-only: {how}") from None
        if not report_only:  # the folders of logs never written (a planner that raised)
            remove_empty_folders(logs)
        raise
    return ClosedLoopBenchResult(cfg, tuple(sorted(rows, key=report_order(cfg, tasks))),
                                 missing=expected - len(rows))


def report_order(cfg: ClosedLoopBenchConfig,
                 tasks: Sequence[RunTask]) -> Callable[[RunRow], tuple[int, int, int, int]]:
    """The sort key of the outputs: noise, house, episode, planner, each in run order."""
    house_rank: dict[str, int] = {}
    for t in tasks:
        house_rank.setdefault(t.house.id, len(house_rank))

    def key(row: RunRow) -> tuple[int, int, int, int]:
        t = row.task
        return (cfg.noise.index(t.noise), house_rank[t.house.id], t.episode,
                cfg.planners.index(t.planner))
    return key


# the names of a run-bench folder's entries (what ``--force`` may replace, and what marks a
# folder without a manifest as a run-bench folder: :func:`sgtool.files.output_folder`)
OUTPUT_NAMES: tuple[str, ...] = ("logs", "episodes.jsonl", "summary.md", "summary.json",
                                 "run.md", "efficiency_*.png")


def write_outputs(res: ClosedLoopBenchResult, out_dir: str | Path,
                  timings: bool = True) -> list[Path]:
    """summary.md, summary.json (no wall-clock figure: two runs give the same bytes),
    episodes.jsonl (the same but its measured ``wall`` fields), run.md (decision times,
    frames/s; not with ``timings`` False: a report of logs run earlier keeps the run's
    own), the efficiency curves per noise profile (distance, steps, frames per room; those
    of other profiles, an earlier run's, are removed), each written atomically."""
    from sgtool.analysis.curves import plot_efficiency

    out = output_dir(out_dir)
    cfg = res.config
    paths = [write_jsonl(res.results(), out / "episodes.jsonl")]
    for noise in cfg.noise:
        by_planner = [(p, [r for r in res.results(noise) if r.planner == p])
                      for p in cfg.planners]
        for model in (*cost_models(cfg.distance_budget, cfg.step_budget),
                      res.frames_model(noise)):
            paths.append(plot_efficiency(by_planner, model,
                                         out / f"efficiency_{noise_folder(noise)}_"
                                         f"{model.name}.png"))
    for stale in stale_curves(out, paths, cfg):
        stale.unlink()
    paths.append(atomic_write(out / "summary.md", res.table()))
    if timings:
        paths.append(atomic_write(out / "run.md", res.timings()))
    paths.append(atomic_write(out / "summary.json", json.dumps(
        strict_json(res.summary()), indent=1, sort_keys=True, allow_nan=False) + "\n"))
    return paths


def stale_curves(out: Path, written: Sequence[Path], cfg: ClosedLoopBenchConfig) -> list[Path]:
    """The efficiency curves in ``out`` that are not ``written``: another profile's."""
    models = {m.name for m in cost_models(cfg.distance_budget, cfg.step_budget)} | {"frames"}
    return sorted(p for p in set(out.glob("efficiency_*_*.png")) - set(written)
                  if p.stem.rpartition("_")[2] in models)


def run_symbolic(cfg: ClosedLoopBenchConfig) -> tuple[EpisodeResult, ...]:
    """The symbolic bench (one seed) on the run's houses and episodes, with its planners,
    step budget and success rule: the symbolic order on the same episodes."""
    from sgtool.analysis.bench import BenchConfig, run_benchmark

    bench = BenchConfig(planners=cfg.planners, houses=cfg.houses, episodes=cfg.episodes,
                        seeds=1, rooms=cfg.rooms, preset=cfg.preset, house_seed=cfg.house_seed,
                        max_steps=cfg.options.max_steps, planner_options=cfg.planner_options,
                        house_files=cfg.house_files, success=cfg.options.success)
    return run_benchmark(bench, progress=False).results  # a failed task raises
