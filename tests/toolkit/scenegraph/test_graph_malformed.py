"""A scene graph that is not one sgtool wrote (a log of another writer, a hand-edited JSON
file) is one ArgumentError line (a ValueError and an SgtoolError) naming what is wrong,
in Python and in `sgtool diff`; before, KeyError: 'robot' and a traceback."""

from __future__ import annotations

import pytest
from click.testing import CliRunner

import sgtool
from sgtool.cli import cli
from sgtool.errors import ArgumentError, SgtoolError
from sgtool.scenegraph.graph import SceneGraph


@pytest.mark.parametrize(("given", "message"), [
    ({"version": "1.0"}, "scene graph: field 'robot' missing"),
    ("{}", "scene graph: a JSON object, got str"),
    ({"version": "9.0"}, "scene graph version 9.0 is not readable"),
    # a node's fault names the node: which list, which item, its id when it has one
    ({"version": "1.0", "robot": {"position": [0, 0]}, "objects": [
        {"id": "object:1", "category": "cup", "parent": "room:0", "room": "room:0",
         "position": [0, 0, 0]},
        {"id": "object:2", "category": "mug", "parent": "room:0", "position": [1, 0, 0]}]},
     r"^scene graph: objects\[1\] \('object:2'\): field 'room' missing$"),
    ({"version": "1.0", "robot": {"position": [0, 0]}, "doors": [7]},
     r"^scene graph: doors\[0\]: 'int' object is not subscriptable$"),
])
def test_from_dict_names_what_is_wrong(given, message) -> None:
    with pytest.raises(ArgumentError, match=message) as e:
        SceneGraph.from_dict(given)
    assert isinstance(e.value, ValueError) and isinstance(e.value, SgtoolError)


def test_from_json_of_text_that_is_no_json() -> None:
    with pytest.raises(ArgumentError, match=r"scene graph: not JSON \("):
        SceneGraph.from_json("garbage")


def test_diff_of_a_log_with_a_foreign_scene_graph_is_one_line(tmp_path) -> None:
    out = tmp_path / "bad.mcap"
    with sgtool.LogWriter(out, seed=1) as w:
        w.write_record(sgtool.EpisodeRecord(kind="search", status="started", query="mug"), 0)
        w.write_record("scene_graph", 10**9, {"version": "1.0", "rooms": [{"id": "room:0"}],
                                              "objects": []})
    r = CliRunner().invoke(cli, ["diff", str(out), str(out)])
    assert r.exit_code == 2, r.output
    assert f"{out}: scene graph record at 1000000000 ns: scene graph: field 'robot' missing" \
        in r.output
    assert "Traceback" not in r.output
