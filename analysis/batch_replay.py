"""Replaying many logs into a folder on an executor (``sgtool replay LOG... --out-dir DIR``).

Every input log ``NAME.mcap`` gives ``DIR/NAME.mcap``, the same bytes as
``sgtool replay NAME.mcap -o DIR/NAME.mcap`` with the same options (a replay depends on the
input bytes and the options only). Two inputs with one name are refused before anything
runs. An output that is already complete (it opens as a log, and its ``sgtool.replay``
metadata holds the options this run would use) is skipped unless ``force``.

Each log is one task of :mod:`sgtool.analysis.executor`: the worker replays into its own
temporary folder and returns the derived log's bytes, which this process writes
atomically (:func:`sgtool.files.atomic_write`) as each task finishes, so the output folder
only ever holds complete logs (no shared folder is needed on a cluster for the outputs;
the workers must be able to read the inputs). A log whose replay fails twice is reported
with its error and gets no output; the others are written all the same.

:func:`replay_into` is the command's whole run on the output folder
(:func:`sgtool.files.output_folder`): a new folder, or one an earlier ``--out-dir`` run
wrote, is written in place, log by log, so that a run cut short is taken up again by the
same command; another non-empty folder is refused unless ``force``; with ``force`` every
log is replayed again into a folder beside the target, moved in complete (replacing what
sgtool wrote there, keeping other files), and Ctrl-C leaves the target as it was.
"""

from __future__ import annotations

import os
import tempfile
import time
from collections.abc import Sequence
from dataclasses import dataclass
from dataclasses import replace as replace_field
from pathlib import Path

from sgtool.analysis.batch_inputs import expand_inputs
from sgtool.analysis.executor import Executor, LocalExecutor, Outcome, RayExecutor, Task
from sgtool.arg_checks import of_type
from sgtool.errors import SgtoolError
from sgtool.files import atomic_write, output_folder, sha256_file
from sgtool.log.reader import LogReader
from sgtool.replayers.derived_log import (
    REPLAY_METADATA,
    ReplayOptions,
    replay,
    replay_metadata,
    resolve_options,
)


@dataclass(frozen=True)
class ReplayJob:
    """One log to replay into ``output``."""

    input: str
    output: str
    options: ReplayOptions
    verify: bool = False  # check the input's chunk CRCs as it is read


@dataclass(frozen=True)
class Replayed:
    """What a worker sends back: the derived log and its counts."""

    frames: int
    refreshes: int
    data: bytes


@dataclass(frozen=True)
class LogResult:
    """One input's fate: ``replayed``, ``skipped`` (complete already) or ``failed``."""

    input: str
    output: str
    status: str
    frames: int = 0
    refreshes: int = 0
    error: str | None = None

    def line(self) -> str:
        if self.status == "replayed":
            return f"wrote {self.output}: {self.frames} frames, {self.refreshes} refreshes"
        if self.status == "skipped":
            return f"kept {self.output}: complete already (--force replays it again)"
        return f"failed {self.input}: {self.reason}"

    @property
    def reason(self) -> str:
        """The error without the input's path it may start with (named beside it)."""
        err = self.error or ""
        return err.removeprefix(f"{self.input}: ")


@dataclass(frozen=True)
class BatchReport:
    """What a batch replay did: one :class:`LogResult` per input, in input order, and
    the run's wall-clock seconds; :meth:`lines` says it as the command prints it."""

    logs: tuple[LogResult, ...]
    seconds: float  # wall clock of the run (reported, never written)

    def count(self, status: str) -> int:
        return sum(r.status == status for r in self.logs)

    def lines(self) -> list[str]:
        done = self.count("replayed")
        rate = done / self.seconds * 60 if self.seconds > 0 else 0.0
        return [r.line() for r in self.logs] + [
            f"{done} replayed, {self.count('skipped')} skipped, {self.count('failed')} failed "
            f"in {self.seconds:.1f} s ({rate:.1f} logs/minute)"]


def plan_jobs(inputs: Sequence[Path], out_dir: Path, options: ReplayOptions, *,
              verify: bool = False) -> list[ReplayJob]:
    """One job per input, ``DIR/<input name>`` (``.mcap``); one line when two inputs share
    a name or an input lies where its output would go."""
    jobs: list[ReplayJob] = []
    by_name: dict[str, Path] = {}
    for src in inputs:
        name = src.stem + ".mcap"
        if name in by_name:
            raise SgtoolError(f"{by_name[name]} and {src} would both be replayed into "
                              f"{out_dir / name}; replay them into different folders")
        by_name[name] = src
        dst = out_dir / name
        if dst.exists() and dst.resolve() == src.resolve():
            raise SgtoolError(f"--out-dir {out_dir}: holds the input {src}; the outputs "
                              "must not overwrite the inputs")
        jobs.append(ReplayJob(str(src), str(dst), options, verify))
    return jobs


def is_complete(job: ReplayJob) -> bool:
    """The output exists, opens as a log, and was replayed from this input (its sha256)
    with the options this job would use."""
    dst = Path(job.output)
    if not dst.is_file():
        return False
    try:
        with LogReader(dst) as done:
            meta = done.metadata.get(REPLAY_METADATA)
        with LogReader(job.input) as src:
            wanted = replay_metadata(resolve_options(src, job.options), job.options.tf_time,
                                     sha256_file(job.input))
    except (SgtoolError, OSError):  # the input's frames unreadable: the job says why
        return False
    return meta == wanted


def replay_job(job: ReplayJob) -> Replayed:
    """Replay one log into a temporary folder of this worker; the derived log's bytes."""
    with tempfile.TemporaryDirectory(prefix="sgtool-replay-") as tmp:
        out = Path(tmp) / Path(job.output).name
        report = replay(job.input, out, job.options, verify=job.verify)
        return Replayed(report.frames, report.refreshes, out.read_bytes())


def replay_many(jobs: Sequence[ReplayJob], executor: Executor, *, force: bool = False,
                progress: bool = False) -> BatchReport:
    """Replay every job whose output is not complete yet (all with ``force``); outputs are
    written as tasks finish, results listed in job order."""
    t0 = time.perf_counter()
    todo = [j for j in jobs if force or not is_complete(j)]
    tasks = [Task(j.input, j) for j in todo]
    by_input = {j.input: j for j in todo}
    written: list[str] = []

    def write(o: Outcome) -> None:
        if o.ok:
            atomic_write(by_input[o.id].output, o.value.data)
            written.append(by_input[o.id].output)

    try:
        outcomes = {o.id: o for o in executor.run(replay_job, tasks, progress=progress,
                                                  desc="replay", on_result=write)}
    except KeyboardInterrupt as e:
        e.note = (f"{len(written)} complete derived log(s) kept, none half-written; run the "  # type: ignore[attr-defined]
                  "same command again to replay the rest")
        raise
    results = []
    for j in jobs:
        o = outcomes.get(j.input)
        if o is None:
            results.append(LogResult(j.input, j.output, "skipped"))
        elif o.ok:
            results.append(LogResult(j.input, j.output, "replayed", o.value.frames,
                                     o.value.refreshes))
        else:
            results.append(LogResult(j.input, j.output, "failed", error=o.error))
    return BatchReport(tuple(results), time.perf_counter() - t0)


def replay_into(jobs: Sequence[ReplayJob], out_dir: str | os.PathLike[str],
                executor: Executor, *, force: bool = False,
                progress: bool = False) -> BatchReport:
    """:func:`replay_many` of ``jobs`` (planned into ``out_dir`` by :func:`plan_jobs`)
    through :func:`sgtool.files.output_folder` (module doc): in place into a new folder or
    one of an earlier run, or, with ``force``, built beside ``out_dir`` and moved in
    complete. The report names the outputs under ``out_dir``."""
    target = out_folder(out_dir)
    with output_folder(target, force=force, command="replay", option="--out-dir",
                       resume=True) as root:
        staged = [replace_field(j, output=str(root / Path(j.output).name)) for j in jobs]
        report = replay_many(staged, executor, force=force, progress=progress)
    final = {s.output: j.output for s, j in zip(staged, jobs, strict=True)}
    return BatchReport(tuple(replace_field(r, output=final[r.output]) for r in report.logs),
                       report.seconds)


def replay_logs(logs: str | os.PathLike[str] | Sequence[str | os.PathLike[str]],
                out_dir: str | os.PathLike[str], options: ReplayOptions | None = None, *,
                executor: Executor | None = None, force: bool = False,
                progress: bool = False, verify: bool = False) -> BatchReport:
    """Replay many logs into the folder ``out_dir`` on an executor, as ``sgtool replay
    --out-dir`` does (module doc): ``logs`` is a log, a folder of logs or a glob pattern,
    or a list of them; every ``NAME.mcap`` gives ``out_dir/NAME.mcap``, outputs already
    complete are kept (unless ``force``), and a folder sgtool did not write is refused
    unless ``force``. ``executor``:
    :func:`~sgtool.make_executor` (default: in this process); ``verify`` checks the
    inputs' chunk CRCs. A log that fails twice is a ``failed`` entry of the report (the
    others are written all the same), not an exception."""
    items = [logs] if isinstance(logs, (str, os.PathLike)) else logs
    if not isinstance(items, Sequence) or not items or \
            not all(isinstance(i, (str, os.PathLike)) and os.fspath(i) for i in items):
        raise SgtoolError(f"logs: a log's path, a folder or a list of them, got {logs!r}")
    if not isinstance(out_dir, (str, os.PathLike)) or not os.fspath(out_dir):
        raise SgtoolError(f"out_dir: a folder's path, got {out_dir!r}")
    if options is not None:
        of_type("options", options, ReplayOptions, "a ReplayOptions")
    for name, flag in (("force", force), ("progress", progress), ("verify", verify)):
        of_type(name, flag, bool, "True or False")
    if executor is not None:
        of_type("executor", executor, (LocalExecutor, RayExecutor),
                "one of sgtool.make_executor")
    inputs = expand_inputs(items, (".mcap",))
    jobs = plan_jobs(inputs, out_folder(out_dir), options or ReplayOptions(), verify=verify)
    return replay_into(jobs, out_dir, executor or LocalExecutor(1), force=force,
                       progress=progress)


def out_folder(path: str | os.PathLike[str]) -> Path:
    """The output folder (it may not exist yet); one line when it is a file."""
    p = Path(path)
    if p.exists() and not p.is_dir():
        raise SgtoolError(f"--out-dir {p} is a file; give a folder")
    return p
