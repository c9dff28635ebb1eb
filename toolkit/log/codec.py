"""Conversions between numpy arrays and Foxglove protobuf messages (pure functions)."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from foxglove_schemas_protobuf.CameraCalibration_pb2 import CameraCalibration
from foxglove_schemas_protobuf.FrameTransform_pb2 import FrameTransform
from foxglove_schemas_protobuf.Grid_pb2 import Grid
from foxglove_schemas_protobuf.PackedElementField_pb2 import PackedElementField
from foxglove_schemas_protobuf.RawImage_pb2 import RawImage
from foxglove_schemas_protobuf.Vector2_pb2 import Vector2
from google.protobuf.timestamp_pb2 import Timestamp
from numpy.typing import DTypeLike

from sgtool.errors import LogFormatError
from sgtool.log import schemas as S
from sgtool.log.frame import CameraIntrinsics
from sgtool.log.image_wire import RawImageView

_DTYPES: dict[str, tuple[np.dtype[Any], int]] = {
    "rgb8": (np.dtype(np.uint8), 3),
    "bgr8": (np.dtype(np.uint8), 3),
    "rgba8": (np.dtype(np.uint8), 4),
    "bgra8": (np.dtype(np.uint8), 4),
    "mono8": (np.dtype(np.uint8), 1),
    "8UC1": (np.dtype(np.uint8), 1),
    "8UC3": (np.dtype(np.uint8), 3),
    "mono16": (np.dtype("<u2"), 1),
    "16UC1": (np.dtype("<u2"), 1),
    "32SC1": (np.dtype("<i4"), 1),
    "32FC1": (np.dtype("<f4"), 1),
}


def timestamp(t_ns: int) -> Timestamp:
    return Timestamp(seconds=int(t_ns // 1_000_000_000), nanos=int(t_ns % 1_000_000_000))


def encode_image(t_ns: int, arr: np.ndarray, encoding: str, frame_id: str) -> RawImage:
    """``arr`` as a ``RawImage`` of ``encoding``; values the encoding's integer type cannot
    hold as they are (floats, values out of its range) are a ``ValueError``: cast, they
    would read back as other values (0.8 as 0, 300 as 44)."""
    dtype, channels = _DTYPES[encoding]
    src = np.asarray(arr)
    if np.issubdtype(dtype, np.integer) and src.dtype != dtype:
        if src.dtype.kind not in "iub":
            raise ValueError(f"a {encoding} image as {src.dtype}: give integers ({dtype}), "
                             "e.g. colours as uint8 0..255")
        info = np.iinfo(dtype)
        if src.size and (int(src.min()) < info.min or int(src.max()) > info.max):
            raise ValueError(f"a {encoding} image with values {int(src.min())}.."
                             f"{int(src.max())}: {dtype} holds {info.min}..{info.max}")
    a = np.ascontiguousarray(src, dtype=dtype)
    h, w = a.shape[:2]
    if (channels == 1 and a.ndim != 2) or (channels > 1 and a.shape[2:] != (channels,)):
        raise ValueError(f"image of shape {a.shape} does not fit encoding {encoding}")
    return RawImage(
        timestamp=timestamp(t_ns), frame_id=frame_id, width=w, height=h, encoding=encoding,
        step=w * channels * dtype.itemsize, data=a.tobytes(),
    )


INTEGER_ENCODINGS = frozenset({"mono8", "8UC1", "mono16", "16UC1", "32SC1"})


def encode_ids(t_ns: int, ids: np.ndarray, frame_id: str) -> RawImage:
    """An instance-id image as a ``RawImage`` in an encoding Foxglove's Image panel shows:
    ``16UC1`` (exact ids, 0 = none) when every id fits in 0..65535, else ``32SC1`` (exact,
    not drawn by Foxglove; sgtool's readers take both); ids outside int32 are a
    ``ValueError`` (they would wrap)."""
    if np.asarray(ids).dtype.kind not in "iub":
        raise ValueError(f"instance ids as {np.asarray(ids).dtype}: give an integer array "
                         "(an id per pixel, 0 = none)")
    lo, hi = (int(ids.min()), int(ids.max())) if ids.size else (0, 0)
    if lo < -(2 ** 31) or hi > 2 ** 31 - 1:
        raise ValueError(f"instance ids {lo}..{hi}: ids must fit int32 (the instance table "
                         "takes no others)")
    fits = ids.size == 0 or (lo >= 0 and hi <= S.IDS_MAX_16)
    return encode_image(t_ns, ids, S.IDS_ENCODING_16 if fits else S.IDS_ENCODING, frame_id)


def decode_image(msg: RawImage | RawImageView, dtype: DTypeLike | None = None) -> np.ndarray:
    """The pixels of ``msg`` (as ``dtype``, when given: converted as they are copied);
    :class:`LogFormatError` (naming the field) when its encoding, size, step and data
    disagree. The array never shares memory with a
    :class:`~sgtool.log.image_wire.RawImageView`'s chunk (it is copied out of it)."""
    a = _pixels(msg)
    if dtype is not None:
        return np.array(a, dtype=dtype)
    return a.copy() if isinstance(msg.data, memoryview) else a


def _pixels(msg: RawImage | RawImageView) -> np.ndarray:
    """:func:`decode_image`, possibly a view of ``msg.data``."""
    if msg.encoding not in _DTYPES:
        raise LogFormatError(f"field encoding: unsupported image encoding "
                             f"{msg.encoding[:40]!r}")
    dtype, channels = _DTYPES[msg.encoding]
    if msg.width <= 0 or msg.height <= 0:
        raise LogFormatError(f"fields width/height: image of {msg.width}x{msg.height} pixels")
    row = msg.width * channels * dtype.itemsize
    if msg.step < row:
        raise LogFormatError(f"field step: {msg.step} bytes, a row of {msg.width} "
                             f"{msg.encoding} pixels takes {row}")
    data = msg.data  # a protobuf bytes field is copied on every access: read it once
    if len(data) != msg.step * msg.height:
        raise LogFormatError(f"field data: {len(data)} bytes, {msg.height} rows of "
                             f"{msg.step} bytes (step) take {msg.step * msg.height}")
    buf = np.frombuffer(data, dtype=np.uint8)
    if msg.step != row:  # rows padded
        buf = buf.reshape(msg.height, msg.step)[:, :row].copy()
    a = buf.view(dtype)
    shape = (msg.height, msg.width) if channels == 1 else (msg.height, msg.width, channels)
    a = a.reshape(shape)
    if msg.encoding in ("bgr8", "bgra8"):
        a = a[..., [2, 1, 0]]
    elif msg.encoding == "rgba8":
        a = a[..., :3]
    return a


def encode_depth(t_ns: int, depth_m: np.ndarray, frame_id: str) -> RawImage:
    """A depth image (float metres, or already uint16 millimetres) as the ``16UC1``
    millimetre ``RawImage`` of the log. Other integer types, and float depth most of whose
    valid pixels lie beyond what uint16 millimetres hold (65.535 m: millimetres given as
    float), are a ``ValueError``: written, they would read back as no depth at all."""
    if depth_m.dtype != np.uint16 and depth_m.dtype.kind in "iub":
        raise ValueError(f"depth as {depth_m.dtype}: give float metres or uint16 millimetres")
    if depth_m.dtype != np.uint16:
        d = np.asarray(depth_m, dtype=np.float32)
        valid = int(np.count_nonzero(np.isfinite(d) & (d > 0)))
        far = int(np.count_nonzero(np.isfinite(d) & (d > S.DEPTH_MAX_M)))
        if valid and far > valid // 2:
            raise ValueError(f"depth beyond {S.DEPTH_MAX_M:g} m in {far} of {valid} valid "
                             "pixels: give float metres (millimetres / 1000) or uint16 "
                             "millimetres")
    mm = depth_m if depth_m.dtype == np.uint16 else depth_to_mm(depth_m)
    return encode_image(t_ns, mm, S.DEPTH_ENCODING, frame_id)


def depth_to_mm(depth_m: np.ndarray) -> np.ndarray:
    """Metric depth (float, NaN/inf/<=0 = no return) -> uint16 millimetres (0 = none)."""
    d = np.nan_to_num(np.asarray(depth_m, dtype=np.float32), nan=0.0, posinf=0.0, neginf=0.0)
    mm = np.rint(d * S.DEPTH_SCALE)
    mm[(mm < 0) | (mm > 65535)] = 0
    return mm.astype("<u2")


def depth_from_image(msg: RawImage | RawImageView, scale: float = S.DEPTH_SCALE
                     ) -> np.ndarray:
    """Depth image -> float32 metres (0 = no return)."""
    a = _pixels(msg)  # converted below: no copy needed
    if msg.encoding == "32FC1":
        return np.nan_to_num(a.astype(np.float32), nan=0.0, posinf=0.0, neginf=0.0)
    out = a.astype(np.float32)
    out /= np.float32(scale)  # in place: no second image
    return out


def encode_calibration(t_ns: int, k: CameraIntrinsics, frame_id: str) -> CameraCalibration:
    return CameraCalibration(
        timestamp=timestamp(t_ns), frame_id=frame_id, width=k.width, height=k.height,
        distortion_model="plumb_bob", D=[0.0] * 5,
        K=[k.fx, 0.0, k.cx, 0.0, k.fy, k.cy, 0.0, 0.0, 1.0],
        R=[1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0],
        P=[k.fx, 0.0, k.cx, 0.0, 0.0, k.fy, k.cy, 0.0, 0.0, 0.0, 1.0, 0.0],
    )


def decode_calibration(msg: CameraCalibration) -> CameraIntrinsics:
    """Pinhole intrinsics of ``msg``; :class:`LogFormatError` (naming the field) unless K
    has 9 finite values, positive focal lengths and the image a positive size."""
    K = list(msg.K)  # noqa: N806
    if len(K) != 9:
        raise LogFormatError(f"field K: {len(K)} values, a 3x3 matrix has 9")
    if not all(np.isfinite(K)):
        raise LogFormatError("field K: values that are not finite")
    if not (K[0] > 0 and K[4] > 0):
        raise LogFormatError(f"field K: focal lengths fx {K[0]}, fy {K[4]} (must be > 0)")
    if msg.width <= 0 or msg.height <= 0:
        raise LogFormatError(f"fields width/height: {msg.width}x{msg.height} pixels")
    return CameraIntrinsics(int(msg.width), int(msg.height), K[0], K[4], K[2], K[5])


def quat_from_matrix(R: np.ndarray) -> tuple[float, float, float, float]:  # noqa: N803
    """Rotation matrix -> unit quaternion (x, y, z, w), w >= 0 (Shepperd's method)."""
    m = np.asarray(R, dtype=np.float64)
    tr = m[0, 0] + m[1, 1] + m[2, 2]
    if tr > 0:
        s = np.sqrt(tr + 1.0) * 2
        w, x = 0.25 * s, (m[2, 1] - m[1, 2]) / s
        y, z = (m[0, 2] - m[2, 0]) / s, (m[1, 0] - m[0, 1]) / s
    elif m[0, 0] > m[1, 1] and m[0, 0] > m[2, 2]:
        s = np.sqrt(1.0 + m[0, 0] - m[1, 1] - m[2, 2]) * 2
        w, x = (m[2, 1] - m[1, 2]) / s, 0.25 * s
        y, z = (m[0, 1] + m[1, 0]) / s, (m[0, 2] + m[2, 0]) / s
    elif m[1, 1] > m[2, 2]:
        s = np.sqrt(1.0 + m[1, 1] - m[0, 0] - m[2, 2]) * 2
        w, x = (m[0, 2] - m[2, 0]) / s, (m[0, 1] + m[1, 0]) / s
        y, z = 0.25 * s, (m[1, 2] + m[2, 1]) / s
    else:
        s = np.sqrt(1.0 + m[2, 2] - m[0, 0] - m[1, 1]) * 2
        w, x = (m[1, 0] - m[0, 1]) / s, (m[0, 2] + m[2, 0]) / s
        y, z = (m[1, 2] + m[2, 1]) / s, 0.25 * s
    # the norm in plain floats: np.linalg.norm is a BLAS dot whose last bits depend on
    # the CPU's kernel (OpenBLAS picks one per machine), so logs would differ by machine
    x, y, z, w = float(x), float(y), float(z), float(w)
    n = math.sqrt(x * x + y * y + z * z + w * w)
    q = (x / n, y / n, z / n, w / n)
    if q[3] < 0:
        q = (-q[0], -q[1], -q[2], -q[3])
    return q


def compose(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``a @ b`` for 4x4 transforms in plain float arithmetic, each entry summed in one
    fixed order: a BLAS product's last bits depend on the CPU kernel OpenBLAS picks, so
    logs written with ``@`` differ from machine to machine."""
    A, B = np.asarray(a, dtype=np.float64).tolist(), np.asarray(b, dtype=np.float64).tolist()
    return np.array([[A[i][0] * B[0][j] + A[i][1] * B[1][j] + A[i][2] * B[2][j]
                      + A[i][3] * B[3][j] for j in range(4)] for i in range(4)])


def relative(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``inv(a) @ b`` for a rigid 4x4 transform ``a`` (rotation and translation), in plain
    float arithmetic (:func:`compose`)."""
    A = np.asarray(a, dtype=np.float64).tolist()
    inv = [[A[0][i], A[1][i], A[2][i],
            -(A[0][i] * A[0][3] + A[1][i] * A[1][3] + A[2][i] * A[2][3])] for i in range(3)]
    return compose(np.array(inv + [[0.0, 0.0, 0.0, 1.0]]), b)


def matrix_from_quat(x: float, y: float, z: float, w: float) -> np.ndarray:
    n = x * x + y * y + z * z + w * w
    if n == 0:
        return np.eye(3)
    s = 2.0 / n
    return np.array(
        [
            [1 - s * (y * y + z * z), s * (x * y - z * w), s * (x * z + y * w)],
            [s * (x * y + z * w), 1 - s * (x * x + z * z), s * (y * z - x * w)],
            [s * (x * z - y * w), s * (y * z + x * w), 1 - s * (x * x + y * y)],
        ]
    )


def encode_transform(t_ns: int, parent: str, child: str, T: np.ndarray) -> FrameTransform:  # noqa: N803
    """``T`` is parent_T_child (4x4): the pose of ``child`` in ``parent``. A matrix that
    is not a rigid transform (not 4x4 and finite, or :func:`rigid_problem`) is a
    ``ValueError``: its quaternion would be another pose."""
    T = np.asarray(T, dtype=np.float64)  # noqa: N806
    if T.shape != (4, 4) or not np.isfinite(T).all():
        raise ValueError(f"transform {parent} -> {child}: a finite 4x4 matrix is needed, not "
                         f"{'x'.join(str(n) for n in T.shape)}"
                         + ("" if T.shape != (4, 4) else " with values that are not finite"))
    problem = rigid_problem(T)
    if problem is not None:
        raise ValueError(f"transform {parent} -> {child}: {problem[1]}")
    qx, qy, qz, qw = quat_from_matrix(T[:3, :3])
    msg = FrameTransform(timestamp=timestamp(t_ns), parent_frame_id=parent, child_frame_id=child)
    msg.translation.x, msg.translation.y, msg.translation.z = (float(v) for v in T[:3, 3])
    msg.rotation.x, msg.rotation.y, msg.rotation.z, msg.rotation.w = qx, qy, qz, qw
    return msg


MAX_TRANSLATION_M = 1e9  # beyond any map: a transform this far is damage, not a pose
RIGID_TOL = 5e-3  # |R^T R - I|, |det R - 1| and the last row (7-Scenes: up to 5e-4)


def rigid_problem(m: np.ndarray) -> tuple[int, str] | None:
    """Why a finite 4x4 matrix is not a rigid pose, with the matrix row (0-3) to name:
    the last row is not 0 0 0 1, or the rotation is not orthonormal with det +1 (within
    :data:`RIGID_TOL`); None when it is rigid."""
    last = m[3]
    if np.abs(last - (0.0, 0.0, 0.0, 1.0)).max() > RIGID_TOL:
        return 3, f"the last row is {' '.join(f'{v:g}' for v in last)}, not 0 0 0 1"
    r = m[:3, :3]
    big = float(np.abs(r).max())
    if big > 1e100:  # (r.T @ r would overflow; a rotation's entries are within +-1)
        return 0, (f"the rotation is not orthonormal with det +1 (an entry of magnitude "
                   f"{big:.4g}): not a rigid camera pose (scaled or sheared)")
    ortho = float(np.abs(r.T @ r - np.eye(3)).max())
    det = float(np.linalg.det(r))
    if ortho > RIGID_TOL or abs(det - 1.0) > RIGID_TOL:
        return 0, (f"the rotation is not orthonormal with det +1 (|R^T R - I| = {ortho:.3g}, "
                   f"det {det:.4g}): not a rigid camera pose (scaled or sheared)")
    return None


def _numbers(*values: float) -> str:
    return ", ".join(f"{v:.6g}" for v in values)


def decode_transform(msg: FrameTransform) -> np.ndarray:
    """parent_T_child of ``msg``; :class:`LogFormatError` (naming the field, numbers to 6
    significant digits) when the translation is not finite or beyond
    :data:`MAX_TRANSLATION_M` on an axis (its products would overflow downstream) or the
    rotation is not a quaternion that can be normalised (a zero quaternion is no rotation,
    not the identity)."""
    t, r = msg.translation, msg.rotation
    tx, ty, tz = t.x, t.y, t.z
    if not (math.isfinite(tx) and math.isfinite(ty) and math.isfinite(tz)):
        raise LogFormatError(f"field translation: ({_numbers(tx, ty, tz)}) is not finite")
    if max(abs(tx), abs(ty), abs(tz)) > MAX_TRANSLATION_M:
        raise LogFormatError(f"field translation: ({_numbers(tx, ty, tz)}) m is beyond "
                             f"+-{MAX_TRANSLATION_M:g} m on an axis")
    x, y, z, w = r.x, r.y, r.z, r.w
    big = max(abs(x), abs(y), abs(z), abs(w))
    scale = big if 0 < big and not 1e-100 < big < 1e100 else 1.0  # no square over/underflows
    if math.isfinite(big):
        x, y, z, w = x / scale, y / scale, z / scale, w / scale
    if not (math.isfinite(big)
            and scale * math.sqrt(x * x + y * y + z * z + w * w) > 1e-6):
        raise LogFormatError(f"field rotation: quaternion ({_numbers(r.x, r.y, r.z, r.w)}) "
                             "cannot be normalised")
    s = 2.0 / (x * x + y * y + z * z + w * w)  # matrix_from_quat's, in one array
    return np.array([
        [1 - s * (y * y + z * z), s * (x * y - z * w), s * (x * z + y * w), tx],
        [s * (x * y + z * w), 1 - s * (x * x + z * z), s * (y * z - x * w), ty],
        [s * (x * z - y * w), s * (y * z + x * w), 1 - s * (x * x + y * y), tz],
        [0.0, 0.0, 0.0, 1.0]])


def encode_grid(
    t_ns: int, cells: np.ndarray, origin_xy: tuple[float, float], resolution: float,
    frame_id: str = S.WORLD_FRAME, z: float = 0.0,
) -> Grid:
    """An int8 occupancy grid (rows = +y, cols = +x) as a Foxglove Grid with one int8 field
    ``occupancy`` (-1 unknown, 0 free, 100 occupied; the ROS convention)."""
    a = np.ascontiguousarray(cells, dtype=np.int8)
    h, w = a.shape
    msg = Grid(
        timestamp=timestamp(t_ns), frame_id=frame_id, column_count=w,
        cell_size=_vec2(resolution, resolution), row_stride=w, cell_stride=1,
        fields=[PackedElementField(name="occupancy", offset=0, type=PackedElementField.INT8)],
        data=a.tobytes(),
    )
    msg.pose.position.x, msg.pose.position.y, msg.pose.position.z = origin_xy[0], origin_xy[1], z
    msg.pose.orientation.w = 1.0
    return msg


def decode_grid(msg: Grid) -> tuple[np.ndarray, tuple[float, float], float]:
    w = int(msg.column_count)
    if not 0 < w <= msg.row_stride or len(msg.data) % msg.row_stride:
        raise LogFormatError(f"fields column_count/row_stride/data: {w} columns, rows of "
                             f"{msg.row_stride} bytes, {len(msg.data)} bytes of data")
    h = len(msg.data) // int(msg.row_stride)
    a = np.frombuffer(msg.data, dtype=np.int8).reshape(h, msg.row_stride)[:, :w].copy()
    return a, (msg.pose.position.x, msg.pose.position.y), float(msg.cell_size.x)


def _vec2(x: float, y: float) -> Vector2:
    return Vector2(x=x, y=y)
