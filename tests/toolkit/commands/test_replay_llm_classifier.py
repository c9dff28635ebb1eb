"""``sgtool replay --classifier llm``: MoMa-LLM's room classification against a scripted
endpoint, its transcript, and an offline replay of that transcript giving the same bytes."""

from __future__ import annotations

import json

import pytest
from click.testing import CliRunner
from support.paths import GOLDEN
from support.semantics_fixtures import ChatServer

from sgtool.cli import cli

LOG = GOLDEN / "house6-tour.mcap"
FRAMES = "12"


def by_objects(request: dict) -> dict:
    """A bathroom for a room with a toilet or a sink, else "It is a kitchen." (a sentence:
    the classifier finds the type name in it)."""
    user = request["messages"][1]["content"]
    return {"text": "bathroom" if "toilet" in user or "sink" in user else "It is a kitchen."}


@pytest.fixture(scope="module")
def live(tmp_path_factory):
    d = tmp_path_factory.mktemp("llmrooms")
    with ChatServer(responder=by_objects) as srv:
        r = CliRunner().invoke(cli, [
            "replay", str(LOG), "-o", str(d / "live.mcap"), "--max-frames", FRAMES,
            "--classifier", "llm", "--llm-base-url", srv.base_url, "--llm-model", "m",
            "--llm-api-key", "k", "--llm-constraint", "none",
            "--llm-transcript", str(d / "rooms.jsonl"), "--score", "--json"])
    assert r.exit_code == 0, r.output
    return d, json.loads(r.output), srv


def test_the_llm_names_the_rooms_and_its_exchanges_are_kept(live) -> None:
    d, doc, srv = live
    cats = doc["graph"]["categories"]
    assert cats and set(cats.values()) <= {"kitchen", "bathroom"}
    lines = [json.loads(x) for x in (d / "rooms.jsonl").read_text().splitlines()]
    # one request per distinct object set (cached), each logged with its verdict
    assert len(lines) == len(srv.requests) == doc["llm_answers"]["requests"] >= 1
    assert {x["purpose"] for x in lines} == {"room_classification"}
    assert {x["verdict"] for x in lines} == {"ok"}
    assert {x["constraint"] for x in lines} == {"none"}
    assert {r.get("max_tokens") for r in srv.requests} == {32}  # a room type, bounded
    assert doc["llm_answers"]["invalid"] == 0
    assert doc["options"]["classifier"] == "llm"
    assert all(0.0 <= v["category_accuracy"] <= 1.0 for v in doc["score"].values())


def test_an_offline_replay_of_the_transcript_gives_the_same_bytes(live) -> None:
    d, doc, _ = live
    outs = []
    for name in ("a.mcap", "b.mcap"):
        r = CliRunner().invoke(cli, [
            "replay", str(LOG), "-o", str(d / name), "--max-frames", FRAMES,
            "--classifier", "llm", "--llm-replay", str(d / "rooms.jsonl")])
        assert r.exit_code == 0, r.output
        assert "LLM answers in room classification" in r.output
        outs.append((d / name).read_bytes())
    assert outs[0] == outs[1] == (d / "live.mcap").read_bytes()


def test_a_transcript_that_lacks_a_prompt_is_one_line(live, tmp_path) -> None:
    d, _, _ = live
    rec = json.loads((d / "rooms.jsonl").read_text().splitlines()[0])
    rec["messages"][1]["content"] = "A room contains: a piano."  # another room's prompt
    del rec["prompt_sha256"]
    short = tmp_path / "short.jsonl"
    short.write_text(json.dumps(rec) + "\n")
    r = CliRunner().invoke(cli, [
        "replay", str(LOG), "-o", str(tmp_path / "x.mcap"), "--max-frames", FRAMES,
        "--classifier", "llm", "--llm-replay", str(short),
        "--llm-transcript", str(tmp_path / "t.jsonl")])
    assert r.exit_code == 2
    assert "--llm-replay" in r.output and "diverged" in r.output
    assert "Traceback" not in r.output
    assert sorted(p.name for p in tmp_path.iterdir()) == ["short.jsonl"]  # no half outputs


@pytest.mark.parametrize("args, says", [
    (["--classifier", "llm"], "no LLM endpoint configured"),
    (["--classifier", "containment", "--llm-base-url", "http://127.0.0.1:9"],
     "are for --classifier llm"),
    (["--classifier", "llm", "--out-dir", "OUT"], "one log at a time"),
])
def test_misuse_is_one_line(args, says, tmp_path, monkeypatch) -> None:
    for var in ("SGTOOL_LLM_BASE_URL", "OPENAI_BASE_URL", "SGTOOL_LLM_API_KEY",
                "OPENAI_API_KEY"):
        monkeypatch.delenv(var, raising=False)
    args = [a.replace("OUT", str(tmp_path / "out")) for a in args]
    r = CliRunner().invoke(cli, ["replay", str(LOG), "--max-frames", "2", *args])
    assert r.exit_code == 2, r.output
    assert says in r.output and len(r.output.strip().splitlines()) == 1


def test_the_transcript_is_never_the_input_the_output_or_a_user_file(live, tmp_path) -> None:
    """--llm-transcript naming the input log, the output log or another file is refused in
    one line before anything runs, and every file stays as it was."""
    d, _, _ = live
    log = tmp_path / "in.mcap"
    log.write_bytes(LOG.read_bytes())
    notes = tmp_path / "notes.txt"
    notes.write_text("mine\n")
    out = tmp_path / "out.mcap"
    for transcript, why in ((log, "it is the input log"), (out, "it is the output log (-o)"),
                            (notes, "exists and is not a JSONL transcript")):
        r = CliRunner().invoke(cli, [
            "replay", str(log), "-o", str(out), "--max-frames", FRAMES, "--classifier",
            "llm", "--llm-replay", str(d / "rooms.jsonl"), "--llm-transcript", str(transcript)])
        assert r.exit_code == 2 and why in r.output, r.output
    assert log.read_bytes() == LOG.read_bytes() and notes.read_text() == "mine\n"
    assert not out.exists()
