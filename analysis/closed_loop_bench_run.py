"""`sgtool run-bench` after its checks: the closed-loop benchmark written in place into its
folder (episode log by episode log, so that a run cut short resumes; with ``force`` a fresh
run built beside it), then its table shown.

The command checks the options and builds :class:`RunBenchRequest`; the run is
:func:`sgtool.analysis.closed_loop_bench.run_closed_loop_bench`, the folder
:func:`sgtool.files.output_folder`. ``show`` receives the table and the files written.
"""

from __future__ import annotations

import sys
from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

from sgtool.analysis.closed_loop_bench import ClosedLoopBenchConfig

Echo = Callable[[str], None]


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


def run_bench_into(request: RunBenchRequest, show: Echo) -> None:
    """Run (or, resuming, read back) every episode into ``request.out_dir``, add the
    symbolic rows, write the tables and curves, and show the table and the files written;
    Ctrl-C keeps the complete episode logs (with ``force``: the folder as it was)."""
    from tqdm import tqdm

    from sgtool.analysis.closed_loop_bench import OUTPUT_NAMES, run_closed_loop_bench
    from sgtool.analysis.closed_loop_bench import write_outputs as write_tables
    from sgtool.files import output_folder

    runner, show_bar = _runner(request)
    with output_folder(request.out_dir, force=request.force, command="run-bench",
                       known=OUTPUT_NAMES, resume=True) as root:
        bar = tqdm(total=None, unit="episode", desc="run-bench", file=sys.stderr,
                   disable=not show_bar, dynamic_ncols=True)
        try:
            res = run_closed_loop_bench(request.config, root, progress=bar,
                                        report_only=request.report_only, runner=runner)
        except KeyboardInterrupt as e:  # the CLI prints the note; exit 130 (143: killed)
            e.note = (f"the complete episode logs are kept in {request.out_dir}/logs "  # type: ignore[attr-defined]
                      "(run the same command again to resume)")
            raise  # (with --force, output_folder says OUT is as it was instead)
        finally:
            bar.close()
        res = _with_symbolic(request, res)
        written = [p.name for p in write_tables(res, root)]
    show(res.table())
    show(f"wrote {', '.join(str(Path(request.out_dir) / name) for name in written)}")


def _runner(request: RunBenchRequest) -> tuple[Any, bool]:
    """(map over the episodes, whether to show this module's bar): in this process one
    after the other, else on the executor (whose bar counts the episodes)."""
    show = sys.stderr.isatty() if request.progress is None else request.progress
    parallel = request.executor != "local" or request.workers > 1 or request.ray_address
    if not parallel or request.report_only:
        return map, show
    from sgtool.analysis.executor import as_map, make_executor

    runner = as_map(make_executor(request.executor, request.workers, request.ray_address),
                    progress=show, desc="run-bench", task_id=lambda _, t: str(t.output))
    return runner, False


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
