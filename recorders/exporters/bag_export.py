"""``sgtool export bag``: an sgtool log (typically a derived log of ``sgtool replay``) as a
ROS 1 ``.bag`` or a ROS 2 bag folder (MCAP storage), written with ``rosbags`` so that RViz,
``ros2 bag``, Foxglove and Rerun's ROS importers show the maps.

Topics, each message at its log time (the header stamp is the log time too):

- ``/camera/depth``, ``/camera/rgb``, ``/camera/instances`` -> ``/camera/.../image_raw``,
  ``sensor_msgs/Image`` with the same encoding and bytes;
- ``/camera/calibration`` -> ``/camera/camera_info``, ``sensor_msgs/CameraInfo``;
- ``/tf`` -> ``/tf``, ``tf2_msgs/TFMessage``;
- ``/map/occupancy`` -> ``/map/occupancy``, ``nav_msgs/OccupancyGrid``;
- ``/map/voronoi``, ``/map/rooms`` -> same topics, ``visualization_msgs/MarkerArray``;
- ``/sgtool/scene_graph`` -> same topic, ``std_msgs/String`` (its JSON), and
  ``/map/objects``, ``MarkerArray`` of the graph's objects.

The bag is written in a temporary folder beside OUT and moved to OUT when complete, so an
error leaves no half-written bag; an existing OUT is refused unless ``force``.
"""

from __future__ import annotations

import os
import shutil
import tempfile
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from sgtool.errors import SgtoolError
from sgtool.files import output_error
from sgtool.log import codec
from sgtool.log import schemas as S
from sgtool.log.reader import LogReader
from sgtool.recorders.exporters import ros_maps
from sgtool.recorders.exporters.bagwriter import BagWriter

FORMATS = {"ros1": "ros1", "ros2": "ros2-mcap"}
GRAPH_TOPIC = S.RECORDS["scene_graph"].topic
IMAGE_TOPICS = {S.DEPTH: "/camera/depth/image_raw", S.RGB: "/camera/rgb/image_raw",
                S.IDS: "/camera/instances/image_raw"}
INFO_TOPIC = "/camera/camera_info"
OBJECTS_TOPIC = "/map/objects"
MAP_TYPES = {
    S.OCCUPANCY: "nav_msgs/msg/OccupancyGrid",
    S.VORONOI: "visualization_msgs/msg/MarkerArray",
    S.ROOMS: "visualization_msgs/msg/MarkerArray",
}


@dataclass(frozen=True)
class ExportReport:
    """What :func:`export_bag` wrote: the bag ``output`` and its ``fmt`` (ros1, ros2),
    (ROS topic, type, messages) per topic, and whether the log had derived layers;
    :meth:`lines` is what ``sgtool export bag`` prints."""

    output: Path
    fmt: str
    counts: tuple[tuple[str, str, int], ...]  # (ROS topic, type, messages)
    derived: bool  # the log had derived layers

    def lines(self) -> list[str]:
        total = sum(n for _, _, n in self.counts)
        out = [f"wrote {self.output} ({self.fmt}): {total} messages"]
        w = max((len(t) for t, _, _ in self.counts), default=5)
        out.extend(f"  {t:<{w}}  {ty}  {n}" for t, ty, n in self.counts)
        if not self.derived:
            out.append("note: the log has no derived layers (occupancy, Voronoi graph, rooms, "
                       "scene graph): export the output of `sgtool replay LOG -o DERIVED.mcap`")
        return out


def _image(w: BagWriter, t_ns: int, msg: Any) -> Any:
    return w.make("sensor_msgs/msg/Image", header=w.header(t_ns, msg.frame_id),
                  height=int(msg.height), width=int(msg.width), encoding=msg.encoding,
                  is_bigendian=0, step=int(msg.step),
                  data=np.frombuffer(bytes(msg.data), dtype=np.uint8))


def _converters(w: BagWriter) -> dict[str, tuple[str, str, Callable[[int, Any], Any]]]:
    """sgtool topic -> (ROS topic, ROS type, convert(t_ns, decoded message))."""
    tf_type = "tf2_msgs/msg/TFMessage"
    out: dict[str, tuple[str, str, Callable[[int, Any], Any]]] = {
        src: (dst, "sensor_msgs/msg/Image", lambda t, m: _image(w, t, m))
        for src, dst in IMAGE_TOPICS.items()
    }
    out[S.CALIBRATION] = (INFO_TOPIC, "sensor_msgs/msg/CameraInfo",
                          lambda t, m: w.camera_info(t, m.frame_id, codec.decode_calibration(m)))
    out[S.TF] = (S.TF, tf_type, lambda t, m: w.tf(t, [w.transform_stamped(
        t, m.parent_frame_id, m.child_frame_id, codec.decode_transform(m))]))
    out[S.OCCUPANCY] = (S.OCCUPANCY, MAP_TYPES[S.OCCUPANCY],
                        lambda t, m: ros_maps.occupancy_grid(w, t, m))
    for topic in (S.VORONOI, S.ROOMS):
        out[topic] = (topic, MAP_TYPES[topic], lambda t, m: ros_maps.marker_array(w, t, m))
    return out


def export_bag(log: str | Path, out: str | Path, fmt: str = "ros2",
               force: bool = False) -> ExportReport:
    """Write the sgtool log ``log`` (best a derived one) as a ROS bag at ``out`` (module
    doc), ``fmt`` ``ros2`` (a bag folder) or ``ros1`` (a file); an existing ``out`` is
    replaced only with ``force``. The bag appears under its name only when complete."""
    log, out = Path(log), Path(out)
    if fmt not in FORMATS:
        raise SgtoolError(f"--format {fmt!r}: give ros1 or ros2")
    if not log.is_file():
        raise SgtoolError(f"{log}: no such file")
    if out.resolve() == log.resolve():
        raise SgtoolError(f"-o {out}: the output must not be the input log")
    if (out.exists() or out.is_symlink()) and not force:
        raise SgtoolError(f"{out} exists; not overwriting it (use --force)")
    if not out.parent.is_dir():
        raise SgtoolError(f"-o {out}: folder {out.parent} does not exist")
    with LogReader(log) as r:
        if not r.is_sgtool:
            raise SgtoolError(f"{log} is not an sgtool log (`sgtool info {log}` says what it "
                              "is); export works on sgtool logs and their replays")
        derived = r.has(GRAPH_TOPIC) or r.has(S.OCCUPANCY)
        try:  # the bag is made under its own name in a unique temporary folder beside OUT
            tmp_dir = Path(tempfile.mkdtemp(prefix=f".{out.name}.", suffix=".partial",
                                            dir=out.parent))
        except OSError as e:
            raise output_error(e, out) from None
        try:
            counts = _write(r, tmp_dir / out.name, FORMATS[fmt])
            _remove(out)
            os.replace(tmp_dir / out.name, out)
        finally:
            shutil.rmtree(tmp_dir, ignore_errors=True)
    return ExportReport(out, fmt, tuple(counts), derived)


def _remove(p: Path) -> None:
    """An existing output (a ROS 2 bag is a folder) before it is replaced (--force)."""
    if p.is_dir() and not p.is_symlink():
        shutil.rmtree(p)
    elif p.exists() or p.is_symlink():
        p.unlink()


def _write(r: LogReader, tmp: Path, fmt: str) -> list[tuple[str, str, int]]:
    with BagWriter(tmp, fmt) as w:
        conv = _converters(w)
        types: dict[str, str] = {}
        topics = [t for t in [*conv, GRAPH_TOPIC] if r.has(t)]
        for d in r.messages(topics):
            t = d.log_time_ns
            if d.topic == GRAPH_TOPIC:
                for dst, ty, msg in ((GRAPH_TOPIC, "std_msgs/msg/String",
                                      ros_maps.graph_string(w, d.message)),
                                     (OBJECTS_TOPIC, "visualization_msgs/msg/MarkerArray",
                                      ros_maps.object_markers(w, t, d.message))):
                    w.write(dst, ty, t, msg)
                    types[dst] = ty
                continue
            dst, ty, make = conv[d.topic]
            w.write(dst, ty, t, make(t, d.message))
            types[dst] = ty
        return [(topic, types[topic], n) for topic, n in sorted(w.counts.items())]
