"""The replay's lines about what a third party's log can miss: instance ids without a table
entry, a table without doors, objects that name no spec element (scoring)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from sgtool.replayers.instance_notes import instance_notes
from sgtool.scenegraph.instances import InstanceInfo

TABLE = {1: InstanceInfo(1, "floor", "structure"), 5: InstanceInfo(5, "door", "door"),
         9: InstanceInfo(9, "mug", "object")}


def test_a_complete_table_says_nothing():
    assert instance_notes(np.array([0, 1, 5, 9, -1]), TABLE, rooms=1) == []
    assert instance_notes(np.array([0]), {}, rooms=0) == []  # no ids: nothing to say


def test_ids_without_an_entry_are_counted_and_named():
    (line,) = instance_notes(np.arange(0, 20), TABLE, rooms=2)
    assert line.startswith("16 of 19 instance ids in the images have no entry")
    assert line.endswith(": 2, 3, 4, 6, 7, ... (16 in all)")


def test_no_table_at_all():
    (line,) = instance_notes(np.array([3, 4]), {}, rooms=1)
    assert "2 instance ids but the log has no instance table" in line


def test_no_door_is_said_only_when_the_graph_is_one_room():
    table = {k: v for k, v in TABLE.items() if v.kind != "door"}
    assert instance_notes(np.array([1, 9]), table, rooms=3) == []  # open plan: fine
    (line,) = instance_notes(np.array([1, 9]), table, rooms=1)
    assert line.startswith("one room: the instance table names no door")


def test_a_score_without_scorable_objects_says_so():
    """Objects none of which name a spec element are "not scored", not 0 % of 0."""
    from sgtool.replayers.score import score_dict, score_lines
    from sgtool.scenegraph.quality import Quality

    def q(objects: int) -> Quality:
        return Quality(gt_rooms=3, gt_rooms_seen=3, rooms=3, room_count_error=0, purity=1.0,
                       ari=1.0, objects=objects, object_accuracy=1.0 if objects else 0.0,
                       categorised=3, category_accuracy=1.0)

    none, some = score_lines({"strict": q(0), "merged": q(9)})
    assert "objects not scored (no object's instance names a spec element" in none
    assert "objects in the right room 100.0% of 9" in some
    # a graph without objects has nothing to score, for no fault of the instance table
    empty, _ = score_lines({"strict": q(0), "merged": q(9)}, graph_objects=0)
    assert "no object in the graph to score" in empty and "spec_id" not in empty
    # --json: an accuracy over nothing is null, not 0
    d = score_dict({"strict": q(0), "merged": q(9)})
    assert d["strict"]["object_accuracy"] is None and d["merged"]["object_accuracy"] == 1.0


def test_a_score_says_how_much_of_the_house_the_graph_saw(tmp_path):
    """A tour that never reached half the house scored its objects 100 % over what it saw,
    saying nothing of the rest: the score names the pieces of the house the graph holds."""
    import json

    from click.testing import CliRunner

    from sgtool.cli import cli

    log = Path(__file__).resolve().parents[1] / "golden" / "house6-tour.mcap"
    r = CliRunner().invoke(cli, ["replay", str(log), "--score", "--json", "--max-frames", "40"])
    assert r.exit_code == 0, r.output
    merged = json.loads(r.output)["score"]["merged"]
    assert 0 < merged["objects_seen"] < merged["house_objects"]
    r = CliRunner().invoke(cli, ["replay", str(log), "--score", "--max-frames", "40"])
    assert (f"({merged['objects_seen']} of the house's {merged['house_objects']} pieces "
            "seen)") in r.output
