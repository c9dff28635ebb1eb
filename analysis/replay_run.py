"""`sgtool replay` after its checks: one log replayed into a derived log (with a progress
bar, an optional live Rerun stream, a Rerun recording and the score of the final graph), or
many logs into a folder on an executor (:mod:`sgtool.analysis.batch_replay`).

The command checks the options, the outputs and the inputs and builds these requests; the
work is :func:`sgtool.replayers.derived_log.replay`. ``show`` receives the report's lines
(stdout), ``note`` the viewer's messages (stderr).
"""

from __future__ import annotations

import sys
from collections.abc import Callable
from contextlib import AbstractContextManager
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from sgtool.canonical import json_text
from sgtool.errors import SgtoolError
from sgtool.files import quoted

if TYPE_CHECKING:
    from sgtool.replayers.derived_log import ReplayOptions

Echo = Callable[[str], None]


@dataclass(frozen=True)
class ReplayRequest:
    """A checked one-log replay: ``log`` into ``output`` (None: nothing written) with
    ``options``; ``house`` is the log's house spec when the final graph is scored (None:
    no score); ``frames`` sizes the progress bar; ``rooms`` makes the room classifier
    context (:meth:`sgtool.commands.room_llm.LlmOptions.room_classifier`)."""

    log: Path
    output: Path | None
    options: ReplayOptions
    rooms: Callable[[], AbstractContextManager[Any]]
    frames: int = 0
    house: Any = None
    rrd: str | None = None
    rerun_to: str | None = None
    as_json: bool = False
    progress: bool = False
    verify: bool = True


@dataclass(frozen=True)
class BatchReplayRequest:
    """A checked ``--out-dir`` replay: every log of ``logs`` (files, folders, glob
    patterns) into ``out_dir`` on the executor named by ``executor``/``workers``/
    ``ray_address`` (:func:`sgtool.analysis.executor.make_executor`)."""

    logs: tuple[str, ...]
    out_dir: Path
    options: ReplayOptions
    force: bool = False
    as_json: bool = False
    progress: bool = False
    executor: str = "local"
    workers: int = 1
    ray_address: str | None = None
    verify: bool = False


def replay_one(request: ReplayRequest, show: Echo, note: Echo) -> None:
    """Replay one log as ``request`` says and show the report (text or one JSON line),
    the LLM answer counts and the score."""
    from tqdm import tqdm

    from sgtool.replayers.derived_log import replay

    final: dict[str, Any] = {}
    if request.rrd is not None or request.rerun_to is not None:
        from sgtool.extras import require

        require("rerun")  # before the work: a missing viewer is one line, not a late one

    def keep(ref: Any, stream: Any) -> None:
        final["refresh"], final["stream"] = ref, stream

    with request.rooms() as rooms, tqdm(
            total=request.frames, unit="frame", desc="replay", file=sys.stderr, leave=False,
            disable=not request.progress, dynamic_ncols=True) as bar:
        live = None
        if request.rerun_to is not None:
            from sgtool.analysis.rerun_live import LiveReplay

            live = LiveReplay.start(request.rerun_to, request.log, note)
        on_refresh = keep if request.house is not None else None
        report = replay(request.log, request.output, request.options,
                        on_refresh=live.chain(on_refresh) if live else on_refresh,
                        progress=bar, verify=request.verify, room_classifier=rooms.make)
    if live is not None:
        live.finish(note)
    scores, align = _score(request.house, final, request.log) \
        if request.house is not None else (None, None)
    if request.rrd is not None and request.output is not None:
        try:
            write_view(request.output, Path(request.rrd), request.progress)
        except KeyboardInterrupt as e:  # the derived log is complete: say so
            e.note = (f"{request.output} was written; {request.rrd} was not (make it with: "  # type: ignore[attr-defined]
                      f"sgtool view {quoted(request.output)} -o {quoted(request.rrd)})")
            raise
        except SgtoolError as e:  # (a full disk) the derived log is complete: say so
            said = str(e).removesuffix(" (nothing was written)")
            raise SgtoolError(f"{said}; {request.output} was written, {request.rrd} was not "
                              f"(make it with: sgtool view {quoted(request.output)} -o "
                              f"{quoted(request.rrd)})") from e
    _show_report(request, report, rooms, scores, align, show)


def _show_report(request: ReplayRequest, report: Any, rooms: Any, scores: Any, align: Any,
                 show: Echo) -> None:
    rrd = request.rrd
    if request.as_json:
        doc = replay_dict(report, scores, rrd)
        if align is not None:
            doc["score_alignment"] = {"frames": align.frames, "rms_m": align.rms_m}
        if rooms.exchanges:
            doc["llm_answers"] = rooms.stats().as_dict()
        show(json_text(doc, sort_keys=True))
        return
    for line in report.lines() + rooms.lines():
        show(line)
    if scores is not None:
        from sgtool.replayers.score import score_lines

        last = report.last
        if align is not None:
            show(align.line())
        for line in score_lines(scores, None if last is None else len(last.graph.objects)):
            show(line)
    if rrd:
        show(f"wrote {rrd}; open it with: rerun {quoted(rrd)}")


def replay_many(request: BatchReplayRequest, show: Echo) -> None:
    """``--out-dir``: every log replayed on the executor
    (:func:`sgtool.analysis.batch_replay.replay_into`); a log that failed twice is one
    error line after the others are written."""
    from sgtool.analysis.batch_replay import replay_logs
    from sgtool.analysis.executor import make_executor

    runner = make_executor(request.executor, request.workers, request.ray_address)
    report = replay_logs(request.logs, request.out_dir, request.options, executor=runner,
                         force=request.force, progress=request.progress,
                         verify=request.verify)
    if request.as_json:
        show(json_text({"logs": [asdict(r) for r in report.logs],
                         "seconds": report.seconds}, sort_keys=True))
    else:
        for line in report.lines():
            show(line)
    failed = [r for r in report.logs if r.status == "failed"]
    if failed:
        raise SgtoolError(f"{len(failed)} of {len(report.logs)} log(s) failed to replay "
                          f"(after a retry); the first: {failed[0].input}: {failed[0].reason}")


def _score(spec: Any, final: dict[str, Any], log: Any) -> tuple[Any, Any]:
    """The scores of the final graph against ``spec`` and the alignment of a drifted map
    to the true poses in ``log`` (None when it holds none)."""
    from sgtool.log import LogReader
    from sgtool.replayers.score import score, truth_alignment

    if "refresh" not in final:
        raise SgtoolError("the log produced no scene graph to score (no frames?)")
    ref, stream = final["refresh"], final["stream"]
    if ref.layers is None:
        raise SgtoolError("the last refresh has no map layers to score")
    with LogReader(log) as reader:  # the poses of the frames replayed (--max-frames)
        align = truth_alignment(reader, ref.time_ns)
    return score(spec, stream.builder.instances, ref.layers, ref.graph,
                 stream.builder.trajectory, align), align


def write_view(derived: Path, rrd: Path, show: bool) -> None:
    """A Rerun recording of a derived log with the voxel map (``sgtool view`` with its
    defaults), with a progress bar when ``show``."""
    from tqdm import tqdm

    from sgtool.analysis.rerun_view import export
    from sgtool.log import LogReader
    from sgtool.replayers.voxel_timeline import voxel_snapshots

    with LogReader(derived) as r:
        total = r.frame_count()
    with tqdm(total=total, unit="frame", desc="view", file=sys.stderr, leave=False,
              disable=not show, dynamic_ncols=True) as bar:
        export(derived, rrd, progress=bar.update,
               voxels=lambda reader: voxel_snapshots(reader, every=10))


def replay_dict(report: Any, scores: Any, rrd: str | None) -> dict[str, Any]:
    """The ``--json`` object of a one-log replay: the report, the final graph's counts,
    the score (when scored) and the Rerun recording's path."""
    from sgtool.replayers.score import score_dict

    g = report.last.graph if report.last is not None else None
    out: dict[str, Any] = {
        "input": str(report.input), "output": str(report.output) if report.output else None,
        "options": asdict(report.options), "frames": report.frames,
        "refreshes": report.refreshes, "semantic": report.semantic,
        "truncated": report.truncated, "seconds": report.seconds,
        "stages_ms": {k: {"median": v[0], "max": v[1], "calls": v[2]}
                      for k, v in report.stages.items()},
        "graph": None if g is None else {
            "rooms": sum(r.explored for r in g.rooms),
            "unexplored_rooms": sum(not r.explored for r in g.rooms),
            "objects": len(g.objects), "frontiers": len(g.frontiers()),
            "doors": len(g.doors),
            "categories": {r.id: r.category for r in g.rooms if r.explored},
        },
        "rrd": rrd,
    }
    warnings = [*report.warnings, *report.graph_warnings()]
    if warnings:
        out["warnings"] = warnings
    if report.notes:
        out["notes"] = list(report.notes)
    if scores is not None:
        out["score"] = score_dict(scores)
    return out
