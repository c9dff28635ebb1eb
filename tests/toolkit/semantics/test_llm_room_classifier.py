"""MoMa-LLM's LLM room classification: prompt, cache per object set, constraint, fallback,
logged exchanges that replay offline."""

from __future__ import annotations

from support.semantics_fixtures import ChatServer

from sgtool.llm.client import ChatResult, LlmSettings, OpenAIChatClient
from sgtool.llm.constraints import choice_grammar
from sgtool.llm.recorded import ReplayChatClient, TranscriptWriter
from sgtool.semantics.room_classification import LlmRoomClassifier, match_room_type

TYPES = ("bathroom", "bedroom", "kitchen", "living_room")


def client(srv: ChatServer) -> OpenAIChatClient:
    return OpenAIChatClient(LlmSettings.resolve(base_url=srv.base_url, model="m",
                                                api_key="k", timeout_s=5.0))


class Fixed:
    name = "fixed"

    def classify(self, cats):
        return [("bedroom", 0.7), ("kitchen", 0.3)]


def test_asks_once_per_object_set_and_logs(tmp_path) -> None:
    with ChatServer([{"text": "Living room."}, {"text": "kitchen"}]) as srv:
        c = LlmRoomClassifier(client(srv), TYPES)
        assert c.constraint == "none"  # the scripted server is no llama.cpp
        assert c.classify(["sofa", "TV_stand", "sofa"]) == [("living_room", 1.0)]
        assert c.classify(["tv stand", "sofa"]) == [("living_room", 1.0)]  # cached
        assert c.classify(["fridge"]) == [("kitchen", 1.0)]
        assert c.classify([]) == []
        assert len(srv.requests) == 2
    user = srv.requests[0]["messages"][1]["content"]
    assert user.startswith("A room contains: sofa, tv stand.\n")
    assert "Choose one of: bathroom, bedroom, kitchen, living room." in user
    assert [e["purpose"] for e in c.exchanges] == ["room_classification"] * 2
    assert [e["verdict"] for e in c.exchanges] == ["ok", "ok"]
    # the exchanges replay without the endpoint
    path = tmp_path / "rooms.jsonl"
    with TranscriptWriter(path, append=False) as t:
        for e in c.exchanges:
            t.write(e)
    r = LlmRoomClassifier(ReplayChatClient(path), TYPES)
    assert r.classify(["fridge"]) == [("kitchen", 1.0)]
    assert r.classify(["sofa", "tv stand"]) == [("living_room", 1.0)]


def test_unusable_answers_and_faults_fall_back() -> None:
    with ChatServer([{"text": "a garage, I think"}, {"status": 500}]) as srv:
        c = LlmRoomClassifier(client(srv), TYPES, fallback=Fixed())
        assert c.classify(["car"]) == [("bedroom", 0.7), ("kitchen", 0.3)]
        assert c.classify(["bike"]) == [("bedroom", 0.7), ("kitchen", 0.3)]
    assert c.exchanges[0]["verdict"] == "invalid: no room type"
    assert "HTTP 500" in c.exchanges[1]["error"]
    with ChatServer([{"text": "no idea"}]) as srv:
        assert LlmRoomClassifier(client(srv), TYPES).classify(["car"]) == []


def test_constrained_to_the_room_types() -> None:
    seen = []

    class Grammar:
        model = "g"
        takes_constraint = True

        def complete(self, messages, constraint=None):
            seen.append(constraint)
            return ChatResult("bathroom", "g", 0.01)

    c = LlmRoomClassifier(Grammar(), TYPES, constraint="grammar")
    assert c.classify(["toilet"]) == [("bathroom", 1.0)]
    assert seen[0].request_fields() == {"extra_body": {"grammar": choice_grammar(
        ["bathroom", "bedroom", "kitchen", "living room"])}}


def test_match_room_type() -> None:
    words = ("bathroom", "bedroom", "kitchen", "living room", "room")
    assert match_room_type("It is a living room.", words) == "living room"
    assert match_room_type('{"answer": "kitchen"}', words) == "kitchen"
    assert match_room_type("Bedroom", words) == "bedroom"
    assert match_room_type("garage", words) is None
