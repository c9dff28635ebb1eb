"""Crafted logs with inconsistent or malformed content (issue 14, items 4 and 6): every
reader path refuses them with one LogFormatError naming the channel, the log time and the
field, never a traceback, never a silently different graph."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from foxglove_schemas_protobuf.RawImage_pb2 import RawImage
from support.logfixtures import synthetic_frame

from sgtool.errors import LogFormatError, SgtoolError
from sgtool.log import LogReader, LogWriter, codec
from sgtool.log import schemas as S
from sgtool.log.inspect import summarize
from sgtool.replayers.derived_log import ReplayOptions, replay

DT = 100_000_000


def _messages(n: int = 3) -> list[tuple[str, int, object]]:
    out: list[tuple[str, int, object]] = []
    for i in range(n):
        k, rgb, depth, ids, pose, base = synthetic_frame(i)
        t = i * DT
        if i == 0:
            out.append((S.CALIBRATION, t, codec.encode_calibration(t, k, S.CAMERA_FRAME)))
        cam = np.linalg.inv(base) @ pose
        out.append((S.TF, t, codec.encode_transform(t, S.WORLD_FRAME, S.BASE_FRAME, base)))
        out.append((S.TF, t, codec.encode_transform(t, S.BASE_FRAME, S.CAMERA_FRAME, cam)))
        out.append((S.RGB, t, codec.encode_image(t, rgb, S.RGB_ENCODING, S.CAMERA_FRAME)))
        out.append((S.DEPTH, t, codec.encode_image(t, codec.depth_to_mm(depth),
                                                   S.DEPTH_ENCODING, S.CAMERA_FRAME)))
        out.append((S.IDS, t, codec.encode_image(t, ids, S.IDS_ENCODING, S.CAMERA_FRAME)))
    return out


def craft(path: Path, messages: list[tuple[str, int, object]], **kw) -> Path:
    with LogWriter(path, seed=kw.pop("seed", 1), **kw) as w:
        for topic, t, msg in messages:
            if isinstance(msg, bytes):  # raw bytes on the channel's usual schema
                cid = (w._proto_channel(topic, RawImage) if topic.startswith("/camera")
                       else w._json_channel(next(k for k in S.RECORDS.values()
                                                 if k.topic == topic)))
                w.write_raw(cid, t, msg)
            else:
                w.write_proto(topic, t, msg)
    return path


def _edit(topic: str, index: int, change) -> list:  # noqa: ANN001
    msgs = _messages()
    hits = [i for i, (tp, _, _) in enumerate(msgs) if tp == topic]
    change(msgs[hits[index]][2])
    return msgs


def _zero_quaternion(m) -> None:  # noqa: ANN001
    m.rotation.x = m.rotation.y = m.rotation.z = m.rotation.w = 0.0


def _nan_translation(m) -> None:  # noqa: ANN001
    m.translation.x = float("nan")


def _negative_focal(m) -> None:  # noqa: ANN001
    m.K[0] = -m.K[0]


def _short_k(m) -> None:  # noqa: ANN001
    del m.K[4:]


def _wider_calibration(m) -> None:  # noqa: ANN001
    m.width += 1


def _zero_size(m) -> None:  # noqa: ANN001
    m.width = m.height = m.step = 0
    m.data = b""


def _float_ids(m) -> None:  # noqa: ANN001
    m.encoding = "32FC1"


def _padded_step(m) -> None:  # noqa: ANN001
    m.step += 2


CASES = {
    # name: (messages, channel named, field named)
    "zero quaternion": (_edit(S.TF, 1, _zero_quaternion), S.TF, "rotation"),
    "NaN pose": (_edit(S.TF, 2, _nan_translation), S.TF, "translation"),
    "negative focal length": (_edit(S.CALIBRATION, 0, _negative_focal), S.CALIBRATION, "K"),
    "short K": (_edit(S.CALIBRATION, 0, _short_k), S.CALIBRATION, "K"),
    "depth size != calibration": (_edit(S.CALIBRATION, 0, _wider_calibration), S.DEPTH,
                                  "width"),
    "zero-size depth": (_edit(S.DEPTH, 1, _zero_size), S.DEPTH, "width"),
    "float instance ids": (_edit(S.IDS, 0, _float_ids), S.IDS, "encoding"),
    "step disagrees with size": (_edit(S.RGB, 2, _padded_step), S.RGB, "data"),
    "no calibration": ([m for m in _messages() if m[0] != S.CALIBRATION], S.DEPTH,
                       S.CALIBRATION),
    "equal timestamps": ([(tp, 0, m) for tp, _, m in _messages()], S.RGB, "same log time"),
    "protobuf garbage": (_messages() + [(S.DEPTH, 3 * DT, b"\xff\xff\xff\x0f")], S.DEPTH,
                         "RawImage"),
}


@pytest.mark.parametrize("case", list(CASES))
def test_inconsistent_sensor_data_is_refused(case, tmp_path):
    msgs, topic, field = CASES[case]
    log = craft(tmp_path / "bad.mcap", msgs)
    with pytest.raises(LogFormatError) as e:
        replay(log, None, ReplayOptions(every=100, voxel_size=0.2))
    text = str(e.value)
    assert "\n" not in text and topic in text and field in text and " ns" in text, text
    with pytest.raises(LogFormatError), LogReader(log) as r:
        list(r.frames())
    try:  # info reads the calibration and the records only: it may succeed
        summarize(log)
    except SgtoolError:
        pass


def test_the_consistent_log_replays(tmp_path):
    """The control: the same messages, unedited, replay to a graph."""
    rep = replay(craft(tmp_path / "ok.mcap", _messages()), None,
                 ReplayOptions(every=100, voxel_size=0.2))
    assert rep.frames == 3 and rep.refreshes == 1


@pytest.mark.parametrize("data", [b"{not json", b"\xff\xfe", b"[1, 2]", b'"text"', b"1e999"])
def test_malformed_json_records_are_one_error(data, tmp_path):
    log = craft(tmp_path / "bad.mcap", _messages() + [(S.RECORDS["episode"].topic, 0, data)])
    for fn in (lambda: summarize(log),
               lambda: replay(log, None, ReplayOptions(every=100, voxel_size=0.2))):
        with pytest.raises(LogFormatError) as e:
            fn()
        assert S.RECORDS["episode"].topic in str(e.value) or "Episode" in str(e.value)


def test_a_seed_that_is_not_a_number_is_one_error(tmp_path):
    log = craft(tmp_path / "bad.mcap", _messages(), metadata={"seed": "xyz"})
    with pytest.raises(LogFormatError, match="seed"):
        summarize(log)
    with pytest.raises(LogFormatError, match="seed"):
        replay(log, tmp_path / "out.mcap")
    assert not (tmp_path / "out.mcap").exists()
