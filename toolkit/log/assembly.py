"""Assembling frames from the frame-topic messages of a log, pushed in log order.

A *frame* is the depth message at one log time together with the RGB and instance-id
messages of the same log time, the camera calibration in force and the camera pose composed
from the ``/tf`` transforms (world -> ... -> camera) in force at that time. The reader
(:meth:`sgtool.log.reader.LogReader.frames`) and replay
(:mod:`sgtool.replayers.derived_log`) both assemble frames with :class:`FrameAssembler`.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from sgtool.log import codec
from sgtool.log import schemas as S
from sgtool.log.frame import CameraIntrinsics, Frame


class TransformBuffer:
    """Transforms by (parent, child) over time; lookup of the latest at or before t."""

    def __init__(self) -> None:
        self._parent: dict[str, str] = {}
        self._times: dict[str, list[int]] = {}
        self._values: dict[str, list[np.ndarray]] = {}

    def add(self, t_ns: int, parent: str, child: str, T: np.ndarray) -> None:  # noqa: N803
        self._parent[child] = parent
        times = self._times.setdefault(child, [])
        vals = self._values.setdefault(child, [])
        if times and t_ns < times[-1]:
            i = int(np.searchsorted(times, t_ns, side="right"))
            times.insert(i, t_ns)
            vals.insert(i, T)
        else:
            times.append(t_ns)
            vals.append(T)

    def lookup(self, t_ns: int, target: str, root: str = S.WORLD_FRAME) -> np.ndarray | None:
        """root_T_target at ``t_ns``, or None when the chain is not known yet."""
        T = np.eye(4)  # noqa: N806
        frame = target
        for _ in range(32):
            if frame == root:
                return T
            if frame not in self._parent:
                return None
            times = self._times[frame]
            i = int(np.searchsorted(times, t_ns, side="right")) - 1
            if i < 0:
                return None
            T = self._values[frame][i] @ T  # noqa: N806
            frame = self._parent[frame]
        return None


FRAME_TOPICS = (S.RGB, S.DEPTH, S.IDS, S.CALIBRATION, S.TF)


class FrameAssembler:
    """Groups decoded frame-topic messages, pushed in log order, into frames: the depth
    image of one log time with the RGB and id images of the same time, the calibration in
    force and the camera pose from the transforms in force (module doc).

    :meth:`push` returns the previous frame when a message of a new log time arrives;
    :meth:`flush` returns the frame being assembled (when it has its depth image), so a
    caller that meets another record of the same time can take the frame first."""

    def __init__(self, index: int = 0, transforms: TransformBuffer | None = None,
                 calibration: CameraIntrinsics | None = None) -> None:
        self.index = index
        self.transforms = transforms or TransformBuffer()
        self.calibration = calibration
        self._pending: dict[str, Any] = {}
        self._t: int | None = None

    def push(self, topic: str, t_ns: int, message: Any) -> Frame | None:
        out = None
        if self._t is not None and t_ns != self._t:
            out = self.flush()
            self._pending = {}
        self._t = t_ns
        if topic == S.TF:
            self.transforms.add(t_ns, message.parent_frame_id, message.child_frame_id,
                                codec.decode_transform(message))
        elif topic == S.CALIBRATION:
            self.calibration = codec.decode_calibration(message)
        elif topic == S.DEPTH:
            self._pending["depth"] = message
        elif topic == S.RGB:
            self._pending["rgb"] = message
        elif topic == S.IDS:
            self._pending["ids"] = message
        return out

    def flush(self) -> Frame | None:
        """The frame of the current log time, if its depth image has arrived (it is then
        handed out once); None otherwise."""
        pending, t = self._pending, self._t
        if "depth" not in pending or t is None:
            return None
        self._pending = {}
        depth_msg = pending["depth"]
        k = self.calibration or _fallback_intrinsics(depth_msg)
        pose = self.transforms.lookup(t, depth_msg.frame_id or S.CAMERA_FRAME)
        if pose is None:
            pose = np.full((4, 4), np.nan)
        fr = Frame(
            index=self.index,
            time_ns=t,
            rgb=codec.decode_image(pending["rgb"]) if "rgb" in pending else None,
            depth=codec.depth_from_image(depth_msg),
            ids=codec.decode_image(pending["ids"]).astype(np.int32)
            if "ids" in pending else None,
            pose=pose,
            intrinsics=k,
            base_pose=self.transforms.lookup(t, S.BASE_FRAME),
        )
        self.index += 1
        return fr


def _fallback_intrinsics(depth_msg: Any) -> CameraIntrinsics:
    return CameraIntrinsics.from_fov(int(depth_msg.width), int(depth_msg.height), 60.0)
