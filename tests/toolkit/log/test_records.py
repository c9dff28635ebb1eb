"""Typed log records (sgtool.log.records): round trips, checks on write and on read."""

from __future__ import annotations

import json
import re

import pytest

from sgtool.errors import LogFormatError
from sgtool.log import LogReader, LogWriter
from sgtool.log import schemas as S
from sgtool.log.records import (
    ABSENT,
    RECORD_TYPES,
    Action,
    Episode,
    InstanceItem,
    Instances,
    LlmExchange,
    SceneGraphRecord,
)
from sgtool.scenegraph.graph import RobotState, RoomNode, SceneGraph

GRAPH = SceneGraph(robot=RobotState(position=(1.0, 2.0), room="room:0"),
                   rooms=(RoomNode(id="room:0", category="kitchen", position=(0.5, 0.5),
                                   explored=True),),
                   distances={"room:0": 1.25})

SAMPLES = [
    Episode(kind="search", status="started", source="pybullet", house_id="house-1",
            query="cup", planner="scout", steps=0, travelled_m=0.0, shortest_m=None,
            frames=0, extra={"mapping": {"every": 10}, "hidden": True, "list": [1, 2]}),
    Episode(kind="import", status="ended", source="", frames=3),
    Action(skill="look_around", outcome="success", target=None, reason="", travelled_m=0.0,
           decision_time_s=0.0, planner=None, step=0, graph_time_ns=None),
    Action(skill="explore", outcome="failure", target="room:1", graph_time_ns=10),
    Action(skill="done", outcome="success"),
    Action(skill="navigate", outcome="success", target="room:0", graph_time_ns=10,
           view_distances={"room:0": 2.5, "obj:3": 0.75}),
    Instances((InstanceItem(id=1, category="fridge", kind="furniture", state="closed",
                            affordances=("container", "openable"), parent=None,
                            relation=None, synset="fridge.n.01", spec_id="f0"),
               InstanceItem(id=2, category="cup", kind="object", parent=1,
                            relation="inside"))),
    SceneGraphRecord.of_graph(GRAPH),
    LlmExchange(model="m", messages=({"role": "user", "content": "hi"},),
                prompt_sha256="abc", response=None, latency_s=0.5, prompt_tokens=None,
                completion_tokens=3, error="HTTP 500", attempt=1, step=None, query="cup",
                source="endpoint"),
]


@pytest.mark.parametrize("record", SAMPLES, ids=lambda r: type(r).__name__)
def test_round_trip(record) -> None:
    d = record.to_json()
    assert type(record).from_json(d) == record
    assert type(record).from_json(json.loads(json.dumps(d))).to_json() == d


def test_every_json_channel_has_a_record_type_matching_its_schema() -> None:
    assert set(RECORD_TYPES) == set(S.RECORDS)
    for kind, rtype in RECORD_TYPES.items():
        schema = S.RECORDS[kind].schema
        names = {f for f in rtype.__dataclass_fields__ if f != "unknown"}
        assert set(schema["properties"]) <= names, kind
        assert rtype.channel() is S.RECORDS[kind]


def test_absent_and_null_differ_and_unknown_keys_survive() -> None:
    a = Action.from_json({"skill": "done", "outcome": "success"})
    b = Action.from_json({"skill": "done", "outcome": "success", "graph_time_ns": None})
    assert a.graph_time_ns is ABSENT and a.decided
    assert b.graph_time_ns is None and not b.decided
    assert "graph_time_ns" not in a.to_json() and b.to_json()["graph_time_ns"] is None
    future = {"skill": "done", "outcome": "success", "confidence": 0.9}
    assert Action.from_json(future).to_json() == future


def test_an_action_shows_the_graph_with_the_distances_the_planner_saw() -> None:
    """``view_distances`` replace the logged graph's distances (written rounded, keys
    sorted); without them the logged graph is what was shown."""
    a = Action(skill="navigate", outcome="success", target="room:0",
               view_distances={"room:0": 2.123456, "obj:9": 1.0})
    assert a.to_json()["view_distances"] == {"obj:9": 1.0, "room:0": 2.1235}
    shown = Action.from_json(a.to_json()).shown(GRAPH)
    assert shown.distances == {"obj:9": 1.0, "room:0": 2.1235}
    assert shown.rooms == GRAPH.rooms and shown.robot == GRAPH.robot
    assert Action(skill="done", outcome="success").shown(GRAPH) is GRAPH


def test_the_graph_record_is_the_graph_json() -> None:
    rec = SceneGraphRecord.of_graph(GRAPH)
    assert json.dumps(rec.to_json(), sort_keys=True, separators=(",", ":")) == GRAPH.to_json()
    assert rec.graph() == GRAPH


def test_typed_write_is_byte_identical_to_the_dict_write(tmp_path) -> None:
    def write(path, typed: bool) -> bytes:
        with LogWriter(path) as w:
            for i, r in enumerate(SAMPLES):
                if typed:
                    w.write_record(r, i)
                else:
                    w.write_record(r.KIND, i, r.to_json())
        return path.read_bytes()

    assert write(tmp_path / "a.mcap", True) == write(tmp_path / "b.mcap", False)
    with LogReader(tmp_path / "a.mcap") as r:
        assert [rec for _, rec in r.records(Action)] == [s for s in SAMPLES
                                                         if isinstance(s, Action)]
        assert r.last_record(Episode) == SAMPLES[1]
        assert r.last_record("episode") == SAMPLES[1].to_json()


@pytest.mark.parametrize("record, field", [
    (Action(skill="navigate", outcome="success", travelled_m="far"), "travelled_m"),
    (Action(skill="navigate", outcome="maybe"), "outcome"),
    (Action(skill="navigate", outcome="success", view_distances={"room:0": "far"}),
     "view_distances.room:0"),
    (Episode(kind="search", status="started", steps=1.5), "steps"),
    (Instances((InstanceItem(id=1, category="cup", kind="thing"),)), "instances[0].kind"),
    (LlmExchange(model="m", messages=({"role": "user", "content": "x"},), attempt=True),
     "attempt"),
])
def test_a_wrong_type_is_refused_on_write(tmp_path, record, field) -> None:
    with LogWriter(tmp_path / "x.mcap") as w, \
            pytest.raises(LogFormatError,
                          match=re.escape(record.channel().topic) + ".*" + re.escape(f"'{field}'")):
        w.write_record(record, 5)


@pytest.mark.parametrize("record, field, why", [
    (Action(skill="navigate", outcome="success", travelled_m=float("nan")), "travelled_m",
     "NaN and infinity are no JSON numbers"),
    (Episode(kind="search", status="success", travelled_m=float("inf")), "travelled_m",
     "NaN and infinity"),
    (Episode(kind="search", status="success", travelled_m=-1.0), "travelled_m",
     "a distance is never negative"),
    (Episode(kind="search", status="success", shortest_m=-2.0), "shortest_m", "negative"),
    (Episode(kind="search", status="started", extra={"score": float("nan")}), "extra.score",
     "NaN"),
])
def test_a_number_the_reader_would_refuse_is_refused_on_write(tmp_path, record, field,
                                                              why) -> None:
    """What a log must not hold (NaN or infinity is no JSON; a negative distance is read
    as a broken episode and dropped) is refused when written, naming the field, and the
    log written so far stays readable."""
    path = tmp_path / "x.mcap"
    with LogWriter(path) as w:
        with pytest.raises(LogFormatError, match=re.escape(f"'{field}'") + ".*" + why):
            w.write_record(record, 5)
        w.write_record(Episode(kind="search", status="started"), 6)
    with LogReader(path) as r:
        assert [e.status for _, e in r.records(Episode)] == ["started"]


def test_a_missing_field_is_refused_on_write(tmp_path) -> None:
    with LogWriter(tmp_path / "x.mcap") as w, pytest.raises(LogFormatError, match="'status'"):
        w.write_record("episode", 0, {"kind": "search"})


def _raw_log(path, kind: str, messages: list[tuple[int, bytes]]) -> None:
    """A log whose records on ``kind``'s channel are the given raw bytes (unchecked: the
    writer's private channel API, as a damaged or foreign writer would write them)."""
    with LogWriter(path) as w:
        for t, data in messages:
            w._add(w._json_channel(S.RECORDS[kind]), t, data)


@pytest.mark.parametrize("kind, bad, field", [
    ("action", {"skill": "open", "outcome": "success", "travelled_m": "1.0"}, "travelled_m"),
    ("action", {"skill": "open"}, "outcome"),
    ("episode", {"kind": "search", "status": "ended", "frames": "3"}, "frames"),
    ("instances", {"instances": [{"id": 1, "category": "cup"}]}, "instances[0].kind"),
    ("scene_graph", {"rooms": []}, "version"),
    ("llm_exchange", {"model": "m", "messages": [], "step": "4"}, "step"),
])
def test_a_bad_record_in_a_log_names_channel_record_and_field(tmp_path, kind, bad,
                                                              field) -> None:
    good = RECORD_TYPES[kind].from_json(
        {"episode": {"kind": "search", "status": "started"},
         "action": {"skill": "done", "outcome": "success"},
         "instances": {"instances": []},
         "scene_graph": json.loads(GRAPH.to_json()),
         "llm_exchange": {"model": "m", "messages": []}}[kind])
    path = tmp_path / "bad.mcap"
    _raw_log(path, kind, [(1000, json.dumps(good.to_json()).encode()),
                          (2000, json.dumps(bad).encode())])
    topic = S.RECORDS[kind].topic
    with LogReader(path) as r, pytest.raises(LogFormatError) as e:
        list(r.records(RECORD_TYPES[kind]))
    msg = str(e.value)
    assert topic in msg and "record 1 at 2000 ns" in msg and f"'{field}'" in msg, msg
    with LogReader(path) as r, pytest.raises(LogFormatError, match=re.escape(f"'{field}'")):
        r.last_record(kind)


def test_a_record_that_is_not_json_is_a_log_format_error(tmp_path) -> None:
    path = tmp_path / "garbage.mcap"
    _raw_log(path, "action", [(7, b"{not json")])
    with LogReader(path) as r, pytest.raises(LogFormatError, match="/sgtool/action.*not JSON"):
        list(r.records(Action))


def _table(*items: tuple[int, str, str | None]) -> Instances:
    return Instances(tuple(InstanceItem(id=i, category=c, kind="furniture", state=s)
                           for i, c, s in items))


def test_instance_tables_written_again_check_what_changed(tmp_path) -> None:
    """A writer checks each instance-table item once: a second table with one item changed
    is written as the first (the same JSON a reader gets), a changed item that is wrong
    is refused naming its index in the whole table, and an id given twice is refused even
    when both items passed before."""
    first = _table((1, "fridge", "closed"), (2, "door", "closed"), (3, "sofa", None))
    with LogWriter(tmp_path / "x.mcap") as w:
        assert w.write_record(first, 0) == first.to_json()
        again = _table((1, "fridge", "open"), (2, "door", "closed"), (3, "sofa", None))
        assert w.write_record(again, 1) == again.to_json()
        bad = _table((1, "fridge", "open"), (2, "door", "closed"), (3, " ", None))
        with pytest.raises(LogFormatError, match=re.escape("'instances[2].category' is empty")):
            w.write_record(bad, 2)
        twice = _table((1, "fridge", "open"), (1, "fridge", "open"), (3, "sofa", None))
        with pytest.raises(LogFormatError, match=re.escape("'instances[1].id' 1 is given twice")):
            w.write_record(twice, 3)
    got = [d for _, d in LogReader(tmp_path / "x.mcap").records("instances")]
    assert got == [first.to_json(), again.to_json()]
