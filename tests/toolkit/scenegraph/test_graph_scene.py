"""Foxglove sees the scene graph: a derived log's ``/map/graph`` SceneUpdate decodes with
mcap-protobuf-support against Foxglove's schema and holds one entity per object, door and
frontier with its metadata, plus the edges; the recorder's instance ids are 16UC1 (an
encoding Foxglove's Image panel shows) when they fit, 32SC1 otherwise, exact either way."""

from __future__ import annotations

import numpy as np
import pytest
from mcap.reader import make_reader
from mcap_protobuf.decoder import DecoderFactory
from support.paths import GOLDEN

from sgtool.log import LogReader, codec
from sgtool.log import schemas as S
from sgtool.recorders.sim.recording import instance_image
from sgtool.replayers.derived_log import ReplayOptions, replay
from sgtool.scenegraph.graph_scene import graph_scene_update


def test_derived_log_has_graph_entities_with_metadata(tmp_path):
    derived = tmp_path / "derived.mcap"
    replay(GOLDEN / "house10-start.mcap", derived, ReplayOptions(max_frames=40))
    with LogReader(derived) as r:
        graphs = list(r.records("scene_graph"))
    with open(derived, "rb") as fh:
        updates = [(msg.log_time, proto) for _, ch, msg, proto in make_reader(
            fh, decoder_factories=[DecoderFactory()]).iter_decoded_messages(
            topics=[S.GRAPH_SCENE])]
    assert len(updates) == len(graphs) >= 2
    (t, graph), (tu, upd) = graphs[-1], updates[-1]
    assert t == tu and type(upd).DESCRIPTOR.full_name == "foxglove.SceneUpdate"
    ents = {e.id: e for e in upd.entities}
    assert upd.deletions[0].type == upd.deletions[0].ALL
    objs = graph["objects"]
    assert objs and {o["id"] for o in objs} <= set(ents)
    o = objs[0]
    meta = {kv.key: kv.value for kv in ents[o["id"]].metadata}
    assert meta["category"] == o["category"] and meta["room"] == str(o["room"])
    assert len(ents[o["id"]].cubes) == 1
    assert ents[o["id"]].cubes[0].pose.position.x == pytest.approx(o["position"][0])
    for d in graph["doors"]:
        assert {kv.key: kv.value for kv in ents[d["id"]].metadata}["state"] == d["state"]
    frontiers = [x for x in graph["regions"] if x["kind"] == "frontier"]
    assert {f["id"] for f in frontiers} <= set(ents)
    assert len(ents["edges"].lines[0].points) % 2 == 0 and ents["edges"].lines[0].points


def test_edges_join_objects_to_parents_and_doors_to_rooms():
    graph = {"rooms": [{"id": "room:1", "position": [0.0, 0.0]}],
             "regions": [{"id": "region:1.1", "kind": "region", "position": [1.0, 0.0]}],
             "objects": [{"id": "obj:3", "category": "cabinet", "room": "room:1",
                          "parent": "region:1.1", "position": [1.0, 1.0, 0.5]},
                         {"id": "obj:4", "category": "apple", "room": "room:1",
                          "parent": "obj:3", "position": [1.0, 1.0, 0.9], "state": None}],
             "doors": [{"id": "door:5", "position": [2.0, 0.0], "rooms": ["room:1", "room:9"],
                        "state": "closed"}]}
    upd = graph_scene_update(2_500_000_000, graph)
    pts = [(p.x, p.y, p.z) for p in upd.entities[-1].lines[0].points]
    # obj:3 -> region:1.1, obj:4 -> obj:3, door:5 -> room:1 (room:9 is not in the graph)
    assert pts == [(1, 1, 0.5), (1, 0, 0.05), (1, 1, 0.9), (1, 1, 0.5), (2, 0, 0.05),
                   (0, 0, 1.5)]
    assert [e.id for e in upd.entities] == ["obj:3", "obj:4", "door:5", "edges"]
    assert upd.entities[0].timestamp.seconds == 2 and upd.entities[0].timestamp.nanos == 5e8


@pytest.mark.parametrize(("top", "encoding"), [(65535, "16UC1"), (65536, "32SC1")])
def test_instance_ids_are_16_bit_when_they_fit(top, encoding):
    ids = np.array([[0, 3], [7, top]], np.int32)
    msg = instance_image(0, ids)
    assert msg.encoding == encoding
    assert np.array_equal(codec.decode_image(msg, np.int32), ids)
