"""The LLM client and MoMa-LLM against hostile endpoints: malformed replies are retryable
one-line faults, a decision has a total deadline, huge replies are cut in the record, and
the API key is written nowhere."""

from __future__ import annotations

import json
import re
import time

import pytest
from support.semantics_fixtures import ChatServer, answer, house

from sgtool.llm.client import (
    MAX_REPLY_CHARS,
    ChatResult,
    LlmConfigError,
    LlmSettings,
    LlmTransportError,
    LlmUnreachableError,
    OpenAIChatClient,
    reply_text,
)
from sgtool.llm.recorded import TranscriptWriter, read_transcript
from sgtool.planning.moma.planner import MomaLlmPlanner

KEY = "sk-test-SECRET-0123456789"


def client(server: ChatServer, **kw) -> OpenAIChatClient:
    return OpenAIChatClient(LlmSettings.resolve(base_url=server.base_url, model="m",
                                                api_key=KEY, timeout_s=kw.pop("timeout_s", 5)))


def body(**fields) -> dict:
    return {"raw": json.dumps({"id": "x", "object": "chat.completion", "model": "m",
                               **fields}).encode()}


MESSAGE = {"message": {"role": "assistant", "content": "hi"}}


@pytest.mark.parametrize(("reply", "reason"), [
    (body(choices={"0": MESSAGE}), "'choices' is a dict, not a list"),
    (body(choices=[]), "'choices' is empty"),
    (body(), "'choices' is missing, not a list"),
    (body(choices=["text"]), "choices[0] has no message"),
    (body(choices=[{"message": {"content": 7}}]), "the message content is an int, not text"),
    (body(choices=[{"message": {"content": None}}]), "the message content is missing"),
    ({"raw": b'{"choices": [ '}, "unusable reply: "),
    ({"raw": b"[1, 2]"}, "unusable reply: "),
])
def test_malformed_replies_are_retryable_one_line_faults(reply, reason):
    with ChatServer([reply]) as srv:
        with pytest.raises(LlmTransportError) as info:
            client(srv).complete([{"role": "user", "content": "x"}])
    msg = str(info.value)
    assert reason in msg and "\n" not in msg and KEY not in msg


def test_a_body_that_is_not_json_is_named_so() -> None:
    """The openai package hands back the text of a reply that is not JSON (a web page
    served as text/html): named as such, not as a reply without 'choices'."""
    for resp in ("<html>\n<body>a web page</body></html>", b"<html>a web page"):
        with pytest.raises(LlmTransportError) as info:
            reply_text(resp, "http://x/v1")
        assert str(info.value).startswith("http://x/v1: unusable reply: not JSON (it begins "
                                          "'<html>")
    for resp, says in (("\n" * 45 + "<html>x</html>", "(it begins '<html>x</html>')"),
                       ("", "(an empty body)"), (b" \r\n", "(an empty body)")):
        with pytest.raises(LlmTransportError) as info:
            reply_text(resp, "http://x/v1")
        assert str(info.value).endswith(f"not JSON {says}")


@pytest.mark.parametrize(("first", "says"), [
    ({"status": 401}, "refused the first request: HTTP 401"),
    ({"status": 404}, "refused the first request: HTTP 404"),
    ({"status": 501}, "refused the first request: HTTP 501"),
])
def test_a_wrong_setup_stops_at_the_first_request(first, says):
    """A wrong key, path or model, or a server that is no chat endpoint, refuses the first
    request: a one-line user error (the run stops), not a fault every decision retries;
    the same status once answers came is a fault, and a 500 is one from the start."""
    with ChatServer([first]) as srv:
        with pytest.raises(LlmConfigError) as info:
            client(srv).complete([{"role": "user", "content": "x"}])
    assert says in str(info.value) and "\n" not in str(info.value)
    with ChatServer([{"text": "fine"}, first, {"status": 500}]) as srv:
        c = client(srv)
        c.complete([{"role": "user", "content": "x"}])
        with pytest.raises(LlmTransportError):
            c.complete([{"role": "user", "content": "x"}])
    with ChatServer([{"status": 500}]) as srv, pytest.raises(LlmTransportError):
        client(srv).complete([{"role": "user", "content": "x"}])


def test_a_server_closing_the_connection_is_named_so() -> None:
    """A server that takes the request and hangs up is reached, not out of reach: a setup
    error before any answer, a retryable fault after one; both name the hang-up."""
    with ChatServer([{"drop": True}, {"text": "a"}, {"drop": True}]) as srv:
        with pytest.raises(LlmUnreachableError) as first:
            client(srv).complete([{"role": "user", "content": "x"}])
        c = client(srv)
        assert c.complete([{"role": "user", "content": "x"}]).text == "a"
        with pytest.raises(LlmTransportError) as later:
            c.complete([{"role": "user", "content": "y"}])
    assert str(first.value).startswith(
        f"the LLM endpoint {srv.base_url} closed the connection without replying (")
    assert not isinstance(later.value, LlmUnreachableError)
    assert str(later.value).startswith(
        f"{srv.base_url}: closed the connection without replying: ")


def test_bad_token_counts_are_dropped_not_fatal():
    reply = body(choices=[MESSAGE], usage={"prompt_tokens": "many", "completion_tokens": -1})
    with ChatServer([reply]) as srv:
        r = client(srv).complete([{"role": "user", "content": "x"}])
    assert (r.text, r.prompt_tokens, r.completion_tokens) == ("hi", None, None)


def test_reply_text_reads_plain_dicts_too():
    assert reply_text({"choices": [{"message": {"content": "ok"}}]}) == "ok"


def test_planner_survives_a_choices_object_and_retries():
    with ChatServer([body(choices={"0": MESSAGE}),
                     answer("go_to_and_open(kitchen, fridge)")]) as srv:
        p = MomaLlmPlanner(client(srv))
        p.reset("milk")
        a = p.decide(house())
    assert (a.skill, a.target) == ("open", "obj:10")
    first, second = p.exchanges
    assert "'choices' is a dict" in first["error"] and second["error"] is None


def test_a_huge_reply_is_cut_and_the_cut_is_recorded(tmp_path):
    huge = "x" * (16 * 1024 * 1024)
    transcript = tmp_path / "t.jsonl"
    with ChatServer([{"text": huge}] * 3) as srv:
        p = MomaLlmPlanner(client(srv, timeout_s=30), max_attempts=3, transcript=transcript)
        p.reset("milk")
        a = p.decide(house())
        p.close()
    assert a.skill == "done" and a.reason.startswith("llm failure")
    assert len(p.exchanges) == 3
    for ex in p.exchanges:
        assert len(ex["response"]) == MAX_REPLY_CHARS
        assert ex["response_truncated_from"] == len(huge)
    # three cut replies, each also echoed in the next prompt: well under a megabyte each
    assert transcript.stat().st_size < 3 * 4 * MAX_REPLY_CHARS
    assert [r["response_truncated_from"] for r in read_transcript(transcript)] == [len(huge)] * 3


class SlowClient:
    """Fails every request after using the time it is given (at most ``per_call`` s)."""

    model = "slow"
    takes_timeout = True

    def __init__(self, clock: list[float], per_call: float) -> None:
        self.clock, self.per_call, self.timeouts = clock, per_call, []

    def complete(self, messages, timeout_s=None) -> ChatResult:
        self.timeouts.append(timeout_s)
        self.clock[0] += min(self.per_call, timeout_s)
        raise LlmTransportError(f"no reply within {timeout_s:g} s")


def test_a_decision_has_a_total_deadline(monkeypatch):
    clock = [1000.0]
    monkeypatch.setattr("sgtool.planning.moma.planner.time.monotonic", lambda: clock[0])
    c = SlowClient(clock, per_call=25.0)
    p = MomaLlmPlanner(c, max_attempts=5)  # the default deadline: 60 s over all attempts
    p.reset("milk")
    a = p.decide(house())
    assert c.timeouts == [60.0, 35.0, 10.0]  # each request waits at most what is left
    assert clock[0] - 1000.0 == 60.0
    assert a.skill == "done"
    assert a.reason == ("llm failure: no valid command after 3 attempts: the decision "
                        "deadline of 60 s is spent")


def test_the_deadline_bounds_a_real_request():
    with ChatServer([{"sleep": 3.0, "text": "late"}]) as srv:
        p = MomaLlmPlanner(client(srv, timeout_s=30), decision_timeout_s=0.5)
        p.reset("milk")
        t0 = time.perf_counter()
        a = p.decide(house())
        elapsed = time.perf_counter() - t0
    assert a.skill == "done" and "deadline" in a.reason + p.exchanges[-1]["error"]
    assert elapsed < 2.5  # not a speed target: the server answers only after 3 s


def test_a_key_read_with_its_newline_still_works():
    """A key or URL from a file keeps its line end; it goes out without it (an HTTP header
    cannot hold one), and a key with white space inside is a one-line setup error."""
    with ChatServer([{"text": "hi"}]) as srv:
        c = OpenAIChatClient(LlmSettings.resolve(base_url=f" {srv.base_url}\n", model="m\r\n",
                                                 api_key=f"{KEY}\r\n", timeout_s=5))
        assert c.complete([{"role": "user", "content": "x"}]).text == "hi"
        assert srv.auth == [f"Bearer {KEY}"] and srv.requests[0]["model"] == "m"
    with pytest.raises(LlmConfigError, match="white space") as info:
        LlmSettings.resolve(base_url="http://127.0.0.1:9/v1", api_key="sk-a b")
    assert "sk-a" not in str(info.value)


def test_the_api_key_is_not_in_error_messages(monkeypatch):
    c = OpenAIChatClient(LlmSettings.resolve(base_url="http://user:pw-XYZ1@127.0.0.1:9/v1",
                                             api_key=KEY))

    def create(**kw):
        raise ValueError(f"Incorrect API key provided: {KEY}")

    monkeypatch.setattr(c._client.chat.completions, "create", create)
    with pytest.raises(LlmTransportError) as info:
        c.complete([{"role": "user", "content": "x"}])
    msg = str(info.value)
    assert KEY not in msg and "pw-XYZ1" not in msg and "<redacted>" in msg


def test_a_fresh_transcript_uses_a_unique_temporary_name(tmp_path):
    path = tmp_path / "t.jsonl"
    a, b = TranscriptWriter(path, append=False), TranscriptWriter(path, append=False)
    a.write({"model": "m", "messages": [], "response": "a"})
    b.write({"model": "m", "messages": [], "response": "b"})
    a.close()
    b.close()
    assert [json.loads(x)["response"] for x in path.read_text().splitlines()] == ["b"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["t.jsonl"]
    with pytest.raises(RuntimeError), TranscriptWriter(tmp_path / "u.jsonl", append=False) as w:
        w.write({"model": "m", "messages": []})
        raise RuntimeError("boom")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["t.jsonl"]


@pytest.mark.parametrize("url", ["127.0.0.1:8080/v1", "ftp://127.0.0.1:8080/v1",
                                 "localhost:8080"])
def test_a_base_url_without_http_is_a_setup_error(url):
    """A URL without its scheme is no unreachable server: it is refused before any request,
    naming what it must start with."""
    with pytest.raises(LlmConfigError, match="must start with http:// or https://"):
        LlmSettings.resolve(base_url=url, model="m")
    assert LlmSettings.resolve(base_url="HTTPS://example.org/v1").base_url


@pytest.mark.parametrize(("url", "says"), [
    ("http://127.0.0.1:80a/v1", "not a valid URL (Port could not be cast"),
    ("http://[::1", "not a valid URL (Invalid IPv6 URL)"),
    ("http://127.0.0.1:99999/v1", "not a valid URL (Port out of range"),
    ("http:///v1", "no host in it"),
])
def test_a_mistyped_base_url_is_a_setup_error(url, says):
    """A typo in the port or host is refused in one line before any client is built (the
    HTTP client raised its own exception from inside)."""
    with pytest.raises(LlmConfigError, match=re.escape(says)):
        LlmSettings.resolve(base_url=url, model="m")
    assert LlmSettings.resolve(base_url="http://[::1]:8080/v1").base_url


def test_an_llm_planner_pickles_and_its_copy_asks_the_endpoint() -> None:
    """An LLM planner goes to another process as the other planners do (it did not: the
    client's factory was a lambda); the copy makes its own HTTP client and asks the same
    endpoint with the same key."""
    import pickle

    from sgtool.planning.registry import make_planner

    with ChatServer([{"text": "fine"}]) as srv:
        planner = make_planner("moma-llm", base_url=srv.base_url, model="m", api_key=KEY)
        copy = pickle.loads(pickle.dumps(planner))
        llm = copy.inner.client  # type: ignore[attr-defined]
        assert llm is not planner.inner.client  # type: ignore[attr-defined]
        assert llm.complete([{"role": "user", "content": "x"}]).text == "fine"
    assert srv.auth == [f"Bearer {KEY}"]


def test_a_planner_writing_a_transcript_is_refused_a_copy_in_one_line(tmp_path) -> None:
    """Two processes writing one transcript would interleave it: pickling such a planner
    is one SgtoolError line naming the file (it was a TypeError about a TextIOWrapper)."""
    import pickle

    from sgtool.errors import SgtoolError
    from sgtool.planning.registry import make_planner

    t = tmp_path / "llm.jsonl"
    planner = make_planner("moma-llm", base_url="http://127.0.0.1:9/v1", model="m",
                           api_key=KEY, transcript=str(t))
    with pytest.raises(SgtoolError, match="cannot be copied to another process") as e:
        pickle.dumps(planner)
    assert str(t) in str(e.value) and "\n" not in str(e.value)
