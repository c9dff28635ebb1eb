"""``sgtool llm``: one-line errors (missing extra, bad model file) and ``llm check`` against a
scripted endpoint (no model needed)."""

from __future__ import annotations

import json
import sys

from click.testing import CliRunner
from support.semantics_fixtures import ChatServer, answer

from sgtool.analysis.llm_check_run import check_scene as _scene
from sgtool.cli import cli
from sgtool.planning.moma.choices import valid_commands
from sgtool.planning.moma.scene_text import encode_scene


def test_missing_extra_is_one_line(monkeypatch) -> None:
    monkeypatch.setitem(sys.modules, "xllamacpp", None)  # import fails as if not installed
    r = CliRunner().invoke(cli, ["llm", "serve", "--port", "0"])
    assert r.exit_code == 2
    assert r.output.strip().splitlines() == [
        "sgtool: error: sgtool llm serve needs llama.cpp (xllamacpp): "
        "pip install 'sgtool[llm]'"]


def test_a_model_that_is_no_gguf_is_one_line(tmp_path) -> None:
    bad = tmp_path / "model.gguf"
    bad.write_bytes(b"not a model")
    r = CliRunner().invoke(cli, ["llm", "serve", "--model", str(bad), "--port", "0"])
    assert r.exit_code == 2
    assert r.output.strip() == f"sgtool: error: {bad}: not a GGUF model file (llama.cpp " \
                               "needs GGUF)"
    r = CliRunner().invoke(cli, ["llm", "serve", "--model", str(tmp_path / "none.gguf")])
    assert r.exit_code == 2 and "model file not found" in r.output
    # a model to serve and an endpoint to check: one is ignored, so both are refused
    r = CliRunner().invoke(cli, ["llm", "check", "--model", str(bad), "--llm-base-url",
                                 "http://127.0.0.1:9/v1"])
    assert r.exit_code == 2 and r.output.strip() == (
        "sgtool: error: --model and --llm-base-url: give one (--model starts a local server "
        "for the check, --llm-base-url checks a running endpoint)")


def test_check_against_a_scripted_endpoint() -> None:
    words = "kitchen bathroom bedroom hallway"
    graph, query = _scene()
    first = valid_commands(graph, encode_scene(graph), query)[0]
    with ChatServer([{"text": words}, {"text": "no idea"}, {"text": words},
                     answer(first)]) as srv:
        r = CliRunner().invoke(cli, ["llm", "check", "--base-url", srv.base_url,
                                     "--model-name", "m", "--json"])
        assert r.exit_code == 1, r.output  # answers, but no usable command: a failed check
        d = json.loads(r.output)
        # one failed answer, no retry (max one request): not parsed
        assert d["completion_tokens"] == 4 and d["tokens_per_s"] > 0
        assert d["decision_parsed"] is False and "no command found" in d["decision"]
        assert d["constraint"] == "none" and d["requests"] == 1
        assert srv.requests[0]["max_tokens"] == 48
        # the model that answered, as the endpoint names it (not the default asked for)
        assert srv.requests[0]["model"] == "m" and d["model"] == "scripted-model"
        r = CliRunner().invoke(cli, ["llm", "check", "--base-url", srv.base_url])
        assert r.exit_code == 0, r.output
        assert f"scene decision (find {query}, constraint none): parsed: " in r.output
        assert ", model scripted-model (asked for " in r.output
