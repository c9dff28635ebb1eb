"""Golden-log regression: the committed logs must replay to the committed scene graphs.

The project's golden logs are checked with the code users check their own pinned logs
with (``sgtool golden check``): on a mismatch the failure shows what changed in the first
refresh that differs (rooms, objects, doors, edges, frontiers), not two hashes. To accept
a deliberate change, run ``python tests/golden/regenerate.py`` and say why in the commit
(tests/golden/README.md).
"""

from __future__ import annotations

import dataclasses

import pytest
from support.paths import GOLDEN

from sgtool.analysis.golden_check import check_pins
from sgtool.replayers.golden import (
    CASES,
    REPLAY,
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
    assert sum(r.explored for r in tour.rooms) == 4
    assert {d.state for d in tour.doors} == {"open"}  # the closed bathroom door was opened
    assert any(o.relation == "inside" for o in tour.objects)  # contents of opened containers
    start = final["house10-start"]
    assert start.frontiers()  # stopped early: unexplored space remains


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
