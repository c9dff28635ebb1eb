"""`sgtool replay` on recordings that are not sgtool logs says what they are and which import
command turns them into one (issue 18): a ROS 2 MCAP with camera topics, one with poses
only, a ROS 1 bag, a ROS 2 bag's sqlite3 storage; sgtool logs pass."""

from __future__ import annotations

from click.testing import CliRunner
from support.bag_export import write_frames_bag
from support.logfixtures import synthetic_frame, write_log

from sgtool.cli import cli
from sgtool.log.frame import Frame
from sgtool.log.inspect import foreign_log_problem


def frames(n: int = 3) -> list[Frame]:
    out = []
    for i in range(n):
        k, rgb, depth, ids, pose, _ = synthetic_frame(i)
        out.append(Frame(index=i, time_ns=1_000 + i * 33_000_000, rgb=rgb, depth=depth,
                         ids=ids, pose=pose, intrinsics=k))
    return out


def replay_error(path) -> str:  # type: ignore[no-untyped-def]
    r = CliRunner().invoke(cli, ["replay", str(path)])
    assert r.exit_code == 2 and "Traceback" not in r.output
    assert len(r.output.strip().splitlines()) == 1
    return r.output


def test_ros2_mcap_with_camera_topics_points_to_import_bag(tmp_path):
    bag = tmp_path / "cam"
    write_frames_bag(frames(), bag, "ros2-mcap")
    storage = bag / "cam.mcap"
    out = replay_error(storage)
    assert ("is a ROS 2 recording (MCAP, profile 'ros2') with 5 topic(s) of messages "
            "encoded 'cdr'") in out
    assert f"sgtool import bag {storage} -o OUT.mcap --depth /camera/depth/image_raw" in out
    assert "--list` shows its topics" in out


def test_trajectory_only_ros1_and_sqlite(tmp_path):
    bag = tmp_path / "b.bag"
    write_frames_bag(frames(), bag, "ros1")
    assert "is a ROS 1 bag, not an sgtool log; turn it into one with `sgtool import bag" \
        in replay_error(bag)
    db = tmp_path / "sq"
    write_frames_bag(frames(), db, "ros2-sqlite3")
    out = replay_error(db / "sq.db3")
    assert "SQLite file (a ROS 2 bag's storage?)" in out and f"import bag {db} -o" in out


def test_sgtool_logs_and_other_files_are_not_flagged(tmp_path):
    log = write_log(tmp_path / "log.mcap", n=2)
    assert foreign_log_problem(log) is None
    text = tmp_path / "x.txt"
    text.write_text("hello")
    assert foreign_log_problem(text) is None  # the reader's own error says what is wrong
    assert foreign_log_problem(tmp_path / "missing.mcap") is None


def test_an_sgtool_profile_without_its_metadata_record_says_so(tmp_path):
    """A log a tool rewrote without the 'sgtool' metadata record: the message says what is
    missing (it said "profile 'sgtool' ... not an sgtool log (profile 'sgtool')")."""
    from mcap.reader import make_reader
    from mcap.writer import Writer

    log = write_log(tmp_path / "log.mcap", n=2)
    out = tmp_path / "bare.mcap"
    with open(log, "rb") as f, open(out, "wb") as g:
        r = make_reader(f)
        w = Writer(g)
        w.start(profile="sgtool", library="a tool")
        ids: dict[int, int] = {}
        for schema, channel, message in r.iter_messages():
            if channel.id not in ids:
                sid = w.register_schema(schema.name, schema.encoding, schema.data) \
                    if schema else 0
                ids[channel.id] = w.register_channel(channel.topic, channel.message_encoding,
                                                     sid, channel.metadata)
            w.add_message(ids[channel.id], message.log_time, message.data,
                          message.publish_time)
        w.finish()
    msg = foreign_log_problem(out)
    assert msg is not None and "has the MCAP profile 'sgtool' but no 'sgtool' metadata" in msg
    r2 = CliRunner().invoke(cli, ["replay", str(out)])
    assert r2.exit_code == 2 and "no 'sgtool' metadata record" in r2.output


def test_view_refuses_a_foreign_recording_in_one_line(tmp_path):
    """`sgtool view` of a ROS 2 MCAP (its /tf is CDR, not sgtool's) says what it is, as
    replay does, and writes no recording."""
    bag = tmp_path / "poses"
    write_frames_bag(frames(), bag, "ros2-mcap")
    r = CliRunner().invoke(cli, ["view", str(bag / "poses.mcap"), "-o", str(tmp_path / "v.rrd")])
    assert r.exit_code == 2 and "Traceback" not in r.output
    assert len(r.output.strip().splitlines()) == 1
    assert "is a ROS 2 recording" in r.output and "sgtool import bag" in r.output
    assert sorted(p.name for p in tmp_path.iterdir()) == ["poses"]


def test_diff_refuses_a_foreign_recording_in_one_line(tmp_path):
    """`sgtool diff` of an exported ROS 2 bag and a log says what the bag is (it read the
    bag's std_msgs/String /sgtool/scene_graph topic as a record before)."""
    bag = tmp_path / "cam"
    write_frames_bag(frames(), bag, "ros2-mcap")
    log = write_log(tmp_path / "log.mcap", n=2)
    r = CliRunner().invoke(cli, ["diff", str(bag / "cam.mcap"), str(log)])
    assert r.exit_code == 2 and len(r.output.strip().splitlines()) == 1
    assert "is a ROS 2 recording" in r.output


def _foreign_mcap(path, profile: str = "",  # type: ignore[no-untyped-def]
                  sgtool_metadata: bool = False) -> None:
    """A valid MCAP file another tool might write: /tf as JSON (a foxglove.FrameTransform
    JSON schema) and a foxglove.RawImage in 'uyvy', which sgtool does not decode."""
    import json

    from foxglove_schemas_protobuf.RawImage_pb2 import RawImage
    from mcap.writer import Writer

    from sgtool.log.reader import proto_class

    assert proto_class("foxglove.RawImage") is not None
    with open(path, "wb") as f:
        w = Writer(f)
        w.start(profile=profile, library="another tool")
        tf = w.register_channel("/tf", "json", w.register_schema(
            "foxglove.FrameTransform", "jsonschema", json.dumps({"type": "object"}).encode()))
        from google.protobuf import descriptor_pb2

        fds = descriptor_pb2.FileDescriptorSet()
        RawImage.DESCRIPTOR.file.CopyToProto(fds.file.add())
        from google.protobuf.timestamp_pb2 import Timestamp

        Timestamp.DESCRIPTOR.file.CopyToProto(fds.file.add())
        img = w.register_channel("/front/image", "protobuf", w.register_schema(
            "foxglove.RawImage", "protobuf", fds.SerializeToString()))
        for i in range(3):
            t = 1_000_000_000 + i * 100_000_000
            w.add_message(tf, t, json.dumps({"parent_frame_id": "map", "child_frame_id": "base",
                                             "translation": {"x": i}}).encode(), t)
            raw = RawImage(width=2, height=2, encoding="uyvy", step=4, data=bytes(8))
            w.add_message(img, t, raw.SerializeToString(), t)
        if sgtool_metadata:
            w.add_metadata("sgtool", {"sgtool_version": "0.1.0"})
        w.finish()


def test_doctor_keeps_a_foreign_files_valid_messages(tmp_path):
    """Another tool's /tf (JSON) and a 'uyvy' RawImage are valid MCAP: doctor called the
    file corrupt ("written malformed", sgtool's own reading of /tf applied) and --recover
    dropped them. Only an sgtool log is held to sgtool's reading of its topics."""
    f = tmp_path / "other.mcap"
    _foreign_mcap(f)
    r = CliRunner().invoke(cli, ["doctor", str(f), "--recover", str(tmp_path / "r.mcap")])
    assert r.exit_code == 0, r.output
    assert "complete" in r.output.splitlines()[0]
    assert "readable: 6 messages on 2 channels" in r.output
    from mcap.reader import make_reader

    with open(tmp_path / "r.mcap", "rb") as fh:
        assert sum(1 for _ in make_reader(fh).iter_messages()) == 6
    # the same file calling itself an sgtool log is held to sgtool's reading, by its
    # header's profile or (a header lost and rewritten) by its sgtool metadata record
    for profile, meta in (("sgtool", False), ("", True)):
        own = tmp_path / f"own{profile}.mcap"
        _foreign_mcap(own, profile=profile, sgtool_metadata=meta)
        r = CliRunner().invoke(cli, ["doctor", str(own)])
        assert r.exit_code == 1 and "sgtool reads /tf as protobuf foxglove.FrameTransform" \
            in r.output


def test_pin_of_a_foreign_file_says_what_it_is_and_topics_count_once(tmp_path):
    """golden pin on another tool's file said only that it had no /camera/depth channel;
    two channels on one topic were counted as two topics."""
    from mcap.writer import Writer

    f = tmp_path / "other.mcap"
    with open(f, "wb") as fh:
        w = Writer(fh)
        w.start(profile="", library="another tool")
        a = w.register_channel("/a", "json", w.register_schema("A", "jsonschema", b"{}"))
        b = w.register_channel("/a", "json", w.register_schema("B", "jsonschema", b"{}"))
        w.add_message(a, 1, b"{}", 1)
        w.add_message(b, 2, b"{}", 2)
        w.finish()
    assert "with 1 topic(s) of messages encoded 'json', not an sgtool log" in \
        foreign_log_problem(f)
    r = CliRunner().invoke(cli, ["golden", "pin", str(f), "--dir", str(tmp_path / "g")])
    assert r.exit_code == 2 and "not an sgtool log" in r.output
    assert not (tmp_path / "g").exists()
