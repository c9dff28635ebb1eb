"""`sgtool bench` after its checks: the symbolic benchmark run into its output folder (and
the episode logs into theirs), complete or not at all, then its tables shown.

The command checks the options and builds :class:`BenchRunRequest`; the run is
:func:`sgtool.analysis.bench.run_benchmark`, the files
:func:`sgtool.analysis.bench.write_outputs`, the folders :func:`sgtool.files.output_folder`
(checked before any episode runs). ``show`` receives the tables and the list of files
written (stdout).
"""

from __future__ import annotations

import contextlib
from collections.abc import Callable
from dataclasses import dataclass, replace
from pathlib import Path

from sgtool.analysis.bench import BenchConfig
from sgtool.errors import SgtoolError

Echo = Callable[[str], None]


@dataclass(frozen=True)
class BenchRunRequest:
    """A checked `sgtool bench`: the run's ``config`` (its ``log_dir`` is the folder named
    by ``--log-dir``), the output folder, whether to replace sgtool's files in a non-empty
    one, the command line written to run.md/run.json (no API key in it) and the progress
    bar (None: when stderr is a terminal)."""

    config: BenchConfig
    out_dir: str
    command_line: str
    force: bool = False
    progress: bool | None = None


def bench_into(request: BenchRunRequest, show: Echo) -> None:
    """Run the benchmark into ``request.out_dir`` (and the logs into ``config.log_dir``),
    then show the tables and the files written; a task that failed after a retry is one
    error line and nothing is written; Ctrl-C leaves both folders as they were."""
    from sgtool.analysis.bench import OUTPUT_NAMES, run_benchmark, write_outputs
    from sgtool.analysis.report import invalid_action_notes, llm_warnings
    from sgtool.files import output_folder, refuse_input_folder
    from sgtool.leftovers import leftover_notes
    from sgtool.llm.recorded import transcript_run

    out_dir, log_dir = request.out_dir, request.config.log_dir
    request.config.check()  # before anything is emptied or written (the transcript)
    refuse_input_folder(out_dir, request.config.house_files, what="--house")
    within = None if log_dir is None else _within(log_dir, out_dir)
    if within is not None and within.parts and within.parts[0] in OUTPUT_NAMES:
        raise SgtoolError(f"--log-dir {log_dir}: {within.parts[0]} is a file the bench "
                          f"writes in {out_dir}; give the logs another folder")
    try:
        with output_folder(out_dir, force=request.force, command="bench", known=OUTPUT_NAMES,
                           inner=() if within is None else within.parts[:1]
                           ) as stage, contextlib.ExitStack() as stack:
            logs: Path | None = None
            if log_dir is not None:  # the logs' own folder, or OUT itself
                logs = stage if within == Path() else \
                    stack.enter_context(output_folder(log_dir, force=request.force,
                                                      command="bench", option="--log-dir"))
            cfg = replace(request.config, log_dir=None if logs is None else str(logs))
            stack.enter_context(transcript_run(
                cfg.planner_options.get("moma-llm", {}).get("transcript")))
            res = run_benchmark(cfg, progress=request.progress, partial=True)
            if res.failed:  # tables without some houses' episodes would pass for a result
                raise SgtoolError(f"{len(res.failed)} task(s) failed after a retry, nothing "
                                  f"written to {out_dir}; the first: {res.failed[0]}")
            written = [p.name for p in write_outputs(res, stage,
                                                     command=request.command_line)]
    except KeyboardInterrupt as e:
        if log_dir is not None:  # (output_folder's note names one folder)
            e.note = (f"{out_dir} and {log_dir} are as they were: the outputs of the "  # type: ignore[attr-defined]
                      "interrupted run were discarded")
        raise
    for text in (res.table, res.side_by_side, res.seen_table, res.interval_tables()):
        show(text)
    for h in res.houses:
        for line in h.notes:
            show(f"sgtool: note: {h.source}: {line}")
    for line in llm_warnings(res.results, res.config.planners):
        show(line)
    for line in invalid_action_notes(res.results, res.config.planners):
        show(f"sgtool: note: {line}")
    for line in res.retried:  # a planner that raises now and then, a worker lost
        show(f"sgtool: note: task retried after an error: {line}")
    show(f"wrote {', '.join(str(Path(out_dir) / name) for name in written)}")
    for folder in (out_dir, *([log_dir] if log_dir is not None else [])):
        for line in leftover_notes(folder):
            show(line)


def _within(folder: str, out_dir: str) -> Path | None:
    """``folder``'s path relative to ``out_dir`` when it lies within it (``.`` for the same
    folder), else None."""
    try:
        return Path(folder).resolve().relative_to(Path(out_dir).resolve())
    except ValueError:
        return None
