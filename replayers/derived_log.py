"""Replaying a log into scene graphs, frame by frame, and writing the derived log.

:func:`replay` reads a log once, in log-time order (ties in file order, i.e. the order the
recorder wrote them), and feeds a :class:`~sgtool.scenegraph.stream.SceneGraphStream`:
instance tables, frames (assembled by :class:`~sgtool.log.frame_assembly.FrameAssembler`) and
action records. With an output it also writes the derived log: a copy of every input
message (same bytes, same channels and schemas, same order), the input's attachments and
its ``sgtool`` metadata, and after the message that caused each refresh the derived
channels of :mod:`sgtool.scenegraph.derived_layers` and the scene graph as a Foxglove
``SceneUpdate`` (:mod:`sgtool.scenegraph.graph_scene`, ``/map/graph``) at the refresh time.
Derived channels of the input (a log that was already replayed, or a closed-loop log) are
not copied: they are rebuilt. A metadata record ``sgtool.replay`` holds the options. Input
chunks go into the derived log as they are, not recompressed (:mod:`sgtool.log.chunk_copy`),
wherever that gives the same messages in the same order (:func:`_can_copy`, :func:`_copyable`).
With an output every input chunk's CRC is checked as it is read (a copied chunk would
carry damage under a CRC that no longer matches, a rewritten one under a fresh CRC that
hides it): a damaged log is refused in one line, and no derived log is left.

Options default to what the log says it was built with: a closed-loop log records its
mapping options in its ``sgtool.Episode`` record (``extra.mapping``), so replaying it with
the defaults rebuilds the same graphs it decided on. Otherwise: a refresh every 10 frames
and at every action, the frequency room classifier (the containment model for a room none
of whose categories it knows), MoMa-LLM's "seen" threshold of 50
points per frame scaled by the image size (``50 * W * H / 320 / 240``, at least 5), and
depth mapped to MoMa-LLM's 5 m, or less where the log's own depth noise would read far
floor as obstacles (measured on its first frames, :mod:`sgtool.replayers.depth_range`;
the report says so and the ``sgtool.replay`` metadata records the depth).

Logs without instance ids (imported real data) replay to geometry only: voxels,
occupancy, Voronoi graph, rooms without door cuts, frontiers; the report says that the
semantics are absent.

Determinism: the output depends on the input bytes and the options only (no wall clock,
no path names), so replaying a log twice gives byte-identical files.
"""

from __future__ import annotations

import collections
import os
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from sgtool.arg_checks import function, number, of_type, whole
from sgtool.arg_checks import progress as check_progress
from sgtool.blas import single_blas_thread
from sgtool.datasets.room_evidence import make_classifier
from sgtool.errors import LogFormatError, SgtoolError
from sgtool.files import sha256_file
from sgtool.heap import frozen_heap, small_pages
from sgtool.log import schemas as S
from sgtool.log.chunk_copy import RawChunk, in_sequence
from sgtool.log.frame_assembly import FRAME_TOPICS, FrameAssembler
from sgtool.log.reader import LogReader
from sgtool.log.records import Episode, Instances
from sgtool.log.writer import LogWriter
from sgtool.mapping.voxels import VoxelConfig
from sgtool.progress import Progress
from sgtool.replayers.depth_range import FirstFrames, first_frames
from sgtool.replayers.instance_notes import instance_notes
from sgtool.scenegraph.build_options import (
    CLASSIFIERS,
    MAX_DEPTH_M,
    MAX_DEPTH_RANGE,
    MIN_POINTS_320x240,
    ResolvedOptions,
    builder_config,
    default_min_points,
)
from sgtool.scenegraph.derived_layers import DERIVED_TOPICS, write_refresh
from sgtool.scenegraph.stream import Refresh, SceneGraphStream

REPLAY_METADATA = "sgtool.replay"
REBUILT_TOPICS = frozenset({*DERIVED_TOPICS, S.GRAPH_SCENE})  # not copied: written anew
_INSTANCES = S.RECORDS["instances"].topic
_ACTION = S.RECORDS["action"].topic
_EPISODE = S.RECORDS["episode"].topic


@dataclass(frozen=True)
class ReplayOptions:
    """How to rebuild; ``None`` fields take the log's recorded value, else the default."""

    every: int | None = None  # frames between refreshes (K)
    classifier: str | None = None  # containment | frequency | none
    min_points: int | None = None  # points in one frame for an instance to count as seen
    voxel_size: float | None = None  # m
    max_frames: int | None = None  # stop after this many frames
    max_depth: float | None = None  # m; depth farther is not mapped
    tf_time: str = "log"  # what pairs /tf with frames: "log" time or header "stamp"

    def __post_init__(self) -> None:  # a caller's wrong type: one line, here (the ranges
        for name in ("every", "min_points", "max_frames"):  # when resolved, named as flags)
            whole(name, getattr(self, name), optional=True)
        for name in ("voxel_size", "max_depth"):
            number(name, getattr(self, name), optional=True)
        if self.classifier is not None and not isinstance(self.classifier, str):
            raise SgtoolError(f"classifier={self.classifier!r}: a classifier's name")


def resolve_options(reader: LogReader, options: ReplayOptions) -> ResolvedOptions:
    """Fill the unset options from the log's Episode record, else the defaults
    (:func:`resolve_options_measured` without what it measured)."""
    return resolve_options_measured(reader, options)[0]


def resolve_options_measured(reader: LogReader, options: ReplayOptions
                             ) -> tuple[ResolvedOptions, FirstFrames | None]:
    """Fill the unset options from the log's Episode record (a live map's), else the
    options a derived log was built with (its ``sgtool.replay`` metadata), else the
    defaults; the depth to map to, unless given or recorded, is lowered to where the log's
    depth noise reaches the floor tolerance
    (:func:`~sgtool.replayers.depth_range.first_frames`, returned with the options)."""
    if options.max_frames is not None and options.max_frames < 1:
        raise SgtoolError(f"max frames {options.max_frames} (--max-frames): must be >= 1")
    if options.tf_time not in ("log", "stamp"):
        raise SgtoolError(f"tf time {options.tf_time!r} (--tf-time): \"log\" (pair /tf with "
                          "frames by log time) or \"stamp\" (by header stamp)")
    recorded, found = _recorded_mapping(reader)
    size = _image_size(reader)
    every = options.every if options.every is not None else int(recorded.get("every", 10))
    clf = options.classifier or str(recorded.get("classifier", "frequency"))
    if clf not in CLASSIFIERS:
        raise SgtoolError(f"unknown room classifier {clf!r}; one of {', '.join(CLASSIFIERS)}")
    mp = options.min_points if options.min_points is not None else recorded.get("min_points")
    if mp is None:
        mp = default_min_points(*size) if size is not None else MIN_POINTS_320x240
    vs = options.voxel_size if options.voxel_size is not None else float(
        recorded.get("voxel_size", VoxelConfig().resolution))
    if every < 1:
        raise SgtoolError(f"every {every} (--every): must be >= 1")
    if not 0.01 <= vs <= 0.5:
        raise SgtoolError(f"voxel size {vs} m (--voxel-size): must be 0.01..0.5")
    if int(mp) < 1:
        raise SgtoolError(f"min points {mp} (--min-points): must be >= 1")
    md = options.max_depth if options.max_depth is not None else float(
        recorded.get("max_depth", MAX_DEPTH_M))
    first = None
    if options.max_depth is None and not found:
        first = first_frames(reader, md, options.tf_time, max_frames=options.max_frames)
        if first.noise is not None and first.noise.max_depth is not None:
            md = max(MAX_DEPTH_RANGE[0], first.noise.max_depth)
    if not MAX_DEPTH_RANGE[0] <= md <= MAX_DEPTH_RANGE[1]:
        raise SgtoolError(f"max depth {md:g} m (--max-depth): must be {MAX_DEPTH_RANGE[0]:g}.."
                          f"{MAX_DEPTH_RANGE[1]:g}")
    return ResolvedOptions(every=int(every), classifier=clf, min_points=int(mp),
                           voxel_size=float(vs), max_frames=options.max_frames,
                           max_depth=float(md)), first


def _recorded_mapping(reader: LogReader) -> tuple[dict[str, Any], bool]:
    """The mapping options ``reader``'s log was built with, and whether it says: a derived
    log's ``sgtool.replay`` metadata (text; ``max_depth`` there only when it was not the
    default), else a live map's Episode record (``extra.mapping``; a derived log of a
    closed-loop log copies it, so the metadata of its own build comes first)."""
    meta = reader.metadata.get(REPLAY_METADATA)
    if not meta:
        for _, rec in reader.records(Episode):
            m = rec.extras.get("mapping")
            if isinstance(m, dict):
                return m, True
        return {}, False
    out: dict[str, Any] = {"max_depth": MAX_DEPTH_M}
    try:
        for key, kind in (("every", int), ("classifier", str), ("min_points", int),
                          ("voxel_size", float), ("max_depth", float)):
            if meta.get(key):
                out[key] = kind(meta[key])
    except ValueError:
        raise SgtoolError(f"{reader.path}: its sgtool.replay metadata is damaged "
                          f"({dict(meta)}); give the replay options") from None
    return out, True


def replay_metadata(opts: ResolvedOptions, tf_time: str = "log",
                    input_sha256: str | None = None) -> dict[str, str]:
    """The ``sgtool.replay`` metadata of a derived log: the resolved options, ``tf_time``
    when it is not the default "log" (default replays stay as they were), and the sha256
    of the input log's bytes (what a derived log was made from: a folder replay keeps a
    derived log only while its input is the same)."""
    return {**opts.to_metadata(), **({"tf_time": tf_time} if tf_time != "log" else {}),
            **({"input_sha256": input_sha256} if input_sha256 else {})}


def _image_size(reader: LogReader) -> tuple[int, int] | None:
    """(width, height) of the camera: its first calibration, else its first depth image."""
    for topic in (S.CALIBRATION, S.DEPTH):
        if reader.has(topic):
            for d in reader.messages([topic]):
                return int(d.message.width), int(d.message.height)
    return None


def stage_lines(stages: dict[str, tuple[float, float, int]]) -> list[str]:
    """A table of per-stage (median ms, max ms, calls), empty without stages."""
    if not stages:
        return []
    out = [f"{'stage':<12}{'median ms':>10}{'max ms':>10}{'calls':>7}"]
    for stage, (med, mx, n) in stages.items():
        out.append(f"{stage:<12}{med:>10.2f}{mx:>10.2f}{n:>7}")
    return out


@dataclass
class ReplayReport:
    """What :func:`replay` did: its ``input`` and ``output`` (None without one), the
    resolved ``options``, the frames integrated and refreshes made, whether the log has
    instance ids (``semantic``), the ``last`` refresh, per-stage (median ms, max ms,
    calls), the wall-clock ``seconds`` (reported, never written) and ``truncated`` when
    ``max_frames`` stopped it; :meth:`lines` is what ``sgtool replay`` prints."""

    input: Path
    output: Path | None
    options: ResolvedOptions
    frames: int = 0
    refreshes: int = 0
    semantic: bool = True  # the log has instance ids
    last: Refresh | None = field(default=None, repr=False)  # graph and map layers
    stages: dict[str, tuple[float, float, int]] = field(default_factory=dict, repr=False)
    seconds: float = 0.0  # wall clock of the run (reported, never written)
    truncated: bool = False  # stopped at max_frames
    warnings: list[str] = field(default_factory=list)  # one line each (/tf stamps)
    notes: list[str] = field(default_factory=list)  # one line each (the depth measured)

    def lines(self) -> list[str]:
        out = []
        if self.output is not None and self.output.exists():
            out.append(f"wrote {self.output} ({self.output.stat().st_size / 1e6:.1f} MB)")
        fps = self.frames / self.seconds if self.seconds > 0 else 0.0
        o = self.options
        out.append(f"{self.frames} frames, {self.refreshes} refreshes (every {o.every} frames "
                   f"and at every action), {self.seconds:.1f} s ({fps:.1f} frames/s); room "
                   f"classifier {o.classifier}, voxels {o.voxel_size} m, seen at "
                   f">= {o.min_points} points"
                   + (f", depth to {o.max_depth:g} m" if o.max_depth != MAX_DEPTH_M else ""))
        out.extend(self.notes)
        if not self.semantic:
            out.append("the log has no instance ids: semantics are absent, so the graph has "
                       "geometry only (occupancy, Voronoi graph, rooms without door cuts, "
                       "frontiers; no objects, doors or room categories)")
        out.extend(f"warning: {w}" for w in self.warnings)
        if self.truncated:
            out.append(f"stopped after {self.frames} frames (--max-frames)")
        if self.last is not None:
            g = self.last.graph
            explored = [r for r in g.rooms if r.explored]
            cats = ", ".join(f"{r.id} {r.category}" for r in explored)
            out.append(f"final graph: {len(explored)} rooms ({cats}), "
                       f"{len(g.rooms) - len(explored)} unexplored behind closed doors, "
                       f"{len(g.objects)} objects, {len(g.frontiers())} frontiers, "
                       f"{len(g.doors)} doors")
            out.extend(f"warning: {w}" for w in self.graph_warnings())
        return out + stage_lines(self.stages)

    def graph_warnings(self) -> list[str]:
        """What the final graph says went wrong (no room, no object or door of a log with
        ids, doors joining one room), for the report and ``--json``."""
        if self.last is None:
            return []
        g, out = self.last.graph, []
        if not g.rooms and self.frames >= self.options.every:
            out.append(f"no room in the final graph after {self.frames} frames: the map "
                       "found no free floor for its Voronoi graph; noisy depth far from the "
                       "camera reads as obstacles (try --max-depth "
                       f"{max(1.0, self.options.max_depth - 2):g})")
        if self.semantic and not g.objects and not g.doors \
                and self.frames >= self.options.every:
            out.append(f"the log has instance ids, but no object or door was seen in "
                       f"{self.frames} frames (ids on floor and walls only, a segmenter that "
                       "failed, or ids its instance table does not name): the graph has "
                       "geometry only")
        lone = sum(len(set(d.rooms)) < 2 for d in g.doors)
        if lone and g.rooms:
            out.append(f"{lone} of {len(g.doors)} doors join one room only: the floor behind "
                       "them was not mapped, or the rooms on their two sides merged (pose "
                       "drift or jumps, or a door unlabelled in most frames)")
        return out


def replay(
    log: str | os.PathLike[str],
    output: str | os.PathLike[str] | None = None,
    options: ReplayOptions | None = None,
    *,
    on_refresh: Callable[[Refresh, SceneGraphStream], None] | None = None,
    progress: Progress | None = None,
    compression: str = "zstd",
    verify: bool = True,
    room_classifier: Callable[[str], Any] | None = None,
    copy_chunks: bool = True,
) -> ReplayReport:
    """Replay ``log`` (module doc). ``on_refresh`` sees every refresh as it happens;
    ``progress`` is anything with ``update(n)`` (a tqdm bar), advanced per frame;
    ``verify`` (the default) checks every chunk CRC of the input as it is read, always on
    with an ``output`` (module doc; ``sgtool doctor`` checks everything; without it damage
    still gives a one-line error, or a frame read from damaged bytes);
    ``room_classifier`` builds the classifier from the resolved name instead of
    :func:`~sgtool.datasets.room_evidence.make_classifier` (``llm`` with a chat client);
    ``copy_chunks`` copies the input's chunks into the derived log as they are where that
    gives the same messages in the same order (:func:`_can_copy`), instead of writing them
    message by message (recompressed)."""
    of_type("log", log, (str, os.PathLike), "a log's path")
    if options is not None:
        of_type("options", options, ReplayOptions, "a ReplayOptions")
    function("on_refresh", on_refresh, ("refresh", "stream"))
    progress = check_progress("progress", progress)
    function("room_classifier", room_classifier, ("name",))
    if output is not None and not os.fspath(output):
        raise SgtoolError("output: an empty path; give the derived log's name (*.mcap)")
    src = Path(log)
    dst = Path(output) if output is not None else None
    if dst is not None and dst.suffix != ".mcap":
        raise SgtoolError(f"{output}: the derived log is an MCAP log; name it *.mcap")
    if dst is not None and dst.exists() and src.exists() and dst.resolve() == src.resolve():
        raise SgtoolError("the output must not be the input log")
    with LogReader(src, verify=verify or dst is not None) as reader, single_blas_thread():
        reader.require(S.DEPTH, why="replay builds the map from depth images")
        tf_time = (options or ReplayOptions()).tf_time
        opts, first = resolve_options_measured(reader, options or ReplayOptions())
        report = ReplayReport(src, dst, opts, semantic=reader.has(S.IDS))
        if first is not None and first.noise is not None and first.noise.max_depth is not None:
            report.notes.append(first.noise.describe())
        if first is not None:
            report.warnings.extend(n for n in (first.up_note, first.tilt_note) if n)
        stream = SceneGraphStream(None, (room_classifier or make_classifier)(opts.classifier),
                                  builder_config(opts))
        with frozen_heap(), small_pages():  # no full-collection or huge-page stalls
            t0 = time.perf_counter()
            if dst is None:
                _run(reader, stream, None, opts, report, on_refresh, progress, tf_time=tf_time)
            else:
                meta = dict(reader.metadata.get(S.METADATA_NAME, {}))
                extra = {k: v for k, v in meta.items()
                         if k not in ("sgtool_version", "log_schema_version", "seed")}
                with LogWriter(dst, seed=reader.seed, compression=compression,
                               metadata=extra, keep_partial=False) as writer:
                    for name, data in sorted(reader.metadata.items()):
                        if name not in (S.METADATA_NAME, REPLAY_METADATA):
                            writer.add_metadata(name, data)
                    writer.add_metadata(REPLAY_METADATA, replay_metadata(
                        opts, tf_time, sha256_file(src)))
                    for a in reader.iter_attachments():
                        writer.attach(a.name, a.data, a.media_type, a.log_time,
                                      create_time_ns=a.create_time)
                    _run(reader, stream, writer, opts, report, on_refresh, progress, copy_chunks,
                         tf_time=tf_time)
        report.seconds = time.perf_counter() - t0
        report.stages = stream.builder.stage_summary()
        if report.semantic:
            rooms = len(report.last.graph.rooms) if report.last is not None else 0
            report.warnings.extend(instance_notes(stream.builder.voxels.label_ids(),
                                                  stream.builder.instances, rooms))
    return report


def _run(reader: LogReader, stream: SceneGraphStream, writer: LogWriter | None,
         opts: ResolvedOptions, report: ReplayReport,
         on_refresh: Callable[[Refresh, SceneGraphStream], None] | None,
         progress: Progress | None,
         copy_chunks: bool = False, tf_time: str = "log") -> None:
    feed = _Feed(reader, stream, writer, opts, report, on_refresh, progress, tf_time)
    if copy_chunks and writer is not None and _can_copy(reader, writer, opts):
        for chunk, items in reader.chunks(views=True):
            if chunk is not None and _copyable(chunk, items):
                feed.settle_before(int(chunk.index.message_start_time))
            copied = chunk is not None and _copyable(chunk, items) and writer.copy_chunk(chunk)
            for schema, channel, message in items:
                feed.message(schema, channel, message, write=not copied)
    else:
        for schema, channel, message in reader.raw_messages():
            if not feed.message(schema, channel, message, write=writer is not None):
                break
    feed.end()
    for note in (feed.asm.tf_stamp_note(), feed.asm.depth_stamp_note(), feed.asm.stale.note(),
                 unposed_note(feed), feed.asm.unpaired_note()):
        if note is not None:
            report.warnings.append(note)


def unposed_note(feed: _Feed) -> str | None:
    """One line for the frames left out without a camera pose (before the first /tf, a
    chain broken); an error when no frame had one."""
    why = (f"{S.TF} has no chain from '{S.WORLD_FRAME}' to the depth image's frame (sgtool's "
           f"logs name them '{S.WORLD_FRAME}' and '{S.CAMERA_FRAME}') at their time")
    if not feed.report.frames and not feed.report.truncated and feed.stale_out:
        raise LogFormatError(f"{feed.reader.path}: no frame has a camera pose: "
                             f"{feed.asm.stale.note()}")
    if not feed.unposed:
        return None
    if not feed.report.frames and not feed.report.truncated:
        raise LogFormatError(f"{feed.reader.path}: no frame has a camera pose: {why}")
    return f"{feed.unposed} frame(s) without a camera pose left out: {why}"


def _can_copy(reader: LogReader, writer: LogWriter, opts: ResolvedOptions) -> bool:
    """Input chunks can be copied into the derived log as they are (:mod:`sgtool.log.
    chunk_copy`) when the whole log is replayed, it has no derived channels to rebuild,
    its chunks follow each other in time and its channels keep their ids in the output."""
    return (opts.max_frames is None and not reader.topics() & REBUILT_TOPICS
            and in_sequence(reader.summary.chunk_indexes)
            and writer.copy_channels(reader.summary))


def _copyable(chunk: RawChunk, items: list[Any]) -> bool:
    """The messages of ``chunk`` (``items``, in log-time order) can be written as the
    chunk: its indexes count them, and it holds no instance table or action record. A
    frame's refresh is made when a message of a later log time arrives, and may go after
    the chunk; an action record's refresh belongs right after the messages of its log
    time, before what follows it in its chunk."""
    counts: dict[int, int] = {}
    for _, channel, _ in items:
        if channel.topic in (_INSTANCES, _ACTION):
            return False
        counts[channel.id] = counts.get(channel.id, 0) + 1
    return counts == chunk.counts


class _Feed:
    """Input messages, in log-time order, into the stream (frames, instance tables, action
    records) and, when asked, into the derived log; refreshes into the derived log."""

    def __init__(self, reader: LogReader, stream: SceneGraphStream, writer: LogWriter | None,
                 opts: ResolvedOptions, report: ReplayReport,
                 on_refresh: Callable[[Refresh, SceneGraphStream], None] | None,
                 progress: Progress | None, tf_time: str = "log") -> None:
        self.reader, self.stream, self.writer = reader, stream, writer
        self.opts, self.report, self.on_refresh, self.progress = opts, report, on_refresh, progress
        self.frame_topics = set(FRAME_TOPICS)
        self.needed = self.frame_topics | {_INSTANCES, _ACTION}
        self.copied: dict[int, int] = {}  # input channel id -> output channel id
        self.asm = FrameAssembler(where=str(reader.path), tf_time=tf_time, drop_stale=True)
        self.last_t = 0
        # instance tables and actions of one log time, held until that time's messages
        # are all in (:meth:`settle`): MCAP orders no messages of one time
        self.held: list[tuple[int, Instances | None]] = []
        # records of earlier times waiting for their frames (held for a later /tf)
        self.queue: collections.deque[tuple[int, Instances | None]] = collections.deque()
        self.unposed = 0  # frames without a camera pose, left out
        self.stale_out = 0  # frames left out whose pose would come from a stale /tf

    def refreshed(self, r: Refresh | None) -> None:
        if r is None:
            return
        self.report.refreshes += 1
        self.report.last = r
        if self.writer is not None:
            write_refresh(self.writer, r)
        if self.on_refresh is not None:
            self.on_refresh(r, self.stream)

    def take_frame(self, frames: list[Any]) -> bool:
        """Integrate finished frames, each after the records that come before it (a frame
        /tf did not pose is left out and counted), then the records whose frames are all
        in; False when the frame budget is spent."""
        report = self.report
        for fr in frames:
            if self.opts.max_frames is not None and fr.index >= self.opts.max_frames:
                report.truncated = True  # (frames are numbered from 0 as they are read)
                return False
            self._records(before=fr.time_ns)
            if not np.isfinite(fr.pose).all():
                if fr.index in self.asm.stale_left_out:
                    self.stale_out += 1
                else:
                    self.unposed += 1
                continue
            report.frames += 1
            if self.progress is not None:
                self.progress.update(1)
            self.refreshed(self.stream.frame(fr))
        if not self.asm.holding:
            self._records(before=None)
        return True

    def _records(self, before: int | None) -> None:
        """Take the queued records that come before a frame at log time ``before`` (every
        one: None): instance tables of that time or earlier, actions of earlier times."""
        while self.queue:
            t, table = self.queue[0]
            if before is not None and (t > before or (t == before and table is None)):
                return
            self.queue.popleft()
            if table is not None:
                self.stream.instances(t, table)
            else:
                self.refreshed(self.stream.action(t))

    def message(self, schema: Any, channel: Any, message: Any, write: bool) -> bool:
        """Take one input message (``write``: also copy it into the derived log); False
        when the frame budget is spent (the message is then not taken)."""
        topic = channel.topic
        t = int(message.log_time)
        if self.held and self.held[0][0] != t and not self.settle():
            return False
        if self.budget_read():  # the budget's frames are read: only /tf that poses them
            self.take_frame(self.asm.push(topic, t, self.reader.decode(
                schema, channel, message)) if topic in (S.TF, S.TF_STATIC)
                else self.asm.tick(t))
            self.report.truncated |= topic == S.DEPTH  # a frame past the budget
            return self.budget_waits()
        if topic in self.needed:
            decoded = self.reader.decode(schema, channel, message)
            if topic in self.frame_topics:
                if not self.take_frame(self.asm.push(topic, t, decoded)):
                    return False
                if self.budget_read():  # (this message is past the budget: not copied)
                    return self.budget_waits()
            else:
                if self.asm.time != t and not self.take_frame(self.asm.flush()):
                    return False  # (the frame of an earlier time comes before the record)
                if self.budget_read():  # (a record past the budget: neither taken nor copied)
                    return self.budget_waits()
                self.held.append((t, Instances.from_json(
                    decoded, where=f"{self.reader.path}: {Instances.describe(t_ns=t)}")
                    if topic == _INSTANCES else None))
        if write and self.writer is not None and topic not in REBUILT_TOPICS:
            self._write(schema, channel, message, t)
        self.last_t = max(self.last_t, t)
        return True

    def budget_read(self) -> bool:
        """The ``max_frames`` frames are all read (assembled; some may wait for /tf)."""
        return self.opts.max_frames is not None and self.asm.index >= self.opts.max_frames

    def budget_waits(self) -> bool:
        """Past the frame budget: True while a frame within it waits for its /tf (read
        on, copying nothing), else False (the replay stops there)."""
        first = self.asm.first_held
        if first is not None and self.opts.max_frames is not None and \
                first < self.opts.max_frames:
            return True
        self.report.truncated = True
        return False

    def _write(self, schema: Any, channel: Any, message: Any, t: int) -> None:
        writer = self.writer
        assert writer is not None
        cid = self.copied.get(channel.id)
        if cid is None:
            cid = writer.copy_channel(
                channel.topic, schema.name if schema else "", schema.encoding if schema else "",
                bytes(schema.data) if schema else b"", channel.message_encoding,
                dict(channel.metadata))
            self.copied[channel.id] = cid
        # as in a copied chunk: the input's sequence number and publish time
        writer.write_raw(cid, t, bytes(message.data), message.sequence, message.publish_time)

    def end(self) -> None:
        """After the last message taken: the frames and records still held (within the
        frame budget), the last refresh."""
        if self.settle():
            self.take_frame(self.asm.finish())
            self._records(before=None)
        self.refreshed(self.stream.finish(self.last_t if not self.report.truncated else None))

    def settle(self) -> bool:
        """Queue the records held at one log time in the order sgtool writes them, whatever
        the file's order among messages of that time: its instance tables before its
        frame, its actions (each a refresh) after it (:meth:`take_frame` takes them in
        turn with the frames). False when the frame budget is spent."""
        held, self.held = self.held, []
        self.queue.extend(sorted(held, key=lambda r: r[1] is None))  # tables first (stable)
        return self.take_frame(self.asm.flush())

    def settle_before(self, t_ns: int) -> None:
        """Settle the held records when they are older than ``t_ns`` (a copied chunk's
        first log time: their refreshes go before it, as they were written)."""
        if self.held and self.held[0][0] < t_ns:
            self.settle()
