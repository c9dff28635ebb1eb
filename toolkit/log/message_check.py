"""What sgtool reads each of its channels as, and whether one message fits it.

sgtool reads its frame topics as Foxglove protobuf messages (images as
``foxglove.RawImage``, the calibration as ``foxglove.CameraCalibration``, ``/tf`` and
``/tf_static`` as ``foxglove.FrameTransform``, the occupancy grid as ``foxglove.Grid``) and
its records as JSON (:data:`sgtool.log.schemas.RECORDS`). :func:`channel_problem` says, in
one line naming the channel, its message encoding and its schema, why a channel of one of
those topics cannot be read so (a depth channel in CDR, or with no schema); None when it
can, or when the topic is not one of sgtool's.

:func:`message_problem` decodes one message the way the reader and replay do and checks it
as they would: an image must decode to the size its width, height, step and encoding
advertise, a transform must be finite and its quaternion normalisable, a calibration must
have a 3x3 K with positive focal lengths, a record must be JSON that fits its record type
(:mod:`sgtool.log.records`, instance tables included), other protobuf messages must parse
with their schema, JSON messages must parse. Diagnosis and recovery (:mod:`sgtool.log.recover`)
run it on every message (one that fails is not copied). Encodings sgtool cannot
decode (CDR, ROS 1, flatbuffer ...) are not checked: :func:`checkable` says which are.
"""

from __future__ import annotations

import json
from collections.abc import Callable
from typing import Any

from mcap.records import Channel, Schema

from sgtool.errors import LogFormatError
from sgtool.log import codec
from sgtool.log import schemas as S

PROTO_TOPICS: dict[str, str] = {
    S.RGB: "foxglove.RawImage",
    S.DEPTH: "foxglove.RawImage",
    S.IDS: "foxglove.RawImage",
    S.CALIBRATION: "foxglove.CameraCalibration",
    S.TF: "foxglove.FrameTransform",
    S.TF_STATIC: "foxglove.FrameTransform",
    S.OCCUPANCY: "foxglove.Grid",
}
_RECORD_TOPICS = {k.topic: k for k in S.RECORDS.values()}
_PROTO_CHECKS: dict[str, Callable[[Any], object]] = {
    "foxglove.RawImage": codec.decode_image,
    "foxglove.CameraCalibration": codec.decode_calibration,
    "foxglove.FrameTransform": codec.decode_transform,
    "foxglove.Grid": codec.decode_grid,
}


def _schema_words(schema: Schema | None) -> str:
    if schema is None:
        return "no schema"
    return f"schema {schema.name[:60]!r} ({schema.encoding[:20] or 'no schema encoding'})"


def channel_problem(schema: Schema | None, channel: Channel) -> str | None:
    """Why messages of ``channel`` cannot be read as sgtool reads its topic (module doc),
    or None."""
    topic, enc = channel.topic, channel.message_encoding
    want = PROTO_TOPICS.get(topic)
    if want is not None:
        if enc == "protobuf" and schema is not None and schema.name == want:
            return None
        return (f"channel {topic} has message encoding {enc[:20]!r} and "
                f"{_schema_words(schema)}; sgtool reads {topic} as protobuf {want}")
    kind = _RECORD_TOPICS.get(topic)
    if kind is not None and enc != "json":
        return (f"channel {topic} has message encoding {enc[:20]!r} and "
                f"{_schema_words(schema)}; sgtool reads {topic} as JSON {kind.schema_name}")
    return None


def checkable(schema: Schema | None, channel: Channel) -> bool:
    """Whether :func:`message_problem` can decode messages of ``channel``: JSON, or
    protobuf with a protobuf schema."""
    return channel.message_encoding == "json" or (
        channel.message_encoding == "protobuf" and schema is not None
        and schema.encoding == "protobuf")


def message_problem(schema: Schema | None, channel: Channel, data: bytes | memoryview,
                    sgtool_log: bool = True) -> str | None:
    """Why message bytes ``data`` of ``channel`` do not decode and check as the reader
    and replay would read them (module doc), in a few words; None when they do, or when
    the encoding is not :func:`checkable`. In a file that is not an sgtool log
    (``sgtool_log`` False) only whether they parse with their schema (protobuf) or as
    JSON: its topics follow other conventions (a ``/tf`` of ``foxglove.FrameTransforms``,
    image encodings sgtool does not decode), none of them wrong."""
    if not checkable(schema, channel):
        return None
    if sgtool_log and (problem := channel_problem(schema, channel)) is not None:
        return problem
    try:
        if channel.message_encoding == "json":
            value = json.loads(bytes(data))
            kind = _RECORD_TOPICS.get(channel.topic) if sgtool_log else None
            if kind is not None:
                from sgtool.log.records import RECORD_TYPES

                RECORD_TYPES[kind.key].from_json(value, where=kind.schema_name)
            return None
        assert schema is not None
        return _protobuf_problem(schema, bytes(data), sgtool_log)
    except LogFormatError as e:
        return str(e)[:200]
    except (ValueError, RecursionError) as e:
        return f"not JSON ({str(e)[:80]})"


def _protobuf_problem(schema: Schema, data: bytes, check_values: bool = True) -> str | None:
    from sgtool.log.reader import proto_class

    cls = proto_class(schema.name)
    try:
        if cls is None:
            from mcap_protobuf.decoder import DecoderFactory

            decoder = DecoderFactory().decoder_for("protobuf", schema)
            if decoder is not None:
                decoder(data)
            return None
        msg = cls()
        msg.ParseFromString(data)
    except Exception as e:  # noqa: BLE001 - protobuf's DecodeError and kin
        return f"not a valid {schema.name[:60]} ({type(e).__name__}: {str(e)[:80]})"
    check = _PROTO_CHECKS.get(schema.name) if check_values else None
    if check is not None:
        check(msg)  # LogFormatError naming the field
    return None
