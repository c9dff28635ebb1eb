"""Writing sgtool frames as ROS bags (ROS 1 ``.bag``, ROS 2 sqlite3 or MCAP), to test the
importer on bags whose content is known exactly; the writer itself is the product's
(:mod:`sgtool.recorders.exporters.bagwriter`, used by ``sgtool export bag``). Each frame
becomes, at its log time:
- ``/tf``: ``TFMessage`` with WORLD -> CAMERA (the optical frame) at the frame time;
- the depth image as ``sensor_msgs/Image`` 16UC1 (millimetres), the colour image as rgb8
  ``Image`` or JPEG/PNG ``CompressedImage``, instance ids as 32SC1 ``Image``;
- ``sensor_msgs/CameraInfo`` (plumb_bob, zero distortion, K and P from the intrinsics).

Writers refuse to overwrite (``rosbags`` does too).
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from sgtool.log.codec import depth_to_mm
from sgtool.log.frame import Frame
from sgtool.recorders.exporters.bagwriter import FORMATS, BagWriter, typestore_for

__all__ = ["FORMATS", "BagTopics", "BagWriter", "typestore_for", "write_frames_bag",
           "write_log_as_bag"]


@dataclass(frozen=True)
class BagTopics:
    depth: str = "/camera/depth/image_raw"
    rgb: str = "/camera/rgb/image_raw"
    ids: str = "/camera/instances/image_raw"
    info: str = "/camera/depth/camera_info"
    tf: str = "/tf"
    world: str = "world"
    camera: str = "camera_optical_frame"


def write_frames_bag(
    frames: Iterable[Frame],
    out: str | Path,
    fmt: str = "ros2-mcap",
    *,
    topics: BagTopics | None = None,
    rgb_format: str = "raw",  # raw | jpg | png
    tf: bool = True,
    depth_units: float | None = None,
    record_offset_ns: int = 0,
    info_stamped: bool = True,
    tf_stamped: bool = True,
) -> int:
    """Write sgtool frames as a bag (see the module docstring); returns the frame count.
    ``tf=False`` leaves the poses out (a camera recorded alone); ``depth_units`` writes the
    depth as 32FC1 floats in that many units per metre (1: metres; default: 16UC1 mm);
    ``record_offset_ns`` records each message that much after its header stamp (a bag
    recorded on the wall clock of a simulation whose clock starts at 0); ``info_stamped``
    False leaves the CameraInfo header stamps at 0 (a driver that never sets them);
    ``tf_stamped`` False those of the transforms (a tf broadcaster that never sets them)."""
    tp = topics or BagTopics()
    n = 0
    with BagWriter(out, fmt) as w:
        for fr in frames:
            t = fr.time_ns
            rt = t + record_offset_ns
            if tf:
                w.write(tp.tf, "tf2_msgs/msg/TFMessage", rt,
                        w.tf(t, [w.transform_stamped(t if tf_stamped else 0, tp.world,
                                                     tp.camera, fr.pose)]))
            w.write(tp.info, "sensor_msgs/msg/CameraInfo", rt,
                    w.camera_info(t if info_stamped else 0, tp.camera, fr.intrinsics))
            if depth_units is None:
                w.write(tp.depth, "sensor_msgs/msg/Image", rt,
                        w.image(t, tp.camera, depth_to_mm(fr.depth), "16UC1"))
            else:
                d = depth_to_mm(fr.depth).astype("<f4") * float(depth_units / 1000.0)
                w.write(tp.depth, "sensor_msgs/msg/Image", rt, w.image(t, tp.camera, d, "32FC1"))
            if fr.rgb is not None:
                if rgb_format == "raw":
                    w.write(tp.rgb, "sensor_msgs/msg/Image", rt,
                            w.image(t, tp.camera, fr.rgb, "rgb8"))
                else:
                    w.write(tp.rgb, "sensor_msgs/msg/CompressedImage", rt,
                            w.compressed(t, tp.camera, fr.rgb, rgb_format))
            if fr.ids is not None:
                w.write(tp.ids, "sensor_msgs/msg/Image", rt,
                        w.image(t, tp.camera, fr.ids.astype("<i4"), "32SC1"))
            n += 1
    return n


def write_log_as_bag(log: str | Path, out: str | Path, fmt: str = "ros2-mcap", **kw: Any) -> int:
    """An sgtool log's frames as a bag."""
    from sgtool.log.reader import LogReader

    with LogReader(log) as r:
        return write_frames_bag(r.frames(), out, fmt, **kw)
