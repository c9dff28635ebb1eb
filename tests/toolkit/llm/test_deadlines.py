"""Deadlines are wall-clock: one per LLM request (connecting, headers and body together),
one per planner decision over all its attempts, one for `sgtool llm check`.

The endpoints here trickle their reply a few bytes at a time: every socket read gets data
well within any per-read timeout, so only a deadline over the whole request cuts them. A
full trickled reply would take :data:`TRICKLE_S` seconds; every deadline here is a second
or two, and the bounds checked are far below the trickle (whether the request was cut,
not how fast)."""

from __future__ import annotations

import json
import threading
import time
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer

import pytest
from click.testing import CliRunner
from support.semantics_fixtures import ChatServer, house

from sgtool.cli import cli
from sgtool.llm.client import LlmSettings, LlmTransportError, OpenAIChatClient
from sgtool.planning.moma.planner import MomaLlmPlanner

TRICKLE_S = 30.0  # how long a whole trickled reply would take


def reply_bytes(text: str = "Command: explore(kitchen)") -> bytes:
    return json.dumps({"id": "x", "object": "chat.completion", "model": "m",
                       "choices": [{"index": 0, "message": {"role": "assistant",
                                                            "content": text}}]}).encode()


class TrickleServer:
    """A chat endpoint on 127.0.0.1 that sends its (valid) reply slowly: ``part`` is
    ``"body"`` (headers at once, then the body a byte at a time) or ``"headers"`` (the
    status line and headers a byte at a time too), spread over :data:`TRICKLE_S`.
    ``requests`` counts the requests; ``cut`` those whose client hung up mid-reply."""

    def __init__(self, part: str) -> None:
        self.requests = 0
        self.cut = 0
        server = self
        body = reply_bytes()
        head = (f"HTTP/1.1 200 OK\r\nContent-Type: application/json\r\n"
                f"Content-Length: {len(body)}\r\n\r\n").encode()
        slow, fast = (body, head) if part == "body" else (head + body, b"")
        pause = TRICKLE_S / len(slow)

        class Handler(BaseHTTPRequestHandler):
            def log_message(self, *args: object) -> None:
                pass

            def do_POST(self) -> None:  # noqa: N802
                self.rfile.read(int(self.headers.get("Content-Length", "0")))
                server.requests += 1
                try:
                    self.wfile.write(fast)
                    for i in range(len(slow)):
                        self.wfile.write(slow[i:i + 1])
                        self.wfile.flush()
                        time.sleep(pause)
                except OSError:  # the client gave up: the request was cut
                    server.cut += 1
                self.close_connection = True

        self._httpd = ThreadingHTTPServer(("127.0.0.1", 0), Handler)
        self._httpd.daemon_threads = True
        self.base_url = f"http://127.0.0.1:{self._httpd.server_address[1]}/v1"
        self._thread = threading.Thread(target=self._httpd.serve_forever, daemon=True)

    def __enter__(self) -> TrickleServer:
        self._thread.start()
        return self

    def __exit__(self, *exc: object) -> None:
        self._httpd.shutdown()
        self._httpd.server_close()


def client(url: str, timeout_s: float) -> OpenAIChatClient:
    return OpenAIChatClient(LlmSettings.resolve(base_url=url, model="m", api_key="k",
                                                timeout_s=timeout_s))


@pytest.mark.parametrize("part", ["body", "headers"])
def test_a_trickled_reply_is_cut_at_the_request_deadline(part):
    with TrickleServer(part) as srv:
        c = client(srv.base_url, timeout_s=1.0)
        t0 = time.monotonic()
        with pytest.raises(LlmTransportError) as info:
            c.complete([{"role": "user", "content": "x"}])
        elapsed = time.monotonic() - t0
    assert str(info.value).endswith("no reply within 1 s")
    assert "\n" not in str(info.value)
    assert srv.requests == 1
    assert elapsed < TRICKLE_S / 3  # cut, not read to its end


def test_the_client_answers_again_after_a_cut_request():
    with ChatServer([{"sleep": 3.0, "text": "late"}, {"text": "fine"}]) as srv:
        c = client(srv.base_url, timeout_s=1.0)
        with pytest.raises(LlmTransportError, match="no reply within 1 s"):
            c.complete([{"role": "user", "content": "x"}])
        assert c.complete([{"role": "user", "content": "x"}]).text == "fine"


def test_a_decision_of_many_attempts_ends_at_the_decision_deadline():
    # a request deadline of 1 s, 5 attempts, a decision deadline of 1.5 s: two requests
    # fit (the second gets the 0.5 s left), and the decision ends with the deadline
    with TrickleServer("body") as srv:
        p = MomaLlmPlanner(client(srv.base_url, timeout_s=1.0), max_attempts=5,
                           decision_timeout_s=1.5)
        p.reset("milk")
        t0 = time.monotonic()
        a = p.decide(house())
        elapsed = time.monotonic() - t0
    assert a.skill == "done" and a.target is None
    assert a.reason.startswith("llm failure: no valid command after 2 attempts")
    assert a.reason.endswith("the decision deadline of 1.5 s is spent")
    first, second = (e["error"].split(": ", 1)[1] for e in p.exchanges)
    assert first == "no reply within 1 s"
    assert second.startswith("no reply within 0.")  # what was left of 1.5 s
    assert elapsed < TRICKLE_S / 3


def test_a_server_answering_after_the_request_timeout_ends_at_the_decision_deadline():
    # the campaign's 70 s answers against a 60 s request timeout and 5 attempts, scaled
    # down: answers after 1.4 s, requests of at most 1 s, a decision deadline of 1.5 s
    late = [{"sleep": 1.4, "text": "Command: explore(kitchen)"}] * 5
    with ChatServer(late) as srv:
        p = MomaLlmPlanner(client(srv.base_url, timeout_s=1.0), max_attempts=5,
                           decision_timeout_s=1.5)
        p.reset("milk")
        a = p.decide(house())
    assert a.reason == ("llm failure: no valid command after 2 attempts: the decision "
                        "deadline of 1.5 s is spent")
    assert len(p.exchanges) == 2 and all(e["response"] is None for e in p.exchanges)
    # each failed request logs the time it took until it was cut (1 s, then what was left)
    first, second = (e["latency_s"] for e in p.exchanges)
    assert first >= 0.9 and second >= 0.3  # not 0: a timeout took its time


def test_llm_check_has_one_deadline_and_says_so_in_one_line():
    with TrickleServer("body") as srv:
        r = CliRunner().invoke(cli, ["llm", "check", "--llm-base-url", srv.base_url,
                                     "--llm-model", "m", "--llm-timeout", "1"])
    assert r.exit_code == 2, r.output
    lines = r.output.strip().splitlines()
    assert len(lines) == 1
    assert lines[0].startswith("sgtool: error: llm check: no complete reply to the speed "
                               "request within the check's deadline of 1 s (--llm-timeout)")


def test_llm_check_cuts_a_slow_decision_at_the_same_deadline():
    script = [{"text": "kitchen bathroom"}, {"sleep": 3.0, "text": "late"}]
    with ChatServer(script) as srv:
        r = CliRunner().invoke(cli, ["llm", "check", "--llm-base-url", srv.base_url,
                                     "--llm-model", "m", "--llm-timeout", "1",
                                     "--constraint", "none"])
    assert r.exit_code == 2, r.output
    lines = r.output.strip().splitlines()
    assert len(lines) == 1
    assert lines[0].startswith("sgtool: error: llm check: no scene decision within the "
                               "check's deadline of 1 s (--llm-timeout): llm failure: ")


def test_llm_timeout_help_says_what_the_deadline_covers():
    text = " ".join(CliRunner().invoke(cli, ["llm", "check", "-h"]).output.split())
    assert "Deadline of the whole check in wall-clock seconds" in text
    text = " ".join(CliRunner().invoke(cli, ["bench", "-h"]).output.split())
    assert "wall-clock seconds per request (connecting, headers and body together" in text
    assert "moma-llm.decision_timeout_s" in text
