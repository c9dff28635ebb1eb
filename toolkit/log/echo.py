"""A frame as a reader of the log will see it: the round trip through the log's encodings.

A log stores depth as uint16 millimetres and poses as translation + quaternion transforms
(world -> base -> camera); reading gives back slightly different numbers than were
written. Whoever builds a scene graph *live* from frames it also logs (the closed loop)
and wants ``sgtool replay`` of that log to reproduce its graphs bit for bit must build from
what the log holds: :func:`as_logged` returns exactly the :class:`~sgtool.log.frame.Frame`
that :meth:`sgtool.log.reader.LogReader.frames` yields for a frame written by
:meth:`sgtool.log.writer.LogWriter.write_frame` (same encoders, same composition of the
transform chain), without writing or reading a file.
"""

from __future__ import annotations

import numpy as np

from sgtool.log import codec
from sgtool.log import schemas as S
from sgtool.log.frame import Frame


def as_logged(frame: Frame) -> Frame:
    """``frame`` after a write/read round trip through an sgtool log (module doc)."""
    t = int(frame.time_ns)
    depth = codec.depth_from_image(codec.encode_image(
        t, codec.depth_to_mm(frame.depth) if frame.depth.dtype != np.uint16 else frame.depth,
        S.DEPTH_ENCODING, S.CAMERA_FRAME))
    rgb = None
    if frame.rgb is not None:
        rgb = codec.decode_image(codec.encode_image(t, frame.rgb, S.RGB_ENCODING,
                                                    S.CAMERA_FRAME))
    ids = None
    if frame.ids is not None:
        ids = codec.decode_image(codec.encode_image(t, frame.ids, S.IDS_ENCODING,
                                                    S.CAMERA_FRAME)).astype(np.int32)
    k = codec.decode_calibration(codec.encode_calibration(t, frame.intrinsics, S.CAMERA_FRAME))

    def echo(parent: str, child: str, m: np.ndarray) -> np.ndarray:
        return codec.decode_transform(codec.encode_transform(t, parent, child, m))

    if frame.base_pose is not None:
        # the writer's chain world -> base -> camera, composed as the reader's TransformBuffer
        world_T_base = echo(S.WORLD_FRAME, S.BASE_FRAME, frame.base_pose)  # noqa: N806
        base_T_cam = echo(S.BASE_FRAME, S.CAMERA_FRAME,  # noqa: N806
                          codec.relative(frame.base_pose, frame.pose))
        pose = world_T_base @ (base_T_cam @ np.eye(4))
        base = world_T_base @ np.eye(4)
    else:
        pose = echo(S.WORLD_FRAME, S.CAMERA_FRAME, frame.pose) @ np.eye(4)
        base = None
    return Frame(index=frame.index, time_ns=t, rgb=rgb, depth=depth, ids=ids, pose=pose,
                 intrinsics=k, base_pose=base)
