"""``tools/closed_loop_misses.py`` on a real closed-loop log: a planner that gives up at
once fails, and the tool says where the target is from the log's own ground truth, that
no frame showed it, that its holder was never opened and what the robot's map named its
room."""

from __future__ import annotations

import importlib
from pathlib import Path

import pytest
from support.scripted_planner import Scripted
from support.seed0_episodes import seed0_episode

from sgtool.datasets.generator import generate_house
from sgtool.house.spec import room_at
from sgtool.log import LogReader
from sgtool.log.records import SceneGraphRecord
from sgtool.planning.base import Action
from sgtool.recorders.sim import CameraConfig
from sgtool.recorders.sim.closed_loop import ClosedLoopOptions, run_episode
from sgtool.results import EpisodeResult, write_jsonl

TOOL = Path(__file__).resolve().parents[1] / "tools" / "closed_loop_misses.py"


def _named(house, log: Path, query: str) -> list[str]:
    """Categories the log's last graph gives its room nodes in the room of ``query``."""
    target = next(o for o in house.objects if o.category == query)
    with LogReader(log) as r:
        graph = [g for _, g in r.records(SceneGraphRecord)][-1].graph()
    return sorted({rm.category for rm in graph.rooms
                   if room_at(house, rm.position[0], rm.position[1]) == target.room})


def test_a_give_up_is_a_miss_of_the_search(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                           monkeypatch: pytest.MonkeyPatch) -> None:
    from sgtool.recorders.sim import closed_loop

    # the robot explores on after the give-up (as when every goal on offer had failed), so
    # the map holds rooms the planner never chose
    monkeypatch.setattr(closed_loop, "give_up_handed_over", lambda offered, failed: True)
    house = generate_house(6, rooms=(4, 4))
    opts = ClosedLoopOptions(camera=CameraConfig(width=64, height=48), max_steps=1)
    (tmp_path / "logs").mkdir()
    # the first episode whose target is not in view but whose room the map holds
    for index in range(len(house.objects)):
        idx, ep = seed0_episode(house, index)
        log = tmp_path / "logs" / f"ep-{idx}.mcap"
        rep = run_episode(house, ep, Scripted([Action("done")]), log, opts,
                          house_id="house-0", episode_index=idx)
        if not rep.success and _named(house, log, rep.query):
            break
        log.unlink()
    assert not rep.success
    write_jsonl([EpisodeResult("done", 0, "house-0", idx, rep.query, False, rep.steps,
                               rep.travelled_m, rep.shortest_m, end=rep.end,
                               source=str(log))], tmp_path / "episodes.jsonl")
    monkeypatch.syspath_prepend(str(TOOL.parent))
    tool = importlib.import_module("closed_loop_misses")
    [miss] = tool.misses(tmp_path)
    target = next(o for o in house.objects if o.category == rep.query)
    room = next(r.category for r in house.rooms if r.id == target.room)
    parent = next(x.category for x in (*house.furniture, *house.objects)
                  if x.id == target.parent)
    assert miss.where.startswith(f"{room}: {target.relation} {parent}")
    with LogReader(log) as r:
        assert miss.frames == r.frame_count() > 0
    assert 0 <= miss.frames_in_room <= miss.frames
    assert not miss.holder_opened
    assert miss.frames_showing == miss.most_pixels == 0
    # what the robot's last graph named the target's room: its room nodes standing there
    there = _named(house, log, rep.query)
    assert there and list(miss.named) == there
    assert miss.named_right == (room in there)
    assert tool.main([str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert "1 failed episodes: the target in no frame's pixels in 1 (its holder never " \
        "opened in 1, opened without the camera seeing in, in 0)" in out
    assert f"the target's room named right on the map in {int(miss.named_right)}" in out
    assert tool.main([str(tmp_path / "absent")]) == 1
