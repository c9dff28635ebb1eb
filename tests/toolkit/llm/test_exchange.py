"""The ``sgtool.LlmExchange`` record and transcripts: schema conformance, keys, replay order."""

from __future__ import annotations

import json

import pytest

from sgtool.llm.client import LlmTransportError
from sgtool.llm.exchange import exchange_record, prompt_key
from sgtool.llm.recorded import ReplayChatClient, ReplayMiss, TranscriptError, TranscriptWriter
from sgtool.log.schemas import RECORDS

MSGS = [{"role": "system", "content": "You are a robot."},
        {"role": "user", "content": "Find a cup."}]
JSON_TYPES = {"string": str, "number": (int, float), "integer": int, "null": type(None),
              "array": list, "object": dict, "boolean": bool}


def conforms(record: dict, schema: dict) -> bool:
    """Required keys present and every declared property of the declared JSON type."""
    if any(k not in record for k in schema["required"]):
        return False
    for key, spec in schema["properties"].items():
        if key not in record:
            continue
        types = spec.get("type")
        if types is None:
            continue
        types = types if isinstance(types, list) else [types]
        if not isinstance(record[key], tuple(JSON_TYPES[t] for t in types)):
            return False
        if "integer" not in types and isinstance(record[key], bool):
            return False
    return True


def test_record_matches_the_log_schema() -> None:
    ok = exchange_record(model="m", messages=MSGS, response="Command: done()", latency_s=0.5,
                         prompt_tokens=12, completion_tokens=3, attempt=0, step=4, query="cup")
    bad = exchange_record(model="m", messages=MSGS, response=None, latency_s=0.0,
                          error="HTTP 500", attempt=2)
    schema = RECORDS["llm_exchange"].schema
    assert conforms(ok, schema) and conforms(bad, schema)
    assert json.loads(json.dumps(ok)) == ok
    assert ok["prompt_sha256"] == prompt_key(MSGS) == bad["prompt_sha256"]


def test_prompt_key_depends_on_role_and_content_only() -> None:
    extra = [dict(m, name="x") for m in MSGS]
    assert prompt_key(extra) == prompt_key(MSGS)
    assert prompt_key(MSGS[:1]) != prompt_key(MSGS)
    assert prompt_key([{"role": "user", "content": "Find a cup."}]) != \
        prompt_key([{"role": "system", "content": "Find a cup."}])


def test_replay_serves_answers_per_prompt_in_order(tmp_path) -> None:
    path = tmp_path / "t.jsonl"
    other = [{"role": "user", "content": "Find a mug."}]
    with TranscriptWriter(path, append=False) as w:
        w.write(exchange_record(model="m", messages=MSGS, response=None, latency_s=0,
                                error="timeout"))
        w.write(exchange_record(model="m", messages=other, response="B", latency_s=0))
        w.write(exchange_record(model="m", messages=MSGS, response="A1", latency_s=0))
        w.write(exchange_record(model="m", messages=MSGS, response="A2", latency_s=0))
    assert not (tmp_path / "t.jsonl.partial").exists()
    c = ReplayChatClient(path)
    with pytest.raises(LlmTransportError, match="replayed"):
        c.complete(MSGS)  # the recorded fault comes back first
    assert c.complete(MSGS).text == "A1"
    assert c.complete(other).text == "B"
    assert c.complete(MSGS).text == "A2"
    with pytest.raises(ReplayMiss):
        c.complete(MSGS)
    assert c.remaining() == 0


def test_transcript_errors_and_interrupted_last_line(tmp_path) -> None:
    with pytest.raises(TranscriptError, match="not found"):
        ReplayChatClient(tmp_path / "missing.jsonl")
    bad = tmp_path / "bad.jsonl"
    bad.write_text('{"model": "m"}\n')
    with pytest.raises(TranscriptError, match="not an sgtool.LlmExchange"):
        ReplayChatClient(bad)
    cut = tmp_path / "cut.jsonl"
    line = json.dumps(exchange_record(model="m", messages=MSGS, response="A", latency_s=0))
    cut.write_text(line + "\n" + line[:20])  # killed while writing the second record
    assert ReplayChatClient(cut).remaining() == 1
    mid = tmp_path / "mid.jsonl"
    mid.write_text(line[:20] + "\n" + line + "\n")
    with pytest.raises(TranscriptError, match=":1: not a JSON line"):
        ReplayChatClient(mid)
    from support.paths import TESTS

    tour = TESTS / "golden" / "house6-tour.mcap"  # an MCAP log without /sgtool/llm
    with pytest.raises(TranscriptError, match=r"holds no LLM exchanges \(/sgtool/llm\)"):
        ReplayChatClient(tour)


def test_the_planners_verdict_is_a_field_of_the_record(tmp_path) -> None:
    """A planner's verdict on an answer was read back from a log only in ``unknown`` (an
    outside lab looked for ``record.verdict``); its constraint stays an extra field."""
    from sgtool.log import LogReader, LogWriter
    from sgtool.log.records import LlmExchange

    d = exchange_record(model="m", messages=MSGS, response="Command: fly()", latency_s=0.1,
                        extra={"verdict": "invalid: unknown skill 'fly'", "constraint": "x"})
    assert d["verdict"] == "invalid: unknown skill 'fly'" and d["constraint"] == "x"
    with LogWriter(tmp_path / "x.mcap") as w:
        w.write_record(LlmExchange.from_json(d), 1)
    [(_, rec)] = list(LogReader(tmp_path / "x.mcap").records(LlmExchange))
    assert rec.verdict == "invalid: unknown skill 'fly'"
    assert dict(rec.unknown) == {"constraint": "x"}
    assert LlmExchange.json_schema()["properties"]["verdict"] == {"type": ["string", "null"]}
