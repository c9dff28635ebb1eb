"""A Foxglove ``RawImage`` read straight from its protobuf bytes, pixels left in place.

Parsing a ``RawImage`` with protobuf copies its pixels into the message, and every access
to the ``data`` field copies them again; reading frames, that is two copies of every image
before numpy sees it. :func:`parse_raw_image` reads the seven fields of a well-formed
``RawImage`` from a ``memoryview`` (the message's slice of its decompressed chunk) and
returns a :class:`RawImageView` whose ``data`` is a view of the pixels: the decoders of
:mod:`sgtool.log.codec` then copy or convert them once.

Only the plain encoding is accepted: each field with its own wire type, the timestamp a
sequence of varints, the strings UTF-8. Anything else (unknown fields, packed or damaged
bytes) gives None, and the caller parses the message with protobuf, which then reports the
damage as before.
"""

from __future__ import annotations

import struct
from dataclasses import dataclass

_FIXED32 = struct.Struct("<I")
# tag byte (field number << 3 | wire type) of each RawImage field
_TIMESTAMP, _WIDTH, _HEIGHT, _ENCODING, _STEP, _DATA, _FRAME_ID = (
    0x0A, 0x15, 0x1D, 0x22, 0x2D, 0x32, 0x3A)


@dataclass(frozen=True, slots=True)
class RawImageView:
    """The fields of a ``RawImage`` that images are decoded from; ``data`` a read-only
    view of the pixels (no timestamp: frames take the log time)."""

    frame_id: str
    width: int
    height: int
    encoding: str
    step: int
    data: memoryview


def _varint(buf: memoryview, pos: int) -> tuple[int, int]:
    """(value, next position) of the varint at ``pos``; IndexError/ValueError when cut
    short or longer than 10 bytes."""
    value = shift = 0
    for _ in range(10):
        b = buf[pos]
        pos += 1
        value |= (b & 0x7F) << shift
        if b < 0x80:
            return value, pos
        shift += 7
    raise ValueError("varint longer than 10 bytes")


def _timestamp_ok(buf: memoryview) -> bool:
    """``buf`` is a plain ``Timestamp`` (seconds and nanos varints)."""
    pos = 0
    while pos < len(buf):
        if buf[pos] not in (0x08, 0x10):
            return False
        _, pos = _varint(buf, pos + 1)
    return True


_SIZE_ENCODING = struct.Struct("<BIBIBB")  # width tag, width, height tag, height, encoding
_STEP_DATA = struct.Struct("<BIB")  # step tag, step, data tag


def _in_field_order(buf: memoryview) -> RawImageView | None:
    """:func:`parse_raw_image` of the layout protobuf writes (fields by number, short
    timestamp, encoding and frame id), in a few steps; None for any other layout."""
    n = len(buf)
    if n < 2 or buf[0] != _TIMESTAMP or buf[1] >= 0x80:
        return None
    pos = 2 + buf[1]
    if pos + _SIZE_ENCODING.size > n or not _timestamp_ok(buf[2:pos]):
        return None
    wt, width, ht, height, et, elen = _SIZE_ENCODING.unpack_from(buf, pos)
    pos += _SIZE_ENCODING.size
    if wt != _WIDTH or ht != _HEIGHT or et != _ENCODING or elen >= 0x80:
        return None
    encoding = str(buf[pos:pos + elen], "utf-8")
    pos += elen
    if pos + _STEP_DATA.size > n:
        return None
    st, step, dt = _STEP_DATA.unpack_from(buf, pos)
    if st != _STEP or dt != _DATA:
        return None
    size, pos = _varint(buf, pos + _STEP_DATA.size)
    end = pos + size
    if end > n:
        return None
    data = buf[pos:end]
    frame_id = ""
    if end < n:
        if buf[end] != _FRAME_ID or end + 2 + buf[end + 1] != n or buf[end + 1] >= 0x80:
            return None
        frame_id = str(buf[end + 2:n], "utf-8")
    return RawImageView(frame_id, width, height, encoding, step, data)


def parse_raw_image(buf: memoryview) -> RawImageView | None:
    """The image in ``buf`` (protobuf ``foxglove.RawImage`` bytes), or None when they are
    not a plain, well-formed encoding of one (module doc)."""
    try:
        fast = _in_field_order(buf)
    except (IndexError, ValueError):  # cut short, too long a varint, not UTF-8
        fast = None
    return fast if fast is not None else _any_order(buf)


def _any_order(buf: memoryview) -> RawImageView | None:
    """:func:`parse_raw_image`, fields in any order."""
    width = height = step = 0
    encoding = frame_id = ""
    data = buf[0:0]
    pos, n = 0, len(buf)
    unpack = _FIXED32.unpack_from
    try:
        while pos < n:
            tag = buf[pos]
            if tag == _WIDTH or tag == _HEIGHT or tag == _STEP:  # noqa: PLR1714 - speed
                if pos + 5 > n:
                    return None
                (v,) = unpack(buf, pos + 1)
                pos += 5
                if tag == _WIDTH:
                    width = v
                elif tag == _HEIGHT:
                    height = v
                else:
                    step = v
                continue
            size = buf[pos + 1]
            if size < 0x80:
                pos += 2
            else:
                size, pos = _varint(buf, pos + 1)
            end = pos + size
            if end > n:
                return None
            if tag == _DATA:
                data = buf[pos:end]
            elif tag == _ENCODING:
                encoding = str(buf[pos:end], "utf-8")
            elif tag == _FRAME_ID:
                frame_id = str(buf[pos:end], "utf-8")
            elif tag != _TIMESTAMP or not _timestamp_ok(buf[pos:end]):
                return None
            pos = end
    except (IndexError, ValueError):  # cut short, too long a varint, not UTF-8
        return None
    return RawImageView(frame_id, width, height, encoding, step, data)
