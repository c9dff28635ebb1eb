"""Golden-log regression: the committed logs must replay to the committed scene graphs.

The project's golden logs are checked with the code users check their own pinned logs
with (``sgtool golden check``): on a mismatch the failure shows what changed in the first
refresh that differs (rooms, objects, doors, edges, frontiers), not two hashes. To accept
a deliberate change, run ``python tests/golden/regenerate.py`` and say why in the commit
(tests/golden/README.md).
"""

from __future__ import annotations

import dataclasses
import json
import math

import pytest
from support.paths import GOLDEN

from sgtool import LogReader
from sgtool.analysis.golden_check import check_pins
from sgtool.replayers.golden import (
    CASES,
    REPLAY,
    ROUNDING,
    describe_mismatch,
    diff_graphs,
    read_graphs,
    sequence_digest,
)
from sgtool.replayers.golden_pins import read_pins
from sgtool.scenegraph.graph import SceneGraph

PINS = read_pins(GOLDEN)


def test_the_golden_folder_is_a_pin_folder_of_the_cases():
    assert sorted(PINS.logs) == sorted(c.name for c in CASES)
    for pin in PINS.logs.values():
        assert pin.options == REPLAY
        assert pin.log_path(GOLDEN) == GOLDEN / f"{pin.name}.mcap"
        assert pin.log_path(GOLDEN).stat().st_size < 2_000_000
        graphs = read_graphs(GOLDEN / f"{pin.name}.graphs.jsonl.gz")
        assert sequence_digest(graphs) == pin.sequence_sha256


@pytest.mark.parametrize("case", [c.name for c in CASES])
def test_golden_log_replays_to_the_committed_graphs(case):
    check = check_pins(GOLDEN, names=[case]).logs[0]
    if check.status != "unchanged":
        pytest.fail(f"{case}: the replayed scene graphs changed\n" + "\n".join(check.report())
                    + "\n(deliberate? `python tests/golden/regenerate.py`, and say why in the "
                    "commit)", pytrace=False)
    assert check.refreshes == (PINS.logs[case].refreshes,) * 2


def test_the_golden_cases_cover_what_they_claim():
    final = {c.name: SceneGraph.from_json(read_graphs(GOLDEN / f"{c.name}.graphs.jsonl.gz")[-1])
             for c in CASES}
    tour = final["house6-tour"]
    # corridor, bathroom, and the open-plan kitchen + living room: no door between
    # those two, so one room (the merged truth)
    assert sum(r.explored for r in tour.rooms) == 3
    assert {d.state for d in tour.doors} == {"open"}  # the closed bathroom door was opened
    assert any(o.relation == "inside" for o in tour.objects)  # contents of opened containers
    start = final["house10-start"]
    assert start.frontiers()  # stopped early: unexplored space remains


def test_the_golden_graphs_doors_stand_in_their_doorways():
    """Every door of the final graphs stands within 0.1 m of a doorway of the house (the
    swung panel's centroid stands about 0.6 m off it) and joins two rooms."""
    for c in CASES:
        with LogReader(GOLDEN / f"{c.name}.mcap") as r:
            spec = r.house_spec()
        assert spec is not None
        g = SceneGraph.from_json(read_graphs(GOLDEN / f"{c.name}.graphs.jsonl.gz")[-1])
        assert g.doors
        for d in g.doors:
            off = min(math.dist(d.position, s.center) for s in spec.doors)
            assert off < 0.1, (c.name, d.id, off)
            assert len(set(d.rooms)) == 2, (c.name, d.id, d.rooms)


def test_diff_names_what_changed():
    g = SceneGraph.from_json(read_graphs(GOLDEN / "house6-tour.graphs.jsonl.gz")[-1])
    room = g.rooms[0]
    obj = g.objects[0]
    door = g.doors[0]
    changed = dataclasses.replace(
        g,
        rooms=(dataclasses.replace(room, category="garage"),) + g.rooms[1:],
        objects=(dataclasses.replace(obj, room="room:99"),) + g.objects[2:],
        doors=(dataclasses.replace(door, state="closed"),) + g.doors[1:],
    )
    lines = diff_graphs(g, changed)
    text = "\n".join(lines)
    assert f"rooms: {room.id} category {room.category} -> garage" in text
    assert f"objects: {obj.id} {obj.category} room {obj.room} -> room:99" in text
    assert f"objects: - {g.objects[1].id}" in text
    assert f"doors: {door.id} state {door.state} -> closed" in text
    assert diff_graphs(g, g) == []


def _merged(g, keep, gone):
    """``g`` with room ``gone`` merged into ``keep``: its objects, regions and frontiers
    now lie in ``keep``."""
    def move(n):
        return dataclasses.replace(n, room=keep) if n.room == gone else n
    return dataclasses.replace(
        g, rooms=tuple(r for r in g.rooms if r.id != gone),
        objects=tuple(move(o) for o in g.objects), regions=tuple(move(r) for r in g.regions))


def test_diff_tells_merged_and_split_rooms_from_removed_and_added_ones():
    from sgtool.replayers.golden_layers import LayerSummary

    g = SceneGraph.from_json(read_graphs(GOLDEN / "house6-tour.graphs.jsonl.gz")[-1])
    keep, gone = (r.id for r in g.rooms[:2])
    merged = _merged(g, keep, gone)
    cat = {r.id: r.category for r in g.rooms}
    areas = (LayerSummary(40, 41, {keep: 10.0, gone: 6.5}), LayerSummary(39, 40, {keep: 16.5}))
    text = "\n".join(diff_graphs(g, merged, layers=areas))
    assert (f"rooms: {gone} ({cat[gone]}, 6.50 m²) merged into {keep} ({cat[keep]}, "
            "16.50 m²)") in text
    assert f"rooms: {keep} area 10.00 -> 16.50 m²" in text
    assert "voronoi: 40 nodes, 41 edges -> 39 nodes, 40 edges" in text
    assert f"rooms: - {gone}" not in text
    back = "\n".join(diff_graphs(merged, g, layers=areas[::-1]))
    assert (f"rooms: {keep} ({cat[keep]}, 16.50 m²) split into {keep} ({cat[keep]}, "
            f"10.00 m²) + {gone} ({cat[gone]}, 6.50 m²)") in back
    # a room whose contents vanish with it is removed, not merged
    bare = dataclasses.replace(merged, objects=(), regions=())
    assert f"rooms: - {gone} ({cat[gone]})" in diff_graphs(
        dataclasses.replace(g, objects=(), regions=()), bare)


def test_tolerance_and_exactness_of_describe_mismatch():
    graphs = read_graphs(GOLDEN / "house10-start.graphs.jsonl.gz")[:3]
    g = SceneGraph.from_json(graphs[1])
    o = g.objects[0]
    nudged = dataclasses.replace(g, objects=(dataclasses.replace(
        o, position=(o.position[0] + 0.003, *o.position[1:])),) + g.objects[1:])

    class Ref:
        time_ns, frames, reason = 2_500_000_000, 20, "every"

    actual = [(Ref, graphs[0]), (Ref, nudged.to_json()), (Ref, graphs[2])]
    lines = describe_mismatch(graphs, actual, tol=0.0)
    assert lines[0] == "refresh 1 at 2.500 s (after 20 frames, every) differs:"
    assert lines[1] == f"  objects: {o.id} {o.category} moved 0.003 m"
    assert describe_mismatch(graphs, actual, tol=0.005, exact=False) == []
    # exact: a difference below the tolerance still counts, as rounding
    assert describe_mismatch(graphs, actual, tol=0.005) == [
        "refresh 1 at 2.500 s (after 20 frames, every) differs:", f"  {ROUNDING}"]
    assert describe_mismatch(graphs, [(Ref, x) for x in graphs[:2]], tol=0.0) == [
        "2 refreshes where 3 were expected; the first 2 agree"]


def test_a_graph_key_added_or_removed_is_a_difference_at_tolerance_0():
    """Keys the scene graph does not read (a key renamed, added, removed) leave the graphs
    it parses equal: at tolerance 0 (byte-identical graphs wanted) the check still says
    where the JSON differs; with a tolerance they pass."""
    import json

    graphs = read_graphs(GOLDEN / "house10-start.graphs.jsonl.gz")[:2]
    d = json.loads(graphs[1])
    d["objects"][0]["confidence"] = 0.9
    d["objects"][0].pop("relation", None)

    class Ref:
        time_ns, frames, reason = 2_500_000_000, 20, "every"

    actual = [(Ref, graphs[0]), (Ref, json.dumps(d, sort_keys=True, separators=(",", ":")))]
    lines = describe_mismatch(graphs, actual, tol=0.0)
    assert lines[0] == "refresh 1 at 2.500 s (after 20 frames, every) differs:"
    assert "  json: objects[0].confidence: key added" in lines
    assert describe_mismatch(graphs, actual, tol=0.01, exact=False) == []
    spaced = [(Ref, graphs[0]), (Ref, json.dumps(json.loads(graphs[1]), indent=1))]
    assert describe_mismatch(graphs, spaced, tol=0.0)[1:] == [
        "  json: the same fields and values, written otherwise (key order, spacing or "
        "number form)"]


def _changed(value):
    """A value of the same type that reads differently in the canonical JSON."""
    if isinstance(value, bool):
        return not value
    if isinstance(value, int):
        return value + 1
    if isinstance(value, float):
        return value + 0.5
    if isinstance(value, str):
        return value + "x"
    if isinstance(value, tuple) and value and all(isinstance(v, float) for v in value):
        return (value[0] + 0.5, *value[1:])
    if isinstance(value, tuple):
        return (*value, ("kitchen", 0.5)) if value and isinstance(value[0], tuple) else \
            (*value, "x")
    if isinstance(value, dict):
        return {**value, "x": 1.0}
    return "x" if value is None else None


def test_every_field_of_a_graph_is_compared():
    """A change to any one field of any node, of the robot or of the graph (a door moved
    0.5 m, a robot turned, another instance) reads as a difference naming it, never as
    rounding: a real change must not pass a check run with a tolerance."""
    g = SceneGraph.from_json(read_graphs(GOLDEN / "house6-tour.graphs.jsonl.gz")[-1])
    assert g.rooms and g.objects and g.doors and g.regions
    tried = 0
    for layer in ("rooms", "objects", "doors", "regions"):
        node = getattr(g, layer)[0]
        for f in dataclasses.fields(node):
            if f.name == "id":
                continue
            other = dataclasses.replace(node, **{f.name: _changed(getattr(node, f.name))})
            changed = dataclasses.replace(g, **{layer: (other, *getattr(g, layer)[1:])})
            lines = diff_graphs(g, changed, tol=0.01)
            assert lines and ROUNDING not in lines, (layer, f.name, lines)
            tried += 1
    for f in dataclasses.fields(g.robot):
        robot = dataclasses.replace(g.robot, **{f.name: _changed(getattr(g.robot, f.name))})
        lines = diff_graphs(g, dataclasses.replace(g, robot=robot), tol=0.01)
        assert lines and ROUNDING not in lines, ("robot", f.name, lines)
    for name in ("time_ns", "version", "distances"):
        lines = diff_graphs(g, dataclasses.replace(g, **{name: _changed(getattr(g, name))}),
                            tol=0.01)
        assert lines and ROUNDING not in lines, (name, lines)
    assert tried >= 20
    # each line names what changed: the time alone is no change of version
    later = dataclasses.replace(g, time_ns=g.time_ns + 1)
    assert diff_graphs(g, later) == [f"graph: time {g.time_ns} -> {g.time_ns + 1} ns"]
    # affordances are a set (the JSON sorts them): their order is no change
    obj = next(o for o in g.objects if len(o.affordances) > 1)
    turned = dataclasses.replace(obj, affordances=tuple(reversed(obj.affordances)))
    same = dataclasses.replace(g, objects=tuple(turned if o is obj else o for o in g.objects))
    assert diff_graphs(g, same) == []


def test_a_difference_of_exactly_the_tolerance_passes_and_small_ones_read():
    """Values the canonical JSON rounds to 4 decimals that differ by exactly the tolerance
    pass, in every layer; below 1 mm a report prints the change with its digits."""
    g = SceneGraph.from_json(read_graphs(GOLDEN / "house6-tour.graphs.jsonl.gz")[-1])
    o, r = g.objects[0], g.rooms[0]
    for tol in (0.0001, 0.001, 0.01):
        moved = dataclasses.replace(g, objects=(dataclasses.replace(
            o, position=(round(o.position[0] + tol, 4), *o.position[1:])),) + g.objects[1:],
            rooms=(dataclasses.replace(r, position=(round(r.position[0] + tol, 4),
                                                    r.position[1])),) + g.rooms[1:],
            distances={k: round(v + tol, 4) for k, v in g.distances.items()})
        assert diff_graphs(g, moved, tol=tol) == [ROUNDING], tol
    tiny = dataclasses.replace(g, objects=(dataclasses.replace(
        o, position=(o.position[0] + 0.0002, *o.position[1:])),) + g.objects[1:])
    assert diff_graphs(g, tiny, tol=0.0) == [f"objects: {o.id} {o.category} moved 0.0002 m"]


def test_format_1_pin_folders_are_still_read(tmp_path):
    for f in GOLDEN.glob("house10-start.*"):
        (tmp_path / f.name).symlink_to(f)
    pin = PINS.logs["house10-start"]
    (tmp_path / "expected.json").write_text(json.dumps({
        "format": 1, "replay": {"every": 10, "classifier": "containment"},
        "cases": {"house10-start": {k: getattr(pin, k) for k in (
            "log_sha256", "refreshes", "final_sha256", "sequence_sha256")}}}))
    old = read_pins(tmp_path)
    assert old.format == 1
    assert old.logs["house10-start"].options == REPLAY
    assert old.logs["house10-start"].log_path(tmp_path) == tmp_path / "house10-start.mcap"


def test_frontiers_found_in_another_order_read_as_renumbered() -> None:
    """A replay that refreshes at other times numbers the same frontiers otherwise: the
    diff says which id each now has (its distance followed), not one frontier removed and
    another added; a frontier that did move is still a move."""
    def graph(frontiers: list[tuple[str, float]]) -> SceneGraph:
        return SceneGraph.from_dict({
            "version": "1.0", "robot": {"position": [0, 0]},
            "regions": [{"id": i, "room": "room:0", "position": [x, 1.0], "kind": "frontier",
                         "frontier_type": "leading_out", "size": 1.4} for i, x in frontiers],
            "distances": {i: 2.0 + x for i, x in frontiers}})

    before = graph([("frontier:1", 0.0), ("frontier:3", 5.0), ("frontier:4", 9.0)])
    after = graph([("frontier:1", 5.0), ("frontier:2", 0.0), ("frontier:4", 9.5)])
    assert diff_graphs(before, after) == [
        "frontiers: frontier:1 is frontier:2 (renumbered)",
        "frontiers: frontier:3 is frontier:1 (renumbered)",
        "frontiers: frontier:4 moved 0.500 m",
        "distances: 1 differ, largest 0.500 m (frontier:4)"]


def test_a_renumbering_that_would_take_a_kept_id_is_left_out() -> None:
    """frontier:1 found as frontier:2 and frontier:2 as frontier:3 while frontier:3 is gone:
    frontier:2 cannot take frontier:3's id, so frontier:1 cannot take frontier:2's either;
    no frontier is lost from the report (one removed, as the counts say)."""
    def graph(frontiers: list[tuple[str, float]]) -> SceneGraph:
        return SceneGraph.from_dict({
            "version": "1.0", "robot": {"position": [0, 0]},
            "regions": [{"id": i, "room": "room:0", "position": [x, 1.0], "kind": "frontier",
                         "frontier_type": "leading_out", "size": 1.4} for i, x in frontiers]})

    before = graph([("frontier:1", 0.0), ("frontier:2", 5.0), ("frontier:3", 9.0)])
    after = graph([("frontier:2", 0.0), ("frontier:3", 5.0)])
    got = diff_graphs(before, after)
    assert not any("renumbered" in x for x in got), got
    assert sum(x.startswith("frontiers: - ") for x in got) == 1, got
