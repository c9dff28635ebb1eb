"""``sgtool replay LOG -o derived.mcap``: rebuild the scene graph of a log, frame by frame.

The work is done in :mod:`sgtool.replayers`; this module parses options, shows a progress
bar, prints the report, the per-stage timings and, with ``--score``, the quality of the
final graph against the house the log was recorded in.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path
from typing import Any

import click

from sgtool.commands.options import executor_options, llm_endpoint_options
from sgtool.commands.room_llm import LlmOptions
from sgtool.errors import SgtoolError
from sgtool.scenegraph.options import CLASSIFIERS


@click.command("replay")
@click.argument("logs", metavar="LOG...", nargs=-1, required=True, type=click.Path())
@click.option("-o", "--output", type=click.Path(dir_okay=False),
              help="Derived log to write: a copy of LOG's messages plus /map/occupancy, "
              "/map/voronoi, /map/rooms and /sgtool/scene_graph at every refresh. Without "
              "it nothing is written (use with --score or --json).")
@click.option("--every", type=click.IntRange(min=1), default=None,
              help="Refresh the graph every K frames (and always at every action). "
              "Default: what the log was built with, else 10.")
@click.option("--classifier", type=click.Choice(list(CLASSIFIERS)),
              default=None, help="Room categories from contents: the distilled containment "
              "model, the naive-Bayes frequency model of the training knowledge, an LLM "
              "(MoMa-LLM's room classification; give --llm-base-url or --llm-replay), or "
              "none. Default: the log's, else containment.")
@llm_endpoint_options("--classifier llm", timeout=60.0)
@click.option("--llm-constraint", type=click.Choice(["auto", "grammar", "json_schema", "none"]),
              default="auto", show_default=True,
              help="--classifier llm: answers constrained to the room types by a llama.cpp "
              "grammar or a JSON schema (auto: detected per endpoint), or parsed.")
@click.option("--llm-replay", type=click.Path(dir_okay=False), multiple=True,
              help="--classifier llm: answer from this transcript (JSONL, or an MCAP log's "
              "/sgtool/llm; repeatable) instead of an endpoint: offline, same output bytes.")
@click.option("--llm-transcript", type=click.Path(dir_okay=False), default=None,
              help="--classifier llm: write every exchange to this JSONL transcript (for "
              "--llm-replay); the report counts valid and rejected answers.")
@click.option("--min-points", type=click.IntRange(min=1), default=None,
              help="Points an instance needs in one frame to count as seen. Default: the "
              "log's, else MoMa-LLM's 50 at 320x240 scaled by the image size.")
@click.option("--voxel-size", type=float, default=None,
              help="Voxel edge in metres. Default: the log's, else 0.05.")
@click.option("--max-frames", type=click.IntRange(min=1), default=None,
              help="Stop after this many frames.")
@click.option("--tf-time", type=click.Choice(["log", "stamp"]), default="log",
              show_default=True,
              help="The time that pairs /tf transforms with camera frames: the log time each "
              "message was recorded at, or the messages' header stamps (sgtool's own logs "
              "stamp every message with its log time). Pairing by log time, /tf stamps more "
              "than 0.05 s from their log times are warned about (the largest offset named), "
              "more than 1 s refused.")
@click.option("--rrd", type=click.Path(dir_okay=False),
              help="Also write a Rerun recording of the derived log (needs -o).")
@click.option("--rerun", "rerun_to", default=None, metavar="spawn|connect[:URL]|serve[:PORT]",
              help="Stream every refresh (maps, scene graph, robot) to Rerun while replaying: "
              "spawn a viewer, connect to one, or serve a web viewer (headless machines; "
              "waits for Ctrl-C at the end).")
@click.option("--score", is_flag=True,
              help="Score the final graph against the house spec in the log: room count "
              "error, Voronoi node purity and adjusted Rand index, object-to-room and room "
              "category accuracy, strict and with open-plan rooms merged.")
@click.option("--json", "as_json", is_flag=True, help="Print one JSON object instead of text.")
@click.option("--force", is_flag=True, help="Overwrite the output files.")
@click.option("--verify", is_flag=True,
              help="Check every chunk CRC of LOG as it is read (always on with -o or "
              "--out-dir: a damaged chunk is never copied into a derived log; `sgtool doctor "
              "LOG` checks a whole log without replaying it).")
@click.option("--progress/--no-progress", default=None,
              help="Progress bar on stderr (default: when stderr is a terminal).")
@click.option("--out-dir", type=click.Path(file_okay=False), default=None,
              help="Replay many logs (files, folders of *.mcap, quoted glob patterns) into "
              "this folder, one DIR/NAME.mcap per LOG, byte-identical to one-by-one "
              "replays; outputs that are complete already are kept unless --force. A "
              "non-empty folder that no --out-dir run wrote is refused unless --force; "
              "--force replays all into a folder beside DIR, moved in complete, replacing "
              "what sgtool wrote there and keeping other files.")
@executor_options("replays (one per log, with --out-dir)")
def command(logs: tuple[str, ...], output: str | None, every: int | None,
            classifier: str | None, min_points: int | None, voxel_size: float | None,
            max_frames: int | None, rrd: str | None, score: bool, as_json: bool, force: bool,
            progress: bool | None, out_dir: str | None = None, executor: str = "local",
            workers: int = 1, ray_address: str | None = None, verify: bool = False,
            llm_base_url: str | None = None, llm_model: str | None = None,
            llm_api_key: str | None = None, llm_timeout: float = 60.0,
            llm_constraint: str = "auto", llm_replay: tuple[str, ...] = (),
            llm_transcript: str | None = None, tf_time: str = "log",
            rerun_to: str | None = None) -> None:
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
    from tqdm import tqdm

    from sgtool.log import LogReader
    from sgtool.replayers.derived_log import ReplayOptions, replay

    llm = LlmOptions(llm_base_url, llm_model, llm_api_key, llm_timeout, llm_constraint,
                     llm_replay, llm_transcript)
    if out_dir is not None or len(logs) > 1 or Path(logs[0]).is_dir():
        if llm.given() or classifier == "llm":
            raise SgtoolError("--classifier llm and the --llm-* options replay one log at a "
                              "time; leave out --out-dir")
        if out_dir is None:
            raise SgtoolError("several logs (or a folder) replay into a folder: give "
                              "--out-dir DIR")
        for given, opt in ((output, "-o"), (rrd, "--rrd"), (score, "--score"),
                           (rerun_to, "--rerun")):
            if given:
                raise SgtoolError(f"{opt} takes one log; leave it out with --out-dir")
        _batch(logs, Path(out_dir), ReplayOptions(
            every=every, classifier=classifier, min_points=min_points, voxel_size=voxel_size,
            max_frames=max_frames, tf_time=tf_time), force=force, as_json=as_json,
            progress=progress, executor=executor, workers=workers, ray_address=ray_address,
            verify=verify)
        return
    if executor != "local" or workers != 1 or ray_address:
        raise SgtoolError("--executor, --workers and --ray-address run many logs: give "
                          "--out-dir DIR")
    src = Path(logs[0])
    dst = Path(output) if output else None
    if not src.exists():
        raise SgtoolError(f"{src}: no such file")
    if dst is None and rrd:
        raise SgtoolError("--rrd views the derived log: give -o derived.mcap as well")
    for p, opt in ((dst, "-o"), (Path(rrd) if rrd else None, "--rrd")):
        if p is None:
            continue
        if p.resolve() == src.resolve():
            raise SgtoolError(f"{opt} {p}: the output must not be the input log")
        if p.exists() and not force:
            raise SgtoolError(f"{p} exists; not overwriting it (use --force)")
        if not p.parent.exists():
            raise SgtoolError(f"{opt} {p}: folder {p.parent} does not exist")
    if dst is not None and dst.suffix != ".mcap":
        raise SgtoolError(f"-o {dst}: the output is an MCAP log; name it *.mcap")
    if voxel_size is not None and not 0.01 <= voxel_size <= 0.5:
        raise SgtoolError(f"--voxel-size {voxel_size}: must be 0.01..0.5 m")
    from sgtool.log.inspect import foreign_log_problem

    if (foreign := foreign_log_problem(src)) is not None:
        raise SgtoolError(foreign)
    with LogReader(src) as r:
        total = r.frame_count() if r.has("/camera/depth") else 0
        house = r.house_spec() if score else None  # validated like a house file
    if score and house is None:
        raise SgtoolError(f"{src} has no house spec attachment (house.json): --score needs "
                          "the ground truth of a simulated log")
    if max_frames is not None:
        total = min(total, max_frames)
    final: dict[str, Any] = {}

    def keep(ref, stream) -> None:  # type: ignore[no-untyped-def]  # noqa: ANN001
        final["refresh"], final["stream"] = ref, stream

    show = progress if progress is not None else sys.stderr.isatty()
    opts = ReplayOptions(every=every, classifier=classifier, min_points=min_points,
                         voxel_size=voxel_size, max_frames=max_frames, tf_time=tf_time)
    with llm.room_classifier() as rooms, tqdm(
            total=total, unit="frame", desc="replay", file=sys.stderr, leave=False,
            disable=not show, dynamic_ncols=True) as bar:
        live = None
        if rerun_to is not None:
            from sgtool.analysis.rerun_live import LiveReplay

            live = LiveReplay.start(rerun_to, src, lambda m: click.echo(m, err=True))
        on_refresh = keep if score else None
        report = replay(src, dst, opts, on_refresh=live.chain(on_refresh) if live else on_refresh,
                        progress=bar, verify=verify, room_classifier=rooms.make)
    if live is not None:
        live.finish(lambda m: click.echo(m, err=True))
    scores = None
    if score:
        scores = _score(house, final)
    if rrd and dst is not None:
        write_view(dst, Path(rrd), show)
    if as_json:
        doc = _as_dict(report, scores, rrd)
        if rooms.exchanges:
            doc["llm_answers"] = rooms.stats().as_dict()
        click.echo(json.dumps(doc, sort_keys=True))
        return
    for line in report.lines() + rooms.lines():
        click.echo(line)
    if scores is not None:
        from sgtool.replayers.score import score_lines

        for line in score_lines(scores):
            click.echo(line)
    if rrd:
        click.echo(f"wrote {rrd}; open it with: rerun {rrd}")


def _batch(logs: tuple[str, ...], out_dir: Path, opts: Any, *, force: bool, as_json: bool,
           progress: bool | None, executor: str, workers: int,
           ray_address: str | None, verify: bool = False) -> None:
    """``--out-dir``: every log replayed on the executor (sgtool.analysis.batch_replay)."""
    from dataclasses import asdict

    from sgtool.analysis.batch_inputs import expand_inputs
    from sgtool.analysis.batch_replay import out_folder, plan_jobs, replay_into
    from sgtool.analysis.executor import make_executor

    if opts.voxel_size is not None and not 0.01 <= opts.voxel_size <= 0.5:
        raise SgtoolError(f"--voxel-size {opts.voxel_size}: must be 0.01..0.5 m")
    runner = make_executor(executor, workers, ray_address)
    inputs = expand_inputs(logs, (".mcap",))
    jobs = plan_jobs(inputs, out_folder(out_dir), opts, verify=verify)
    show = progress if progress is not None else sys.stderr.isatty()
    report = replay_into(jobs, out_dir, runner, force=force, progress=show)
    if as_json:
        click.echo(json.dumps({"logs": [asdict(r) for r in report.logs],
                               "seconds": report.seconds}, sort_keys=True))
    else:
        for line in report.lines():
            click.echo(line)
    failed = [r for r in report.logs if r.status == "failed"]
    if failed:
        raise SgtoolError(f"{len(failed)} of {len(report.logs)} log(s) failed to replay "
                          f"(after a retry); the first: {failed[0].input}: {failed[0].error}")


def _score(spec: Any, final: dict[str, Any]) -> Any:
    from sgtool.replayers.score import score

    if "refresh" not in final:
        raise SgtoolError("the log produced no scene graph to score (no frames?)")
    ref, stream = final["refresh"], final["stream"]
    if ref.layers is None:
        raise SgtoolError("the last refresh has no map layers to score")
    return score(spec, stream.builder.instances, ref.layers, ref.graph)


def write_view(derived: Path, rrd: Path, show: bool) -> None:
    """A Rerun recording of a derived log with the voxel map (``sgtool view`` with its
    defaults), with a progress bar when ``show``."""
    from tqdm import tqdm

    from sgtool.analysis.rerun_view import export
    from sgtool.log import LogReader
    from sgtool.replayers.voxels import voxel_snapshots

    with LogReader(derived) as r:
        total = r.frame_count()
    with tqdm(total=total, unit="frame", desc="view", file=sys.stderr, leave=False,
              disable=not show, dynamic_ncols=True) as bar:
        export(derived, rrd, progress=bar.update,
               voxels=lambda reader: voxel_snapshots(reader, every=10))


def _as_dict(report: Any, scores: Any, rrd: str | None) -> dict[str, Any]:
    from dataclasses import asdict

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
    if report.warnings:
        out["warnings"] = list(report.warnings)
    if scores is not None:
        out["score"] = score_dict(scores)
    return out
