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


@pytest.mark.parametrize(("edit", "message"), [
    (lambda d: d["objects"][0].__setitem__("position", "abc"),
     r"^scene graph: objects\[0\] \('obj:1'\): position 'abc': give 3 numbers$"),
    (lambda d: d["robot"].__setitem__("position", [0, "x"]),
     r"^scene graph: robot.position: 'x' is not a finite number$"),
    (lambda d: d["distances"].__setitem__("obj:1", float("nan")),
     r"^scene graph: distances\['obj:1'\]: nan is not a finite number$"),
])
def test_from_dict_refuses_positions_and_distances_that_are_no_numbers(edit, message) -> None:
    """A hand-made graph with a position of text or a NaN distance was taken and failed
    later, in to_json() or a planner, with a bare ValueError."""
    d = {"version": "1.0", "robot": {"position": [0, 0]}, "distances": {"obj:1": 1.0},
         "objects": [{"id": "obj:1", "category": "cup", "parent": "region:0.1",
                      "room": "room:0", "position": [0, 0, 0]}]}
    edit(d)
    with pytest.raises(ArgumentError, match=message):
        SceneGraph.from_dict(d)


def test_from_dict_takes_numpy_positions() -> None:
    """Another lab's graph turned into sgtool's form in Python: positions as numpy arrays
    are numbers too."""
    import numpy as np

    g = SceneGraph.from_dict({"version": "1.0", "robot": {"position": np.zeros(2)},
                              "objects": [{"id": "obj:1", "category": "cup",
                                           "parent": "region:0.1", "room": "room:0",
                                           "position": np.array([1.0, 2.0, 0.5])}]})
    assert g.objects[0].position == (1.0, 2.0, 0.5)
    assert SceneGraph.from_json(g.to_json()) == g
