"""A thin writer of ROS bags over ``rosbags``: a ROS 1 ``.bag``, a ROS 2 sqlite3 bag or a
ROS 2 MCAP bag, with builders for the messages sgtool writes (headers, transforms, poses,
images, camera info).

The ROS 1 Noetic type store of ``rosbags`` lacks ``tf2_msgs/TFMessage``; it is registered
from its message definition. The writer refuses to overwrite (``rosbags`` does too): the
exporter writes to a temporary name and renames.

Options of the writer (all off by default):

- ``frames``: a renaming of frame ids applied to every header and child frame it builds;
- ``compression``: ``zstd`` chunks for ROS 2 MCAP storage, ``lz4`` or ``bz2`` chunks for
  ROS 1 (``none`` or None: uncompressed);
- ``distro``: the ROS 2 distribution whose message types and ``metadata.yaml`` layout are
  written: ``humble`` (metadata version 5, QoS profiles as a YAML string, no type hashes)
  or ``jazzy`` (version 9, QoS profiles as a list, ``ros_distro: jazzy``); None writes
  rosbags' own version 9 with Humble's types;
- per topic, ``write(..., latched=True)`` offers a transient-local, depth-1 QoS profile in
  ROS 2 and a latching connection in ROS 1 (maps, ``/tf_static``); other topics offer a
  reliable, volatile, keep-last-10 profile.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

from sgtool.errors import SgtoolError
from sgtool.log.frame import CameraIntrinsics
from sgtool.log.poses import tq_from_pose

FORMATS = ("ros1", "ros2-sqlite3", "ros2-mcap")
DISTROS = ("humble", "jazzy")
COMPRESSIONS = {"ros1": ("none", "lz4", "bz2"), "ros2-mcap": ("none", "zstd"),
                "ros2-sqlite3": ("none",)}
METADATA_VERSION = {"humble": 5, "jazzy": 9}  # metadata.yaml version each distro writes
TF_MSG_DEF = "geometry_msgs/TransformStamped[] transforms\n"


def typestore_for(fmt: str, distro: str | None = None) -> Any:
    from rosbags.typesys import Stores, get_types_from_msg, get_typestore

    if fmt == "ros1":
        ts = get_typestore(Stores.ROS1_NOETIC)
        if "tf2_msgs/msg/TFMessage" not in ts.fielddefs:
            ts.register(get_types_from_msg(TF_MSG_DEF, "tf2_msgs/msg/TFMessage"))
        return ts
    return get_typestore(Stores.ROS2_JAZZY if distro == "jazzy" else Stores.ROS2_HUMBLE)


def _qos(latched: bool) -> Any:
    """The QoS profile offered for a topic: transient-local depth 1 when ``latched``
    (late subscribers such as RViz2's Map display get the last message), else reliable,
    volatile, keep-last 10. Zero durations mean the middleware's default (infinite)."""
    from rosbags.interfaces import (
        Qos,
        QosDurability,
        QosHistory,
        QosLiveliness,
        QosReliability,
        QosTime,
    )

    zero = QosTime(0, 0)
    return Qos(QosHistory.KEEP_LAST, 1 if latched else 10, QosReliability.RELIABLE,
               QosDurability.TRANSIENT_LOCAL if latched else QosDurability.VOLATILE,
               zero, zero, QosLiveliness.AUTOMATIC, zero, False)


def rewrite_metadata(bag: Path, distro: str) -> None:
    """Rewrite ``bag/metadata.yaml`` (written by rosbags at version 8 for humble, 9 for
    jazzy) into the layout ``distro``'s rosbag2 writes (module doc)."""
    from io import StringIO

    from ruamel.yaml import YAML

    meta_path = bag / "metadata.yaml"
    yaml = YAML(typ="safe")
    yaml.default_flow_style = False
    doc = yaml.load(meta_path.read_text("utf8"))
    info = doc["rosbag2_bagfile_information"]
    info["version"] = METADATA_VERSION[distro]
    if distro == "humble":
        for topic in info["topics_with_message_count"]:
            topic["topic_metadata"].pop("type_description_hash", None)
        info.pop("custom_data", None)
        info.pop("ros_distro", None)
    else:
        info["ros_distro"] = distro
    text = StringIO()
    yaml.dump(doc, text)
    meta_path.write_text(text.getvalue(), "utf8")


_NUMPY = {"byte": "uint8", "char": "uint8", "bool": "bool"}


class BagWriter:
    """A thin writer over ``rosbags``: ``write(topic, msgtype, t_ns, msg)``."""

    def __init__(self, path: str | Path, fmt: str, *, frames: Mapping[str, str] | None = None,
                 compression: str | None = None, distro: str | None = None) -> None:
        if fmt not in FORMATS:
            raise SgtoolError(f"unknown bag format {fmt!r} ({', '.join(FORMATS)})")
        compression = compression or "none"
        if compression not in COMPRESSIONS[fmt]:
            raise SgtoolError(f"compression {compression!r}: a {fmt} bag takes "
                              f"{', '.join(COMPRESSIONS[fmt])}")
        if distro is not None and distro not in DISTROS:
            raise SgtoolError(f"distro {distro!r}: give {' or '.join(DISTROS)}")
        self.path = Path(path)
        if self.path.exists():
            raise SgtoolError(f"{self.path} exists; not overwriting it")
        self.fmt = fmt
        self.distro = None if fmt == "ros1" else distro
        self.frames = dict(frames or {})
        self.ts = typestore_for(fmt, self.distro)
        if fmt == "ros1":
            from rosbags.rosbag1 import Writer as W1

            self._w: Any = W1(self.path)
            if compression != "none":
                self._w.set_compression(W1.CompressionFormat[compression.upper()])
        else:
            from rosbags.rosbag2 import CompressionFormat, CompressionMode, StoragePlugin
            from rosbags.rosbag2 import Writer as W2

            plugin = StoragePlugin.MCAP if fmt == "ros2-mcap" else StoragePlugin.SQLITE3
            self._w = W2(self.path, version=8 if self.distro == "humble" else 9,
                         storage_plugin=plugin)
            if compression == "zstd":  # zstd chunks inside the MCAP file
                self._w.set_compression(CompressionMode.STORAGE, CompressionFormat.ZSTD)
        self._w.open()
        self._conns: dict[str, Any] = {}
        self.counts: dict[str, int] = {}  # messages written per topic
        self._has_seq = any(n == "seq" for n, _ in self.ts.fielddefs["std_msgs/msg/Header"][1])

    # ----- message builders ------------------------------------------------------------
    def T(self, name: str) -> Any:  # noqa: N802
        return self.ts.types[name]

    def make(self, msgtype: str, **given: Any) -> Any:
        """A ``msgtype`` message with the ``given`` fields and every other field at its
        zero value (numbers 0, strings empty, arrays and sequences empty, nested messages
        made the same way): one builder for the ROS 1 and ROS 2 spellings of a type."""
        return self.T(msgtype)(**{name: given[name] if name in given else
                                  self._zero(desc, name, msgtype)
                                  for name, desc in self.ts.fielddefs[msgtype][1]})

    def _zero(self, desc: tuple[Any, Any], name: str, msgtype: str) -> Any:
        from rosbags.interfaces import Nodetype

        kind, spec = desc
        if kind == Nodetype.NAME:
            return self.make(spec)
        if kind == Nodetype.BASE:
            base = spec[0]
            return "" if base == "string" else False if base == "bool" else (
                0.0 if base.startswith("float") else 0)
        sub_kind, sub = spec[0]
        if sub_kind == Nodetype.BASE and sub[0] != "string":
            n = spec[1] if kind == Nodetype.ARRAY else 0
            return np.zeros(n, dtype=_NUMPY.get(sub[0], sub[0]))
        if kind == Nodetype.ARRAY:
            return [self._zero(spec[0], name, msgtype) for _ in range(spec[1])]
        return []

    def frame(self, frame_id: str) -> str:
        """``frame_id`` as written (renamed by ``frames``)."""
        return self.frames.get(frame_id, frame_id)

    def header(self, t_ns: int, frame_id: str) -> Any:
        stamp = self.T("builtin_interfaces/msg/Time")(sec=int(t_ns // 1_000_000_000),
                                                       nanosec=int(t_ns % 1_000_000_000))
        if self._has_seq:
            return self.T("std_msgs/msg/Header")(seq=0, stamp=stamp,
                                                 frame_id=self.frame(frame_id))
        return self.T("std_msgs/msg/Header")(stamp=stamp, frame_id=self.frame(frame_id))

    def transform_stamped(self, t_ns: int, parent: str, child: str, T: np.ndarray) -> Any:  # noqa: N803
        tr, q = tq_from_pose(T)
        g = "geometry_msgs/msg/"
        return self.T(g + "TransformStamped")(
            header=self.header(t_ns, parent), child_frame_id=self.frame(child),
            transform=self.T(g + "Transform")(
                translation=self.T(g + "Vector3")(x=float(tr[0]), y=float(tr[1]), z=float(tr[2])),
                rotation=self.T(g + "Quaternion")(x=float(q[0]), y=float(q[1]), z=float(q[2]),
                                                  w=float(q[3])),
            ),
        )

    def pose_stamped(self, t_ns: int, parent: str, T: np.ndarray) -> Any:  # noqa: N803
        tr, q = tq_from_pose(T)
        g = "geometry_msgs/msg/"
        return self.T(g + "PoseStamped")(
            header=self.header(t_ns, parent),
            pose=self.T(g + "Pose")(
                position=self.T(g + "Point")(x=float(tr[0]), y=float(tr[1]), z=float(tr[2])),
                orientation=self.T(g + "Quaternion")(x=float(q[0]), y=float(q[1]), z=float(q[2]),
                                                     w=float(q[3])),
            ),
        )

    def tf(self, t_ns: int, transforms: list[Any]) -> Any:
        return self.T("tf2_msgs/msg/TFMessage")(transforms=transforms)

    def image(self, t_ns: int, frame_id: str, a: np.ndarray, encoding: str) -> Any:
        a = np.ascontiguousarray(a)
        h, w = a.shape[:2]
        return self.T("sensor_msgs/msg/Image")(
            header=self.header(t_ns, frame_id), height=h, width=w, encoding=encoding,
            is_bigendian=0, step=int(a.strides[0]),
            data=np.frombuffer(a.tobytes(), dtype=np.uint8),
        )

    def compressed(self, t_ns: int, frame_id: str, rgb: np.ndarray, fmt: str) -> Any:
        import cv2  # OpenCV (the `import` extra) only for compressed images

        ok, buf = cv2.imencode("." + fmt, cv2.cvtColor(rgb, cv2.COLOR_RGB2BGR))
        if not ok:
            raise SgtoolError(f"OpenCV cannot encode {fmt}")
        return self.T("sensor_msgs/msg/CompressedImage")(
            header=self.header(t_ns, frame_id), format=fmt,
            data=np.asarray(buf, dtype=np.uint8).ravel(),
        )

    def camera_info(self, t_ns: int, frame_id: str, k: CameraIntrinsics) -> Any:
        K = np.array([k.fx, 0, k.cx, 0, k.fy, k.cy, 0, 0, 1], dtype=np.float64)  # noqa: N806
        R = np.eye(3).ravel()  # noqa: N806
        P = np.array([k.fx, 0, k.cx, 0, 0, k.fy, k.cy, 0, 0, 0, 1, 0], dtype=np.float64)  # noqa: N806
        names = [n for n, _ in self.ts.fielddefs["sensor_msgs/msg/CameraInfo"][1]]
        up = "K" in names  # ROS 1 spells the matrices in capitals
        kw = {("D" if up else "d"): np.zeros(5), ("K" if up else "k"): K,
              ("R" if up else "r"): R, ("P" if up else "p"): P}
        roi = self.T("sensor_msgs/msg/RegionOfInterest")(x_offset=0, y_offset=0, height=0,
                                                         width=0, do_rectify=False)
        return self.T("sensor_msgs/msg/CameraInfo")(
            header=self.header(t_ns, frame_id), height=k.height, width=k.width,
            distortion_model="plumb_bob", binning_x=0, binning_y=0, roi=roi, **kw,
        )

    # ----- writing -----------------------------------------------------------------------
    def write(self, topic: str, msgtype: str, t_ns: int, msg: Any, *,
              latched: bool = False) -> None:
        """Append ``msg`` at ``t_ns`` (ns) on ``topic``; the first message of a topic
        decides its connection (``latched``: module doc)."""
        conn = self._conns.get(topic)
        if conn is None:
            if self.fmt == "ros1":
                conn = self._w.add_connection(topic, msgtype, typestore=self.ts,
                                              latching=1 if latched else None)
            else:
                conn = self._w.add_connection(topic, msgtype, typestore=self.ts,
                                              offered_qos_profiles=[_qos(latched)])
            self._conns[topic] = conn
        data = (self.ts.serialize_ros1(msg, msgtype) if self.fmt == "ros1"
                else self.ts.serialize_cdr(msg, msgtype))
        self._w.write(conn, int(t_ns), data)
        self.counts[topic] = self.counts.get(topic, 0) + 1

    def close(self) -> None:
        self._w.close()
        if self.distro is not None:
            rewrite_metadata(self.path, self.distro)

    def __enter__(self) -> BagWriter:
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()
