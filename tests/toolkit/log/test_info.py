"""`sgtool info` and `sgtool doctor` on sgtool logs and on real ROS 2 MCAP recordings."""

from __future__ import annotations

import json
import shutil

import pytest
from click.testing import CliRunner
from support.logfixtures import write_log

from sgtool.cli import cli

ROS2_FILES = {
    # file: {topic: message count}, as `ros2 bag info` lists them
    "talker.mcap": {"/topic": 10, "/rosout": 10, "/parameter_events": 0},
    "evo_nav2_turtlebot.mcap": {"/odom": 2639, "/tf": 5422, "/tf_static": 1, "/amcl_pose": 135},
    "cdr_test_0.mcap": {"/test_topic": 3, "/array_topic": 4},
    "rewriter_b_0.mcap": {"a_empty": 25, "c_strings": 50},
    "only_topics.mcap": {"/rosout": 0, "/parameter_events": 7, "/events/write_split": 0},
}


def test_info_on_sgtool_log(tmp_path):
    path = write_log(tmp_path / "run.mcap")
    r = CliRunner().invoke(cli, ["info", str(path)])
    assert r.exit_code == 0, r.output
    assert "schema version 1.2" in r.output and "frames 12" in r.output
    assert "/camera/rgb" in r.output and "foxglove.RawImage" in r.output
    assert "episode: kind=recording, status=ended" in r.output
    j = json.loads(CliRunner().invoke(cli, ["info", "--json", str(path)]).output)
    assert j["frames"] == 12 and j["log_schema_version"] == "1.2" and j["seed"] == 7
    counts = {c["topic"]: c["messages"] for c in j["channels"]}
    assert counts["/camera/depth"] == 12 and counts["/tf"] == 24
    assert j["camera"] == {"width": 64, "height": 48, "fx": pytest.approx(41.569, abs=1e-3),
                           "fy": pytest.approx(41.569, abs=1e-3)}
    assert j["attachments"][0]["name"] == "house.json"


def test_info_names_truncation(tmp_path):
    path = write_log(tmp_path / "run.mcap")
    data = path.read_bytes()
    cut = tmp_path / "cut.mcap"
    cut.write_bytes(data[: len(data) // 2])
    r = CliRunner().invoke(cli, ["info", str(cut)])
    assert r.exit_code == 2
    assert "sgtool doctor" in r.output and "Traceback" not in r.output


@pytest.mark.parametrize("name", sorted(ROS2_FILES))
def test_info_and_doctor_on_real_ros2_mcap(shared_data_dir, tmp_path, name):
    src = shared_data_dir / "logs" / "rosbag2-mcap" / name
    if not src.exists():
        pytest.skip(f"{src} is absent")
    r = CliRunner().invoke(cli, ["info", "--json", str(src)])
    assert r.exit_code == 0, r.output
    j = json.loads(r.output)
    assert j["sgtool_log"] is False and j["profile"] == "ros2"
    counts = {c["topic"]: c["messages"] for c in j["channels"]}
    assert counts == ROS2_FILES[name]
    assert all(c["message_encoding"] == "cdr" for c in j["channels"])
    text = CliRunner().invoke(cli, ["info", str(src)]).output
    assert "foreign MCAP file" in text
    # doctor: a complete file, all messages readable; recovery gives an equivalent file
    local = tmp_path / name
    shutil.copy(src, local)
    r = CliRunner().invoke(cli, ["doctor", "--json", str(local), "--recover",
                                 str(tmp_path / "out.mcap")])
    assert r.exit_code == 0, r.output
    d = json.loads(r.output)
    # complete where the writer wrote chunk CRCs; unverified (nothing wrong, nothing to
    # check message bytes against) where it wrote none
    crcs = d["checks"]["chunks"] != "no CRCs written"
    assert d["status"] == ("complete" if crcs else "unverified")
    assert d["readable_messages"] == sum(counts.values())
    j2 = json.loads(CliRunner().invoke(cli, ["info", "--json", str(tmp_path / "out.mcap")]).output)
    assert {c["topic"]: c["messages"] for c in j2["channels"]} == counts


def test_info_warns_of_frames_that_share_a_time(tmp_path):
    """Depth images at one log time (written below write_frame, which refuses them): info
    says so, since replay refuses such a log; a log without them says nothing."""
    from support.logfixtures import synthetic_frame

    from sgtool.log import LogWriter

    k, _, depth, _, pose, _ = synthetic_frame(0)
    with LogWriter(tmp_path / "dup.mcap", seed=1) as w:
        w.write_frame(0, depth=depth, pose=pose, intrinsics=k)
        w.write_depth(0, depth)
        w.write_frame(10**8, depth=depth, pose=pose, intrinsics=k)
    r = CliRunner().invoke(cli, ["info", str(tmp_path / "dup.mcap")])
    assert r.exit_code == 0 and ("warning: 1 depth image(s) share a log time with another: "
                                 "replay refuses such a log") in r.output
    r = CliRunner().invoke(cli, ["info", str(tmp_path / "dup.mcap"), "--json"])
    assert json.loads(r.output)["repeated_frame_times"] == 1
    r = CliRunner().invoke(cli, ["info", str(write_log(tmp_path / "ok.mcap"))])
    assert "share a log time" not in r.output


@pytest.mark.parametrize("command", ["info", "doctor"])
def test_a_bag_is_told_how_to_import(tmp_path, command):
    """info and doctor on a ROS 1 bag say what it is and the import command, as replay
    does, not only "not an MCAP file"."""
    bag = tmp_path / "run.bag"
    bag.write_bytes(b"#ROSBAG V2.0\n" + bytes(64))
    r = CliRunner().invoke(cli, [command, str(bag)])
    assert r.exit_code == 2
    assert "is a ROS 1 bag, not an sgtool log" in r.output and "sgtool import bag" in r.output


def test_scenes_show_never_draws_over_its_house(tmp_path):
    from sgtool.datasets.generator import generate_house
    from sgtool.house.io import save_house

    house = tmp_path / "h.png"  # a house file under an image's name
    save_house(generate_house(3, rooms=(4, 4)), house)
    before = house.read_bytes()
    r = CliRunner().invoke(cli, ["scenes", "show", str(house), "--force"])
    assert r.exit_code == 2 and "would replace the house file" in r.output
    assert house.read_bytes() == before


def test_info_leaves_out_a_seed_the_log_has_none_of(tmp_path):
    """An imported log has no seed: info says nothing of one, never "seed None"."""
    from sgtool.log import LogWriter

    out = tmp_path / "imported.mcap"
    with LogWriter(out) as w:
        w.write_record("episode", 0, {"kind": "import", "status": "started", "frames": 0})
    r = CliRunner().invoke(cli, ["info", str(out)])
    assert r.exit_code == 0, r.output
    assert "None" not in r.output


def test_info_shows_what_the_import_warned_of(tmp_path):
    """An import's warnings are kept in the log's sgtool.import metadata; info showed them
    only with --json."""
    from support.logfixtures import synthetic_frame

    from sgtool.log import LogWriter
    from sgtool.log.inspect import format_summary, summarize
    from sgtool.log.schemas import IMPORT_METADATA_NAME

    log = tmp_path / "imported.mcap"
    with LogWriter(log, seed=0) as w:
        w.add_metadata(IMPORT_METADATA_NAME, {"source": "x", "warnings": "first\nsecond"})
        k, rgb, depth, ids, pose, base = synthetic_frame(0)
        w.write_frame(0, rgb=rgb, depth=depth, ids=ids, pose=pose, intrinsics=k)
    text = format_summary(summarize(log))
    assert "import warning: first\nimport warning: second" in text
