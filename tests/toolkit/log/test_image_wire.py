"""RawImage read in place (sgtool.log.image_wire) == protobuf's parse; anything unusual is
left to protobuf (None); frames read through views == frames assembled from protobuf
messages, and own their pixels."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from foxglove_schemas_protobuf.RawImage_pb2 import RawImage

from sgtool.log import LogReader, codec
from sgtool.log import schemas as S
from sgtool.log.frame_assembly import FRAME_TOPICS, FrameAssembler
from sgtool.log.image_wire import parse_raw_image

GOLDEN = Path(__file__).resolve().parents[2] / "golden" / "house6-tour.mcap"
FIELDS = ("frame_id", "width", "height", "encoding", "step")


def _same(buf: bytes) -> None:
    want = RawImage()
    want.ParseFromString(buf)
    got = parse_raw_image(memoryview(buf))
    assert got is not None
    for f in FIELDS:
        assert getattr(got, f) == getattr(want, f)
    assert bytes(got.data) == want.data


@pytest.mark.parametrize("enc, shape, dtype", [
    ("rgb8", (5, 7, 3), np.uint8), ("16UC1", (300, 2), np.uint16),
    ("32SC1", (4, 129), np.int32), ("32FC1", (1, 1), np.float32), ("mono8", (0, 0), np.uint8)])
def test_parse_equals_protobuf_on_encoded_images(enc, shape, dtype):
    rng = np.random.default_rng(1)
    arr = rng.integers(0, 200, shape).astype(dtype)
    if arr.size:
        msg = codec.encode_image(123_456_789_012, arr, enc, "cämera")  # UTF-8 frame id
    else:
        msg = RawImage(encoding=enc)  # every field at its default: nothing on the wire
    _same(msg.SerializeToString())


def test_parse_equals_protobuf_on_a_recorded_log():
    n = 0
    with LogReader(GOLDEN) as r:
        for _, _ch, m in r.raw_messages([S.RGB, S.DEPTH, S.IDS]):
            _same(bytes(m.data))
            n += 1
    assert n > 100


def test_unusual_or_damaged_bytes_are_left_to_protobuf():
    good = codec.encode_image(5, np.zeros((3, 4), np.uint16), "16UC1", "cam")
    buf = good.SerializeToString()
    assert parse_raw_image(memoryview(buf)) is not None
    extra = buf + b"\x40\x01"  # field 8 (unknown), varint
    bad_utf8 = RawImage(encoding="x").SerializeToString().replace(b"x", b"\xff")
    bad_ts = b"\x0a\x02\x18\x01" + buf  # timestamp with an unknown field 3
    for b in (extra, buf[:-3], buf[:10], bad_utf8, bad_ts, b"\x32\xff"):
        assert parse_raw_image(memoryview(b)) is None


def test_depth_in_metres_is_unchanged_for_every_millimetre_value():
    mm = np.arange(65536, dtype="<u2").reshape(256, 256)
    msg = codec.encode_image(0, mm, "16UC1", "cam")
    view = parse_raw_image(memoryview(msg.SerializeToString()))
    want = mm.astype(np.float32) / np.float32(S.DEPTH_SCALE)  # the formula before
    for m in (msg, view):
        got = codec.depth_from_image(m)
        assert got.dtype == np.float32
        assert np.array_equal(got.view(np.int32), want.view(np.int32))


def test_frames_read_through_views_equal_frames_from_protobuf_messages():
    with LogReader(GOLDEN) as r:
        fast = list(r.frames())
        asm = FrameAssembler(where=str(GOLDEN))
        slow = []
        for d in r.messages(FRAME_TOPICS):  # protobuf classes, copied bytes
            assert not isinstance(d.message, memoryview)
            slow += asm.push(d.topic, d.log_time_ns, d.message)
        slow += asm.finish()
    assert len(fast) == len(slow) > 10
    for a, b in zip(fast, slow, strict=True):
        assert a.time_ns == b.time_ns and a.index == b.index
        assert a.rgb is not None and a.ids is not None
        for x, y in ((a.rgb, b.rgb), (a.depth, b.depth), (a.ids, b.ids), (a.pose, b.pose)):
            assert x.dtype == y.dtype and np.array_equal(x, y)
        assert a.rgb.flags.owndata  # copied out of the chunk: keeping a frame keeps no chunk
        assert a.intrinsics == b.intrinsics


def _one_field_each(msg: RawImage) -> list[bytes]:
    """The bytes of each field of ``msg`` alone, in field-number order."""
    out = []
    for name in ("timestamp", "width", "height", "encoding", "step", "data", "frame_id"):
        one = RawImage()
        if name == "timestamp":
            one.timestamp.CopyFrom(msg.timestamp)
        else:
            setattr(one, name, getattr(msg, name))
        out.append(one.SerializeToString())
    return out


def test_parse_equals_protobuf_whatever_the_order_of_the_fields():
    """Protobuf writes fields by number (the layout read in a few steps); any other order,
    and a frame id too long for that shortcut, is read field by field: both == protobuf."""
    rng = np.random.default_rng(2)
    for enc, shape, dtype, frame_id, t in [
            ("rgb8", (6, 5, 3), np.uint8, "camera", 7), ("16UC1", (70, 90), np.uint16, "", 0),
            ("32SC1", (2, 3), np.int32, "x" * 200, 1 << 40)]:
        arr = rng.integers(0, 200, shape).astype(dtype)
        msg = codec.encode_image(t, arr, enc, frame_id)
        fields = _one_field_each(msg)
        assert b"".join(fields) == msg.SerializeToString()
        _same(b"".join(fields))
        for _ in range(6):
            _same(b"".join(fields[i] for i in rng.permutation(len(fields))))
        width, height = fields[1:3]  # width, then height: swapped
        _same(b"".join([fields[0], height, width, *fields[3:]]))
