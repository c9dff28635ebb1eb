"""Agreement of LLM-generated relational labels with a reference set, and ``--llm-slice``."""

from __future__ import annotations

import math

import pytest
from click.testing import CliRunner

from sgtool.cli import cli
from sgtool.commands.distill import parse_llm_slice
from sgtool.errors import SgtoolError
from sgtool.semantics.llm_knowledge import agreement
from sgtool.semantics.relational_set import table_to_set


def test_agreement_on_common_pairs() -> None:
    llm = table_to_set("containment", {("kitchen", "frying pans"): 0.9, ("bathroom", "pot"): 0.6,
                                       ("bathroom", "soap"): 0.8, ("garage", "car"): 1.0})
    ref = table_to_set("containment", {("kitchen", "frying_pan"): 0.3, ("bathroom", "pot"): 0.0,
                                       ("bathroom", "soap"): 0.5, ("kitchen", "soap"): 0.0})
    a = agreement(llm, ref)
    # three pairs in both (names compared as singular words); the pot in the bathroom: no
    assert (a.relation, a.common, a.agree, a.llm_pairs) == ("containment", 3, 2, 4)
    assert a.rate == pytest.approx(2 / 3)
    empty = agreement(table_to_set("containment", {("attic", "x"): 1.0}), ref)
    assert empty.common == 0 and math.isnan(empty.rate)


def test_slice_option() -> None:
    assert parse_llm_slice(None) == {}
    assert parse_llm_slice("3,2,4") == {"max_rooms": 3, "max_categories": 2, "max_objects": 4}
    for bad in ("3,2", "a,b,c", "0,1,1"):
        with pytest.raises(SgtoolError, match="--llm-slice"):
            parse_llm_slice(bad)
    r = CliRunner().invoke(cli, ["distill", "--source", "llm", "--llm-slice", "1,2"])
    assert r.exit_code == 2 and r.output.startswith("sgtool: error: --llm-slice '1,2'")


def knowledge_answer(request: dict) -> dict:
    """A scripted LLM for SCOUT's generation: two rooms, one category each, a few objects;
    labels a refrigerator and a microwave for the kitchen, a toothbrush for the bathroom."""
    import json

    p = request["messages"][-1]["content"]
    if "most common room categories" in p:
        return {"text": '["kitchen", "bathrooms"]'}
    if "categories of objects found in" in p:
        return {"text": '["appliances"]'}
    if "different appliance found in a kitchen" in p:
        return {"text": '```json\n["refrigerators", "microwave"]\n```'}
    if "different appliance found in a bathroom" in p:
        return {"text": '["toothbrush"]'}
    if p.startswith("For the object"):
        kitchen = "toothbrush" not in p
        return {"text": json.dumps({"kitchen": 0.9 if kitchen else 0.1,
                                    "bathroom": 0.1 if kitchen else 0.9})}
    return {"text": json.dumps([{"object": "sink", "label": 1},
                                {"object": "bed", "label": 0}])}


def test_distill_from_a_recorded_transcript(tmp_path, monkeypatch) -> None:
    """``distill --source llm`` on a small slice against a scripted endpoint records every
    exchange in the cache; the same command offline (no endpoint) answers from that
    transcript alone and prints the same agreement with BEHAVIOR-1K, training the same
    weights."""
    from support.semantics_fixtures import ChatServer

    for var in ("SGTOOL_LLM_BASE_URL", "OPENAI_BASE_URL", "SGTOOL_LLM_API_KEY",
                "OPENAI_API_KEY"):
        monkeypatch.delenv(var, raising=False)
    cache = tmp_path / "cache"
    args = ["distill", "--source", "llm", "--llm-slice", "2,1,2", "--llm-cache", str(cache),
            "--epochs-containment", "1", "--epochs-cooccurrence", "1"]
    with ChatServer(responder=knowledge_answer) as srv:
        live = CliRunner().invoke(cli, [*args, "--out", str(tmp_path / "w1"),
                                        "--llm-base-url", srv.base_url, "--llm-model", "m"])
        asked = len(srv.requests)
        # JSON mode (an object) only where an object is asked for: the containment labels
        modes = {r["messages"][-1]["content"].startswith("For the object"):
                 r.get("response_format") for r in srv.requests}
    assert live.exit_code == 0, live.output
    # 1 room list + 2 category lists + 2 object lists + 2 labels x 3 objects
    assert asked == 11
    assert modes == {True: {"type": "json_object"}, False: None}
    assert {r.get("max_tokens") for r in srv.requests} == {512}  # --llm-max-tokens default
    assert len((cache / "exchanges.jsonl").read_text().splitlines()) == asked
    offline = CliRunner().invoke(cli, [*args, "--out", str(tmp_path / "w2")])
    assert offline.exit_code == 0, offline.output
    assert "11 prompts (11 cached, 0 asked, 0 skipped)" in offline.stderr
    lines = [x for x in live.stderr.splitlines() if "vs BEHAVIOR-1K" in x]
    # 3 objects x 2 rooms containment pairs, 3 x 2 co-occurrence pairs from the answers
    assert [x.split(": ")[1].split(" pairs")[0].split(" of ")[1] for x in lines] == ["6", "6"]
    assert lines == [x for x in offline.stderr.splitlines() if "vs BEHAVIOR-1K" in x]
    for name in ("containment.safetensors", "cooccurrence.safetensors"):
        assert (tmp_path / "w1" / name).read_bytes() == (tmp_path / "w2" / name).read_bytes()
