"""Fields of ROS messages as sgtool needs them: header stamps, poses of pose-like and tf
messages, and the intrinsics and distortion of ``CameraInfo`` (ROS 1 and ROS 2 spellings).

A pose whose translation is not finite, or whose quaternion is not finite or too short to be
normalised, is refused in one line naming the topic, the message time and the field, as
replay refuses such a transform in a log (``matrix_from_quat`` would turn a zero quaternion
into the identity: a frame painted into the map with a made-up orientation)."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from sgtool.errors import SgtoolError
from sgtool.log.poses import pose_from_tq
from sgtool.recorders.importers.tftree import TfTree, frame_name

MIN_QUATERNION_NORM = 1e-6  # shorter quaternions cannot be normalised (replay's limit too)


def stamp_ns(header: Any) -> int:
    return int(header.stamp.sec) * 1_000_000_000 + int(header.stamp.nanosec)


def transform_of(translation: Any, rotation: Any, where: str | None = None,
                 fields: tuple[str, str] = ("translation", "rotation")) -> np.ndarray:
    """parent_T_child of a ROS translation (or position) and quaternion. With ``where``
    (the topic and time, for the message), a translation that is not finite or a quaternion
    that cannot be normalised is a user error naming ``where`` and the field (``fields``:
    the names of the translation and the rotation in the message)."""
    t = (float(translation.x), float(translation.y), float(translation.z))
    q = (float(rotation.x), float(rotation.y), float(rotation.z), float(rotation.w))
    if where is not None:
        if not all(math.isfinite(v) for v in t):
            raise SgtoolError(f"{where}: field {fields[0]}: {t} is not finite")
        if not (all(math.isfinite(v) for v in q) and math.hypot(*q) >= MIN_QUATERNION_NORM):
            raise SgtoolError(f"{where}: field {fields[1]}: quaternion (x, y, z, w) = {q} "
                              "cannot be normalised (not finite, or of length about 0)")
    return pose_from_tq(t, q)


def pose_of_message(msg: Any, msgtype: str, topic: str) -> tuple[int, str, np.ndarray]:
    """(stamp, parent frame, parent_T_child) of a pose-like message on ``topic``; a pose that
    is not finite or has a zero quaternion is a user error (module doc)."""
    t_ns = stamp_ns(msg.header)
    where = f"{topic} message at {t_ns} ns (header stamp)"
    if msgtype.endswith("TransformStamped"):
        T = transform_of(msg.transform.translation, msg.transform.rotation, where,  # noqa: N806
                         ("transform.translation", "transform.rotation"))
    elif msgtype.endswith("PoseStamped"):
        T = transform_of(msg.pose.position, msg.pose.orientation, where,  # noqa: N806
                         ("pose.position", "pose.orientation"))
    else:  # PoseWithCovarianceStamped, Odometry
        T = transform_of(msg.pose.pose.position, msg.pose.pose.orientation, where,  # noqa: N806
                         ("pose.pose.position", "pose.pose.orientation"))
    return t_ns, frame_name(msg.header.frame_id), T


def intrinsics_of_info(msg: Any) -> tuple[int, int, float, float, float, float]:
    """(width, height, fx, fy, cx, cy) of the images a ``CameraInfo`` describes. ``K``,
    ``width`` and ``height`` are the full sensor's; a driver that publishes a region of
    interest (``roi``, all zeros: the whole image) or binned images (``binning_x``/``_y``
    above 1) publishes images of the region's size divided by the binning, with the
    principal point moved and the focal lengths divided alike (REP 104, as ROS's
    ``image_geometry`` reads them)."""
    k = getattr(msg, "k", None)
    if k is None:
        k = msg.K  # ROS 1 spelling
    k = np.asarray(k, dtype=np.float64).ravel()
    width, height = int(msg.width), int(msg.height)
    x0 = y0 = 0
    roi = getattr(msg, "roi", None)
    if roi is not None and int(roi.width) > 0 and int(roi.height) > 0:
        x0, y0 = int(roi.x_offset), int(roi.y_offset)
        width, height = int(roi.width), int(roi.height)
    bx = max(int(getattr(msg, "binning_x", 0) or 0), 1)
    by = max(int(getattr(msg, "binning_y", 0) or 0), 1)
    return (width // bx, height // by, float(k[0]) / bx, float(k[4]) / by,
            (float(k[2]) - x0) / bx, (float(k[5]) - y0) / by)


def distortion_of_info(msg: Any) -> tuple[str, tuple[float, ...]]:
    """(distortion model, coefficients D) of a ``CameraInfo``."""
    d = getattr(msg, "d", None)
    if d is None:
        d = getattr(msg, "D", ())  # ROS 1 spelling
    coeffs = tuple(float(v) for v in np.asarray(d, dtype=np.float64).ravel())
    return str(getattr(msg, "distortion_model", "") or ""), coeffs


def add_tf_message(tree: TfTree, msg: Any, topic: str, *, checked: bool = True,
                   unset_stamp_ns: int | None = None) -> None:
    """Every transform of a ``tf2_msgs/TFMessage`` into ``tree`` (static when the topic is
    ``/tf_static``), at its header stamp (``unset_stamp_ns`` for a zero stamp, when given).
    ``checked``: a transform that is not finite or has a zero quaternion is a user error
    naming the topic, the stamp, the link and the field (module doc); a peek for frame
    names only does not check."""
    static = topic.rstrip("/").endswith("tf_static")
    for i, tr in enumerate(msg.transforms):
        t_ns = stamp_ns(tr.header) or (unset_stamp_ns or 0)
        where = (f"{topic} message at {t_ns} ns (header stamp), transform "
                 f"{frame_name(tr.header.frame_id)} -> {frame_name(tr.child_frame_id)}"
                 if checked else None)
        fields = (f"transforms[{i}].transform.translation", f"transforms[{i}].transform.rotation")
        tree.add(tr.header.frame_id, tr.child_frame_id, t_ns,
                 transform_of(tr.transform.translation, tr.transform.rotation, where, fields),
                 static=static)
