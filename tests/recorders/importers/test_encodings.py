"""Image encodings of real cameras, decoded to known pixels: Bayer (four patterns, 8 and 16
bit), YUV 4:2:2 (UYVY and YUYV), RVL compressed depth (against a reference encoder written
here from Wilson's paper and compressed_depth_image_transport); a bag whose only CameraInfo
topic is used without --info; topic suggestions that respect the encodings."""

from __future__ import annotations

import struct
from types import SimpleNamespace

import numpy as np
import pytest
from support.bag_export import BagWriter
from support.logfixtures import synthetic_frame

from sgtool.errors import SgtoolError
from sgtool.log import LogReader
from sgtool.recorders.importers import images
from sgtool.recorders.importers.bag import BagOptions, import_bag
from sgtool.recorders.importers.bag_topics import suggest_flags
from sgtool.recorders.importers.bagfiles import TopicInfo
from sgtool.recorders.importers.rvl import decode_rvl

RGB = (200, 100, 50)


def raw_msg(a: np.ndarray, encoding: str) -> SimpleNamespace:
    a = np.ascontiguousarray(a)
    return SimpleNamespace(encoding=encoding, is_bigendian=0, height=a.shape[0],
                           width=a.shape[1], step=a.strides[0],
                           data=np.frombuffer(a.tobytes(), np.uint8))


def bayer_mosaic(pattern: str, bits: int, h: int = 6, w: int = 8) -> np.ndarray:
    """A uniform RGB colour sampled through the colour filter ``pattern`` (e.g. rggb: red
    at (0, 0), green at (0, 1) and (1, 0), blue at (1, 1))."""
    scale = 257 if bits == 16 else 1
    a = np.zeros((h, w), np.uint16 if bits == 16 else np.uint8)
    value = {"r": RGB[0], "g": RGB[1], "b": RGB[2]}
    for dy in range(2):
        for dx in range(2):
            a[dy::2, dx::2] = value[pattern[2 * dy + dx]] * scale
    return a


@pytest.mark.parametrize("bits", [8, 16])
@pytest.mark.parametrize("pattern", ["rggb", "bggr", "gbrg", "grbg"])
def test_bayer_patterns_demosaic_to_the_colour(pattern, bits):
    a = bayer_mosaic(pattern, bits)
    out = images.decode_color_message(raw_msg(a, f"bayer_{pattern}{bits}"),
                                      "sensor_msgs/msg/Image", "/c")
    assert out.shape == (6, 8, 3) and out.dtype == np.uint8
    # away from the border every pixel has all four neighbours: the colour exactly
    assert np.all(out[2:-2, 2:-2] == RGB)
    # a swapped pattern would put blue where red is
    assert out[3, 3, 0] == 200 and out[3, 3, 2] == 50


def yuv(r: int, g: int, b: int) -> tuple[int, int, int]:
    """BT.601 limited-range Y'CbCr as YUV 4:2:2 cameras send it."""
    y = 16 + (65.738 * r + 129.057 * g + 25.064 * b) / 256
    u = 128 + (-37.945 * r - 74.494 * g + 112.439 * b) / 256
    v = 128 + (112.439 * r - 94.154 * g - 18.285 * b) / 256
    return round(y), round(u), round(v)


@pytest.mark.parametrize("encoding", ["yuv422", "uyvy", "yuv422_yuy2", "yuyv"])
def test_yuv422_decodes_grey_exactly_and_colour_closely(encoding):
    uyvy = encoding in ("yuv422", "uyvy")
    h, w = 4, 6
    a = np.zeros((h, w, 2), np.uint8)
    # left half: a mid grey (Y=126, U=V=128); right half: the test colour
    y1, u1, v1 = yuv(*RGB)
    for x in range(w):
        yy, uu, vv = (126, 128, 128) if x < w // 2 else (y1, u1, v1)
        chroma = uu if x % 2 == 0 else vv
        a[:, x] = (chroma, yy) if uyvy else (yy, chroma)
    out = images.decode_color_message(raw_msg(a, encoding), "sensor_msgs/msg/Image", "/c")
    assert out.shape == (h, w, 3)
    grey = out[:, :2].astype(int)
    assert np.all(np.abs(grey - grey[0, 0]) == 0) and abs(int(grey[0, 0, 0]) - 128) <= 3
    assert np.all(np.abs(out[:, 4:].astype(int) - RGB) <= 4)


# ----- RVL ------------------------------------------------------------------------------------
def rvl_encode(depth: np.ndarray) -> bytes:
    """Reference RVL encoder, a line-by-line transcription of CompressRVL/EncodeVLE."""
    words: list[int] = []
    state = {"word": 0, "n": 0}

    def vle(value: int) -> None:
        while True:
            nibble = value & 0x7
            value >>= 3
            if value:
                nibble |= 0x8
            state["word"] = ((state["word"] << 4) | nibble) & 0xFFFFFFFF
            state["n"] += 1
            if state["n"] == 8:
                words.append(state["word"])
                state["word"], state["n"] = 0, 0
            if not value:
                break

    px = [int(v) for v in depth.ravel()]
    i, previous = 0, 0
    while i < len(px):
        zeros = 0
        while i < len(px) and px[i] == 0:
            zeros += 1
            i += 1
        vle(zeros)
        nonzeros = 0
        while i + nonzeros < len(px) and px[i + nonzeros] != 0:
            nonzeros += 1
        vle(nonzeros)
        for _ in range(nonzeros):
            delta = px[i] - previous
            vle(((delta << 1) ^ (delta >> 31)) & 0xFFFFFFFF)
            previous = px[i]
            i += 1
    if state["n"]:
        words.append((state["word"] << (4 * (8 - state["n"]))) & 0xFFFFFFFF)
    return struct.pack(f"<{len(words)}I", *words)


def test_rvl_decodes_what_the_reference_encodes():
    rng = np.random.default_rng(3)
    depth = rng.integers(400, 9000, size=(37, 53)).astype(np.uint16)
    depth[rng.random(depth.shape) < 0.2] = 0  # holes
    depth[5:9] = 0  # a long zero run
    depth[-1, -3:] = [65535, 1, 65534]  # big jumps wrap in 16 bits
    data = rvl_encode(depth)
    assert np.array_equal(decode_rvl(data, 53, 37), depth)
    assert np.array_equal(decode_rvl(rvl_encode(np.zeros((4, 4), np.uint16)), 4, 4),
                          np.zeros((4, 4), np.uint16))
    with pytest.raises(SgtoolError, match="RVL depth: the stream ends"):
        decode_rvl(data[: len(data) // 2], 53, 37)


def compressed_depth_rvl(depth: np.ndarray) -> bytes:
    """image_transport's compressedDepth RVL message body: header, size, RVL words."""
    h, w = depth.shape
    return struct.pack("<iff", 0, 0.0, 0.0) + struct.pack("<II", w, h) + rvl_encode(depth)


def test_compressed_depth_rvl_message():
    depth = np.arange(12, dtype=np.uint16).reshape(3, 4) * 250
    msg = SimpleNamespace(format="16UC1; compressedDepth rvl",
                          data=np.frombuffer(compressed_depth_rvl(depth), np.uint8))
    raw, scale = images.decode_depth_message(msg, "sensor_msgs/msg/CompressedImage", "/d")
    assert scale == 1000.0 and np.array_equal(raw, depth)


# ----- a bag with RVL depth, Bayer colour and one CameraInfo topic ------------------------------
def test_bag_with_rvl_bayer_and_the_only_camera_info(tmp_path):
    bag = tmp_path / "rs"
    t0 = 1_700_000_000_000_000_000
    frames = [synthetic_frame(i) for i in range(4)]
    with BagWriter(bag, "ros2-mcap") as w:
        for i, (k, _, depth, _, pose, _) in enumerate(frames):
            t = t0 + i * 33_333_333
            mm = np.round(depth * 1000).astype(np.uint16)
            w.write("/tf", "tf2_msgs/msg/TFMessage", t,
                    w.tf(t, [w.transform_stamped(t, "map", "cam", pose)]))
            w.write("/rs/info", "sensor_msgs/msg/CameraInfo", t, w.camera_info(t, "cam", k))
            w.write("/rs/depth", "sensor_msgs/msg/CompressedImage", t,
                    w.T("sensor_msgs/msg/CompressedImage")(
                        header=w.header(t, "cam"), format="16UC1; compressedDepth rvl",
                        data=np.frombuffer(compressed_depth_rvl(mm), np.uint8)))
            w.write("/rs/color", "sensor_msgs/msg/Image", t,
                    w.image(t, "cam", bayer_mosaic("grbg", 8, k.height, k.width),
                            "bayer_grbg8"))
    rep = import_bag(bag, tmp_path / "o.mcap",
                     BagOptions(depth="/rs/depth", rgb="/rs/color", progress=False,
                                floor=None, floor_auto=False, up=np.array([0, 0, 1.0])))
    assert rep.frames == 4
    assert rep.sources[0][2] == "topic /rs/info (the only CameraInfo topic)"
    with LogReader(tmp_path / "o.mcap") as r:
        got = list(r.frames())
    for fr, (k, _, depth, _, _, _) in zip(got, frames, strict=True):
        assert fr.intrinsics.fx == pytest.approx(k.fx)
        assert np.array_equal(np.round(fr.depth * 1000), np.round(depth * 1000))
        assert np.all(fr.rgb[2:-2, 2:-2] == RGB)


def test_suggestions_follow_the_encodings():
    topics = [TopicInfo("/a/image", "sensor_msgs/msg/Image", 5),
              TopicInfo("/b/image_color", "sensor_msgs/msg/Image", 5),
              TopicInfo("/b/info", "sensor_msgs/msg/CameraInfo", 5)]
    # by names alone, the first "image" topic is offered as colour
    assert suggest_flags(topics)[0] == "--rgb /a/image"
    sugg = suggest_flags(topics, encodings={"/a/image": "16UC1", "/b/image_color": "rgb8"})
    assert sugg == ["--depth /a/image", "--rgb /b/image_color", "--info /b/info"]
    sugg = suggest_flags(topics, encodings={"/a/image": "bayer_rggb8", "/b/image_color": "rgb8"})
    # the native rgb8 topic over the Bayer one that comes first by name
    assert "--depth /a/image" not in sugg and sugg[0] == "--rgb /b/image_color"


@pytest.mark.parametrize("kind, fmt", [("color", "jpeg"), ("depth", "png"), ("ids", "png"),
                                       ("depth", "16UC1; compressedDepth png")])
def test_an_empty_compressed_image_is_one_line(kind, fmt):
    """A CompressedImage with no bytes (a dropped frame some drivers still publish):
    one SgtoolError naming the topic, not OpenCV's assertion from an empty buffer."""
    from sgtool.errors import SgtoolError

    msg = SimpleNamespace(format=fmt, data=np.zeros(0, np.uint8))
    decode = {"color": images.decode_color_message, "depth": images.decode_depth_message,
              "ids": images.decode_ids_message}[kind]
    with pytest.raises(SgtoolError, match="^topic /cam: .*(holds no image data|shorter than "
                                          "its header)"):
        decode(msg, "sensor_msgs/msg/CompressedImage", "/cam")
