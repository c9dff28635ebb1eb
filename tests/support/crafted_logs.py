"""Crafted sgtool logs: well-formed MCAP files whose content is wrong in one way a writer
(or an attacker) could make it wrong, for tests/toolkit/log/test_fuzz.py (in-process) and
tools/fuzz_cli.py (through the CLI).

Every craft starts from the same three-frame log (calibration, /tf world -> base ->
camera, RGB, depth and instance images, an instance table, an episode and a house
attachment) and changes one thing: a channel's schema or encoding, the house attachment,
the /tf tree, an instance table entry, a record's bytes. :data:`CRAFTS` names them; each
builder writes ``path`` and returns it. A crafted log must give each command a clear
one-line refusal or a correct result, never a traceback.
"""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
from foxglove_schemas_protobuf.RawImage_pb2 import RawImage

from sgtool.log import LogWriter, codec
from sgtool.log import schemas as S

DT = 100_000_000
FRAMES = 3
INSTANCES = [
    {"id": 1, "category": "floor", "kind": "structure"},
    {"id": 2, "category": "wall", "kind": "structure"},
    {"id": 3, "category": "cabinet", "kind": "furniture", "state": "closed",
     "affordances": ["openable", "container"]},
]


def frame_messages(n: int = FRAMES, tf: Callable[[int, np.ndarray, np.ndarray],
                                                 list[tuple[str, str, np.ndarray]]] | None = None
                   ) -> list[tuple[str, int, Any]]:
    """(topic, log time, protobuf message) of ``n`` frames of
    :func:`support.logfixtures.synthetic_frame`; ``tf(i, world_T_base, base_T_camera)``
    gives the (parent, child, transform) links of frame ``i`` (default: the two links)."""
    from support.logfixtures import synthetic_frame

    out: list[tuple[str, int, Any]] = []
    for i in range(n):
        k, rgb, depth, ids, pose, base = synthetic_frame(i)
        t = i * DT
        if i == 0:
            out.append((S.CALIBRATION, t, codec.encode_calibration(t, k, S.CAMERA_FRAME)))
        cam = np.linalg.inv(base) @ pose
        links = tf(i, base, cam) if tf else [(S.WORLD_FRAME, S.BASE_FRAME, base),
                                            (S.BASE_FRAME, S.CAMERA_FRAME, cam)]
        out += [(S.TF, t, codec.encode_transform(t, p, c, T)) for p, c, T in links]
        out.append((S.RGB, t, codec.encode_image(t, rgb, S.RGB_ENCODING, S.CAMERA_FRAME)))
        out.append((S.DEPTH, t, codec.encode_image(t, codec.depth_to_mm(depth),
                                                   S.DEPTH_ENCODING, S.CAMERA_FRAME)))
        out.append((S.IDS, t, codec.encode_image(t, ids, S.IDS_ENCODING, S.CAMERA_FRAME)))
    return out


def _small_house() -> str:
    from support.small_house import small_house

    return small_house().to_json()


def write(path: Path, *, messages: list[tuple[str, int, Any]] | None = None,
          house: str | bytes | None | Callable[[], str] = _small_house,
          instances: list[dict[str, Any]] | None = None,
          raw: list[tuple[str, int, bytes]] = (),  # type: ignore[assignment]
          channels: dict[str, tuple[str, str, bytes, str]] | None = None) -> Path:
    """A log of ``messages`` (default :func:`frame_messages`) with the house attachment
    ``house`` (None: none; default: :func:`support.small_house.small_house`), the instance
    table ``instances`` (written raw, unchecked) and ``raw`` (topic, log time, bytes)
    messages. ``channels`` maps a topic to (schema name, schema encoding, schema data,
    message encoding): its messages (protobuf ones serialised) go on a channel registered
    so."""
    channels = channels or {}
    with LogWriter(path, seed=1) as w:
        if house is not None:
            w.attach_house(house() if callable(house) else house)
        ids: dict[str, int] = {t: w.copy_channel(t, *spec) for t, spec in channels.items()}

        def cid(topic: str) -> int:
            if topic not in ids:
                kind = next((k for k in S.RECORDS.values() if k.topic == topic), None)
                ids[topic] = (w._json_channel(kind) if kind is not None
                              else w._proto_channel(topic, RawImage))
            return ids[topic]

        table = INSTANCES if instances is None else instances
        w.write_raw(cid(S.RECORDS["instances"].topic), 0,
                    json.dumps({"instances": table}).encode())
        w.write_record("episode", 0, {"kind": "recording", "status": "started"})
        for topic, t, msg in messages if messages is not None else frame_messages():
            if topic in channels:
                w.write_raw(cid(topic), t, msg.SerializeToString())
            else:
                w.write_proto(topic, t, msg)
        for topic, t, data in raw:
            w.write_raw(cid(topic), t, data)
    return path


def _deep(levels: int) -> str:
    return "[" * levels + "]" * levels


def _huge_translation(i: int, base: np.ndarray, cam: np.ndarray
                      ) -> list[tuple[str, str, np.ndarray]]:
    far = base.copy()
    far[0, 3] = 1e300
    return [(S.WORLD_FRAME, S.BASE_FRAME, far), (S.BASE_FRAME, S.CAMERA_FRAME, cam)]


def _huge_quaternions() -> list[tuple[str, int, Any]]:
    """The frames with every /tf rotation written as a quaternion of 1e200-sized
    components (the same rotations once normalised)."""
    msgs = frame_messages()
    for topic, _, m in msgs:
        if topic == S.TF:
            r = m.rotation
            r.x, r.y, r.z, r.w = (v * 1e200 for v in (r.x, r.y, r.z, r.w))
    return msgs


def _cycle(i: int, base: np.ndarray, cam: np.ndarray) -> list[tuple[str, str, np.ndarray]]:
    return [(S.CAMERA_FRAME, S.BASE_FRAME, base), (S.BASE_FRAME, S.CAMERA_FRAME, cam)]


def _no_camera_link(i: int, base: np.ndarray, cam: np.ndarray
                    ) -> list[tuple[str, str, np.ndarray]]:
    return [(S.WORLD_FRAME, S.BASE_FRAME, base)]


_ROS_IMAGE = ("sensor_msgs/msg/Image", "ros2msg", b"uint32 height\nuint32 width\n", "cdr")
_ITEM = {"category": "mug", "kind": "object"}

CRAFTS: dict[str, Callable[[Path], Path]] = {
    # channels whose schema or encoding is not the one sgtool reads the topic with
    "depth-cdr": lambda p: write(p, channels={S.DEPTH: _ROS_IMAGE}),
    "depth-no-schema": lambda p: write(p, channels={S.DEPTH: ("", "", b"", "protobuf")}),
    "depth-json": lambda p: write(p, channels={S.DEPTH: ("", "", b"", "json")}),
    "tf-wrong-schema": lambda p: write(p, channels={S.TF: (
        "foxglove.RawImage", "protobuf", b"", "protobuf")}),
    "calibration-cdr": lambda p: write(p, channels={S.CALIBRATION: _ROS_IMAGE}),
    "episode-not-json": lambda p: write(p, raw=[(S.RECORDS["episode"].topic, 5, b"\x00{")]),
    # the house attachment
    "house-not-json": lambda p: write(p, house=b"not json {"),
    "house-deep": lambda p: write(p, house=_deep(100_000)),
    "house-not-utf8": lambda p: write(p, house=b"\xff\xfe{}"),
    "house-invalid": lambda p: write(p, house='{"version": "2.0", "rooms": 7}'),
    "no-house": lambda p: write(p, house=None),
    # /tf trees
    "tf-cycle": lambda p: write(p, messages=frame_messages(tf=_cycle)),
    "tf-no-camera": lambda p: write(p, messages=frame_messages(tf=_no_camera_link)),
    "tf-huge": lambda p: write(p, messages=frame_messages(tf=_huge_translation)),
    "tf-huge-quaternion": lambda p: write(p, messages=_huge_quaternions()),
    # instance tables out of range
    "instance-id-2^70": lambda p: write(p, instances=[*INSTANCES, {"id": 2**70, **_ITEM}]),
    "instance-id-negative": lambda p: write(p, instances=[*INSTANCES, {"id": -4, **_ITEM}]),
    "instance-id-0": lambda p: write(p, instances=[*INSTANCES, {"id": 0, **_ITEM}]),
    "instance-id-twice": lambda p: write(p, instances=[*INSTANCES, {"id": 3, **_ITEM}]),
    "instance-parent-2^40": lambda p: write(p, instances=[
        *INSTANCES, {"id": 9, "parent": 2**40, "relation": "inside", **_ITEM}]),
    "instance-empty-category": lambda p: write(p, instances=[
        *INSTANCES, {"id": 9, "category": "", "kind": "object"}]),
    "instance-bad-state": lambda p: write(p, instances=[
        *INSTANCES, {"id": 9, "state": "ajar", **_ITEM}]),
    # the control
    "valid": lambda p: write(p),
}
