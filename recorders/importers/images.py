"""Image decoding for the importers, with OpenCV: image files, and ROS ``sensor_msgs/Image``
and ``sensor_msgs/CompressedImage`` messages (including ``compressedDepth``, PNG or RVL).

Colour ``Image`` encodings: rgb8/bgr8/rgba8/bgra8, mono8/mono16, Bayer (``bayer_rggb8``,
``bggr``, ``gbrg``, ``grbg``; 8 and 16 bit) demosaiced by OpenCV, and YUV 4:2:2 (``yuv422``
and ``uyvy`` are UYVY, ``yuv422_yuy2`` and ``yuyv`` are YUYV) converted by OpenCV.

Colour comes out as (H, W, 3) uint8 RGB. Depth comes out as metres (float32, 0 = no
return) through :func:`depth_to_metres`, or kept as uint16 millimetres when the source
already is millimetres (no rounding at all, so a round trip is exact). Depth sensors mark
"no return" with 0 (ROS, TUM, Open3D) or 65535 (7-Scenes); both become 0.
"""

from __future__ import annotations

import struct
from pathlib import Path
from typing import Any

import numpy as np

from sgtool.errors import SgtoolError
from sgtool.extras import require

INVALID_U16 = 65535


def _cv2() -> Any:
    """OpenCV, imported on first use: the module's types (the options and reports of an
    import) load on a core install; decoding an image needs the ``import`` extra."""
    return require("cv2")


def _imdecode(data: Any) -> np.ndarray | None:
    """``cv2.imdecode`` of image file bytes, unchanged depth and channels; None for bytes
    that are no image, none at all included (OpenCV asserts on an empty buffer)."""
    cv2 = _cv2()
    buf = np.frombuffer(bytes(data), np.uint8) if not isinstance(data, np.ndarray) else \
        np.ascontiguousarray(data, np.uint8).ravel()
    if not buf.size:
        return None
    try:
        a: np.ndarray | None = cv2.imdecode(buf, cv2.IMREAD_UNCHANGED)
    except cv2.error:
        return None
    return a


def read_image_file(path: Path) -> np.ndarray:
    """An image file as OpenCV decodes it (depth and channels unchanged: BGR order for
    colour); one :class:`SgtoolError` line for a missing or undecodable file."""
    if not Path(path).is_file():
        raise SgtoolError(f"{path}: no such image file")
    # decoded from the bytes: cv2.imread takes the name as UTF-8 text and crashes on a
    # file name that is not (a folder named in another encoding)
    try:
        data = np.fromfile(path, dtype=np.uint8)
    except OSError as e:
        raise SgtoolError(f"{path}: cannot read ({e.strerror or e})") from None
    a = _imdecode(data)
    if a is None:
        exr = bytes(data[:4]) == b"\x76\x2f\x31\x01"  # OpenEXR's magic number
        raise SgtoolError(f"{path}: OpenCV cannot read this image" + (
            " (OpenEXR, which this OpenCV build does not decode): store depth as 16-bit PNG "
            "in millimetres" if exr else ""))
    return a


def _jpeg_truncated(path: Path) -> bool:
    """Whether a JPEG file lacks its end-of-image marker (a cut-off file, which libjpeg
    decodes half grey with only a warning on stderr)."""
    with open(path, "rb") as f:
        if f.read(2) != b"\xff\xd8":
            return False
        f.seek(0, 2)
        f.seek(max(0, f.tell() - 64))
        tail = f.read().rstrip(b"\x00\r\n\t ")
    return not tail.endswith(b"\xff\xd9")


def read_color_file_kind(path: Path) -> tuple[np.ndarray, str]:
    """A colour (or grey) image file as (H, W, 3) uint8 RGB, and the file's pixel kind
    (:func:`pixel_kind`, before the conversion to 8-bit RGB); a truncated JPEG is a user
    error."""
    if Path(path).is_file() and _jpeg_truncated(Path(path)):
        raise SgtoolError(f"{path}: truncated JPEG (no end-of-image marker): the file is cut "
                          "off or damaged")
    a = read_image_file(path)
    return _to_rgb(a, str(path)), pixel_kind(a)


def pixel_kind(a: np.ndarray) -> str:
    """Bit depth and channel count of a decoded image, e.g. ``8-bit 3-channel``."""
    ch = 1 if a.ndim == 2 else int(a.shape[2])
    return f"{a.dtype.itemsize * 8}-bit {ch}-channel"


_PNG_MAGIC = b"\x89PNG\r\n\x1a\n"
_PNG_CHANNELS = {0: 1, 2: 3, 3: 3, 4: 2, 6: 4}  # PNG colour type -> channels as decoded


def header_kind(path: Path) -> str | None:
    """The pixel kind (:func:`pixel_kind`) a PNG file's header declares, read from its
    first 26 bytes without decoding; None for other formats or an unreadable header. A
    palette PNG decodes to 8-bit 3-channel."""
    try:
        with open(path, "rb") as f:
            head = f.read(26)
    except OSError:
        return None
    if len(head) < 26 or head[:8] != _PNG_MAGIC or head[12:16] != b"IHDR":
        return None
    bits, ctype = head[24], head[25]
    if ctype not in _PNG_CHANNELS:
        return None
    bits = 8 if ctype == 3 or bits <= 8 else 16
    return f"{bits}-bit {_PNG_CHANNELS[ctype]}-channel"


def colour_kind_problem(kind: str, path: Path | str, first: str, first_path: Path | str
                        ) -> str | None:
    """The problem of a colour image of pixel kind ``kind`` in a folder whose first colour
    image (``first_path``) is ``first``: another bit depth or channel count (a 16-bit grey
    PNG among 8-bit colour frames turns near-black) is not the same camera stream."""
    if kind == first:
        return None
    return (f"{path}: a {kind} image among colour frames that are {first} (the first, "
            f"{Path(first_path).name}): not the same colour stream (a depth or infrared image "
            "in the colour folder?); remove or convert it")


def read_depth_file(path: Path) -> np.ndarray:
    """A 16-bit depth image file (PNG/TIFF) -> its raw uint16 values (units per the
    dataset's depth scale)."""
    a = read_image_file(path)
    if a.ndim == 2 and a.dtype.kind == "f":
        raise SgtoolError(
            f"{path}: a depth image file must be single-channel 16-bit, this one is "
            f"{a.dtype} (depth in metres?); write it as 16-bit millimetres "
            "(uint16(round(depth_m * 1000))) and give --depth-scale 1000 (float depth is "
            "read from bags, 32FC1)")
    if a.ndim != 2 or a.dtype != np.uint16:
        raise SgtoolError(
            f"{path}: a depth image must be single-channel 16-bit, this one is "
            f"{a.dtype} with shape {a.shape}"
        )
    return a


def _to_rgb(a: np.ndarray, what: str) -> np.ndarray:
    cv2 = _cv2()
    if a.dtype == np.uint16:
        a = (a >> 8).astype(np.uint8)
    if a.dtype != np.uint8:
        raise SgtoolError(f"{what}: expected an 8-bit colour image, got {a.dtype}")
    if a.ndim == 2:
        return np.repeat(a[:, :, None], 3, axis=2)
    if a.shape[2] == 4:
        return cv2.cvtColor(a, cv2.COLOR_BGRA2RGB)
    if a.shape[2] == 3:
        return cv2.cvtColor(a, cv2.COLOR_BGR2RGB)
    raise SgtoolError(f"{what}: unsupported channel count {a.shape[2]}")


def depth_to_metres(raw: np.ndarray, scale: float) -> np.ndarray:
    """Raw depth in units of 1/``scale`` metres -> float32 metres (0 = no return)."""
    if raw.dtype == np.uint16:
        out = raw.astype(np.float32) / np.float32(scale)
        out[raw == INVALID_U16] = 0.0
        return out
    out = np.nan_to_num(raw.astype(np.float32), nan=0.0, posinf=0.0, neginf=0.0) / np.float32(
        scale
    )
    out[out < 0] = 0.0
    return out


def depth_for_log(raw: np.ndarray, scale: float) -> np.ndarray:
    """What :meth:`LogWriter.write_frame` takes: uint16 millimetres untouched when the
    source is millimetres, else float32 metres."""
    if raw.dtype == np.uint16 and scale == 1000.0:
        if np.any(raw == INVALID_U16):
            raw = raw.copy()
            raw[raw == INVALID_U16] = 0
        return raw
    return depth_to_metres(raw, scale)


# ----- ROS messages ------------------------------------------------------------------------
_RAW = {
    "rgb8": (np.uint8, 3), "bgr8": (np.uint8, 3), "rgba8": (np.uint8, 4),
    "bgra8": (np.uint8, 4), "mono8": (np.uint8, 1), "8UC1": (np.uint8, 1),
    "8UC3": (np.uint8, 3), "mono16": (np.uint16, 1), "16UC1": (np.uint16, 1),
    "16SC1": (np.int16, 1), "32SC1": (np.int32, 1), "32FC1": (np.float32, 1),
    **{f"bayer_{p}{bits}": (np.uint8 if bits == 8 else np.uint16, 1)
       for p in ("rggb", "bggr", "gbrg", "grbg") for bits in (8, 16)},
    "yuv422": (np.uint8, 2), "uyvy": (np.uint8, 2), "yuv422_yuy2": (np.uint8, 2),
    "yuyv": (np.uint8, 2),
}
# OpenCV names a Bayer pattern by the second row's second and third pixels: ROS's
# bayer_rggb is OpenCV's BayerBG (as cv_bridge maps them)
_BAYER = {"rggb": "COLOR_BayerBG2RGB", "bggr": "COLOR_BayerRG2RGB",
          "gbrg": "COLOR_BayerGR2RGB", "grbg": "COLOR_BayerGB2RGB"}  # OpenCV's names
# ROS's "yuv422" is UYVY (cv_bridge); "yuv422_yuy2" is YUYV
_YUV = {"yuv422": "COLOR_YUV2RGB_UYVY", "uyvy": "COLOR_YUV2RGB_UYVY",
        "yuv422_yuy2": "COLOR_YUV2RGB_YUY2", "yuyv": "COLOR_YUV2RGB_YUY2"}
COLOUR_ENCODINGS = ("rgb8", "bgr8", "rgba8", "bgra8", "mono8", "8UC1", "8UC3", "mono16",
                    *(e for e in _RAW if e.startswith("bayer_")), *_YUV)
DEPTH_ENCODINGS = ("16UC1", "mono16", "32FC1")
ID_ENCODINGS = ("8UC1", "mono8", "16UC1", "mono16", "16SC1", "32SC1")


def decode_raw_image(msg: Any, topic: str) -> tuple[np.ndarray, str]:
    """A ``sensor_msgs/Image`` -> (array, encoding). Rows padded by ``step`` are cut and
    big-endian data swapped."""
    enc = str(msg.encoding)
    if enc not in _RAW:
        raise SgtoolError(
            f"topic {topic}: image encoding {enc!r} is not supported "
            f"(supported: {', '.join(sorted(_RAW))})"
        )
    dtype, ch = _RAW[enc]
    dt = np.dtype(dtype).newbyteorder(">" if msg.is_bigendian else "<")
    h, w, step = int(msg.height), int(msg.width), int(msg.step)
    buf = np.asarray(msg.data, dtype=np.uint8)
    row = w * ch * dt.itemsize
    if step < row or buf.size < step * h:
        raise SgtoolError(
            f"topic {topic}: image data is shorter than {h} rows of {row} bytes "
            f"(step {step}, {buf.size} bytes)"
        )
    a = buf[: step * h].reshape(h, step)[:, :row].copy().view(dt)
    a = a.reshape((h, w) if ch == 1 else (h, w, ch)).astype(dt.newbyteorder("="))
    return a, enc


def color_from_raw(a: np.ndarray, enc: str, topic: str) -> np.ndarray:
    if enc in ("rgb8", "8UC3"):
        return a
    if enc == "bgr8":
        return a[..., ::-1].copy()
    if enc == "rgba8":
        return a[..., :3].copy()
    if enc == "bgra8":
        return a[..., 2::-1].copy()
    if enc in ("mono8", "8UC1"):
        return np.repeat(a[:, :, None], 3, axis=2)
    if enc == "mono16":
        return np.repeat((a >> 8).astype(np.uint8)[:, :, None], 3, axis=2)
    if enc.startswith("bayer_") or enc in _YUV:
        return _convert(a, enc, topic)
    raise SgtoolError(f"topic {topic}: image encoding {enc!r} is not a colour image")


def _convert(a: np.ndarray, enc: str, topic: str) -> np.ndarray:
    """Bayer demosaicing and YUV 4:2:2 conversion by OpenCV -> (H, W, 3) uint8 RGB."""
    if enc in _YUV and a.shape[1] % 2:
        raise SgtoolError(f"topic {topic}: a {enc} image needs an even width (two pixels "
                          f"share U and V); this one is {a.shape[1]} pixels wide")
    cv2 = _cv2()
    code = getattr(cv2, _YUV[enc] if enc in _YUV else _BAYER[enc[6:10]])
    try:
        rgb: np.ndarray = cv2.cvtColor(np.ascontiguousarray(a), code)
    except cv2.error as e:
        raise SgtoolError(f"topic {topic}: OpenCV cannot convert this {a.shape[1]}x"
                          f"{a.shape[0]} {enc} image ({str(e).strip().splitlines()[-1][:80]})"
                          ) from None
    return rgb if rgb.dtype == np.uint8 else (rgb >> 8).astype(np.uint8)


def decode_color_message(msg: Any, msgtype: str, topic: str) -> np.ndarray:
    """``Image`` or ``CompressedImage`` -> (H, W, 3) uint8 RGB."""
    if msgtype.endswith("CompressedImage"):
        a = _imdecode(np.asarray(msg.data, dtype=np.uint8))
        if a is None:
            raise SgtoolError(f"topic {topic}: OpenCV cannot decode a {msg.format!r} image"
                              + (" (the message holds no image data)" if not len(msg.data)
                                 else ""))
        return _to_rgb(a, f"topic {topic}")
    a, enc = decode_raw_image(msg, topic)
    return color_from_raw(a, enc, topic)


def decode_depth_message(msg: Any, msgtype: str, topic: str) -> tuple[np.ndarray, float]:
    """``Image`` (16UC1/mono16 millimetres, 32FC1 metres) or ``CompressedImage`` (PNG, or
    image_transport's ``compressedDepth``) -> (raw array, units per metre)."""
    if msgtype.endswith("CompressedImage"):
        fmt = str(msg.format)
        data = bytes(np.asarray(msg.data, dtype=np.uint8).tobytes())
        if "compresseddepth" in fmt.lower().replace(" ", ""):
            return _decode_compressed_depth(data, fmt, topic)
        a = _imdecode(data)
        if not data:
            raise SgtoolError(f"topic {topic}: a compressed depth message holds no image data")
        if a is None or a.ndim != 2 or a.dtype != np.uint16:
            raise SgtoolError(
                f"topic {topic}: compressed depth format {fmt!r} did not decode to a "
                "single-channel 16-bit image"
            )
        return a, 1000.0
    a, enc = decode_raw_image(msg, topic)
    if enc in ("16UC1", "mono16"):
        return a, 1000.0
    if enc == "32FC1":
        return a, 1.0
    raise SgtoolError(
        f"topic {topic}: image encoding {enc!r} is not a depth encoding (16UC1 mm, 32FC1 m)"
    )


def _decode_compressed_depth(data: bytes, fmt: str, topic: str) -> tuple[np.ndarray, float]:
    """image_transport ``compressedDepth``: a 12-byte header (int32 format, float
    depthQuantA, float depthQuantB) then a PNG. 16UC1 stores millimetres; 32FC1 stores
    quantised inverse depth, depth = A / (v - B) for v != 0."""
    if len(data) < 12:
        raise SgtoolError(f"topic {topic}: compressedDepth message shorter than its header")
    _, qa, qb = struct.unpack("<iff", data[:12])
    payload = data[12:]
    # the payload's magic decides, not the label: some drivers label PNG payloads "rvl"
    if "rvl" in fmt.lower() and not payload.startswith(_PNG_MAGIC):
        a = _decode_rvl_payload(payload, topic)
    else:
        png = _imdecode(payload)
        if png is None or png.dtype != np.uint16 or png.ndim != 2:
            what = ("a PNG that is not single-channel 16-bit" if png is not None else
                    "a PNG that OpenCV cannot decode" if payload.startswith(_PNG_MAGIC) else
                    f"not a PNG (it starts with {payload[:8].hex()})")
            raise SgtoolError(f"topic {topic}: compressedDepth format {fmt!r}: the payload "
                              f"after the 12-byte header is {what}")
        a = png
    if fmt.split(";")[0].strip() == "32FC1":
        v = a.astype(np.float32)
        out = np.zeros(v.shape, np.float32)
        ok = v != 0
        out[ok] = qa / (v[ok] - qb)
        return out, 1.0
    return a, 1000.0


def _decode_rvl_payload(payload: bytes, topic: str) -> np.ndarray:
    """compressedDepth RVL after the 12-byte header: uint32 width, uint32 height, then the
    RVL stream (:func:`~.rvl.decode_rvl`)."""
    from sgtool.recorders.importers.rvl import decode_rvl

    if len(payload) < 8:
        raise SgtoolError(f"topic {topic}: compressedDepth RVL message shorter than its size")
    w, h = struct.unpack("<II", payload[:8])
    if not (0 < w <= 16384 and 0 < h <= 16384):
        raise SgtoolError(f"topic {topic}: compressedDepth RVL image of {w}x{h} pixels")
    try:
        return decode_rvl(payload[8:], w, h)
    except SgtoolError as e:
        raise SgtoolError(f"topic {topic}: {e}") from e


def decode_ids_message(msg: Any, msgtype: str, topic: str) -> np.ndarray:
    """Instance-id image (8/16/32-bit integer) -> int32."""
    if msgtype.endswith("CompressedImage"):
        a = _imdecode(np.asarray(msg.data, dtype=np.uint8))
        if not len(msg.data):
            raise SgtoolError(f"topic {topic}: a compressed ids message holds no image data")
        if a is None or a.ndim != 2:
            raise SgtoolError(f"topic {topic}: instance ids must decode to one channel")
        return a.astype(np.int32)
    a, enc = decode_raw_image(msg, topic)
    if a.ndim != 2 or not np.issubdtype(a.dtype, np.integer):
        raise SgtoolError(
            f"topic {topic}: instance ids need a one-channel integer encoding, got {enc!r}"
        )
    return a.astype(np.int32)


ASPECT_TOL = 0.01  # relative difference of width/height ratios that still counts as equal


class ResizeLog:
    """The resizes of one import: how many images of a stream (``colour``, ``ids``) went from
    which size to which, for the report and ``--json``."""

    def __init__(self) -> None:
        self.counts: dict[tuple[str, int, int, int, int], int] = {}

    def add(self, stream: str, src: tuple[int, int], dst: tuple[int, int]) -> None:
        key = (stream, src[0], src[1], dst[0], dst[1])
        self.counts[key] = self.counts.get(key, 0) + 1

    def lines(self) -> list[str]:
        """One line per (stream, size -> size), in a stable order."""
        return [f"{stream} resized from {w0}x{h0} to the {w1}x{h1} depth images "
                f"({n} {'frame' if n == 1 else 'frames'})"
                for (stream, w0, h0, w1, h1), n in sorted(self.counts.items())]

    def as_dicts(self) -> list[dict[str, object]]:
        return [{"stream": stream, "from": [w0, h0], "to": [w1, h1], "frames": n}
                for (stream, w0, h0, w1, h1), n in sorted(self.counts.items())]


def resize_to(a: np.ndarray, width: int, height: int, what: str = "a colour or id image",
              log: ResizeLog | None = None, stream: str = "colour") -> np.ndarray:
    """Resize an image to the depth image's size (area averaging for colour). An image of
    another aspect ratio (640x360 colour for 640x480 depth) would no longer be registered to
    the depth when stretched: a user error naming ``what``. Each resize is counted in
    ``log`` under ``stream``."""
    cv2 = _cv2()
    if a.shape[1] == width and a.shape[0] == height:
        return a
    if abs(a.shape[1] * height / (a.shape[0] * width) - 1.0) > ASPECT_TOL:
        raise SgtoolError(
            f"{what}: {a.shape[1]}x{a.shape[0]} pixels, another aspect ratio than the "
            f"{width}x{height} depth images; stretching it would misregister colour and "
            "depth (crop or register the colour to the depth first)")
    if log is not None:
        log.add(stream, (a.shape[1], a.shape[0]), (width, height))
    interp = cv2.INTER_AREA if a.dtype == np.uint8 else cv2.INTER_NEAREST
    return cv2.resize(a, (width, height), interpolation=interp)
