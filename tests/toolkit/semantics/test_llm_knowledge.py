"""SCOUT's procedural LLM knowledge generation against a local scripted endpoint:
Household -> Rooms -> Categories -> Objects, labelling, caching, resuming, bad answers."""

from __future__ import annotations

import json
import re

import pytest
from support.semantics_fixtures import ChatServer

from sgtool.llm.client import LlmSettings, OpenAIChatClient
from sgtool.semantics.llm_knowledge import (
    CachedAsker,
    GenerationConfig,
    GenerationError,
    extract_json,
    generate_sets,
    normalize_name,
)

ROOMS = {"kitchen": {"cookware": ["Frying_Pans", "pot"], "appliance": ["fridge"]},
         "bathroom": {"toiletry": ["toothbrushes", "soap"]}}
HOME = {"frying pan": "kitchen", "pot": "kitchen", "fridge": "kitchen",
        "toothbrush": "bathroom", "soap": "bathroom"}


def household(req: dict) -> dict:
    """A deterministic fake LLM for the five prompt kinds."""
    p = req["messages"][-1]["content"]
    if "room categories of a household" in p:
        return {"text": "```json\n" + json.dumps(["Kitchen", "bathrooms"]) + "\n```"}
    m = re.search(r"categories of objects found in a (\w+)", p)
    if m:
        return {"text": json.dumps(sorted(c.title() for c in ROOMS[m.group(1)]))}
    m = re.search(r"List \d+ different (\w+) found in a (\w+)", p)
    if m:
        return {"text": "Sure! " + json.dumps(ROOMS[m.group(2)][m.group(1)])}
    m = re.search(r"For the object '([\w ]+)'", p)
    if m:
        home = HOME[m.group(1)]
        return {"text": json.dumps({"kitchen": 0.9 if home == "kitchen" else 0.1,
                                    "bathroom": 0.9 if home == "bathroom" else 0.2})}
    m = re.search(r"same place as a '([\w ]+)'", p)
    if m:
        q = m.group(1)
        items = [{"object": o, "label": int(HOME[o] == HOME[q])} for o in HOME if o != q]
        return {"text": json.dumps(items)}
    return {"text": "I do not understand"}


def asker(srv: ChatServer, cache) -> CachedAsker:
    client = OpenAIChatClient(LlmSettings.resolve(base_url=srv.base_url, model="m",
                                                  api_key="k", timeout_s=5))
    return CachedAsker(client, cache, max_attempts=2)


def test_generation_builds_both_sets(tmp_path) -> None:
    with ChatServer(responder=household) as srv:
        a = asker(srv, tmp_path)
        cont, cooc, rooms = generate_sets(a, GenerationConfig())
        n_requests = len(srv.requests)
    assert rooms == ("bathroom", "kitchen")  # normalised and singular
    assert set(cont.queries) == set(HOME)
    assert cont.target("kitchen", "frying pan") == pytest.approx(0.9)
    assert cont.target("bathroom", "frying pan") == pytest.approx(0.2)
    assert cooc.target("pot", "frying pan") == 1.0
    assert cooc.target("soap", "frying pan") == 0.0
    # 1 room list + 2 category lists + 3 object lists + 5 objects x 2 labels
    assert n_requests == 1 + 2 + 3 + 10 == a.stats.requested
    # a second run is served entirely from the cache, without any endpoint
    b = CachedAsker(None, tmp_path)
    cont2, cooc2, rooms2 = generate_sets(b, GenerationConfig())
    assert b.stats.requested == 0 and b.stats.cached == n_requests
    assert cont2.fingerprint() == cont.fingerprint() and cooc2.fingerprint() == cooc.fingerprint()


def test_interrupted_generation_resumes_from_the_cache(tmp_path) -> None:
    calls = {"n": 0}

    def dies_after_eight(req: dict) -> dict:
        calls["n"] += 1
        return household(req) if calls["n"] <= 8 else {"status": 503}

    with ChatServer(responder=dies_after_eight) as srv:
        with pytest.raises(GenerationError, match="rerun the same command to resume"):
            generate_sets(asker(srv, tmp_path), GenerationConfig())
    with ChatServer(responder=household) as srv:
        a = asker(srv, tmp_path)
        cont, _, _ = generate_sets(a, GenerationConfig())
        assert a.stats.cached == 8 and len(srv.requests) == 16 - 8
    assert len(cont.queries) == 5


def test_bad_answers_are_retried_once_then_skipped(tmp_path) -> None:
    def garbled_soap(req: dict) -> dict:
        p = req["messages"][-1]["content"]
        if "'soap'" in p and "probability" in p:
            return {"text": "soap is usually in the bathroom"}
        return household(req)

    with ChatServer(responder=garbled_soap) as srv:
        a = asker(srv, tmp_path)
        cont, _, _ = generate_sets(a, GenerationConfig())
        reminders = [r for r in srv.requests if "not valid JSON" in r["messages"][-1]["content"]]
    assert len(reminders) == 1
    assert a.stats.skipped == 1
    assert cont.target("bathroom", "soap") is None  # skipped, not guessed
    assert cont.target("bathroom", "toothbrush") == pytest.approx(0.9)


def test_parsing_helpers() -> None:
    assert normalize_name("Coffee_Mugs") == "coffee mug"
    assert normalize_name("glasses") == "glass"
    assert normalize_name("dishes") == "dish"
    assert normalize_name("bus") == "bus"
    assert extract_json('Here:\n```json\n["a", "b"]\n```') == ["a", "b"]
    assert extract_json('x {"k": 1} y') == {"k": 1}
    with pytest.raises(ValueError):
        extract_json("no json here")


def test_cli_distills_from_an_llm_and_replays_from_the_cache(tmp_path, monkeypatch) -> None:
    from click.testing import CliRunner

    from sgtool.commands.distill import command
    from sgtool.semantics.priors import LearnedPriors

    for var in ("SGTOOL_LLM_BASE_URL", "OPENAI_BASE_URL", "SGTOOL_LLM_API_KEY",
                "OPENAI_API_KEY"):
        monkeypatch.delenv(var, raising=False)
    cache, out = tmp_path / "cache", tmp_path / "w"
    args = ["--source", "llm", "--llm-cache", str(cache), "--out", str(out),
            "--epochs-containment", "2", "--epochs-cooccurrence", "2"]
    with ChatServer(responder=household) as srv:
        res = CliRunner().invoke(command, [*args, "--llm-base-url", srv.base_url,
                                           "--llm-model", "m"])
        assert res.exit_code == 0, res.output
    meta = json.loads((out / "metadata.json").read_text())
    assert meta["room_types"] == ["bathroom", "kitchen"]
    assert meta["split_fingerprint"].startswith("llm:")
    assert LearnedPriors(weights_dir=out).rooms(["kitchen"], "pot").shape == (1,)
    first = (out / "containment.safetensors").read_bytes()
    # no endpoint any more: the complete cache answers every prompt, same weights
    res = CliRunner().invoke(command, [*args, "--force"])  # the same folder again
    assert res.exit_code == 0, res.output
    assert (out / "containment.safetensors").read_bytes() == first
