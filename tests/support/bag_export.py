"""Writing ROS bags with ``rosbags``: sgtool frames or a pose trajectory as a ROS 1 ``.bag``,
a ROS 2 sqlite3 bag or a ROS 2 MCAP bag.

The other direction of the bag importer, for interoperability (replaying an sgtool log in
ROS tools) and to test the importer on bags whose content is known exactly. Each frame
becomes, at its log time:
- ``/tf``: ``TFMessage`` with WORLD -> CAMERA (the optical frame) at the frame time;
- the depth image as ``sensor_msgs/Image`` 16UC1 (millimetres), the colour image as rgb8
  ``Image`` or JPEG/PNG ``CompressedImage``, instance ids as 32SC1 ``Image``;
- ``sensor_msgs/CameraInfo`` (plumb_bob, zero distortion, K and P from the intrinsics).

The ROS 1 Noetic type store of ``rosbags`` lacks ``tf2_msgs/TFMessage``; it is registered
from its message definition. Writers refuse to overwrite (``rosbags`` does too).
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import cv2
import numpy as np

from sgtool.errors import SgtoolError
from sgtool.log.codec import depth_to_mm
from sgtool.log.frame import Frame
from sgtool.recorders.importers.poses import tq_from_pose

FORMATS = ("ros1", "ros2-sqlite3", "ros2-mcap")
TF_MSG_DEF = "geometry_msgs/TransformStamped[] transforms\n"


@dataclass(frozen=True)
class BagTopics:
    depth: str = "/camera/depth/image_raw"
    rgb: str = "/camera/rgb/image_raw"
    ids: str = "/camera/instances/image_raw"
    info: str = "/camera/depth/camera_info"
    tf: str = "/tf"
    world: str = "world"
    camera: str = "camera_optical_frame"


def typestore_for(fmt: str) -> Any:
    from rosbags.typesys import Stores, get_types_from_msg, get_typestore

    if fmt == "ros1":
        ts = get_typestore(Stores.ROS1_NOETIC)
        if "tf2_msgs/msg/TFMessage" not in ts.fielddefs:
            ts.register(get_types_from_msg(TF_MSG_DEF, "tf2_msgs/msg/TFMessage"))
        return ts
    return get_typestore(Stores.ROS2_HUMBLE)


class BagWriter:
    """A thin writer over ``rosbags``: ``write(topic, msgtype, t_ns, msg)``."""

    def __init__(self, path: str | Path, fmt: str) -> None:
        if fmt not in FORMATS:
            raise SgtoolError(f"unknown bag format {fmt!r} ({', '.join(FORMATS)})")
        self.path = Path(path)
        if self.path.exists():
            raise SgtoolError(f"{self.path} exists; not overwriting it")
        self.fmt = fmt
        self.ts = typestore_for(fmt)
        if fmt == "ros1":
            from rosbags.rosbag1 import Writer as W1

            self._w: Any = W1(self.path)
        else:
            from rosbags.rosbag2 import StoragePlugin
            from rosbags.rosbag2 import Writer as W2

            plugin = StoragePlugin.MCAP if fmt == "ros2-mcap" else StoragePlugin.SQLITE3
            self._w = W2(self.path, version=9, storage_plugin=plugin)
        self._w.open()
        self._conns: dict[str, Any] = {}
        self._has_seq = any(n == "seq" for n, _ in self.ts.fielddefs["std_msgs/msg/Header"][1])

    # ----- message builders ------------------------------------------------------------
    def T(self, name: str) -> Any:  # noqa: N802
        return self.ts.types[name]

    def header(self, t_ns: int, frame_id: str) -> Any:
        stamp = self.T("builtin_interfaces/msg/Time")(sec=int(t_ns // 1_000_000_000),
                                                       nanosec=int(t_ns % 1_000_000_000))
        if self._has_seq:
            return self.T("std_msgs/msg/Header")(seq=0, stamp=stamp, frame_id=frame_id)
        return self.T("std_msgs/msg/Header")(stamp=stamp, frame_id=frame_id)

    def transform_stamped(self, t_ns: int, parent: str, child: str, T: np.ndarray) -> Any:  # noqa: N803
        tr, q = tq_from_pose(T)
        g = "geometry_msgs/msg/"
        return self.T(g + "TransformStamped")(
            header=self.header(t_ns, parent), child_frame_id=child,
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
        ok, buf = cv2.imencode("." + fmt, cv2.cvtColor(rgb, cv2.COLOR_RGB2BGR))
        if not ok:
            raise SgtoolError(f"OpenCV cannot encode {fmt}")
        return self.T("sensor_msgs/msg/CompressedImage")(
            header=self.header(t_ns, frame_id), format=fmt,
            data=np.asarray(buf, dtype=np.uint8).ravel(),
        )

    def camera_info(self, t_ns: int, frame_id: str, frame: Frame) -> Any:
        k = frame.intrinsics
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
    def write(self, topic: str, msgtype: str, t_ns: int, msg: Any) -> None:
        conn = self._conns.get(topic)
        if conn is None:
            conn = self._w.add_connection(topic, msgtype, typestore=self.ts)
            self._conns[topic] = conn
        data = (self.ts.serialize_ros1(msg, msgtype) if self.fmt == "ros1"
                else self.ts.serialize_cdr(msg, msgtype))
        self._w.write(conn, int(t_ns), data)

    def close(self) -> None:
        self._w.close()

    def __enter__(self) -> BagWriter:
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()


def write_frames_bag(
    frames: Iterable[Frame],
    out: str | Path,
    fmt: str = "ros2-mcap",
    *,
    topics: BagTopics | None = None,
    rgb_format: str = "raw",  # raw | jpg | png
    tf: bool = True,
) -> int:
    """Write sgtool frames as a bag (see the module docstring); returns the frame count.
    ``tf=False`` leaves the poses out (a camera recorded alone)."""
    tp = topics or BagTopics()
    n = 0
    with BagWriter(out, fmt) as w:
        for fr in frames:
            t = fr.time_ns
            if tf:
                w.write(tp.tf, "tf2_msgs/msg/TFMessage", t,
                        w.tf(t, [w.transform_stamped(t, tp.world, tp.camera, fr.pose)]))
            w.write(tp.info, "sensor_msgs/msg/CameraInfo", t, w.camera_info(t, tp.camera, fr))
            w.write(tp.depth, "sensor_msgs/msg/Image", t,
                    w.image(t, tp.camera, depth_to_mm(fr.depth), "16UC1"))
            if fr.rgb is not None:
                if rgb_format == "raw":
                    w.write(tp.rgb, "sensor_msgs/msg/Image", t,
                            w.image(t, tp.camera, fr.rgb, "rgb8"))
                else:
                    w.write(tp.rgb, "sensor_msgs/msg/CompressedImage", t,
                            w.compressed(t, tp.camera, fr.rgb, rgb_format))
            if fr.ids is not None:
                w.write(tp.ids, "sensor_msgs/msg/Image", t,
                        w.image(t, tp.camera, fr.ids.astype("<i4"), "32SC1"))
            n += 1
    return n


def write_log_as_bag(log: str | Path, out: str | Path, fmt: str = "ros2-mcap", **kw: Any) -> int:
    """An sgtool log's frames as a bag."""
    from sgtool.log.reader import LogReader

    with LogReader(log) as r:
        return write_frames_bag(r.frames(), out, fmt, **kw)
