"""`sgtool import bag --ids TOPIC --instances FILE`: a bag with instance-id images and a
table of what each id stands for replays into the scene graph the recording it came from
gave; without the table the ids are imported and a replay builds geometry only; a bad
table is one line and no output."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from click.testing import CliRunner
from support.bag_export import write_log_as_bag
from support.paths import GOLDEN

from sgtool.cli import cli
from sgtool.log import LogReader
from sgtool.replayers.derived_log import replay

TOUR = GOLDEN / "house6-tour.mcap"
TOPICS = ["--depth", "/camera/depth/image_raw", "--rgb", "/camera/rgb/image_raw",
          "--info", "/camera/depth/camera_info", "--up", "z", "--floor", "none", "--quiet"]
IDS = ["--ids", "/camera/instances/image_raw"]


@pytest.fixture(scope="module")
def bag(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    """The golden tour as a ROS 2 bag, and its first instance table as a file (what a lab's
    segmenter would give: every id with its category and kind)."""
    root = tmp_path_factory.mktemp("instances")
    out = root / "tour_bag"
    write_log_as_bag(TOUR, out)
    with LogReader(TOUR) as r:
        first = next(d for _, d in r.records("instances"))
    table = root / "table.json"
    table.write_text(json.dumps(first))
    return {"bag": out, "table": table, "root": root}


def final_graph(log: Path):  # noqa: ANN201
    last = {}
    replay(log, None, on_refresh=lambda ref, _s: last.update(graph=ref.graph))
    return last["graph"]


def imported(bag: dict[str, Path], name: str, *extra: str) -> tuple[int, str, Path]:
    out = bag["root"] / name
    r = CliRunner().invoke(cli, ["import", "bag", str(bag["bag"]), *TOPICS, *extra,
                                 "-o", str(out)])
    return r.exit_code, r.output, out


def test_a_bag_with_its_table_replays_into_the_recordings_objects(bag):
    code, output, out = imported(bag, "with.mcap", *IDS, "--instances", str(bag["table"]))
    assert code == 0, output
    with LogReader(out) as r:
        tables = [d for _, d in r.records("instances")]
        first_frame = r.frame_times()[0]
        assert [t for t, _ in r.records("instances")] == [first_frame]
    assert tables == [json.loads(bag["table"].read_text())]
    original, back = final_graph(TOUR), final_graph(out)
    ours = sorted(o.instance for o in back.objects)
    assert ours and ours == sorted(o.instance for o in original.objects)
    assert sorted(o.category for o in back.objects) == \
        sorted(o.category for o in original.objects)


def test_without_the_table_the_ids_are_kept_and_no_object_is_built(bag):
    code, output, out = imported(bag, "without.mcap", *IDS)
    assert code == 0, output
    with LogReader(out) as r:
        assert not list(r.records("instances"))
        assert next(iter(r.frames())).ids is not None
    assert final_graph(out).objects == ()


def test_ids_the_table_does_not_list_are_a_note(bag):
    doc = json.loads(bag["table"].read_text())
    kept = [i for i in doc["instances"] if i["kind"] != "object"]
    part = bag["root"] / "part.json"
    part.write_text(json.dumps(kept))  # the items alone are a table too
    code, output, out = imported(bag, "part.mcap", *IDS, "--instances", str(part))
    assert code == 0, output
    dropped = len(doc["instances"]) - len(kept)
    assert "instance id(s) in the id images are not in the instance table" in output
    with LogReader(out) as r:
        ended = r.last_record("episode")
    note = next(n for n in ended["extra"]["notes"] if "not in the instance table" in n)
    assert 0 < int(note.split()[0]) <= dropped


@pytest.mark.parametrize(("text", "says"), [
    ("{", "not JSON"),
    ('{"instances": [{"id": 1, "category": "chair"}]}', "kind"),
    ('{"instances": [{"id": 1, "category": "chair", "kind": "sofa"}]}', "kind"),
    ('{"instances": [{"id": 1, "category": "a", "kind": "object"}, '
     '{"id": 1, "category": "b", "kind": "object"}]}', "instances[1].id"),
    ('{"instances": []}', "lists no instance"),
])
def test_a_bad_table_is_one_line_and_no_output(bag, text, says):
    bad = bag["root"] / "bad.json"
    bad.write_text(text)
    code, output, out = imported(bag, "bad.mcap", *IDS, "--instances", str(bad))
    assert code != 0
    assert says in output and "Traceback" not in output
    assert len(output.strip().splitlines()) == 1
    assert not out.exists()


def test_a_table_without_ids_is_refused(bag):
    code, output, out = imported(bag, "noids.mcap", "--instances", str(bag["table"]))
    assert code != 0 and "--ids TOPIC" in output
    assert not out.exists()
