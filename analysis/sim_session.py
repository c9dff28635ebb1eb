"""One simulator session of the CLI: a recorded tour (`sgtool record`) or one closed-loop
search (`sgtool run`), with a progress bar of frames on stderr and, optionally, a live
Rerun stream.

The commands check the options, the output and the inputs and build these requests; the
work is in :func:`sgtool.recorders.sim.record_house` and
:func:`sgtool.recorders.sim.closed_loop.run_episode`. ``show`` receives the report's lines
(stdout), ``note`` the viewer's messages (stderr).
"""

from __future__ import annotations

import sys
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from sgtool.errors import SgtoolError
from sgtool.house.spec import HouseSpec

if TYPE_CHECKING:
    from sgtool.datasets.episodes import Episode
    from sgtool.recorders.sim import RecordOptions
    from sgtool.recorders.sim.closed_loop import ClosedLoopOptions

Echo = Callable[[str], None]


@dataclass(frozen=True)
class RecordRequest:
    """A checked `sgtool record`: the house, the log to write and the recording options."""

    house: HouseSpec
    house_id: str
    output: Path
    options: RecordOptions
    quiet: bool = False
    rerun_to: str | None = None


@dataclass(frozen=True)
class SearchRequest:
    """A checked `sgtool run`: the house, the episode (its index in `sgtool scenes
    episodes`), the planner by name with its checked options, the log to write and the
    closed-loop options."""

    house: HouseSpec
    house_id: str
    episode_index: int
    episode: Episode
    planner: str
    output: Path
    options: ClosedLoopOptions
    planner_options: dict[str, Any] = field(default_factory=dict)
    force: bool = False
    quiet: bool = False
    rerun_to: str | None = None


@contextmanager
def _progress(total: int | None, desc: str, quiet: bool) -> Iterator[Any]:
    from tqdm import tqdm

    bar = tqdm(total=total, unit="frame", desc=desc, file=sys.stderr, leave=False,
               disable=quiet or not sys.stderr.isatty(), dynamic_ncols=True)
    try:
        yield bar
    finally:
        bar.close()


def _live(rerun_to: str | None, source: str, note: Echo) -> Any:
    if rerun_to is None:
        return None
    import uuid

    from sgtool.analysis.rerun_live import LiveReplay

    # the log's bytes do not exist yet: a recording id of its own per run, so that two
    # runs to one output (other options, --force) never merge in a viewer left open
    return LiveReplay.start(rerun_to, f"{source} {uuid.uuid4()}", note)


def _finish(report: Any, live: Any, quiet: bool, show: Echo, note: Echo) -> None:
    if not quiet:
        for line in report.lines():
            show(line)
    if live is not None:  # after the report: serve keeps the recording up until Ctrl-C
        live.finish(note)


def record_tour(request: RecordRequest, show: Echo, note: Echo) -> None:
    """Record the scripted (or frontier) exploration of the request's house into its log;
    the report's lines go to ``show`` unless quiet."""
    from sgtool.recorders.sim import record_house

    live = _live(request.rerun_to, f"record {request.house_id} {request.output}", note)
    with _progress(request.options.frames, "record", request.quiet) as bar:
        report = record_house(request.house, request.output, request.options,
                              house_id=request.house_id, progress=bar,
                              observers=[live.observer()] if live else ())
    _finish(report, live, request.quiet, show, note)


def run_search(request: SearchRequest, show: Echo, note: Echo) -> None:
    """Run the request's episode in closed loop with its planner into its log; the
    report's lines go to ``show`` unless quiet."""
    from sgtool.llm.recorded import transcript_run
    from sgtool.planning.registry import make_planner
    from sgtool.recorders.sim.closed_loop import run_episode

    name = request.planner
    with _progress(request.options.frames, f"run {name}", request.quiet) as bar, \
            transcript_run(request.planner_options.get("transcript")):
        planner = make_planner(name, **request.planner_options)
        live = _live(request.rerun_to, f"run {request.house_id} {request.episode_index} "
                     f"{name} {request.output}", note)
        report = run_episode(request.house, request.episode, planner, request.output,
                             request.options, house_id=request.house_id,
                             episode_index=request.episode_index, overwrite=request.force,
                             progress=bar, on_decision=live.decision if live else None,
                             planner_options=request.planner_options)
    _finish(report, live, request.quiet, show, note)
    miss = getattr(planner, "replay_miss", None)
    if miss:  # as `sgtool replay` says it: the episode left the recorded transcript
        raise SgtoolError(f"{miss} ({request.output} holds the episode up to there)")
