"""MoMa-LLM against a scripted chat-completions server on 127.0.0.1: commands, faults, replay.

Every fault (garbage text, HTTP 500, timeout, malformed JSON, a room that does not exist,
an early done()) must end in a retry that the model can learn from or in a clear failure,
never in an exception.
"""

from __future__ import annotations

import dataclasses
import json

import pytest
from support.semantics_fixtures import ChatServer, answer, house

from sgtool.llm.client import LlmConfigError
from sgtool.planning.base import Feedback
from sgtool.planning.registry import make_planner
from sgtool.scenegraph.graph import ObjectNode


def planner(server: ChatServer, **kw):
    kw.setdefault("timeout_s", 5.0)
    return make_planner("moma-llm", base_url=server.base_url, model="scripted-model",
                        api_key="test", **kw)


def test_valid_command_is_grounded_and_logged() -> None:
    with ChatServer([answer("go_to_and_open(kitchen, fridge)")]) as srv:
        p = planner(srv)
        p.reset("milk")
        a = p.decide(house())
    assert (a.skill, a.target) == ("open", "obj:10")
    assert a.reason == "Closest lead."
    assert a.decision_time_s > 0
    (ex,) = p.exchanges
    assert ex["model"] == "scripted-model" and ex["error"] is None and ex["attempt"] == 0
    assert ex["prompt_tokens"] == 101 and ex["completion_tokens"] == 9
    assert ex["latency_s"] > 0 and ex["step"] == 1 and ex["query"] == "milk"
    assert ex["response"].endswith("go_to_and_open(kitchen, fridge)")
    # what the model was shown: task, skills, the encoded scene
    sent = srv.requests[0]["messages"]
    assert sent[0]["role"] == "system" and "find a milk" in sent[0]["content"]
    assert "go_to_and_open(room, object)" in sent[0]["content"]
    user = sent[1]["content"]
    assert "- kitchen: [2 chairs, closed bottom cabinet, closed fridge, countertop, " \
           "unexplored area]" in user
    assert "Rooms with space leading out: living room (far)." in user
    assert "Rooms with closed doors: living room." in user
    assert "Unexplored rooms seen through doors: unexplored room 4 (far)." in user
    assert json.dumps(ex)  # a plain JSON-serialisable record


@pytest.mark.parametrize(
    "fault,error_part",
    [
        ({"text": "I think the milk is probably in the fridge."}, None),
        ({"status": 500}, "HTTP 500"),
        ({"raw": b"{this is not json"}, "unusable reply"),
        ({"sleep": 1.5, "text": "too late"}, "no reply within"),
    ],
)
def test_fault_then_retry(fault: dict, error_part: str | None) -> None:
    with ChatServer([fault, answer("explore(kitchen)")]) as srv:
        p = planner(srv, timeout_s=0.5)
        p.reset("milk")
        a = p.decide(house())
    assert (a.skill, a.target) == ("explore", "frontier:1")
    assert [e["attempt"] for e in p.exchanges] == [0, 1]
    if error_part is None:  # garbage text: the model is told what was wrong
        retry = srv.requests[1]["messages"]
        assert retry[-2]["role"] == "assistant"
        assert "could not be executed" in retry[-1]["content"]
        assert "no command found" in retry[-1]["content"]
    else:  # transport fault: the same prompt again, the error in the log
        assert error_part in p.exchanges[0]["error"]
        assert srv.requests[1]["messages"] == srv.requests[0]["messages"]


def test_nonexistent_room_is_fed_back_with_the_valid_rooms() -> None:
    script = [answer("navigate(garage, toolbox)"), answer("navigate(bathroom, sink)"),
              answer("explore(kitchen)")]
    with ChatServer(script) as srv:
        p = planner(srv)
        p.reset("toothbrush")
        a = p.decide(house())
        assert (a.skill, a.target) == ("navigate", "obj:20")
        fb = srv.requests[1]["messages"][-1]["content"]
        assert "room 'garage' does not exist" in fb
        assert "bathroom, kitchen, living room, unexplored room 4" in fb
        p.feedback(Feedback(a, "success", "found towel"))
        p.decide(house())
    # the next decision's history keeps the rejected command (MoMa-LLM: invalid argument)
    hist = srv.requests[2]["messages"][1]["content"].split("Previous actions:")[1]
    assert hist.splitlines()[1:3] == [
        "- navigate(garage, toolbox) - invalid argument: room 'garage' does not exist; "
        "rooms are: bathroom, kitchen, living room, unexplored room 4",
        "- navigate(bathroom, sink) - success: found towel",
    ]


def test_wrong_object_and_early_done_are_invalid() -> None:
    script = [answer("navigate(bathroom, sofa)"), answer("done()"),
              answer("go_to_and_open(bathroom, bottom cabinet)")]
    with ChatServer(script) as srv:
        p = planner(srv)
        p.reset("toothbrush")
        a = p.decide(house())
    assert (a.skill, a.target) == ("open", "obj:21")
    msgs = srv.requests[2]["messages"]
    assert "there is no 'sofa' in the bathroom; it has: bottom cabinet, sink" in msgs[-3]["content"]
    assert "done() is only valid once a toothbrush has been observed" in msgs[-1]["content"]


def test_done_when_target_in_view() -> None:
    brush = ObjectNode("obj:99", "toothbrush", "obj:21", "room:2", (6.5, -1.0, 0.3),
                       relation="inside")
    with ChatServer([answer("done()")]) as srv:
        p = planner(srv)
        p.reset("toothbrush")
        a = p.decide(house(extra_objects=[brush]))
    assert (a.skill, a.target) == ("done", "obj:99")


def test_clear_failure_after_max_attempts() -> None:
    """Answers the planner cannot use (a server error among them) at every attempt: the
    planner's failure, it gives up."""
    with ChatServer([{"raw": b"{this is not json"}, {"status": 500},
                     {"raw": b"[1]"}]) as srv:
        p = planner(srv, max_attempts=3)
        p.reset("milk")
        a = p.decide(house())
    assert a.skill == "done" and a.target is None
    assert a.reason.startswith("llm failure: no valid command after 3 attempts")
    assert len(p.exchanges) == 3 and all(e["error"] for e in p.exchanges)


def test_an_endpoint_gone_at_every_attempt_stops_the_run() -> None:
    """An endpoint that answered before and fails every attempt of a decision (HTTP 5xx,
    or its connection refused): an outage, a one-line error that stops the run, not the
    planner giving up (which would score it, and a resumed run-bench would keep it)."""
    from sgtool.llm.client import LlmUnreachableError

    with ChatServer([answer("explore(kitchen)"), {"status": 500}, {"status": 503},
                     {"status": 502}]) as srv:
        p = planner(srv, max_attempts=3)
        p.reset("milk")
        assert p.decide(house()).skill == "explore"
        with pytest.raises(LlmUnreachableError, match=r"^the LLM endpoint failed at all 3 "
                                                      r"attempts of a decision \(.*HTTP 502"):
            p.decide(house())
    assert len(p.exchanges) == 4 and all(e["error"] for e in p.exchanges[1:])
    srv = ChatServer([answer("explore(kitchen)")])
    with srv:
        p = planner(srv, max_attempts=2)
        p.reset("milk")
        p.decide(house())
    with pytest.raises(LlmUnreachableError, match="connection failed"):  # server gone
        p.decide(house())


@pytest.mark.parametrize("bad", [
    {"status": 500, "type": "model_error", "message": "The model produced invalid content."},
    {"status": 504, "message": "upstream request timeout"},
])
def test_a_model_error_at_every_attempt_is_the_planner_giving_up(bad: dict) -> None:
    """HTTP 500 of type model_error (OpenAI: "The model produced invalid content", the same
    for the same prompt), or a gateway's timeout (504: a model too slow, as a timeout of the
    client), is the model's failure: the episode ends given up, the run goes on (an outage
    would stop it and stop every resumed run)."""
    with ChatServer([answer("explore(kitchen)"), bad, bad, bad]) as srv:
        p = planner(srv, max_attempts=3)
        p.reset("milk")
        assert p.decide(house()).skill == "explore"
        a = p.decide(house())
    assert a.skill == "done" and bad["message"].rstrip(".") in a.reason


def test_an_endpoint_that_never_answers_is_a_configuration_error() -> None:
    """Connection refused before any reply: a wrong address, reported at once (the CLI
    prints it as one line) instead of every episode quietly giving up."""
    from sgtool.llm.client import LlmUnreachableError

    srv = ChatServer([])
    url = srv.base_url
    srv.close()
    p = make_planner("moma-llm", base_url=url, api_key="x", max_attempts=2, timeout_s=2.0)
    p.reset("milk")
    with pytest.raises(LlmUnreachableError, match="cannot reach the LLM endpoint"):
        p.decide(house())


def test_stuck_detector_ends_episode() -> None:
    g = house()
    with ChatServer([answer("navigate(kitchen, countertop)")] * 3) as srv:
        p = planner(srv)
        p.reset("milk")
        actions = []
        for _ in range(3):
            a = p.decide(g)
            actions.append(a)
            p.feedback(Feedback(a, "failure", "blocked"))
    assert [a.target for a in actions[:2]] == ["obj:12", "obj:12"]
    assert actions[2].skill == "done" and actions[2].target is None
    assert actions[2].reason.startswith("stuck:")


def test_history_realigned_and_feedback_visible() -> None:
    g = house()
    script = [answer("explore(living room)"), answer("navigate(kitchen, countertop)")]
    with ChatServer(script) as srv:
        p = planner(srv)
        p.reset("milk")
        a = p.decide(g)
        assert a.target == "frontier:2"
        p.feedback(Feedback(a, "failure", "path blocked by a box"))
        # the living room turns out to be a kitchen annex: reclassified
        rooms = tuple(dataclasses.replace(r, category="pantry_room") if r.id == "room:3" else r
                      for r in g.rooms)
        p.decide(dataclasses.replace(g, rooms=rooms))
    second = srv.requests[1]["messages"][1]["content"]
    assert "- explore(pantry room) - failure: path blocked by a box" in second
    assert "living room" not in second


def test_replay_reproduces_a_run_without_endpoint(tmp_path) -> None:
    transcript = tmp_path / "run.jsonl"
    script = [{"status": 500}, answer("explore(kitchen)"), {"text": "hmm"},
              answer("go_to_and_open(kitchen, fridge)")]
    g = house()
    with ChatServer(script) as srv:
        p = planner(srv, transcript=str(transcript))
        p.reset("milk")
        live = [p.decide(g)]
        p.feedback(Feedback(live[0], "success"))
        live.append(p.decide(g))
        p.close()
    lines = transcript.read_text().splitlines()
    assert len(lines) == 4 and all(json.loads(x)["prompt_sha256"] for x in lines)
    r = make_planner("moma-llm", replay=str(transcript))
    r.reset("milk")
    replayed = [r.decide(g)]
    r.feedback(Feedback(replayed[0], "success"))
    replayed.append(r.decide(g))
    strip = [(a.skill, a.target, a.reason) for a in live]
    assert [(a.skill, a.target, a.reason) for a in replayed] == strip
    assert all(e["source"] == "replay" for e in r.exchanges)
    # a different scene is a prompt the transcript does not hold: clear failure
    r.reset("milk")
    a = r.decide(house(robot_room="room:2"))
    assert a.skill == "done" and a.target is None and "no (more) responses" in a.reason


def test_no_endpoint_configured_is_a_user_error(monkeypatch) -> None:
    for var in ("SGTOOL_LLM_BASE_URL", "OPENAI_BASE_URL", "SGTOOL_LLM_API_KEY",
                "OPENAI_API_KEY"):
        monkeypatch.delenv(var, raising=False)
    with pytest.raises(LlmConfigError, match="no LLM endpoint configured"):
        make_planner("moma-llm")


def test_symbolic_episode_end_to_end_over_http() -> None:
    """A whole SymSearch episode: the endpoint is a rule-following stand-in for an LLM
    that reads the scene text it is sent (explore unexplored rooms, open closed doors, then
    open or look at the first unvisited thing, done() once the target is in reach)."""
    import re

    from sgtool.datasets.episodes import list_episodes
    from sgtool.datasets.generator import generate_house
    from sgtool.recorders.symbolic_environment import SymbolicHouse, run_episode

    spec = generate_house(101, rooms=(6, 8), split="eval")
    house_ = SymbolicHouse(spec)
    ep = list_episodes(spec, n=1, seed=3)[0]
    tried: set[str] = set()

    def llm(req: dict) -> dict:
        user = req["messages"][1]["content"]
        scene, _, history = user.partition("Previous actions:")
        if re.search(rf"\b{re.escape(ep.query)}", scene.split("Observed rooms")[-1]):
            return answer("done()")
        revealed = {x.strip() for m in re.finditer(r"found ([^\n]*)", history)
                    for x in m.group(1).split(",")}

        def first_new(cmds, repeat: bool = False):
            for cmd in cmds:
                if repeat or cmd not in tried:
                    tried.add(cmd)
                    return answer(cmd)
            return None

        doors = re.search(r"Rooms with closed doors: (.*)\.", scene)
        listing = re.findall(r"^- ([^:\n]+): \[([^\]]*)\]", scene, re.M)
        items = [(room, re.sub(r"^\d+ ", "", it.strip())) for room, its in listing
                 for it in its.split(",") if it.strip()]
        return (first_new(f"explore({m})" for m in re.findall(r"(unexplored room \d+)", scene))
                or first_new(f"go_to_and_open({re.sub(r' [(].*', '', r)}, door)"
                             for r in (doors.group(1).split(", ") if doors else []))
                or first_new(f"explore({room})" for room, it in items
                             if it == "unexplored area")
                # closed things stay listed as closed until opened: ask again freely
                or first_new((f"go_to_and_open({room}, {it})" for room, it in items
                              if it.startswith("closed ")), repeat=True)
                or first_new(f"navigate({room}, {it})" for room, it in items
                             if it != "unexplored area" and it.split()[-1].rstrip("s")
                             not in {x.split()[-1] for x in revealed})
                or answer("done()"))

    with ChatServer(responder=llm) as srv:
        p = planner(srv, stuck_repeats=0)
        r = run_episode(house_, p, ep.query, list(ep.targets), seed=0, episode_index=0)
        assert not srv.errors
    assert r.success and r.n_invalid == 0, r.trace
    assert len(p.exchanges) >= r.steps
    assert all(e["step"] >= 1 for e in p.exchanges)
