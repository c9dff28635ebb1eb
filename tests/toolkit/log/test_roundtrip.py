"""Every channel type of the log contract survives a write/read round trip."""

from __future__ import annotations

import dataclasses
import hashlib
import json

import numpy as np
import pytest
from support.logfixtures import DT, synthetic_frame, write_log

from sgtool.errors import LogFormatError, MissingChannelError, SchemaVersionError
from sgtool.log import LogReader, LogWriter, codec
from sgtool.log import schemas as S


def test_round_trip_every_channel(tmp_path):
    path = write_log(tmp_path / "run.mcap")
    assert not (tmp_path / "run.mcap.partial").exists()
    with LogReader(path) as r:
        assert r.is_sgtool and r.schema_version == S.LOG_SCHEMA_VERSION and r.seed == 7
        assert r.house_json() == '{"version": "1.0"}'
        assert r.frame_count() == 12
        frames = list(r.frames())
        assert [f.index for f in frames] == list(range(12))
        for f in frames:
            k, rgb, depth, ids, pose, base = synthetic_frame(f.index)
            assert f.time_ns == f.index * DT
            assert f.intrinsics == k
            np.testing.assert_array_equal(f.rgb, rgb)
            np.testing.assert_array_equal(f.ids, ids)
            # depth is stored in millimetres: exact to half a millimetre
            assert np.max(np.abs(f.depth - depth)) <= 0.0005 + 1e-6
            np.testing.assert_allclose(f.pose, pose, atol=1e-9)
            np.testing.assert_allclose(f.base_pose, base, atol=1e-9)
        grid_msgs = list(r.messages([S.OCCUPANCY]))
        cells, origin, res = codec.decode_grid(grid_msgs[0].message)
        assert cells.shape == (4, 5) and cells[0, 0] == 100 and cells[1, 2] == 0
        assert origin == (1.5, -2.0) and res == pytest.approx(0.05)
        (vor,) = list(r.messages([S.VORONOI]))
        assert vor.schema_name == "foxglove.SceneUpdate"
        assert vor.message.entities[0].lines[0].points[1].y == 2
        assert r.last_record("instances")["instances"][1]["affordances"] == [
            "openable", "container"]
        assert [e["status"] for _, e in r.records("episode")] == ["started", "ended"]
        assert r.last_record("action")["target"] == "obj:3"
        assert r.last_record("llm_exchange")["response"] == "Command: done()"
        schemas = {c.topic: (c.schema_name, c.schema_encoding) for c in r.channels()}
        assert schemas[S.RGB] == ("foxglove.RawImage", "protobuf")
        assert schemas[S.CALIBRATION] == ("foxglove.CameraCalibration", "protobuf")
        assert schemas[S.TF] == ("foxglove.FrameTransform", "protobuf")
        assert schemas[S.OCCUPANCY] == ("foxglove.Grid", "protobuf")
        assert schemas["/sgtool/action"] == ("sgtool.Action", "jsonschema")
        enc = {d.topic: d.message.encoding for d in r.messages([S.RGB, S.DEPTH, S.IDS],
                                                              end_ns=1)}
        assert enc == {S.RGB: "rgb8", S.DEPTH: "16UC1", S.IDS: "16UC1"}  # ids fit 16 bits


def test_json_schemas_are_named_and_versioned(tmp_path):
    path = write_log(tmp_path / "run.mcap", n=1)
    with LogReader(path) as r:
        for sch in r.summary.schemas.values():
            if sch.encoding == "jsonschema":
                doc = json.loads(sch.data)
                assert doc["title"] == sch.name
                assert doc["version"] == S.RECORD_BY_SCHEMA[sch.name].version
                assert sch.name.startswith("sgtool.")


def test_frame_at_uses_the_index(tmp_path):
    path = write_log(tmp_path / "run.mcap")
    with LogReader(path) as r:
        assert r.frame_at(-1) is None
        f = r.frame_at(5 * DT + DT // 2)  # between frames 5 and 6: frame 5
        assert f.index == 5 and f.time_ns == 5 * DT
        np.testing.assert_allclose(f.pose, synthetic_frame(5)[4], atol=1e-9)
        assert r.frame_at(10**12).index == 11


def test_same_calls_give_same_bytes(tmp_path):
    a = write_log(tmp_path / "a.mcap")
    b = write_log(tmp_path / "b.mcap")
    assert hashlib.sha256(a.read_bytes()).digest() == hashlib.sha256(b.read_bytes()).digest()


def test_newer_major_schema_version_is_refused(tmp_path):
    path = tmp_path / "future.mcap"
    with LogWriter(path, metadata={"log_schema_version": "2.3"}) as w:
        k, rgb, depth, ids, pose, _ = synthetic_frame(0)
        w.write_frame(0, depth=depth, pose=pose, intrinsics=k)
    with pytest.raises(SchemaVersionError) as e:
        LogReader(path)
    assert "2.3" in str(e.value) and "1.x" in str(e.value)


def test_newer_minor_version_is_read(tmp_path):
    path = tmp_path / "minor.mcap"
    with LogWriter(path, metadata={"log_schema_version": "1.9"}) as w:
        k, rgb, depth, ids, pose, _ = synthetic_frame(0)
        w.write_frame(0, depth=depth, pose=pose, intrinsics=k)
    with LogReader(path) as r:
        assert r.schema_version == (1, 9) and r.frame_count() == 1


def test_missing_channel_is_named(tmp_path):
    path = tmp_path / "nodepth.mcap"
    with LogWriter(path) as w:
        w.write_record("episode", 0, {"kind": "recording", "status": "started"})
    with LogReader(path) as r, pytest.raises(MissingChannelError, match="/camera/depth"):
        list(r.frames())


def test_frames_without_rgb_or_ids(tmp_path):
    path = tmp_path / "depthonly.mcap"
    with LogWriter(path) as w:
        for i in range(3):
            k, rgb, depth, ids, pose, _ = synthetic_frame(i)
            w.write_frame(i * DT, depth=depth, pose=pose, intrinsics=k)
    with LogReader(path) as r:
        frames = list(r.frames())
        assert len(frames) == 3 and frames[0].rgb is None and frames[0].ids is None
        assert frames[0].base_pose is None


def test_failed_write_leaves_no_file(tmp_path):
    out = tmp_path / "bad.mcap"
    with pytest.raises(RuntimeError), LogWriter(out) as w:
        w.write_record("episode", 0, {"kind": "recording", "status": "started"})
        raise RuntimeError("boom")
    assert not out.exists() and not (tmp_path / "bad.mcap.partial").exists()


def test_not_an_mcap_file(tmp_path):
    p = tmp_path / "x.mcap"
    p.write_text("hello")
    with pytest.raises(LogFormatError, match="not an MCAP file"):
        LogReader(p)


def test_input_that_would_read_back_wrong_is_refused(tmp_path):
    """What the writer would store as something else is a ValueError naming it: depth
    in an integer type other than uint16 or in millimetres as float (it would read back
    as no depth), ids beyond int32 (they would wrap), a pose that is not a rigid 4x4
    transform (its quaternion would be another pose), frames at a time not after the last
    (a replay pairs by time); uint16 millimetres, float metres and ids that fit pass."""
    k, rgb, depth, ids, pose, _ = synthetic_frame(0)
    with LogWriter(tmp_path / "run.mcap", seed=1) as w:
        w.write_frame(2 * DT, depth=depth, pose=pose, intrinsics=k, ids=ids)
        for bad, says in (((depth * 1000).astype(np.int32), "depth as int32"),
                          (depth * 1000.0, "depth beyond 65.535 m")):
            with pytest.raises(ValueError, match=says):
                w.write_depth(DT, bad)
        with pytest.raises(ValueError, match="ids must fit int32"):
            w.write_ids(DT, ids.astype(np.int64) + 2**31)
        scaled = pose.copy()
        scaled[:3, :3] *= 2
        for bad_pose, says in ((pose[:3], "4x4 matrix is needed, not 3x4"),
                               (scaled, "not orthonormal")):
            with pytest.raises(ValueError, match=says):
                w.write_transform(2 * DT, "world", "camera", bad_pose)
        for t in (2 * DT, DT):  # the same time, an earlier one
            with pytest.raises(ValueError, match="frame times must increase"):
                w.write_frame(t, depth=depth, pose=pose, intrinsics=k)
        # seconds given for nanoseconds (2.5 truncated to 2, the next frames' times
        # collided: the log did not read back), negative depth (read back as no return)
        with pytest.raises(ValueError, match=r"log time 2.5: times are whole nanoseconds"):
            w.write_frame(2.5, depth=depth, pose=pose, intrinsics=k)
        with pytest.raises(ValueError, match="log time 2.5"):
            w.write_record("instances", 2.5, {"instances": []})
        negative = np.where(np.arange(depth.size).reshape(depth.shape) == 0, -1.5, depth)
        with pytest.raises(ValueError, match=r"depth -1.5 m at pixel \(row 0, col 0\)"):
            w.write_frame(3 * DT, depth=negative, pose=pose, intrinsics=k)
        with pytest.raises(ValueError, match=r"depth -1.5 m at pixel"):
            w.write_depth(3 * DT, negative)  # (its own writer too)
        w.write_frame(3 * DT, depth=np.rint(depth * 1000).astype(np.uint16), pose=pose,
                      intrinsics=k)  # uint16 millimetres: as given
        # a refused frame leaves nothing of itself, and the same frame mended goes in
        with pytest.raises(ValueError, match="depth as int32"):
            w.write_frame(4 * DT, depth=(depth * 1000).astype(np.int32), pose=pose,
                          intrinsics=synthetic_frame(1)[0], rgb=rgb)
        w.write_frame(4 * DT, depth=depth, pose=pose, intrinsics=k, rgb=rgb)
        # images of another size than the intrinsics', colours as float or beyond uint8,
        # ids as float, intrinsics a reader refuses: each would read back as damage or as
        # other values (0.8 as black, 300 as 44)
        h, w_ = depth.shape
        for frame, says in (
                (dict(depth=depth[: h // 2]), r"depth of shape \("),
                (dict(depth=depth, rgb=rgb[:, : w_ // 2]), r"rgb of shape \("),
                (dict(depth=depth, ids=ids[:-1]), r"ids of shape \("),
                (dict(depth=depth, rgb=rgb / 255.0), "rgb8 image as float64"),
                (dict(depth=depth, rgb=rgb.astype(np.int64) + 200),
                 "uint8 holds 0..255"),
                (dict(depth=depth, ids=ids.astype(np.float64) + 0.6),
                 "instance ids as float64: give an integer array"),
                (dict(depth=depth, intrinsics=dataclasses.replace(k, fx=0.0)),
                 "focal")):
            with pytest.raises(ValueError, match=says):
                w.write_frame(5 * DT, pose=pose, **{"intrinsics": k, **frame})
    with LogReader(tmp_path / "run.mcap") as r:
        a, b, c = r.frames()
        np.testing.assert_allclose(b.depth, a.depth, atol=1e-3)
        assert c.time_ns == 4 * DT and c.intrinsics == k
        counts = {t: sum(1 for _ in r.messages([t])) for t in (S.TF, S.RGB, S.CALIBRATION)}
    assert counts == {S.TF: 3, S.RGB: 1, S.CALIBRATION: 1}


def test_a_read_after_close_says_so_not_damaged(tmp_path):
    """A reader used after its `with` block: one line saying it was closed, never "damaged
    data" pointing to `sgtool doctor` (the file is fine)."""
    from sgtool.errors import SgtoolError

    log = write_log(tmp_path / "a.mcap", n=4)
    with LogReader(log) as r:
        frames = r.frames()
        next(frames)
    for read in (lambda: list(frames), lambda: list(r.messages([S.DEPTH])),
                 lambda: r.last_record("episode")):
        with pytest.raises(SgtoolError, match="read after its LogReader was closed") as e:
            read()
        assert not isinstance(e.value, LogFormatError)
