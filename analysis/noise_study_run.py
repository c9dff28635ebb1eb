"""`sgtool study noise` after its checks: the noise study (and, when asked, the
closed-loop runs under noise) into its output folder, complete or not at all, then the
summary shown.

The command checks the options and builds :class:`NoiseStudyRequest`; the study is
:func:`sgtool.analysis.noise_study.run_study`, the closed-loop part
:func:`sgtool.analysis.noise_study.run_closed_loop` (its episodes run as `run-bench`'s do:
:class:`~sgtool.analysis.closed_loop_bench_run.EpisodeRunner`, logs written as they finish,
sent back from other nodes), the folder
:func:`sgtool.files.output_folder`. ``show`` receives the summary and the closing line.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace
from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from sgtool.analysis.noise_study import StudyConfig

Echo = Callable[[str], None]

OUTPUTS = ("summary.md", "results.json", "results.csv", "plots", "closed_loop")


@dataclass(frozen=True)
class NoiseStudyRequest:
    """A checked `sgtool study noise`: the study's ``config``, the recordings' cache
    folder, the output folder (``force``: replace what sgtool wrote in a non-empty one),
    the executor (:func:`sgtool.analysis.executor.make_executor`) and whether to show
    progress bars."""

    config: StudyConfig
    cache: Path
    out_dir: str
    force: bool = False
    progress: bool = False
    executor: str = "local"
    workers: int = 1
    ray_address: str | None = None


def study_into(request: NoiseStudyRequest, show: Echo) -> None:
    """Run the study into ``request.out_dir``: summary.md, results.json, results.csv,
    plots/ and, with closed-loop planners, closed_loop/; then show the summary."""
    from sgtool.analysis.closed_loop_bench_run import EpisodeRunner
    from sgtool.analysis.executor import make_executor
    from sgtool.analysis.noise_study import run_closed_loop, run_study
    from sgtool.analysis.noise_study_api import write_noise_study_outputs
    from sgtool.analysis.noise_study_tables import summary_md
    from sgtool.files import output_folder

    cfg, show_bars = request.config, request.progress
    runner = make_executor(request.executor, request.workers, request.ray_address)
    with output_folder(request.out_dir, force=request.force, command="study noise",
                       known=OUTPUTS) as out:
        res = run_study(cfg, request.cache, runner, progress=show_bars)
        if cfg.closed_loop.planners:
            from sgtool.analysis.closed_loop_bench import write_outputs

            cl = run_closed_loop(cfg, res.specs, out / "closed_loop",
                                 runner=EpisodeRunner(runner, out / "closed_loop",
                                                      progress=show_bars))
            write_outputs(cl, out / "closed_loop")
            res = replace(res, closed_loop=cl)
        write_noise_study_outputs(res, out)
        summary = summary_md(res)
    show(summary.removesuffix("\n"))  # summary_md ends in one newline; show adds it
    cached = len(res.cells) - res.recorded
    show(f"{len(res.cells)} cells ({res.recorded} log(s) recorded now"
         + (f", {cached} from {request.cache}" if cached else "")
         + f"); wrote {request.out_dir}/summary.md, results.json, results.csv, "
         "plots/")



