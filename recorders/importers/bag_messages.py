"""Fields of ROS messages as sgtool needs them: header stamps, poses of pose-like and tf
messages, and the intrinsics of ``CameraInfo`` (ROS 1 and ROS 2 spellings)."""

from __future__ import annotations

from typing import Any

import numpy as np

from sgtool.recorders.importers.poses import pose_from_tq
from sgtool.recorders.importers.tftree import TfTree, frame_name


def stamp_ns(header: Any) -> int:
    return int(header.stamp.sec) * 1_000_000_000 + int(header.stamp.nanosec)


def transform_of(translation: Any, rotation: Any) -> np.ndarray:
    return pose_from_tq(
        (translation.x, translation.y, translation.z), (rotation.x, rotation.y, rotation.z,
                                                        rotation.w)
    )


def pose_of_message(msg: Any, msgtype: str) -> tuple[int, str, np.ndarray]:
    """(stamp, parent frame, parent_T_child) of a pose-like message."""
    if msgtype.endswith("TransformStamped"):
        T = transform_of(msg.transform.translation, msg.transform.rotation)  # noqa: N806
    elif msgtype.endswith("PoseStamped"):
        T = transform_of(msg.pose.position, msg.pose.orientation)  # noqa: N806
    else:  # PoseWithCovarianceStamped, Odometry
        T = transform_of(msg.pose.pose.position, msg.pose.pose.orientation)  # noqa: N806
    return stamp_ns(msg.header), frame_name(msg.header.frame_id), T


def intrinsics_of_info(msg: Any) -> tuple[int, int, float, float, float, float]:
    k = getattr(msg, "k", None)
    if k is None:
        k = msg.K  # ROS 1 spelling
    k = np.asarray(k, dtype=np.float64).ravel()
    return int(msg.width), int(msg.height), float(k[0]), float(k[4]), float(k[2]), float(k[5])


def add_tf_message(tree: TfTree, msg: Any, topic: str) -> None:
    """Every transform of a ``tf2_msgs/TFMessage`` into ``tree`` (static when the topic is
    ``/tf_static``)."""
    static = topic.rstrip("/").endswith("tf_static")
    for tr in msg.transforms:
        tree.add(tr.header.frame_id, tr.child_frame_id, stamp_ns(tr.header),
                 transform_of(tr.transform.translation, tr.transform.rotation), static=static)
