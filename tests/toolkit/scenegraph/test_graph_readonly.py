"""A scene graph's distances are read-only: a planner handed the graph that is logged and
handed to the next planner cannot change either in place."""

from __future__ import annotations

import copy
import json
import pickle

import pytest

from sgtool.scenegraph.graph import RobotState, SceneGraph


def test_distances_cannot_be_changed_in_place() -> None:
    g = SceneGraph(RobotState((0.0, 0.0)), distances={"room:0": 1.5})
    for change in (lambda d: d.__setitem__("room:0", 9.0), lambda d: d.update({"x": 1.0}),
                   lambda d: d.pop("room:0"), lambda d: d.clear(),
                   lambda d: d.setdefault("x", 1.0), lambda d: d.__delitem__("room:0"),
                   lambda d: d.popitem()):
        with pytest.raises(TypeError, match="SceneGraph.distances is read-only"):
            change(g.distances)
    assert g.distances == {"room:0": 1.5}
    own = dict(g.distances)  # a copy is the planner's own
    own["room:0"] = 9.0
    assert g.distances["room:0"] == 1.5 and g.distances.copy() == {"room:0": 1.5}


def test_read_only_distances_pickle_copy_and_serialise_as_before() -> None:
    g = SceneGraph(RobotState((0.0, 0.0)), distances={"room:0": 1.5, "obj:2": 0.25})
    assert pickle.loads(pickle.dumps(g)) == g and copy.deepcopy(g) == g
    assert SceneGraph.from_json(g.to_json()) == g
    assert json.loads(json.dumps(g.distances)) == {"room:0": 1.5, "obj:2": 0.25}


def test_a_frozen_graph_hashes() -> None:
    """A planner may key a cache on the graph (it raised: the distances were a dict)."""
    a = SceneGraph(RobotState((0.0, 0.0)), distances={"room:0": 1.5, "obj:2": 0.25})
    b = SceneGraph(RobotState((0.0, 0.0)), distances={"obj:2": 0.25, "room:0": 1.5})
    c = SceneGraph(RobotState((0.0, 0.0)), distances={"room:0": 2.5})
    assert a == b and hash(a) == hash(b) and len({a, b, c}) == 2
