"""``sgtool export bag``: an sgtool log (typically a derived log of ``sgtool replay``) as a
ROS 1 ``.bag`` or a ROS 2 bag folder (MCAP storage), written with ``rosbags`` so that RViz,
``ros2 bag``, ``image_proc`` and Foxglove use it (Rerun's ROS importer reads its maps,
images and /tf, not its markers).

Topics (sgtool topic -> ROS topic, type):

- ``/camera/depth``, ``/camera/rgb``, ``/camera/instances`` -> ``/camera/NAME/image_raw``,
  ``sensor_msgs/Image`` with the same encoding and bytes, and with every image a
  ``/camera/NAME/camera_info`` (``sensor_msgs/CameraInfo`` of the calibration in force)
  of the same stamp and frame, as ``image_proc``/``depth_image_proc`` pair them;
- ``/tf`` -> ``/tf`` (``tf2_msgs/TFMessage``) for the links that move, and one latched
  ``/tf_static`` message, at the first stamp, holding every link whose transform never
  changes in the log (``/tf_static`` of the log is taken as fixed too). A link of the
  log's ``/tf_static`` that moves at times (a closed loop's head tilted to look into a
  container) goes to ``/tf`` from its first sample on, its latest value again at each
  image stamp without a sample of its own, so that ``tf2`` (which neither extrapolates
  nor keeps samples older than its cache) resolves every image's frame; a link only ever
  on ``/tf`` is written as logged;
- ``/map/occupancy`` -> ``nav_msgs/OccupancyGrid``; ``/map/voronoi``, ``/map/rooms`` and
  ``/map/graph`` (objects, doors, frontiers, edges) -> ``visualization_msgs/MarkerArray``;
  ``/sgtool/scene_graph`` -> ``std_msgs/String`` (its JSON) and ``/map/objects``
  (``MarkerArray`` of the graph's objects). These, and ``/tf_static``, are latched:
  transient-local QoS in ROS 2, latching in ROS 1.

Time base: a message's bag time and header stamp are its log time plus ``time_base_s``
seconds, so no message falls on stamp 0 (ROS 1's ``rosbag play`` starts at ``TIME_MIN``
and drops what is at zero; ``tf2`` treats stamp 0 as "latest"). By default 1 s for a log
whose time starts within a second of 0 (recorded in simulation), else 0: a recording
imported from a bag keeps its own stamps, and plays beside the original.

Frames are renamed to REP-105's by default (``world`` -> ``map``, ``base`` ->
``base_link``, ``camera`` -> ``camera_optical_frame``: sgtool's camera frame is an optical
one, x right, y down, z forward); ``frames`` gives another mapping (``{}`` keeps sgtool's).
A trajectory imported from a bag's /tf (``sgtool import bag --tf-frames odom:base_link``
without images) is the pose of the frame it names, not of an optical frame: by default
(``frames`` None) its frames keep the source's names (:func:`default_frames`).

The format follows ``out``'s name unless given: ``NAME.bag`` is ROS 1, anything else a
ROS 2 bag folder. Compression: zstd chunks in the ROS 2 MCAP file, lz4 (or bz2) chunks in
ROS 1. ``distro`` (humble, jazzy) sets the ROS 2 message types and ``metadata.yaml``
layout (:mod:`sgtool.recorders.exporters.bagwriter`).

A ROS 1 bag is written beside ``out`` and renamed; a ROS 2 bag folder goes through
:func:`sgtool.files.output_folder`: an existing non-empty ``out`` is refused unless
``force``, and ``force`` replaces only the files sgtool wrote there (other files stay). A
ROS 1 ``out`` that is not a ROS 1 bag is never replaced. An error leaves nothing behind.
"""

from __future__ import annotations

import os
import shutil
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Protocol

import numpy as np

from sgtool.errors import SgtoolError
from sgtool.files import atomic_output, output_folder
from sgtool.log import codec
from sgtool.log import schemas as S
from sgtool.log.frame import CameraIntrinsics
from sgtool.log.reader import LogReader
from sgtool.output_check import check_output
from sgtool.recorders.exporters import ros_maps
from sgtool.recorders.exporters.bagwriter import COMPRESSIONS, DISTROS, BagWriter
from sgtool.recorders.importers.bagfiles import ROS1_MAGIC

FORMATS = {"ros1": "ros1", "ros2": "ros2-mcap"}
DEFAULT_COMPRESSION = {"ros1": "lz4", "ros2": "zstd"}
DEFAULT_TIME_BASE_S = 1.0
REP105 = {S.WORLD_FRAME: "map", S.BASE_FRAME: "base_link",
          S.CAMERA_FRAME: "camera_optical_frame"}
TF_STATIC = "/tf_static"
GRAPH_TOPIC = S.RECORDS["scene_graph"].topic
IMAGE_TOPICS = {S.DEPTH: "/camera/depth", S.RGB: "/camera/rgb", S.IDS: "/camera/instances"}
OBJECTS_TOPIC = "/map/objects"
IMAGE, INFO, TF_TYPE = ("sensor_msgs/msg/Image", "sensor_msgs/msg/CameraInfo",
                        "tf2_msgs/msg/TFMessage")
MARKERS, STRING = "visualization_msgs/msg/MarkerArray", "std_msgs/msg/String"

# ROS topic -> (sgtool source topic, ROS type, latched)
OUTPUTS: dict[str, tuple[str, str, bool]] = {
    **{f"{ns}/image_raw": (src, IMAGE, False) for src, ns in IMAGE_TOPICS.items()},
    **{f"{ns}/camera_info": (src, INFO, False) for src, ns in IMAGE_TOPICS.items()},
    S.TF: (S.TF, TF_TYPE, False),
    TF_STATIC: (S.TF, TF_TYPE, True),
    S.OCCUPANCY: (S.OCCUPANCY, "nav_msgs/msg/OccupancyGrid", True),
    S.VORONOI: (S.VORONOI, MARKERS, True),
    S.ROOMS: (S.ROOMS, MARKERS, True),
    S.GRAPH_SCENE: (S.GRAPH_SCENE, MARKERS, True),
    GRAPH_TOPIC: (GRAPH_TOPIC, STRING, True),
    OBJECTS_TOPIC: (GRAPH_TOPIC, MARKERS, True),
}


class Progress(Protocol):
    """What :func:`export_bag` reports progress to (a ``tqdm`` bar fits): ``total`` is set
    to the number of log messages to convert, ``update(n)`` called as they are."""

    total: float | None

    def update(self, n: float = 1) -> Any: ...


@dataclass(frozen=True)
class ExportReport:
    """What :func:`export_bag` wrote: the bag ``output`` and its ``fmt`` (ros1, ros2),
    (ROS topic, type, messages) per topic, whether the log had derived layers, the time
    base (seconds added to log times) and the compression; :meth:`lines` is what
    ``sgtool export bag`` prints."""

    output: Path
    fmt: str
    counts: tuple[tuple[str, str, int], ...]  # (ROS topic, type, messages)
    derived: bool  # the log had derived layers
    time_base_s: float = DEFAULT_TIME_BASE_S
    compression: str = "none"
    others: tuple[str, ...] = ()  # channels of the log that are none of sgtool's: not exported
    chosen: tuple[str, ...] = ()  # the ROS topics asked for

    def lines(self) -> list[str]:
        total = sum(n for _, _, n in self.counts)
        out = [f"wrote {self.output} ({self.fmt}, {self.compression}): {total} messages, "
               f"stamps = log time + {self.time_base_s:g} s"]
        w = max((len(t) for t, _, _ in self.counts), default=5)
        out.extend(f"  {t:<{w}}  {ty}  {n}" for t, ty, n in self.counts)
        if not total:
            out.append("note: the log holds nothing for the topics chosen"
                       + (" (/tf_static holds only the links that never move)"
                          if TF_STATIC in self.chosen else ""))
        if self.others:
            out.append(f"note: not exported, channels sgtool does not know: "
                       f"{', '.join(self.others)}")
        if not self.derived:
            out.append("note: the log has no derived layers (occupancy, Voronoi graph, rooms, "
                       "scene graph): export the output of `sgtool replay LOG -o DERIVED.mcap`")
        written = {t: n for t, _, n in self.counts}
        bare = [t.removesuffix("/image_raw") for t, n in written.items()
                if t.endswith("/image_raw") and n and f"{t.removesuffix('/image_raw')}"
                f"/camera_info" in self.chosen and not written.get(
                    t.removesuffix("/image_raw") + "/camera_info")]
        if bare:
            out.append(f"note: no CameraInfo for {', '.join(bare)}: the log holds no camera "
                       "calibration (/camera/calibration) to give its images one")
        return out


def format_for(out: Path, fmt: str | None) -> str:
    """The bag format: ``fmt`` when given, else ros1 for ``NAME.bag``, ros2 otherwise; a
    ROS 2 bag (a folder) named ``.bag`` is refused."""
    is_bag = out.suffix.lower() == ".bag"
    if fmt is None:
        return "ros1" if is_bag else "ros2"
    if fmt not in FORMATS:
        raise SgtoolError(f"--format (fmt=) {fmt!r}: give ros1 or ros2")
    if fmt == "ros2" and is_bag:
        raise SgtoolError(f"-o {out}: a .bag name is a ROS 1 bag file, but --format ros2 "
                          "writes a bag folder; drop .bag or use --format ros1")
    return fmt


def select_outputs(names: Iterable[str] | None) -> list[str]:
    """The ROS topics to write for ``names`` (ROS topics or sgtool topics; None: all).
    An sgtool topic selects every ROS topic made from it; an unknown name is refused."""
    if names is None:
        return list(OUTPUTS)
    chosen: list[str] = []
    for name in names:
        hits = [t for t, (src, _, _) in OUTPUTS.items() if name in (t, src)]
        if not hits:
            known = sorted(set(OUTPUTS) | {src for src, _, _ in OUTPUTS.values()})
            raise SgtoolError(f"--topics {name}: not a topic the export writes or reads "
                              f"({', '.join(known)})")
        chosen.extend(t for t in hits if t not in chosen)
    return [t for t in OUTPUTS if t in chosen]


_MAX_STAMP_S = 2**31 - 1  # ROS time: int32 seconds (builtin_interfaces/Time)


def export_bag(log: str | Path, out: str | Path, fmt: str | None = None,
               force: bool = False, *, time_base_s: float | None = None,
               frames: Mapping[str, str] | None = None, distro: str = "humble",
               compression: str | None = None, topics: Iterable[str] | None = None,
               progress: Progress | None = None) -> ExportReport:
    """Write the sgtool log ``log`` (best a derived one) as a ROS bag at ``out`` (module
    doc): ``fmt`` ros1 or ros2 (None: from ``out``'s name), stamps at log time +
    ``time_base_s`` seconds (None: as the module doc says), frames renamed by ``frames``
    (None: :func:`default_frames`), ``compression`` (None: zstd for ros2, lz4 for ros1),
    only the ROS or sgtool ``topics`` given (None: all). The bag appears under its name only
    when complete."""
    from sgtool.arg_checks import progress as check_progress

    progress = check_progress("progress", progress)
    log, out = Path(log), Path(out)
    fmt = format_for(out, fmt)
    compression = compression or DEFAULT_COMPRESSION[fmt]
    if compression not in COMPRESSIONS[FORMATS[fmt]]:
        raise SgtoolError(f"--compression {compression}: a {fmt} bag takes "
                          f"{', '.join(COMPRESSIONS[FORMATS[fmt]])}")
    if distro not in DISTROS:
        raise SgtoolError(f"--distro {distro!r}: give {' or '.join(DISTROS)}")
    if time_base_s is not None and (not np.isfinite(time_base_s) or time_base_s < 0):
        raise SgtoolError(f"--time-base {time_base_s}: give seconds >= 0")
    chosen = select_outputs(topics)
    if not log.is_file():
        raise SgtoolError(f"{log}: no such file")
    if out.resolve() == log.resolve():
        raise SgtoolError(f"-o {out}: the output must not be the input log")
    if fmt == "ros1":
        _check_ros1_target(out, force)
    elif out.parent.exists() and not out.parent.is_dir():
        raise SgtoolError(f"-o {out}: {out.parent} is a file, not a folder")
    elif not out.parent.is_dir():
        raise SgtoolError(f"-o {out}: folder {out.parent} does not exist")
    elif out.exists() and not out.is_dir():
        raise SgtoolError(f"-o {out} is a file; a ROS 2 bag is a folder (not replacing it)")
    with LogReader(log, verify=True) as r:  # a damaged chunk: one line, no bag
        if not r.is_sgtool:
            raise SgtoolError(f"{log} is not an sgtool log (`sgtool info {log}` says what it "
                              "is); export works on sgtool logs and their replays")
        tr = r.time_range()
        if time_base_s is None:
            time_base_s = DEFAULT_TIME_BASE_S if tr is None or tr[0] < 1_000_000_000 else 0.0
        base_ns = int(round(time_base_s * 1e9))
        if tr is not None and tr[0] + base_ns <= 0:
            raise SgtoolError(f"--time-base {time_base_s:g}: the first message would be at "
                              "stamp 0; give a time base > 0")
        if tr is not None and (tr[1] + base_ns) // 1_000_000_000 > _MAX_STAMP_S:
            raise SgtoolError(f"--time-base {time_base_s:g}: the last message's stamp would "
                              f"pass {_MAX_STAMP_S} s, the largest a ROS time holds (a signed "
                              "32-bit count of seconds)")
        derived = r.has(GRAPH_TOPIC) or r.has(S.OCCUPANCY)
        records = {k.topic for k in S.RECORDS.values()}
        others = tuple(sorted(t for t in r.topics() if t not in OUTPUTS_ORDER
                              and t not in records))
        names = dict(frames) if frames is not None else trajectory_frames(
            r.metadata.get(S.IMPORT_METADATA_NAME, {}), REP105)

        def writer(path: Path) -> BagWriter:
            return BagWriter(path, FORMATS[fmt], frames=names, compression=compression,
                             distro=distro if fmt == "ros2" else None)
        if fmt == "ros1":
            with atomic_output(out) as tmp:
                tmp.unlink()  # rosbags creates the file itself
                try:
                    counts = _write(r, writer(tmp), chosen, base_ns, progress)
                except BaseException:
                    tmp.unlink(missing_ok=True)
                    raise
        else:
            with output_folder(out, force=force, command="export bag", option="-o",
                               known=("metadata.yaml", f"{out.name}.mcap")) as stage:
                inner = stage / out.name  # rosbags names the MCAP file after its folder
                counts = _write(r, writer(inner), chosen, base_ns, progress)
                for entry in os.listdir(inner):
                    os.replace(inner / entry, stage / entry)
                shutil.rmtree(inner)
    return ExportReport(out, fmt, tuple(counts), derived, time_base_s, compression, others,
                        tuple(chosen))


def default_frames(log: str | Path) -> dict[str, str]:
    """The frame names :func:`export_bag` gives ``log`` by default (REP-105, a /tf
    trajectory's source names: :func:`trajectory_frames`); REP-105 when the log cannot be
    read (export says why)."""
    try:
        with LogReader(log) as r:
            meta = r.metadata.get(S.IMPORT_METADATA_NAME, {})
    except (SgtoolError, OSError):
        return dict(REP105)
    return trajectory_frames(meta, REP105)


def trajectory_frames(meta: Mapping[str, str], names: Mapping[str, str]) -> dict[str, str]:
    """``names`` (sgtool frame -> bag frame) for a log whose import ``meta`` (the
    ``sgtool.import`` metadata) says it is a trajectory read from /tf: its world and camera
    frames, where ``names`` gives them their REP-105 names, take the source's frame names
    (``odom``, ``base_link``: a robot base's pose is not an optical frame's). Other logs,
    and frames renamed otherwise, keep ``names``."""
    out = dict(names)
    if meta.get("content") != "trajectory":
        return out
    for frame, key in ((S.CAMERA_FRAME, "pose_frame"), (S.WORLD_FRAME, "world_frame")):
        source = meta.get(key, "")
        if source and out.get(frame) == REP105[frame]:
            out[frame] = source
    taken = (out.get(S.CAMERA_FRAME), out.get(S.WORLD_FRAME))
    if S.BASE_FRAME in out and out[S.BASE_FRAME] in taken:
        out.pop(S.BASE_FRAME)  # a trajectory has no base frame: no clash of names
    return out


def _check_ros1_target(out: Path, force: bool) -> None:
    """The one output check of a file (:func:`sgtool.output_check.check_output`); an
    existing ROS 1 ``out`` is replaced only with ``force`` and only if it is a ROS 1 bag
    (what ``export bag`` writes), never another file."""
    check_output(out, force=force)
    if not out.exists():
        return
    try:
        with open(out, "rb") as fh:
            head = fh.read(len(ROS1_MAGIC))
    except OSError as e:
        raise SgtoolError(f"-o {out}: cannot read it ({e.strerror}); not replacing it") from None
    if head != ROS1_MAGIC:
        raise SgtoolError(f"-o {out} is not a ROS 1 bag; --force replaces only a bag, "
                          "not replacing it")


STATIC_TOL = 1e-9  # m, and rotation-matrix entries: a link this still is static


def _static_links(r: LogReader) -> tuple[dict[tuple[str, str], np.ndarray], int]:
    """The (parent, child) links whose transform is the same in every ``/tf`` message of
    the log (to :data:`STATIC_TOL`: a log of schema 1.0 composes base -> camera per frame,
    equal to the last bits), and every link of its ``/tf_static``, with their transform
    (the first); and the log time of the earliest of their messages."""
    seen: dict[tuple[str, str], np.ndarray] = {}
    first: dict[tuple[str, str], int] = {}
    moving: set[tuple[str, str]] = set()
    topics = [t for t in (S.TF, TF_STATIC) if r.has(t)]
    for d in r.messages(topics):
        key = (d.message.parent_frame_id, d.message.child_frame_id)
        T = codec.decode_transform(d.message)  # noqa: N806
        if key in seen and d.topic == S.TF and \
                not np.allclose(seen[key], T, rtol=0.0, atol=STATIC_TOL):
            moving.add(key)
        seen.setdefault(key, T)
        first.setdefault(key, d.log_time_ns)
    static = {k: v for k, v in seen.items() if k not in moving}
    return static, min((first[k] for k in static), default=0)


def _image(w: BagWriter, t_ns: int, msg: Any) -> Any:
    return w.make(IMAGE, header=w.header(t_ns, msg.frame_id),
                  height=int(msg.height), width=int(msg.width), encoding=msg.encoding,
                  is_bigendian=0, step=int(msg.step),
                  data=np.frombuffer(bytes(msg.data), dtype=np.uint8))


def _write(r: LogReader, w: BagWriter, chosen: list[str], base_ns: int,
           progress: Progress | None) -> list[tuple[str, str, int]]:
    """Convert the messages of ``r`` feeding the ``chosen`` ROS topics into ``w``."""
    want = set(chosen)
    sources = {OUTPUTS[t][0] for t in chosen}
    if want & {f"{ns}/camera_info" for ns in IMAGE_TOPICS.values()}:
        sources.add(S.CALIBRATION)
    if S.TF in sources:
        sources.add(TF_STATIC)
    topics = [t for t in OUTPUTS_ORDER if t in sources and r.has(t)]
    if progress is not None:
        progress.total = sum(r.message_count(t) for t in topics)
    with w:
        static, t_static = _static_links(r) if S.TF in sources else ({}, 0)
        if static and TF_STATIC in want:
            t0 = t_static + base_ns
            w.write(TF_STATIC, TF_TYPE, t0, w.tf(t0, [
                w.transform_stamped(t0, p, c, T) for (p, c), T in sorted(static.items())]),
                latched=True)
        calib: CameraIntrinsics | None = None
        # the images of one log time get their camera_info once the time has passed, with
        # the calibration last logged by then (MCAP orders no messages of one log time: a
        # calibration may follow the images it belongs to)
        waiting: list[tuple[str, int, str]] = []  # (namespace, stamp, frame id)
        converters = _converters(w)
        # a mounting that moves at times (on the log's /tf_static, then on /tf): its
        # latest value and the stamp it was last written at
        held: dict[tuple[str, str], tuple[np.ndarray, int]] = {}
        for d in r.messages(topics):
            if progress is not None:
                progress.update(1)
            t = d.log_time_ns + base_ns
            if waiting and waiting[0][1] != t:
                _camera_infos(w, waiting, calib)
            if d.topic == S.CALIBRATION:
                calib = codec.decode_calibration(d.message)
            elif d.topic in (S.TF, TF_STATIC):
                key = (d.message.parent_frame_id, d.message.child_frame_id)
                if key in static or S.TF not in want:
                    continue  # in the one /tf_static message above
                T = codec.decode_transform(d.message)  # noqa: N806
                last = held.get(key)
                if d.topic == TF_STATIC or key in held:
                    held[key] = (T, t)
                if last is not None and last[1] == t and np.array_equal(last[0], T):
                    continue  # written at this stamp already (held for an image)
                w.write(S.TF, TF_TYPE, t, w.tf(t, [w.transform_stamped(t, *key, T)]))
            elif d.topic in IMAGE_TOPICS:
                ns = IMAGE_TOPICS[d.topic]
                for key, (T, since) in list(held.items()):  # noqa: N806
                    if since < t:  # the mounting, holding still: again at the image's stamp
                        held[key] = (T, t)
                        w.write(S.TF, TF_TYPE, t, w.tf(t, [w.transform_stamped(t, *key, T)]))
                if f"{ns}/image_raw" in want:
                    w.write(f"{ns}/image_raw", IMAGE, t, _image(w, t, d.message))
                if f"{ns}/camera_info" in want:
                    waiting.append((ns, t, d.message.frame_id or S.CAMERA_FRAME))
            else:
                for dst, make in converters[d.topic]:
                    if dst in want:
                        w.write(dst, OUTPUTS[dst][1], t, make(t, d.message),
                                latched=OUTPUTS[dst][2])
        _camera_infos(w, waiting, calib)
        return [(topic, OUTPUTS[topic][1], n) for topic, n in sorted(w.counts.items())]


def _camera_infos(w: BagWriter, waiting: list[tuple[str, int, str]],
                  calib: CameraIntrinsics | None) -> None:
    """Write the camera_info of each waiting image (namespace, stamp, frame id) with
    ``calib`` (none before any calibration) and empty ``waiting``."""
    if calib is not None:
        for ns, at, frame in waiting:
            w.write(f"{ns}/camera_info", INFO, at, w.camera_info(at, frame, calib))
    waiting.clear()


OUTPUTS_ORDER = (S.CALIBRATION, S.TF, TF_STATIC, *IMAGE_TOPICS, S.OCCUPANCY, S.VORONOI,
                 S.ROOMS, S.GRAPH_SCENE, GRAPH_TOPIC)


def _converters(w: BagWriter) -> dict[str, list[tuple[str, Callable[[int, Any], Any]]]]:
    """sgtool map topic -> [(ROS topic, convert(t_ns, decoded message))]."""
    return {
        S.OCCUPANCY: [(S.OCCUPANCY, lambda t, m: ros_maps.occupancy_grid(w, t, m))],
        S.VORONOI: [(S.VORONOI, lambda t, m: ros_maps.marker_array(w, t, m))],
        S.ROOMS: [(S.ROOMS, lambda t, m: ros_maps.marker_array(w, t, m))],
        S.GRAPH_SCENE: [(S.GRAPH_SCENE, lambda t, m: ros_maps.marker_array(w, t, m))],
        GRAPH_TOPIC: [(GRAPH_TOPIC, lambda t, m: ros_maps.graph_string(w, m)),
                      (OBJECTS_TOPIC, lambda t, m: ros_maps.object_markers(w, t, m))],
    }
