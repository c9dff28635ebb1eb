"""Crafted logs (tests/support/crafted_logs.py) validated like the files they came from:
the house attachment through the house validator, instance tables in range, channels of
sgtool's topics with the schema and encoding sgtool reads them with, poses within range;
each a one-line error naming what is wrong, never a traceback or a silently empty graph."""

from __future__ import annotations

import re
import warnings

import pytest
from support.crafted_logs import CRAFTS, INSTANCES, write

from sgtool.errors import LogFormatError, SgtoolError, SpecError
from sgtool.log import LogReader
from sgtool.log.inspect import summarize
from sgtool.log.records import INSTANCE_ID_MAX, Instances
from sgtool.replayers.derived_log import ReplayOptions, replay

OPTS = ReplayOptions(every=100, voxel_size=0.2)


def _one_line(e: pytest.ExceptionInfo, *words: str) -> str:
    text = str(e.value)
    assert "\n" not in text and len(text) < 400, text
    for w in words:
        assert w in text, (w, text)
    return text


@pytest.mark.parametrize("craft, words", [
    ("house-not-json", ["house.json", "not valid JSON"]),
    ("house-deep", ["house.json", "nested too deeply"]),
    ("house-not-utf8", ["house.json", "UTF-8"]),
    ("house-invalid", ["house.json", "rooms"]),
])
def test_the_house_attachment_goes_through_the_house_validator(craft, words, tmp_path):
    log = CRAFTS[craft](tmp_path / "log.mcap")
    with LogReader(log) as r, pytest.raises(SpecError) as e:
        r.house_spec()
    _one_line(e, str(log), *words)


def test_a_valid_house_attachment_and_none(tmp_path):
    with LogReader(CRAFTS["valid"](tmp_path / "a.mcap")) as r:
        spec = r.house_spec()
    assert spec is not None and len(spec.rooms) == 2  # the small house: two rooms
    with LogReader(CRAFTS["no-house"](tmp_path / "b.mcap")) as r:
        assert r.house_spec() is None


@pytest.mark.parametrize("craft, field, words", [
    ("instance-id-2^70", "id", ["1.18059e+21", str(INSTANCE_ID_MAX)]),
    ("instance-id-negative", "id", ["-4"]),
    ("instance-id-0", "id", ["is 0"]),
    ("instance-id-twice", "id", ["given twice"]),
    ("instance-parent-2^40", "parent", ["1099511627776"]),
    ("instance-empty-category", "category", ["empty"]),
    ("instance-bad-state", "state", ["ajar"]),
])
def test_instance_entries_out_of_range_are_refused_naming_the_entry(craft, field, words,
                                                                      tmp_path):
    """An id of 2^70 used to replay to an empty scene graph with no warning."""
    log = CRAFTS[craft](tmp_path / "log.mcap")
    for fn in (lambda: replay(log, None, OPTS), lambda: summarize(log)):
        with pytest.raises(LogFormatError) as e:
            fn()
        _one_line(e, "/sgtool/instances", f"instances[3].{field}", *words)


def test_instance_ids_at_the_ends_of_the_range_are_accepted():
    items = [{"id": 1, "category": "a", "kind": "object"},
             {"id": INSTANCE_ID_MAX, "category": "b", "kind": "object", "parent": 1}]
    rec = Instances.from_json({"instances": items})
    assert [i.id for i in rec.instances] == [1, INSTANCE_ID_MAX]
    with pytest.raises(LogFormatError, match="instances.1..id"):
        Instances.from_json({"instances": [items[0], {**items[1], "id": INSTANCE_ID_MAX + 1}]})


@pytest.mark.parametrize("craft, topic, words", [
    ("depth-cdr", "/camera/depth", ["'cdr'", "sensor_msgs/msg/Image", "foxglove.RawImage"]),
    ("depth-no-schema", "/camera/depth", ["'protobuf'", "no schema"]),
    ("depth-json", "/camera/depth", ["'json'"]),
    ("tf-wrong-schema", "/tf", ["foxglove.RawImage", "foxglove.FrameTransform"]),
    ("calibration-cdr", "/camera/calibration", ["'cdr'"]),
])
def test_a_channel_with_another_schema_or_encoding_is_one_line(craft, topic, words,
                                                               tmp_path):
    """A depth channel in CDR or without a schema used to raise AttributeError in the
    codec (replay, view)."""
    log = CRAFTS[craft](tmp_path / "log.mcap")
    with pytest.raises(LogFormatError) as e:
        replay(log, None, OPTS)
    _one_line(e, f"channel {topic}", *words)
    with pytest.raises(LogFormatError) as e, LogReader(log) as r:
        list(r.frames())
    _one_line(e, f"channel {topic}", *words)


@pytest.mark.parametrize("craft", ["tf-huge", "valid", "tf-huge-quaternion"])
def test_a_huge_translation_is_one_clean_line(craft, tmp_path):
    """A 1e300 translation used to print numpy RuntimeWarnings and a 300-digit number."""
    log = CRAFTS[craft](tmp_path / "log.mcap")
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a RuntimeWarning fails the test
        if craft != "tf-huge":  # a quaternion of 1e200s is a rotation once normalised
            assert replay(log, None, OPTS).frames == 3
            return
        with pytest.raises(SgtoolError) as e:
            replay(log, None, OPTS)
    text = _one_line(e, "/tf", "translation", "1e+300")
    assert not re.search(r"\d{16}", text), text


def test_the_crafted_control_is_read_whole(tmp_path):
    log = write(tmp_path / "log.mcap")
    with LogReader(log) as r:
        assert len(list(r.frames())) == 3
        assert len(r.last_record(Instances).instances) == len(INSTANCES)


@pytest.mark.parametrize("craft, words", [
    ("house-not-json", "not valid JSON"), ("house-deep", "JSON nested too deeply")])
def test_replay_score_refuses_a_bad_house_attachment_in_one_line(craft, words, tmp_path):
    """`sgtool replay --score` used to raise JSONDecodeError / RecursionError."""
    from click.testing import CliRunner

    from sgtool.cli import cli

    log = CRAFTS[craft](tmp_path / "log.mcap")
    res = CliRunner().invoke(cli, ["replay", str(log), "--score", "--every", "100",
                                   "--voxel-size", "0.2", "--no-progress"])
    assert res.exit_code == 2, res.output
    assert "Traceback" not in res.output
    assert f"attachment house.json: {words}" in res.output
