"""`sgtool run`: the closed loop in PyBullet, on a small generated 4-room house at 160x120.

The simulator is the real one throughout. Checked: the pure mapping of planner actions to
skills; one scout episode end to end (episode, action and LLM records, scene graphs,
derived map channels, the house attachment), `sgtool replay` of its log rebuilding the
live scene graphs byte for byte, `sgtool eval` recomputing its figures, a rerun giving the
same messages except the measured decision times; a random episode; invalid targets and
done with a scripted planner; the frame budget; moma-llm against a scripted chat server
and then from its transcript; user errors; the graph_time_ns pairing of `sgtool eval`.
"""

from __future__ import annotations

import dataclasses
import json
import re
from pathlib import Path

import pytest
from click.testing import CliRunner
from support.pinned_houses import pinned_house_path
from support.scripted_planner import Scripted
from support.semantics_fixtures import ChatServer

from sgtool.analysis.offline import read_log_episodes, replay_decisions
from sgtool.cli import cli
from sgtool.datasets.generator import generate_house
from sgtool.errors import SgtoolError
from sgtool.log import LogReader, LogWriter
from sgtool.log import schemas as S
from sgtool.log.records import Instances
from sgtool.planning.base import Action
from sgtool.planning.candidates import find_target
from sgtool.planning.episode import planner_seed
from sgtool.planning.registry import make_planner
from sgtool.recorders.sim import CameraConfig
from sgtool.recorders.sim.closed_loop import (
    ClosedLoopOptions,
    SkillCall,
    pick_episode,
    plan_skills,
    run_episode,
)
from sgtool.recorders.sim.closed_loop_report import episode_notes
from sgtool.recorders.sim.noise import PROFILES
from sgtool.recorders.sim.spl_shortest import driven_shortest
from sgtool.replayers.derived_log import ReplayOptions, replay
from sgtool.scenegraph.derived_layers import DERIVED_TOPICS
from sgtool.scenegraph.examined import EXAMINE, close_views
from sgtool.scenegraph.graph import (
    DoorNode,
    ObjectNode,
    RegionNode,
    RobotState,
    RoomNode,
    SceneGraph,
)

SEED, ROOMS = 6, "4-4"
OPTS = ClosedLoopOptions(camera=CameraConfig(width=160, height=120))
GRAPH = S.RECORDS["scene_graph"].topic
MEASURED = ("decision_time_s", "latency_s")  # wall-clock fields, the only ones that vary


@pytest.fixture(scope="module")
def house():
    return generate_house(SEED, rooms=(4, 4))


def messages(path: Path, topics=None) -> list[tuple[str, int, bytes]]:
    with LogReader(path) as r:
        return [(c.topic, int(m.log_time), bytes(m.data))
                for _, c, m in r.raw_messages(topics)]


def masked(path: Path) -> list[tuple[str, int, object]]:
    """Every message, with the measured fields of JSON records blanked."""
    out = []
    for topic, t, data in messages(path):
        if topic.startswith("/sgtool/"):
            rec = json.loads(data)
            for k in MEASURED:
                if k in rec:
                    rec[k] = 0
            out.append((topic, t, rec))
        else:
            out.append((topic, t, data))
    return out


# ----- the pure mapping ---------------------------------------------------------------
def toy_graph() -> SceneGraph:
    return SceneGraph(
        robot=RobotState((0.5, 0.5), room="room:0"),
        rooms=(RoomNode("room:0", "kitchen", (1.0, 1.0)),
               RoomNode("room:1", position=(5.0, 1.0), explored=False)),
        regions=(RegionNode("region:0.0", "room:0", (1.0, 1.5)),
                 RegionNode("frontier:3", "room:0", (2.0, 2.5), kind="frontier",
                            frontier_type="unexplored area", size=1.0)),
        objects=(ObjectNode("obj:7", "refrigerator", "region:0.0", "room:0", (1.0, 2.0, 0.9),
                            instance=7, state="closed", affordances=("openable",)),),
        doors=(DoorNode("door:4", (3.0, 1.0), "closed", ("room:0", "room:1"), instance=4),),
    )


def test_actions_map_to_skills() -> None:
    g = toy_graph()

    def calls(skill, target):
        p = plan_skills(g, Action(skill, target))
        assert p.invalid is None and not p.done
        return p.calls

    assert calls("navigate", "obj:7") == (SkillCall("navigate", 7),)
    assert calls("navigate", "door:4") == (SkillCall("navigate", 4),)
    assert calls("navigate", "room:0") == (SkillCall("navigate", (1.0, 1.0)),)
    assert calls("navigate", "region:0.0") == (SkillCall("navigate", (1.0, 1.5)),)
    assert calls("explore", "frontier:3") == (SkillCall("explore", (2.0, 2.5)),)
    assert calls("explore", "room:1") == (SkillCall("explore", (5.0, 1.0)),)
    # open / close: go to it, then open / close it (MoMa-LLM's go_to_and_open)
    assert calls("open", "obj:7") == (SkillCall("navigate", 7), SkillCall("open", 7))
    assert calls("open", "door:4") == (SkillCall("navigate", 4), SkillCall("open", 4))
    assert calls("close", "obj:7") == (SkillCall("navigate", 7), SkillCall("close", 7))


def test_invalid_targets_and_done() -> None:
    g = toy_graph()
    assert plan_skills(g, Action("done")).done
    assert plan_skills(g, Action("done", "obj:7")).done
    for action, why in [(Action("navigate", "obj:99"), "not a node of the scene graph"),
                        (Action("open", "room:0"), "cannot open a room"),
                        (Action("close", "frontier:3"), "cannot close a frontier"),
                        (Action("explore", None), "needs a target"),
                        (Action("fly", "room:0"), "unknown skill")]:  # type: ignore[arg-type]
        p = plan_skills(g, action)
        assert p.calls == () and not p.done and why in p.invalid


# ----- one scout episode end to end ---------------------------------------------------
@pytest.fixture(scope="module")
def scout_log(tmp_path_factory):
    out = tmp_path_factory.mktemp("run") / "scout.mcap"
    r = CliRunner().invoke(cli, ["run", "--planner", "scout", "--seed", str(SEED), "--rooms",
                                 ROOMS, "--episode", "0", "--resolution", "160x120", "-o",
                                 str(out)])
    assert r.exit_code == 0, r.output
    return out, r.output


def test_scout_episode_log(scout_log, house) -> None:
    path, report = scout_log
    _, ep = pick_episode(house, index=0)
    assert f"scout searching for {ep.query!r}" in report and "frames/s" in report
    assert not path.with_name(path.name + ".partial").exists()
    with LogReader(path) as r:
        assert r.house_json() == house.to_json()
        assert r.schema_version == S.LOG_SCHEMA_VERSION
        started, ended = [rec for _, rec in r.records("episode")]
        assert started["status"] == "started" and started["query"] == ep.query
        assert started["extra"]["mapping"] == {"every": 10, "classifier": "frequency",
                                               "min_points": 12, "voxel_size": 0.05,
                                               "mixed_pixels": True}
        assert ended["status"] == "success" and ended["planner"] == "scout"
        # SPL's shortest: the episode's grid route pulled taut (no longer than the route)
        assert ended["shortest_m"] == pytest.approx(driven_shortest(house, ep), abs=1e-4)
        assert ended["shortest_m"] <= ep.shortest_path + 1e-4
        assert ended["extra"]["end"] == "found" and ended["extra"]["query"] == ep.query
        assert ended["frames"] == r.frame_count() > 20
        actions = list(r.records("action"))
        graphs = {t for t, _ in r.records("scene_graph")}
        look = actions[0][1]
        assert (look["skill"], look["graph_time_ns"], look["step"]) == ("look_around", None, 0)
        decided = [a for _, a in actions[1:]]
        assert len(decided) == ended["steps"] >= 1
        for k, (t, a) in enumerate(actions[1:], start=1):
            assert a["planner"] == "scout" and a["step"] == k and a["decision_time_s"] > 0
            assert a["graph_time_ns"] in graphs and a["graph_time_ns"] <= t
            # a refresh at every action that took frames
            assert t in graphs or a["outcome"] == "invalid" or a["skill"] == "done"
            # the planner's reason, and the executor's message beside it
            assert isinstance(a["message"], str) and a["message"] != a["reason"]
        assert "message" not in look  # the robot's own action: its reason only
        # every logged distance is rounded to 0.1 mm (the records' canonical rounding)
        assert ended["travelled_m"] == pytest.approx(sum(a["travelled_m"] for a in decided),
                                                     abs=5e-5 * (len(decided) + 1))
        for topic in DERIVED_TOPICS:
            assert r.has(topic), topic
        assert r.has(S.RECORDS["instances"].topic)
        assert find_target(SceneGraph.from_dict(r.last_record("scene_graph")), ep.query)


def test_pieces_count_as_searched_only_once_seen_from_close_by(scout_log) -> None:
    """A container or supporter that is not closed is explored exactly when a frame of the
    log gave it the mapping's min_points pixels at a mean depth within EXAMINE_RANGE_M (as
    the symbolic environment reveals what a piece holds only when the agent walks up)."""
    path, _ = scout_log
    with LogReader(path) as r:
        started = next(rec for _, rec in r.records("episode"))
        min_points = started["extra"]["mapping"]["min_points"]
        first = next(iter(r.records(Instances)))[1]
        close: set[int] = set()
        for fr in r.frames():
            close.update(close_views(fr.ids, fr.depth, min_points))
        graph = SceneGraph.from_dict(r.last_record("scene_graph"))
    states = {i.id: i.state for i in first.instances}
    pieces = [o for o in graph.objects if EXAMINE in o.affordances]
    assert pieces and any(o.explored for o in pieces) and any(not o.explored for o in pieces)
    for o in pieces:
        if o.explored:
            assert o.state != "closed" and o.instance in close, o
        elif o.state != "closed" and states.get(o.instance) == o.state:
            assert o.instance not in close, o
    # what is not a carrier is explored unless closed, as before
    assert all(o.explored == (o.state != "closed") for o in graph.objects
               if EXAMINE not in o.affordances)


def test_replay_reproduces_the_live_scene_graphs(scout_log, tmp_path) -> None:
    path, _ = scout_log
    derived = tmp_path / "replayed.mcap"
    r = CliRunner().invoke(cli, ["replay", str(path), "-o", str(derived)])  # default options
    assert r.exit_code == 0, r.output
    live, again = messages(path, [GRAPH]), messages(derived, [GRAPH])
    assert len(live) >= 3 and live == again  # several refreshes, byte for byte
    assert messages(path, list(DERIVED_TOPICS)) == messages(derived, list(DERIVED_TOPICS))


def test_eval_recomputes_the_episode(scout_log) -> None:
    path, _ = scout_log
    r = CliRunner().invoke(cli, ["eval", str(path), "--json"])
    assert r.exit_code == 0, r.output
    doc = json.loads(r.output)
    with LogReader(path) as log:
        ended = log.last_record("episode")
        times = [a["decision_time_s"] for _, a in log.records("action")][1:]
    assert doc["episodes"] == 1
    s = doc["planners"]["scout"]
    assert s["sr"]["mean"] == 1.0 and s["steps"]["mean"] == ended["steps"]
    # the look-around is no decision: the mean is over the planner's decisions only
    assert s["decision_s"]["mean"] == pytest.approx(sum(times) / len(times), abs=2e-6)
    (ep,) = read_log_episodes(path)
    assert [d.decided for d in ep.decisions] == [False] + [True] * ended["steps"]
    # offline: the same planner on the logged graphs makes the same choices
    rep = replay_decisions(make_planner("scout"), [ep])
    assert rep.decisions == ended["steps"] and rep.skipped == 0 and rep.rate("agree") == 1.0


def test_same_inputs_same_log_but_decision_times(scout_log, house, tmp_path) -> None:
    path, _ = scout_log
    idx, ep = pick_episode(house, index=0)
    again = tmp_path / "again.mcap"
    rep = run_episode(house, ep, make_planner("scout"), again, OPTS, house_id=f"house-{SEED}",
                      episode_index=idx)
    assert rep.success and rep.end == "found"
    assert messages(path, [GRAPH]) == messages(again, [GRAPH])
    assert masked(path) == masked(again)


def test_a_replay_shows_the_planner_the_graph_it_was_shown(house, tmp_path) -> None:
    """Live navigation shows the planner the graph with the robot's own distances and the
    goals it cannot reach withheld; the Action record keeps those distances, so the logged
    graph as shown (``Action.shown``) is, decision for decision, the graph the planner got,
    and greedy (which goes by distance) makes every logged choice again offline."""
    idx, ep = pick_episode(house, index=1)
    out = tmp_path / "greedy.mcap"
    given: list[SceneGraph] = []
    run_episode(house, ep, make_planner("greedy"), out,
                dataclasses.replace(OPTS, max_steps=6), episode_index=idx,
                on_decision=lambda g, a: given.append(g))
    (logged,) = read_log_episodes(out)
    decided = [d for d in logged.decisions if d.decided]
    assert len(decided) == len(given) >= 2
    with LogReader(out) as r:  # Foxglove's view of each graph, as a replay writes it
        assert r.message_count(S.GRAPH_SCENE) == r.message_count(GRAPH) >= 2
    # a derived log of it replays with the options of its own build, not the live map's
    derived = tmp_path / "derived.mcap"
    replay(out, derived, ReplayOptions(every=3, voxel_size=0.08))
    again = replay(derived, None).options
    assert (again.every, again.voxel_size) == (3, 0.08)
    assert any(d.action.view_distances for d in decided)
    for d, g in zip(decided, given, strict=True):
        assert d.graph is not None
        assert d.action.shown(d.graph) == g
    rep = replay_decisions(make_planner("greedy"), [logged])
    assert rep.decisions == len(given) and rep.rate("agree") == 1.0


# ----- other planners and endings -----------------------------------------------------
def test_random_episode(house, tmp_path) -> None:
    idx, ep = pick_episode(house, index=3)
    out = tmp_path / "random.mcap"
    rep = run_episode(house, ep, make_planner("random"), out, ClosedLoopOptions(
        camera=OPTS.camera, max_steps=3, planner_seed=1), episode_index=idx)
    assert 1 <= rep.steps <= 3 and rep.end in ("found", "max_steps")
    (logged,) = read_log_episodes(out)
    res = logged.result()
    assert (res.planner, res.steps, res.success, res.episode) == (
        "random", rep.steps, rep.success, idx)
    assert all(d.graph is not None for d in logged.decisions[1:])
    # the planner drew from the episode's own seed (as the symbolic bench's), which the
    # log keeps: another episode of the run draws another stream
    assert logged.episode.extras["seed"] == 1
    assert logged.episode.extras["planner_seed"] == planner_seed(1, house.seed, idx) \
        != planner_seed(1, house.seed, idx + 1)


def test_invalid_targets_and_done_in_the_loop(house, tmp_path) -> None:
    idx, ep = pick_episode(house, index=0)
    p = Scripted([Action("navigate", "obj:424242"),
                  lambda g: Action("open", g.rooms[0].id),
                  lambda g: Action("navigate", g.regions[0].id),
                  Action("done")] + [lambda g: Action("done")] * 20)
    out = tmp_path / "scripted.mcap"
    rep = run_episode(house, ep, p, out, OPTS, episode_index=idx)
    # a give-up while the robot's map has floor to explore hands over to the fallback and
    # the planner is asked again; the episode ends at the give-up with nothing left
    assert (rep.success, rep.end) == (False, "gave_up") and rep.steps >= 4
    assert [f.outcome for f in p.feedbacks[:2]] == ["invalid", "invalid"]
    assert "not a node of the scene graph" in p.feedbacks[0].message
    assert "cannot open a room" in p.feedbacks[1].message
    assert p.feedbacks[2].action.skill == "navigate"  # a real motion, success or failure
    with LogReader(out) as r:
        acts = [a for _, a in r.records("action")]
        ended = r.last_record("episode")
    assert [a["outcome"] for a in acts[1:3]] == ["invalid", "invalid"]
    assert acts[1]["travelled_m"] == 0.0 and acts[-1]["skill"] == "done"
    assert (ended["status"], ended["steps"], ended["extra"]["end"]) == (
        "failure", rep.steps, "gave_up")
    assert [a["skill"] for a in acts if a["planner"] is not None][3:] == \
        ["done"] * (rep.steps - 3)


def test_frame_budget_cuts_the_episode(house, tmp_path) -> None:
    idx, ep = pick_episode(house, index=0)
    out = tmp_path / "budget.mcap"
    # every tick a frame, so the 25 frames end inside the opening look-around
    rep = run_episode(house, ep, make_planner("greedy"), out, ClosedLoopOptions(
        camera=OPTS.camera, frames=25, turn_render_deg=0.0))
    assert (rep.frames, rep.end, rep.success) == (25, "frames", False)
    with LogReader(out) as r:
        assert r.frame_count() == 25
        (look,) = [a for _, a in r.records("action")]
        assert look["outcome"] == "failure" and "frame budget" in look["reason"]
        assert r.last_record("episode")["status"] == "failure"


def test_error_mid_run_leaves_no_file(house, tmp_path) -> None:
    idx, ep = pick_episode(house, index=0)

    def boom(g):
        raise SgtoolError("planner broke")

    out = tmp_path / "broken.mcap"
    with pytest.raises(SgtoolError, match="planner broke"):
        run_episode(house, ep, Scripted([boom]), out, OPTS)
    assert not out.exists() and not out.with_name(out.name + ".partial").exists()


# ----- moma-llm: scripted endpoint, then its transcript -------------------------------
def responder(request: dict) -> dict:
    """Open the first closed thing of the first observed room, else explore that room."""
    user = request["messages"][1]["content"]
    m = re.search(r"^- ([^:\n]+): \[(.*)\]$", user, re.M)
    if m is None:
        return {"text": "Analysis: nothing seen.\nReasoning: look.\nCommand: done()"}
    room, items = m.group(1), [s.strip() for s in m.group(2).split(",")]
    closed = [re.sub(r"^\d+ ", "", s)[len("closed "):] for s in items if "closed " in s]
    retry = len(request["messages"]) > 2
    cmd = f"go_to_and_open({room}, {closed[0]})" if closed and not retry else \
        f"explore({room})"
    return {"text": f"Analysis: the {room} is close.\nReasoning: nearest lead.\n"
                    f"Command: {cmd}"}


def test_moma_llm_episode_and_its_replay(house, tmp_path) -> None:
    idx, ep = pick_episode(house, index=4)
    transcript = tmp_path / "llm.jsonl"
    live = tmp_path / "moma.mcap"
    opts = ClosedLoopOptions(camera=OPTS.camera, max_steps=2)
    with ChatServer(responder=responder) as srv:
        moma = make_planner("moma-llm", base_url=srv.base_url, model="scripted",
                            api_key="test", timeout_s=10.0, transcript=str(transcript))
        rep = run_episode(house, ep, moma, live, opts, episode_index=idx)
        assert not srv.errors
    assert rep.steps >= 1
    with LogReader(live) as r:
        exchanges = [x for _, x in r.records("llm_exchange")]
        acts = [a for _, a in r.records("action")][1:]
    assert len(exchanges) >= rep.steps and all(x["model"] == srv.model for x in exchanges)
    assert "find a" in exchanges[0]["messages"][0]["content"]
    assert all(a["planner"] == "moma-llm" for a in acts)
    if len(exchanges) > 1:  # the executor's outcome reached the model's history
        assert "Previous actions:\n- " in exchanges[-1]["messages"][1]["content"]
    # the same episode from the transcript: the same prompts, graphs and actions
    again = tmp_path / "moma-replay.mcap"
    r = CliRunner().invoke(cli, ["run", "--planner", "moma-llm", "--seed", str(SEED),
                                 "--rooms", ROOMS, "--episode", str(idx), "--resolution",
                                 "160x120", "--max-steps", "2", "--llm-replay",
                                 str(transcript), "--quiet", "-o", str(again)])
    assert r.exit_code == 0, r.output
    assert messages(live, [GRAPH]) == messages(again, [GRAPH])
    with LogReader(again) as r2:
        replayed = [x for _, x in r2.records("llm_exchange")]
        acts2 = [a for _, a in r2.records("action")][1:]
    assert [x["prompt_sha256"] for x in replayed] == [x["prompt_sha256"] for x in exchanges]
    assert [x["response"] for x in replayed] == [x["response"] for x in exchanges]
    strip = [{k: v for k, v in a.items() if k != "decision_time_s"} for a in acts]
    assert [{k: v for k, v in a.items() if k != "decision_time_s"} for a in acts2] == strip


def test_an_endpoint_without_one_valid_answer_is_named(house, tmp_path) -> None:
    """An endpoint that answers, but never with a command (a wrong model, a completion-only
    one): the episode gives up, and the report says why rather than a bare 'not found'."""
    idx, ep = pick_episode(house, index=4)
    with ChatServer(responder=lambda request: {"text": "<html>not a chat model</html>"}) \
            as srv:
        moma = make_planner("moma-llm", base_url=srv.base_url, model="scripted",
                            api_key="test", timeout_s=10.0)
        rep = run_episode(house, ep, moma, tmp_path / "g.mcap",
                          ClosedLoopOptions(camera=OPTS.camera, max_steps=2), episode_index=idx)
    assert not rep.success
    (note,) = [n for n in rep.notes if "LLM requests" in n]
    assert note.startswith("none of the planner's ") and "rejected" in note
    assert "sgtool llm check" in note
    assert episode_notes(5.0, 5.0, 0.0, 3, {"requests": 4, "valid": 1}) == ()


# ----- user errors --------------------------------------------------------------------
@pytest.mark.parametrize("args,message", [
    (["--planner", "nope"], "unknown planner 'nope'"),
    (["--planner", "scout", "--house", "{missing}"], "no such house spec file"),
    (["--planner", "scout", "--house", "{bad}"], "not valid JSON"),
    (["--planner", "scout", "--query", "unicorn"], "no object of category 'unicorn'"),
    (["--planner", "scout", "--episode", "999"], "episode 999: the house has"),
    (["--planner", "scout", "-O", "nonsense=1"], "does not take option(s): nonsense"),
    (["--planner", "scout", "--llm-replay", "x.jsonl"], "are for --planner moma-llm"),
    (["--planner", "scout", "-o", "{exists}"], "exists; not overwriting it (use --force)"),
    (["--planner", "scout", "--optimistic", "5"], "optimistic margin 5.0 m: must be 0..2"),
    (["--planner", "scout", "--noise", "loud"], "unknown profile 'loud'"),
    # a house saved as .mcap given as the output too: it was replaced by the log
    (["--planner", "scout", "--house", "{exists}", "-o", "{exists}", "--force"],
     "the output must not be an input"),
])
def test_user_errors(tmp_path, args, message) -> None:
    (tmp_path / "bad.json").write_text("{not json")
    (tmp_path / "exists.mcap").write_bytes(b"keep me")
    subs = {"{missing}": str(tmp_path / "missing.json"), "{bad}": str(tmp_path / "bad.json"),
            "{exists}": str(tmp_path / "exists.mcap")}
    args = [subs.get(a, a) for a in args]
    if "-o" not in args:
        args += ["-o", str(tmp_path / "out.mcap")]
    r = CliRunner().invoke(cli, ["run", *args])
    assert r.exit_code == 2, r.output
    assert message in r.output and "Traceback" not in r.output
    assert not (tmp_path / "out.mcap").exists()
    assert not list(tmp_path.glob("*.partial"))
    assert (tmp_path / "exists.mcap").read_bytes() == b"keep me"


def test_help_explains_the_loop() -> None:
    r = CliRunner().invoke(cli, ["run", "-h"])
    assert r.exit_code == 0
    for word in ("--planner", "--query", "--episode", "--frames", "--llm-replay", "replay"):
        assert word in r.output


# ----- sgtool eval: which graph an action was decided on ------------------------------
def test_eval_pairs_actions_with_graph_time_ns(tmp_path) -> None:
    def graph(x: float) -> dict:
        return SceneGraph(robot=RobotState((x, 0.0))).to_dict()

    path = tmp_path / "pairing.mcap"
    with LogWriter(path) as w:
        w.write_record("episode", 0, {"kind": "search", "status": "started", "query": "cup"})
        w.write_record("action", 5, {"skill": "look_around", "outcome": "success",
                                     "graph_time_ns": None, "decision_time_s": 0.0})
        w.write_record("scene_graph", 10, graph(1.0))
        w.write_record("scene_graph", 20, graph(2.0))  # mid-skill refresh
        w.write_record("action", 30, {"skill": "explore", "target": "room:0",
                                      "outcome": "success", "graph_time_ns": 10,
                                      "decision_time_s": 0.5})
        w.write_record("scene_graph", 30, graph(3.0))
        w.write_record("action", 40, {"skill": "done", "outcome": "success",
                                      "decision_time_s": 0.1})  # 1.0 log: the old rule
        w.write_record("episode", 40, {"kind": "search", "status": "failure", "steps": 2})
    (ep,) = read_log_episodes(path)  # the closing record at the last action's time
    look, explore, done = ep.decisions
    assert look.graph is None and not look.decided
    assert explore.graph.robot.position == (1.0, 0.0)  # by graph_time_ns, not the latest
    assert done.graph.robot.position == (3.0, 0.0) and done.decided
    res = ep.result()
    assert res.steps == 2 and res.decisions == 2 and res.decision_s == pytest.approx(0.6)


def test_the_log_keeps_the_planners_options(house, tmp_path) -> None:
    """The options a planner was built with go into both episode records (plain values;
    secrets and Python objects left out), so golden and resume build the same planner."""
    from sgtool.recorders.sim.episode_extras import recorded_options

    idx, ep = pick_episode(house, index=0)
    out = tmp_path / "opts.mcap"
    run_episode(house, ep, make_planner("greedy", max_failures=3), out,
                ClosedLoopOptions(camera=OPTS.camera, frames=25, turn_render_deg=0.0),
                planner_options={"max_failures": 3})
    with LogReader(out) as r:
        records = [e for _, e in r.records("episode")]
    assert [e["extra"]["planner_options"] for e in records] == [{"max_failures": 3}] * 2
    # a planner by name, its options given as text from Python: recorded as -O records them
    run_episode(house, ep, "bayes-search", out, ClosedLoopOptions(
        camera=OPTS.camera, frames=25, turn_render_deg=0.0),
        planner_options={"step_cost": "2", "top_k": "4"}, overwrite=True)
    with LogReader(out) as r:
        records = [e for _, e in r.records("episode")]
    assert records[0]["planner"] == "bayes-search"
    assert records[0]["extra"]["planner_options"] == {"step_cost": 2.0, "top_k": 4}
    assert recorded_options({"api_key": "sk-1", "encoder": object(), "delta": 0.2,
                             "rooms": ["a", "b"]}) == {"delta": 0.2, "rooms": ["a", "b"]}


def test_a_noisy_sensor_maps_as_far_as_its_noise_allows(house, tmp_path) -> None:
    # depth noise 0.01 z^2 from a camera 1.2 m up: 4 sigma of the floor reach its 0.1 m
    # tolerance at 2.08 m (sgtool.mapping.depth_noise.sensor_max_depth), so the live map
    # keeps depth to 2 m, says so, records it, and a replay maps the same
    idx, ep = pick_episode(house, index=0)
    out = tmp_path / "noisy.mcap"
    r = CliRunner().invoke(cli, ["run", "--planner", "scout", "--seed", str(SEED), "--rooms",
                                 ROOMS, "--episode", "0", "--resolution", "160x120",
                                 "--max-steps", "2", "--noise", "none,depth_sigma=0.01",
                                 "--noise-seed", "3", "-o", str(out)])
    assert r.exit_code == 0, r.output
    assert "the live map kept depth to 2 m" in r.output
    (logged,) = read_log_episodes(out)
    assert logged.episode.extras["mapping"]["max_depth"] == 2.0
    assert logged.episode.extras["noise_seed"] == 3
    assert logged.result().noise == "depth_sigma=0.01"  # (one spelling: none is the base)
    derived = tmp_path / "replayed.mcap"
    r = CliRunner().invoke(cli, ["replay", str(out), "-o", str(derived)])
    assert r.exit_code == 0, r.output
    assert messages(out, [GRAPH]) == messages(derived, [GRAPH])
    # a depth of the user's own, checked like replay's
    opts = dataclasses.replace(OPTS, noise=PROFILES["strong"])
    assert opts.mapping().max_depth == 3.25  # 0.1 / (4 x 1.2 x 0.006) = 3.47: bin 3.25
    assert dataclasses.replace(opts, max_depth=4.5).mapping().max_depth == 4.5
    with pytest.raises(SgtoolError, match="--max-depth 0.2 m: must be 0.5..20"):
        dataclasses.replace(opts, max_depth=0.2).mapping()
    # the camera at 1.2 m, tilted 15 deg, 75 deg field: its nearest floor is 1.2 m deep
    with pytest.raises(SgtoolError, match="--max-depth 1 m: .* sees no floor nearer than "
                                          "1.20 m"):
        dataclasses.replace(opts, max_depth=1.0).mapping()
    assert dataclasses.replace(opts, max_depth=1.3).mapping().max_depth == 1.3
    assert OPTS.mapping().max_depth == 5.0  # a perfect sensor: MoMa-LLM's 5 m


def test_episode_notes() -> None:
    assert episode_notes(5.0, 5.0, 0.0, 3) == ()
    (depth,) = episode_notes(1.0, 5.0, 0.02, 2)
    assert "kept depth to 1 m" in depth and "0.02 z^2" in depth
    assert episode_notes(4.0, 5.0, 0.0, 2) == ()  # a depth the user chose: no note
    (_, empty) = episode_notes(1.0, 5.0, 0.02, 0)
    assert "ended without a room" in empty
    assert "ended without a room" in episode_notes(5.0, 5.0, 0.0, None)[0]
    (invalid,) = episode_notes(5.0, 5.0, 0.0, 3, None, ["'room:9' is not a node", "x"])
    assert invalid == ("2 of the planner's actions were invalid and spent a step each (the "
                       "first: 'room:9' is not a node)")


def test_live_only_options_refused_with_house_navigation(tmp_path: Path) -> None:
    house_nav = dataclasses.replace(OPTS, navigation="house")
    assert house_nav.mapping().every == 10  # the defaults of live navigation pass
    live = dataclasses.replace(OPTS.live, peek=False, look_in=0.5)
    with pytest.raises(SgtoolError, match="^--look-in, --no-peek: for --navigation live"):
        dataclasses.replace(house_nav, live=live).mapping()
    with pytest.raises(SgtoolError, match="^--explore-on: .* does not use it$"):
        dataclasses.replace(house_nav, explore_on=2).mapping()
    assert dataclasses.replace(OPTS, live=live, explore_on=2).mapping().every == 10
    r = CliRunner().invoke(cli, ["run", "--navigation", "house", "--sight-lines", "--seed",
                                 "3", "--rooms", "4-4", "-p", "random", "-o",
                                 str(tmp_path / "x.mcap")])
    assert r.exit_code == 2 and "--sight-lines: for --navigation live" in r.output


def _scout_in_house_3(tmp_path: Path, query: str, *args: str) -> Path:
    """`sgtool run --planner scout` in the pinned generated house 3 (5 rooms; its targets
    and the drives past them, support.pinned_houses) searching ``query`` with ``args``;
    the log's path."""
    house = pinned_house_path("generated-3-rooms-4-5")
    out = tmp_path / "run.mcap"
    r = CliRunner().invoke(cli, ["run", "--planner", "scout", "--house", str(house), "--query",
                                 query, *args, "-o", str(out)])
    assert r.exit_code == 0, r.output
    return out


def test_house_navigation_ends_the_skill_when_the_target_is_in_the_graph(tmp_path) -> None:
    """`--navigation house`: the episode ends at the refresh whose graph holds the target,
    as live navigation does; it drove on to the next cabinet first (16 frames, 2.1 m
    more, counted in SPL and frames per room)."""
    from sgtool.recorders.sim.live_skills import IN_VIEW

    out = _scout_in_house_3(tmp_path, "apple pie", "--resolution", "96x72", "--max-steps",
                            "10", "--navigation", "house")
    with LogReader(out) as log:
        graphs = [(t, SceneGraph.from_dict(g)) for t, g in log.records("scene_graph")]
        (t_last, last), *_ = reversed(list(log.records("action")))
    first = next(t for t, g in graphs if any(o.category == "apple pie" for o in g.objects))
    assert t_last == first and last["message"] == IN_VIEW and last["outcome"] == "success"


def test_no_step_is_asked_for_once_an_action_took_the_last_frame(tmp_path) -> None:
    """The frame budget spent exactly as an action ends: the episode ends on frames; the
    planner was asked once more and that step (failed at once, 0 m) was counted."""
    out = _scout_in_house_3(tmp_path, "carving knife", "--resolution", "64x48",
                            "--max-steps", "20", "--frames-per-room", "8")
    (logged,) = read_log_episodes(out)
    res = logged.result()
    assert res.end == "frames" and logged.episode.frames == 40  # 8 frames x 5 rooms
    assert not [d for d in logged.decisions if "frame budget" in str(d.action.reason) + str(
        d.action.unknown.get("message"))]


def test_eval_of_logs_run_with_other_step_budgets_says_so(house, tmp_path) -> None:
    """Episode logs of --max-steps 2 and 3 given together: eval said so of bench folders
    only and pooled the logs silently."""
    logs = []
    for steps in ("2", "3"):
        out = tmp_path / f"s{steps}.mcap"
        r = CliRunner().invoke(cli, ["run", "--planner", "greedy", "--seed", str(SEED),
                                     "--rooms", ROOMS, "--episode", "0", "--resolution",
                                     "64x48", "--max-steps", steps, "-o", str(out)])
        assert r.exit_code == 0, r.output
        logs.append(str(out))
    r = CliRunner().invoke(cli, ["eval", *logs])
    assert r.exit_code == 0, r.output
    assert "the logs given ran with different max_steps (2 (1 episode(s)), 3 (1 " \
        "episode(s)))" in r.stderr


def test_an_open_cut_short_by_the_target_in_view_is_no_open(tmp_path) -> None:
    """`--navigation house`: the target came into view while the robot drove to a cabinet
    to open it: the cabinet never opened, and n_open counted it (6 where the simulator
    opened 5)."""
    out = tmp_path / "o2.mcap"
    r = CliRunner().invoke(cli, ["run", "--planner", "scout", "--navigation", "house",
                                 "--success", "done", "--resolution", "80x60", "--episode",
                                 "2", "-o", str(out)])
    assert r.exit_code == 0, r.output
    with LogReader(out) as log:
        instances = [rec for _, rec in log.records("instances")]
        (_, ended), *_ = reversed(list(log.records("episode")))
    opened = {i["spec_id"] for rec in instances for i in rec["instances"]
              if i.get("state") == "open"}  # doors and furniture the robot opened
    shut = {i["spec_id"] for i in instances[0]["instances"] if i.get("state") == "closed"}
    assert ended["extra"]["n_open"] == len(opened & shut)
