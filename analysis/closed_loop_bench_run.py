"""`sgtool run-bench` after its checks: the closed-loop benchmark written in place into its
folder (episode log by episode log, so that a run cut short resumes; with ``force`` a fresh
run built beside it), then its table shown.

The command checks the options and builds :class:`RunBenchRequest`; the run is
:func:`sgtool.analysis.closed_loop_bench.run_closed_loop_bench`, the folder
:func:`sgtool.files.output_folder`. ``show`` receives the table and the files written.

On an executor (``-w N``, ``--executor ray``) the episodes go through
:class:`EpisodeRunner`: every log reaches the folder as its episode finishes, whichever
machine ran it (a worker that sees the folder writes it there; one on another machine
sends it back, :func:`run_task_on`), so a driver killed at any moment leaves the finished
episodes' logs for the next run to resume from. ``run.json`` records, per episode, whether
it ran now, its wall seconds, the Ray node that ran it (``""``: this machine) and whether
its log was sent back.
"""

from __future__ import annotations

import itertools
import json
import sys
import tempfile
from collections.abc import Callable, Iterable, Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

from sgtool.analysis.closed_loop_bench import (
    ClosedLoopBenchConfig,
    RunRow,
    RunTask,
    log_source,
    stale_curves,
)
from sgtool.analysis.executor import Executor, FolderMark
from sgtool.errors import SgtoolError
from sgtool.results import EpisodeResult

Echo = Callable[[str], None]
RunFn = Callable[[RunTask], RunRow]

# run.json: where and how long each episode of the last run ran (not in summary.*: wall
# clock and placement differ from run to run)
RUN_FILE = "run.json"
RUN_OPTIONS_FILE = "run-options.json"  # the options the run was made with


@dataclass(frozen=True)
class RunBenchRequest:
    """A checked `sgtool run-bench`: the run's ``config`` into ``out_dir`` (``force``: a
    fresh run; ``report_only``: the tables of the logs there, nothing run); the executor
    (:func:`sgtool.analysis.executor.make_executor`); the symbolic rows beside the table:
    ``symbolic`` loaded from ``symbolic_dir``, or run on these episodes when
    ``with_symbolic``; the progress bar (None: when stderr is a terminal)."""

    config: ClosedLoopBenchConfig
    out_dir: str
    force: bool = False
    report_only: bool = False
    progress: bool | None = None
    executor: str = "local"
    workers: int = 1
    ray_address: str | None = None
    symbolic_dir: str | None = None
    symbolic: Sequence[Any] = ()
    with_symbolic: bool = False
    options_text: str | None = None  # RUN_OPTIONS_FILE's text (None: not written)


def run_bench_into(request: RunBenchRequest, show: Echo) -> None:
    """Run (or, resuming, read back) every episode into ``request.out_dir``, add the
    symbolic rows, write the tables and curves, and show the table and the files written;
    Ctrl-C keeps the complete episode logs (with ``force``: the folder as it was)."""
    from tqdm import tqdm

    from sgtool.analysis.closed_loop_bench import OUTPUT_NAMES, run_closed_loop_bench
    from sgtool.analysis.closed_loop_bench import write_outputs as write_tables
    from sgtool.files import atomic_write, output_folder, refuse_input_folder
    from sgtool.leftovers import leftover_notes

    refuse_input_folder(request.out_dir, request.config.house_files, what="--house")
    executor, bars = _executor(request)
    with output_folder(request.out_dir, force=request.force, command="run-bench",
                       known=(*OUTPUT_NAMES, RUN_FILE, RUN_OPTIONS_FILE),
                       resume=True) as root:
        runner = EpisodeRunner(executor, root, progress=bars)
        agreed: list[bool] = []  # the logs there agree with this run's options
        runner.checked = lambda: agreed.append(True)
        show_bar = bars and executor is None
        bar = tqdm(total=None, unit="episode", desc="run-bench", file=sys.stderr,
                   disable=not show_bar, dynamic_ncols=True)
        try:
            res = run_closed_loop_bench(request.config, root, progress=bar,
                                        report_only=request.report_only, runner=runner)
        except KeyboardInterrupt as e:  # the CLI prints the note; exit 130 (143: killed)
            kept = any((root / "logs").rglob("*.mcap")) if (root / "logs").is_dir() else False
            e.note = (f"{request.out_dir} is as it was (--report-only runs nothing)"  # type: ignore[attr-defined]
                      if request.report_only else
                      f"the complete episode logs are kept in {request.out_dir}/logs "
                      "(run the same command again to resume)" if kept else
                      "no episode had finished: no log was kept")
            raise  # (with --force, output_folder says OUT is as it was instead)
        finally:
            bar.close()
            if agreed and not request.report_only:
                _record_options(root, request.options_text, ran=bool(runner.nodes))
        left = unreported(root / "logs", {row.task.output for row in res.rows})
        if left:
            shown = ", ".join(str(p.relative_to(root)) for p in left[:2])
            more = f" and {len(left) - 2} more" if len(left) > 2 else ""
            print(f"sgtool: note: {len(left)} episode log(s) in {request.out_dir}/logs are left "
                  f"out of this report ({shown}{more}): give the --noise profiles, --planners, "
                  "houses and --episodes that ran them to report them", file=sys.stderr)
        if not request.with_symbolic and request.symbolic_dir is None \
                and _had_symbolic(root / "summary.json"):
            print("sgtool: note: the earlier report compared the planners' order with the "
                  "symbolic bench's; this one does not (give --with-symbolic or --symbolic "
                  "DIR again to keep it)", file=sys.stderr)
        try:
            res = _with_symbolic(request, res)
            with _report_stage(root) as stage:  # the report's files go in together
                written = [p.name for p in write_tables(  # (a report keeps the run's run.md)
                    res, stage,
                    timings=not (request.report_only and (root / "run.md").is_file()))]
                if not request.report_only:
                    written.append(atomic_write(stage / RUN_FILE, run_record(
                        res.rows, root, runner, request.executor)).name)
        except KeyboardInterrupt as e:
            e.note = (f"the report files in {request.out_dir} are this run's (they went in "  # type: ignore[attr-defined]
                      "as it was interrupted)" if getattr(e, "report_in", False) else
                      "interrupted before the report was written: the report files in "
                      f"{request.out_dir} are as they were; the same command again writes "
                      "them from the logs (nothing runs again)")
            raise
        for stale in stale_curves(root, [root / n for n in written], res.config):
            stale.unlink()
    show(res.table())
    from sgtool.analysis.report import invalid_action_notes, llm_warnings

    results, planners = res.results(), request.config.planners
    for line in llm_warnings(results, planners):
        show(line)
    for line in invalid_action_notes(results, planners):
        show(f"sgtool: note: {line}")
    show(f"wrote {', '.join(str(Path(request.out_dir) / name) for name in written)}")
    for line in leftover_notes(request.out_dir):
        show(line)


@contextmanager
def _report_stage(root: Path) -> Iterator[Path]:
    """A hidden folder in ``root`` to write a report into; on a clean exit its files move
    into ``root`` with Ctrl-C deferred (an interrupt while they are written leaves the
    earlier report whole, not a mix of two), and it is removed either way."""
    import os
    import shutil

    from sgtool.errors import deferred_interrupts
    from sgtool.files import OutputError, output_error

    for stale in root.glob(".report.*.partial"):  # of a run killed outright (SIGKILL)
        shutil.rmtree(stale, ignore_errors=True)
    try:
        stage = Path(tempfile.mkdtemp(prefix=".report.", suffix=".partial", dir=root))
    except OSError as e:
        raise output_error(e, root) from None
    try:
        yield stage
        try:
            with deferred_interrupts():
                for name in sorted(os.listdir(stage)):
                    os.replace(stage / name, root / name)
        except KeyboardInterrupt as e:  # deferred: raised once every file went in
            e.report_in = True  # type: ignore[attr-defined]
            raise
    except OutputError as e:  # a full disk: the report's file, not the stage's
        raise OutputError(str(e).replace(str(stage), str(root))) from None
    finally:
        shutil.rmtree(stage, ignore_errors=True)


def unreported(logs: Path, reported: set[Path]) -> list[Path]:
    """The episode logs under ``logs`` (a run-bench folder's) that are not ``reported``:
    runs of noise profiles, planners, houses or episodes the report does not name;
    sorted."""
    return sorted(p for p in logs.rglob("ep-*.mcap") if p not in reported) \
        if logs.is_dir() else []


def _executor(request: RunBenchRequest) -> tuple[Executor | None, bool]:
    """(the executor, None to run in this process one after the other; whether to show a
    progress bar: the executor's counts the episodes it runs, else this module's)."""
    show = sys.stderr.isatty() if request.progress is None else request.progress
    parallel = request.executor != "local" or request.workers > 1 or request.ray_address
    if not parallel or request.report_only:
        return None, show
    from sgtool.analysis.executor import make_executor

    return make_executor(request.executor, request.workers, request.ray_address), show


@dataclass(frozen=True)
class Shipped:
    """A task's row and its log's bytes, from a worker that does not see the output
    folder (another machine): the driver writes the log."""

    row: RunRow
    log: bytes


def run_task_on(fn: RunFn, folder: FolderMark, task: RunTask) -> RunRow | Shipped:
    """``fn(task)`` on a worker: into the output folder when the worker sees it
    (:meth:`FolderMark.here`), else into a temporary folder of its own, the log sent back
    (:class:`Shipped`; its row names the log as a run in the folder would:
    :func:`~sgtool.analysis.run_bench_paths.log_source`)."""
    if folder.here():
        return fn(task)
    with tempfile.TemporaryDirectory(prefix="sgtool-run-bench-") as tmp:
        local = replace(task, output=Path(tmp) / task.output.name)
        row = fn(local)
        data = local.output.read_bytes()
    result = replace(row.result, source=log_source(task.output))
    return Shipped(replace(row, task=task, result=result), data)


class EpisodeRunner:
    """``runner(fn, tasks)`` for :func:`~sgtool.analysis.closed_loop_bench.
    run_closed_loop_bench`: the rows in task order. The partial files an earlier, killed
    run left beside a log still to run are removed first. Without an executor the tasks
    run here one after the other (rows as they come). On one, a task whose log is in the
    folder is read back here (a worker elsewhere would not see the log) and every other
    task runs on the executor (:func:`run_task_on`); a log sent back is written
    (atomically) as its task finishes; a task that failed after its retry stops the run
    with one line once all have run (the finished logs stay); Ctrl-C removes the partial
    logs of the tasks not finished (a Ray worker cancelled by force cannot).
    :attr:`nodes` maps each log run now to the Ray node that ran it (``""``: this
    machine); :attr:`sent` holds the logs sent back; :attr:`checked` is called once the
    logs there are read back and agree with their tasks, before any task runs."""

    def __init__(self, executor: Executor | None, root: Path, *,
                 progress: bool = False) -> None:
        self.executor = executor
        self.root = root
        self.progress = progress
        self.nodes: dict[Path, str] = {}
        self.sent: set[Path] = set()
        self.checked: Callable[[], object] | None = None

    def __call__(self, fn: RunFn, items: Iterable[RunTask]) -> Iterator[RunRow]:
        tasks = list(items)
        if self.executor is None:  # the logs there first: a resume refused runs nothing
            logged = [t.output.exists() for t in tasks]
            there = list(self._read_back(fn, [t for t, done in zip(tasks, logged, strict=True)
                                              if done]).values())
            return itertools.chain(there, (self._here(fn, t)
                                           for t, done in zip(tasks, logged, strict=True)
                                           if not done))
        return iter(self._on_executor(self.executor, fn, tasks))

    def _read_back(self, fn: RunFn, tasks: list[RunTask]) -> dict[Path, RunRow]:
        """The rows of the logs already there, in order, each checked against its task
        (a bar while they are read, with ``progress``: a large folder takes a while)."""
        from tqdm import tqdm

        with tqdm(tasks, desc="checking logs there", unit="log", file=sys.stderr,
                  leave=False, disable=not self.progress or not tasks,
                  dynamic_ncols=True) as bar:
            rows = {t.output: fn(t) for t in bar}
        if self.checked is not None:
            self.checked()
        return rows

    def _here(self, fn: RunFn, task: RunTask) -> RunRow:
        if not task.output.exists():
            _remove_partials(task)
            self.nodes[task.output] = ""
        return fn(task)

    def _on_executor(self, executor: Executor, fn: RunFn, tasks: list[RunTask]
                     ) -> list[RunRow]:
        from functools import partial

        from sgtool.analysis.executor import ExecutorError, Outcome, Task, failure_lines
        from sgtool.files import atomic_write

        there = [i for i, t in enumerate(tasks) if t.output.exists()]
        read = self._read_back(fn, [tasks[i] for i in there])
        rows: dict[int, RunRow] = {i: read[tasks[i].output] for i in there}
        todo = [i for i in range(len(tasks)) if i not in rows]
        for i in todo:
            _remove_partials(tasks[i])

        def arrived(out: Outcome) -> None:
            if isinstance(out.value, Shipped):
                task = out.value.row.task
                task.output.parent.mkdir(parents=True, exist_ok=True)
                atomic_write(task.output, out.value.log)
                self.sent.add(task.output)
            if out.ok:
                self.nodes[Path(out.id)] = out.node

        try:
            outcomes = executor.run(
                partial(run_task_on, fn, FolderMark.of(self.root)),
                [Task(str(tasks[i].output), tasks[i]) for i in todo],
                progress=self.progress, desc="run-bench", on_result=arrived)
        except KeyboardInterrupt:  # workers killed outright (Ray) leave their partial logs
            for i in todo:
                if not tasks[i].output.exists():
                    _remove_partials(tasks[i])
            raise
        failed = failure_lines(outcomes)
        if failed:
            raise ExecutorError(f"{len(failed)} of {len(todo)} episode(s) failed; the first: "
                                f"{failed[0]}")
        for i, out in zip(todo, outcomes, strict=True):
            rows[i] = out.value.row if isinstance(out.value, Shipped) else out.value
        return [rows[i] for i in range(len(tasks))]


def _record_options(root: Path, text: str | None, *, ran: bool) -> None:
    """Write :data:`RUN_OPTIONS_FILE` once a run that agreed with the logs there has logs
    to show (a run that wrote nothing, a full disk, leaves no file that makes its folder
    look like a run), and either ``ran`` episodes now or finds no readable such file (a
    resume naming fewer planners reads back and keeps the run's options; a damaged file is
    replaced); best effort while an error is on its way."""
    import contextlib
    import json

    from sgtool.files import atomic_write

    if text is None or not any((root / "logs").rglob("*.mcap")):
        return
    if not ran:
        with contextlib.suppress(OSError, ValueError):
            data, ours = json.loads((root / RUN_OPTIONS_FILE).read_bytes()), json.loads(text)
            if isinstance(data, dict) and isinstance(data.get("options"), dict) and \
                    data.get("format") == ours["format"] and \
                    _same_kinds(data["options"], ours["options"]):
                return
    with contextlib.suppress(OSError):
        atomic_write(root / RUN_OPTIONS_FILE, text)


def _same_kinds(saved: dict[str, Any], ours: dict[str, Any]) -> bool:
    """Whether ``saved`` has every option of ``ours`` with a JSON value of its kind (a
    number for a number, text for text...; None on either side agrees): a file edited
    by hand to ``"episodes": "three"`` is no run's options."""
    def kind(v: Any) -> str:
        return "number" if isinstance(v, int | float) and not isinstance(v, bool) \
            else type(v).__name__
    return all(k in saved and (v is None or saved[k] is None or kind(saved[k]) == kind(v))
               for k, v in ours.items())


def _remove_partials(task: RunTask) -> None:
    """The partial files of ``task``'s log that a killed run left (its writer, killed,
    could not remove them): the log writer's, and the driver's temporary file of a log
    sent back (a driver killed while it wrote one)."""
    from sgtool.leftovers import leftover_temps
    from sgtool.log.writer import partial_files

    for p in [*partial_files(task.output), *leftover_temps(task.output)]:
        p.unlink(missing_ok=True)


def run_record(rows: Sequence[RunRow], root: Path, runner: EpisodeRunner,
               executor: str) -> str:
    """run.json: per episode (report order) its log (relative to ``root``), whether it ran
    now (else it was read back), its wall seconds, the Ray node that ran it and whether
    the log was sent back (``runner``'s records)."""
    episodes = []
    for r in rows:
        log = r.task.output
        episodes.append({"log": log.relative_to(root).as_posix() if log.is_relative_to(root)
                         else str(log), "ran": r.seconds is not None,
                         "seconds": None if r.seconds is None else round(r.seconds, 3),
                         "node": runner.nodes.get(log, ""), "sent": log in runner.sent})
    return json.dumps({"executor": executor, "episodes": episodes}, indent=1,
                      sort_keys=True) + "\n"


def _had_symbolic(summary: Path) -> bool:
    """Whether the ``summary.json`` of an earlier report compared with the symbolic bench
    (False when there is none or it does not read)."""
    try:
        doc = json.loads(summary.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return False
    noise = doc.get("noise") if isinstance(doc, dict) else None
    return isinstance(noise, dict) and any(
        isinstance(v, dict) and "symbolic_agreement" in v for v in noise.values())


def _with_symbolic(request: RunBenchRequest, res: Any) -> Any:
    """``res`` with the symbolic rows: run on these episodes, or loaded from a folder."""
    from sgtool.analysis.closed_loop_bench import run_symbolic

    if request.with_symbolic:
        return replace(res, symbolic=run_symbolic(request.config),
                       symbolic_source="the symbolic bench on these episodes, 1 seed")
    if request.symbolic_dir is not None:
        return replace(res, symbolic=request.symbolic,
                       symbolic_source=f"--symbolic {request.symbolic_dir}")
    return res


def load_symbolic(path: str | Path) -> tuple[EpisodeResult, ...]:
    """The episodes of a symbolic bench (``sgtool bench``): its output folder or its
    ``episodes.jsonl``; a one-line :class:`~sgtool.errors.SgtoolError` when there are none
    or they are a closed loop's (a run-bench folder: its own order, tau 1)."""
    from sgtool.results import read_jsonl

    p = Path(path)
    file = p / "episodes.jsonl" if p.is_dir() else p
    if not file.is_file():
        raise SgtoolError(f"--symbolic {path}: no episodes.jsonl of a `sgtool bench` there")
    results = tuple(read_jsonl(file))
    if not results:
        raise SgtoolError(f"--symbolic {path}: holds no episode")
    if other := next((r.source for r in results if r.source != "symbolic"), None):
        raise SgtoolError(f"--symbolic {path}: episodes of logs (source {other}), not of a "
                          "`sgtool bench` (a run-bench's or an eval's); give a bench's folder")
    return results
