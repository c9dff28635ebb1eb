"""``sgtool replay LOG -o derived.mcap``: rebuild the scene graph of a log, frame by frame.

The work is done in :mod:`sgtool.analysis.replay_run` (on :mod:`sgtool.replayers`); this
module parses the options, checks the outputs and the input log, and hands a request over:
one log (with a progress bar, the report, the per-stage timings and, with ``--score``, the
quality of the final graph against the house the log was recorded in) or, with
``--out-dir``, many.
"""

from __future__ import annotations

import sys
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import click

from sgtool.commands.options import (
    FINITE_FLOAT,
    FiniteFloatRange,
    PathParam,
    check_log_output,
    check_output,
    executor_options,
    llm_endpoint_options,
)
from sgtool.commands.room_llm import LlmOptions
from sgtool.errors import SgtoolError
from sgtool.scenegraph.build_options import CLASSIFIERS

if TYPE_CHECKING:
    from sgtool.analysis.replay_run import BatchReplayRequest, ReplayRequest
    from sgtool.replayers.derived_log import ReplayOptions


@click.command("replay")
@click.argument("logs", metavar="LOG...", nargs=-1, required=True, type=PathParam())
@click.option("-o", "--output", type=PathParam(dir_okay=False),
              help="Derived log to write: a copy of LOG's messages plus /map/occupancy, "
              "/map/voronoi, /map/rooms, /map/graph and /sgtool/scene_graph at every "
              "refresh. Without "
              "it nothing is written (use with --score or --json).")
@click.option("--every", type=click.IntRange(min=1), default=None,
              help="Refresh the graph every K frames (and always at every action). "
              "Default: what the log was built with, else 10.")
@click.option("--classifier", type=click.Choice(list(CLASSIFIERS)),
              default=None, help="Room categories from contents: the distilled containment "
              "model, the naive-Bayes frequency model of the training knowledge, an LLM "
              "(MoMa-LLM's room classification; give --llm-base-url or --llm-replay), or "
              "none. Default: the log's, else frequency.")
@llm_endpoint_options("--classifier llm", timeout=60.0)
@click.option("--llm-constraint", type=click.Choice(["auto", "grammar", "json_schema", "none"]),
              default="auto", show_default=True,
              help="--classifier llm: answers constrained to the room types by a llama.cpp "
              "grammar or a JSON schema (auto: detected per endpoint), or parsed.")
@click.option("--llm-replay", type=PathParam(dir_okay=False), multiple=True,
              help="--classifier llm: answer from this transcript (JSONL, or an MCAP log's "
              "/sgtool/llm; repeatable) instead of an endpoint: offline, same output bytes.")
@click.option("--llm-transcript", type=PathParam(dir_okay=False), default=None,
              help="--classifier llm: write every exchange to this JSONL transcript (for "
              "--llm-replay); the report counts valid and rejected answers.")
@click.option("--min-points", type=click.IntRange(min=1), default=None,
              help="Points an instance needs in one frame to count as seen. Default: the "
              "log's, else MoMa-LLM's 50 at 320x240 scaled by the image size.")
@click.option("--voxel-size", type=FINITE_FLOAT, default=None,
              help="Voxel edge in metres. Default: the log's, else 0.05.")
@click.option("--max-depth", type=FiniteFloatRange(0.5, 20.0), default=None,
              help="Depth farther than this (m) is not mapped. Default: the log's (a "
              "closed-loop log records its live map's), else 5 (MoMa-LLM's), lowered to "
              "where the log's depth noise would read far floor as obstacles (measured on "
              "its first 60 frames from the points below the floor; the report says so). "
              "Give it to map to a depth of your own.")
@click.option("--max-frames", type=click.IntRange(min=1), default=None,
              help="Stop after this many frames.")
@click.option("--tf-time", type=click.Choice(["log", "stamp"]), default="log",
              show_default=True,
              help="The time that pairs /tf transforms with camera frames: the log time each "
              "message was recorded at, or the messages' header stamps (sgtool's own logs "
              "stamp every message with its log time). Pairing by log time, /tf stamps more "
              "than 0.05 s from their log times are warned about (the largest offset named), "
              "more than 1 s refused.")
@click.option("--rrd", type=PathParam(dir_okay=False),
              help="Also write a Rerun recording of the derived log (needs -o); its bytes "
              "differ from run to run (Rerun's own chunk and row ids), its content does "
              "not.")
@click.option("--rerun", "rerun_to", default=None,
              metavar="spawn|connect[:URL]|serve[:WEB_PORT[:GRPC_PORT]]",
              help="Stream every refresh (maps, scene graph, robot) to Rerun while replaying: "
              "spawn a viewer, connect to one, or serve a web viewer (headless machines; "
              "waits for Ctrl-C at the end).")
@click.option("--score", is_flag=True,
              help="Score the final graph against the house spec in the log: room count "
              "error, Voronoi node purity and adjusted Rand index, object-to-room and room "
              "category accuracy, strict and with open-plan rooms merged.")
@click.option("--json", "as_json", is_flag=True, help="Print one JSON object instead of text.")
@click.option("--force", is_flag=True, help="Overwrite the output files.")
@click.option("--verify/--no-verify", default=True, show_default=True,
              help="Check every chunk CRC of LOG as it is read: a damaged chunk is an "
              "error, never replayed or copied into a derived log (--no-verify: without "
              "-o or --out-dir, replay what the chunks hold; `sgtool doctor LOG` checks a "
              "whole log without replaying it).")
@click.option("--progress/--no-progress", default=None,
              help="Progress bar on stderr (default: when stderr is a terminal).")
@click.option("--out-dir", type=PathParam(file_okay=False), default=None,
              help="Replay many logs (files, folders of *.mcap, quoted glob patterns) into "
              "this folder, one DIR/NAME.mcap per LOG, byte-identical to one-by-one "
              "replays; outputs that are complete already are kept unless --force. A "
              "non-empty folder that no --out-dir run wrote is refused unless --force; "
              "--force replays all into a folder beside DIR, moved in complete, replacing "
              "what sgtool wrote there and keeping other files.")
@executor_options("replays (one per log, with --out-dir)")
def command(**given: Any) -> None:
    """Replay LOG into a semantic voxel map, BEV occupancy, a Voronoi graph, rooms, objects,
    frontiers and the hierarchical scene graph, deterministically: the same log and options
    give a byte-identical output.

    The graph refreshes every K frames and at every logged action; a closed door or
    container that opens drops its old voxels. Logs without instance ids (imported real
    data) give geometry only. Example: `sgtool replay run.mcap -o derived.mcap --score`.

    Many logs: `sgtool replay 'runs/*.mcap' --out-dir derived/ [-w N | --executor ray]`
    writes derived/NAME.mcap per log (the bytes a one-by-one replay writes), keeps those
    already complete with these options (--force redoes them), lists a log that fails
    twice with its error and exits 2 after the others are written.

    Inconsistent sensor data is refused (exit 2, one error naming the channel, the log
    time and the field), never guessed at: a transform that is not finite or whose
    quaternion is zero; a calibration with a short K or a focal length that is not
    positive; a depth image with no calibration before it (no field of view is assumed);
    a depth image whose size differs from the calibration, or RGB/instance images whose
    size differs from the depth image; zero-size images or image data that does not match
    width x step; instance ids in a non-integer encoding; two images of one channel at one
    log time (frames are told apart by log time, so they would merge). A damaged log is
    refused too; `sgtool doctor LOG --recover OUT` copies what is readable.
    """
    args = ReplayArgs(**given)
    if args.out_dir is not None or len(args.logs) > 1 or Path(args.logs[0]).is_dir():
        from sgtool.analysis.replay_run import replay_many

        replay_many(_batch_request(args), show=click.echo)
        return
    from sgtool.analysis.replay_run import replay_one

    replay_one(_request(args), show=click.echo, note=lambda m: click.echo(m, err=True))


@dataclass(frozen=True)
class ReplayArgs:
    """The options of `sgtool replay` as given (the click parameters, by name)."""

    logs: tuple[str, ...]
    output: str | None
    every: int | None
    classifier: str | None
    min_points: int | None
    voxel_size: float | None
    max_frames: int | None
    rrd: str | None
    score: bool
    as_json: bool
    force: bool
    progress: bool | None
    out_dir: str | None = None
    executor: str = "local"
    workers: int = 1
    ray_address: str | None = None
    verify: bool = True
    llm_base_url: str | None = None
    llm_model: str | None = None
    llm_api_key: str | None = None
    llm_timeout: float = 60.0
    llm_constraint: str = "auto"
    llm_replay: tuple[str, ...] = ()
    llm_transcript: str | None = None
    tf_time: str = "log"
    rerun_to: str | None = None
    max_depth: float | None = None

    def llm(self) -> LlmOptions:
        """The ``--llm-*`` options of ``--classifier llm``."""
        return LlmOptions(self.llm_base_url, self.llm_model, self.llm_api_key,
                          self.llm_timeout, self.llm_constraint, self.llm_replay,
                          self.llm_transcript)

    def show_progress(self) -> bool:
        """``--progress/--no-progress``, else whether stderr is a terminal."""
        return self.progress if self.progress is not None else sys.stderr.isatty()


def _options(args: ReplayArgs) -> ReplayOptions:
    """The replay options, ``--voxel-size`` checked."""
    from sgtool.replayers.derived_log import ReplayOptions

    if args.voxel_size is not None and not 0.01 <= args.voxel_size <= 0.5:
        raise SgtoolError(f"--voxel-size {args.voxel_size}: must be 0.01..0.5 m")
    return ReplayOptions(every=args.every, classifier=args.classifier,
                         min_points=args.min_points, voxel_size=args.voxel_size,
                         max_frames=args.max_frames, max_depth=args.max_depth,
                         tf_time=args.tf_time)


def _batch_request(args: ReplayArgs) -> BatchReplayRequest:
    """The checks of ``--out-dir``: no one-log option, then the replay options."""
    from sgtool.analysis.replay_run import BatchReplayRequest

    if args.llm().given() or args.classifier == "llm":
        raise SgtoolError("--classifier llm and the --llm-* options replay one log at a "
                          "time; leave out --out-dir")
    if args.out_dir is None:
        raise SgtoolError("several logs (or a folder) replay into a folder: give "
                          "--out-dir DIR")
    for given, opt in ((args.output, "-o"), (args.rrd, "--rrd"), (args.score, "--score"),
                       (args.rerun_to, "--rerun")):
        if given:
            raise SgtoolError(f"{opt} takes one log; leave it out with --out-dir")
    return BatchReplayRequest(
        logs=args.logs, out_dir=Path(args.out_dir), options=_options(args), force=args.force,
        as_json=args.as_json, progress=args.show_progress(), executor=args.executor,
        workers=args.workers, ray_address=args.ray_address, verify=args.verify)


def _request(args: ReplayArgs) -> ReplayRequest:
    """The checks of one log: the mode, the outputs (the one output check), the options,
    then the input log (sgtool's, with a house spec when scored)."""
    from sgtool.analysis.replay_run import ReplayRequest

    if args.executor != "local" or args.workers != 1 or args.ray_address:
        raise SgtoolError("--executor, --workers and --ray-address run many logs: give "
                          "--out-dir DIR")
    src = Path(args.logs[0])
    if not src.exists():
        raise SgtoolError(f"{src}: no such file")
    dst = _outputs(args, src)
    opts = _options(args)
    frames, house = _read_input(src, args.score)
    if args.max_frames is not None:
        frames = min(frames, args.max_frames)
    return ReplayRequest(log=src, output=dst, options=opts, rooms=args.llm().room_classifier,
                         frames=frames, house=house, rrd=args.rrd, rerun_to=args.rerun_to,
                         as_json=args.as_json, progress=args.show_progress(),
                         verify=args.verify)


def _outputs(args: ReplayArgs, src: Path) -> Path | None:
    """``-o`` (a log) and ``--rrd``: neither the input log, each through the one output
    check; ``--rrd`` needs ``-o``."""
    if args.output is None and args.rrd:
        raise SgtoolError("--rrd views the derived log: give -o derived.mcap as well")
    for given, opt in ((args.output, "-o"), (args.rrd, "--rrd")):
        if given and Path(given).resolve() == src.resolve():
            raise SgtoolError(f"{opt} {given}: the output must not be the input log")
    for given, what in ((str(src), "the input log"), (args.output, "the output log (-o)"),
                        (args.rrd, "the --rrd output")):
        if args.llm_transcript and given and \
                Path(args.llm_transcript).resolve() == Path(given).resolve():
            raise SgtoolError(f"--llm-transcript {args.llm_transcript}: it is {what}")
    dst = check_log_output(args.output, force=args.force) if args.output else None
    if args.rrd:
        check_output(args.rrd, force=args.force, option="--rrd", suffixes=(".rrd",),
                     what="Rerun recording")
    return dst


def _read_input(src: Path, score: bool) -> tuple[int, Any]:
    """(frames, house spec or None) of the input log: an sgtool log (a foreign one is
    refused naming what it is), with a house spec when ``score``."""
    from sgtool.log import LogReader
    from sgtool.log.inspect import foreign_log_problem

    if (foreign := foreign_log_problem(src)) is not None:
        raise SgtoolError(foreign)
    with LogReader(src) as r:
        total = r.frame_count() if r.has("/camera/depth") else 0
        house = r.house_spec() if score else None  # validated like a house file
    if score and house is None:
        raise SgtoolError(f"{src} has no house spec attachment (house.json): --score needs "
                          "the ground truth of a simulated log")
    return total, house
