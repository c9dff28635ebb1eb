"""Answers constrained to the scene: the valid commands, the grammar, the JSON schema, and
what the planner sends (against a scripted endpoint on 127.0.0.1)."""

from __future__ import annotations

import json

import pytest
from support.semantics_fixtures import ChatServer, answer, house

from sgtool.llm.constraints import (
    Constraint,
    ConstraintError,
    check_kind,
    command_grammar,
    command_schema,
    detect_kind,
    gbnf_literal,
    server_root,
)
from sgtool.planning.moma.choices import valid_commands
from sgtool.planning.moma.commands import ground, parse_response
from sgtool.planning.moma.scene_text import encode_scene
from sgtool.planning.registry import make_planner
from sgtool.scenegraph.graph import ObjectNode

MILK = ObjectNode("obj:15", "milk", "region:1.1", "room:1", (0.2, 1.0, 0.0))


def test_valid_commands_of_the_test_house() -> None:
    g = house()
    cmds = valid_commands(g, encode_scene(g), "milk")
    # no milk in view: no done(); the unexplored room is explored, not searched
    assert "done()" not in cmds
    assert cmds[:3] == ("explore(kitchen)", "explore(living room)", "explore(unexplored room 4)")
    assert "go_to_and_open(kitchen, fridge)" in cmds
    assert "go_to_and_open(living room, door)" in cmds  # the closed door to room 4
    assert "close(kitchen, fridge)" not in cmds  # closed already
    assert "go_to_and_open(kitchen, chair)" not in cmds  # a chair does not open
    assert not any("unexplored room 4," in c for c in cmds)
    # the bathroom has no frontier: nothing to explore there
    assert "explore(bathroom)" not in cmds
    # every listed command grounds
    scene = encode_scene(g)
    for c in cmds:
        ground(parse_response(f"Command: {c}"), g, scene, "milk")
    with_milk = house([MILK])
    assert valid_commands(with_milk, encode_scene(with_milk), "milk")[0] == "done()"


def test_grammar_and_schema_text() -> None:
    assert gbnf_literal('say "hi"\\n') == '"say \\"hi\\"\\\\n"'
    g = command_grammar(["explore(kitchen)", "done()"], reason_chars=30)
    assert g.splitlines() == [
        'root ::= "Analysis: " line "\\nReasoning: " line "\\nCommand: " command',
        "line ::= [^\\n]{1,30}",
        'command ::= "explore(kitchen)" | "done()"',
    ]
    s = command_schema(["done()"], 20)
    assert s["properties"]["command"] == {"type": "string", "enum": ["done()"]}
    assert s["properties"]["analysis"]["maxLength"] == 20
    assert s["required"] == ["analysis", "reasoning", "command"]
    with pytest.raises(ValueError):
        command_grammar([])
    assert Constraint("grammar", ("done()",), 5).request_fields() == {
        "extra_body": {"grammar": command_grammar(["done()"], 5)}}
    rf = Constraint("json_schema", ("done()",), 5).request_fields()["response_format"]
    assert rf["type"] == "json_schema" and rf["json_schema"]["schema"] == command_schema(
        ["done()"], 5)


def test_kinds_and_detection() -> None:
    assert check_kind("JSON-schema") == "json_schema"
    with pytest.raises(ConstraintError, match="choose one of: auto, grammar"):
        check_kind("regex")
    assert server_root("http://h:1/v1/") == "http://h:1"
    assert detect_kind(None) == "json_schema"
    assert detect_kind("https://api.openai.com/v1") == "json_schema"
    assert detect_kind("http://127.0.0.1:9/v1", timeout_s=0.5) == "none"  # nothing there
    with ChatServer([]) as srv:  # answers no GET /props: not llama.cpp
        assert detect_kind(srv.base_url) == "none"


def test_detection_sends_the_api_key() -> None:
    """A llama.cpp server started with a key answers GET /props only with it: without the
    key the planner lost its grammar (a review helper's server, 0 valid answers of 10)."""
    import threading
    from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer

    class Props(BaseHTTPRequestHandler):
        def log_message(self, *args: object) -> None:
            pass

        def do_GET(self) -> None:  # noqa: N802
            ok = self.headers.get("Authorization") == "Bearer lab-key"
            body = json.dumps({"default_generation_settings": {}}).encode() if ok else b"{}"
            self.send_response(200 if ok else 401)
            self.send_header("Content-Length", str(len(body)))
            self.end_headers()
            self.wfile.write(body)

    srv = ThreadingHTTPServer(("127.0.0.1", 0), Props)
    threading.Thread(target=srv.serve_forever, daemon=True).start()
    try:
        url = f"http://127.0.0.1:{srv.server_address[1]}/v1"
        assert detect_kind(url) == "none"
        assert detect_kind(url, api_key="lab-key") == "grammar"
    finally:
        srv.shutdown()
        srv.server_close()


def test_json_answer_parses_with_its_sections() -> None:
    cmd = parse_response(json.dumps({"analysis": "milk is cold", "reasoning": "fridge",
                                     "command": "go_to_and_open(kitchen, fridge)"}))
    assert (cmd.name, cmd.args) == ("go_to_and_open", ("kitchen", "fridge"))
    assert (cmd.analysis, cmd.reasoning) == ("milk is cold", "fridge")


def planner(srv: ChatServer, constraint: str):
    return make_planner("moma-llm", base_url=srv.base_url, model="m", api_key="k",
                        timeout_s=5.0, constraint=constraint, reason_chars=50, timed=False)


def test_planner_sends_the_grammar_of_the_scene_and_logs_the_verdict() -> None:
    with ChatServer([{"text": "Command: explore(garage)"},
                     answer("go_to_and_open(kitchen, fridge)")]) as srv:
        p = planner(srv, "grammar")
        p.reset("milk")
        a = p.decide(house())
    assert (a.skill, a.target) == ("open", "obj:10")
    g = house()
    want = command_grammar(valid_commands(g, encode_scene(g), "milk"), 50)
    assert [r["grammar"] for r in srv.requests] == [want, want]
    assert "response_format" not in srv.requests[0]
    # a reply outside the grammar (a server that ignored it) is still caught and counted
    assert [e["verdict"][:8] for e in p.exchanges] == ["invalid:", "ok"]
    assert {e["constraint"] for e in p.exchanges} == {"grammar"}
    assert p.invalid_commands == 1
    p.reset("milk")
    assert p.invalid_commands == 0
    assert all("cache_prompt" not in r for r in srv.requests)  # the server's default
    # at temperature 0 a llama.cpp request is computed whole: the same answer again
    with ChatServer([answer("go_to_and_open(kitchen, fridge)")]) as srv:
        p = make_planner("moma-llm", base_url=srv.base_url, model="m", api_key="k",
                         timeout_s=5.0, constraint="grammar", temperature=0.0, timed=False)
        p.reset("milk")
        p.decide(house())
    assert srv.requests[0]["cache_prompt"] is False and srv.requests[0]["temperature"] == 0


def test_planner_sends_a_json_schema_and_reads_the_json_answer() -> None:
    reply = json.dumps({"analysis": "a", "reasoning": "b", "command": "explore(kitchen)"})
    with ChatServer([{"text": reply}]) as srv:
        p = planner(srv, "json_schema")
        p.reset("milk")
        a = p.decide(house())
    assert (a.skill, a.target, a.reason) == ("explore", "frontier:1", "b")
    schema = srv.requests[0]["response_format"]["json_schema"]["schema"]
    assert "explore(kitchen)" in schema["properties"]["command"]["enum"]
    assert "grammar" not in srv.requests[0]


def test_auto_and_none_send_nothing_to_an_unknown_endpoint() -> None:
    for kind in ("auto", "none"):
        with ChatServer([answer("explore(kitchen)")]) as srv:
            p = planner(srv, kind)
            p.reset("milk")
            p.decide(house())
        assert p.constraint == "none"
        assert "grammar" not in srv.requests[0] and "response_format" not in srv.requests[0]
        assert "constraint" not in p.exchanges[0] and p.exchanges[0]["verdict"] == "ok"
