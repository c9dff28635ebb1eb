"""Chat completions over any OpenAI-compatible endpoint, and the settings to reach one.

:class:`OpenAIChatClient` wraps the ``openai`` package. It makes exactly one HTTP attempt
per call (the package's own retries are off) so the caller decides about retries and every
attempt is logged. Transport faults (timeout, connection refused, HTTP 5xx/4xx, a reply
without text) raise :class:`LlmTransportError` with a message naming the endpoint (an
endpoint gone after it answered, :class:`LlmEndpointDown`); they are expected at run time
and handled by the planner, unlike configuration mistakes, which raise
:class:`LlmConfigError` (a user error).

Settings come from options, then the environment:

===============  =======================  ======================
setting          option                   environment
===============  =======================  ======================
base URL         ``base_url``             ``SGTOOL_LLM_BASE_URL``, ``OPENAI_BASE_URL``
model            ``model``                ``SGTOOL_LLM_MODEL``
API key          ``api_key``              ``SGTOOL_LLM_API_KEY``, ``OPENAI_API_KEY``
===============  =======================  ======================

A local server (llama.cpp, vLLM, Ollama) needs no key; a placeholder is sent then.

Replies are read tolerantly: any reply that does not hold ``choices[0].message.content``
as text (``choices`` an object, empty, missing; token counts that are no integers) is a
retryable :class:`LlmTransportError` with a one-line reason. A reply longer than
:data:`MAX_REPLY_CHARS` is cut there (:attr:`ChatResult.truncated_from` keeps its length),
so a runaway endpoint cannot fill the log or the transcript. The API key never appears in
an error message (:mod:`sgtool.redact`). :meth:`OpenAIChatClient.complete` takes a
``timeout_s`` for this one request, so a caller can keep a deadline over several attempts
(:func:`complete_within`).

Deadlines are wall-clock: a request's timeout bounds the whole request (connecting, sending,
the reply's headers and its body together), not each socket read, so an endpoint that
trickles its reply a byte at a time is cut at the deadline like one that says nothing.
The request runs on a worker thread that the caller waits for at most the timeout; at the
deadline the caller gets a :class:`LlmTransportError` and the worker's connections are
closed (the worker ends at its next read, bounded by the same timeout per read).
"""

from __future__ import annotations

import os
import threading
import time
from dataclasses import dataclass
from typing import Any, Protocol

from sgtool.errors import SgtoolError, a_or_an
from sgtool.llm.constraints import Constraint
from sgtool.llm.exchange import Message
from sgtool.redact import redact_text

DEFAULT_MODEL = "gpt-5-mini"  # SCOUT's choice for its MoMa-LLM baseline (sec. VI-D)
DEFAULT_TIMEOUT_S = 30.0  # one request; a decision has its own deadline over all attempts
MAX_REPLY_CHARS = 64 * 1024  # longer replies are cut (a valid answer is a few hundred)


class LlmConfigError(SgtoolError):
    """The LLM endpoint is not configured or configured wrongly."""


class LlmUnreachableError(LlmConfigError):
    """The endpoint never answered (connection refused, unknown host): a configuration
    problem, reported at once instead of retried episode after episode."""


class LlmTransportError(Exception):
    """One request failed (timeout, HTTP error, unusable reply); retrying may help."""


class LlmEndpointDown(LlmTransportError):
    """One request found the endpoint down: the server failed (HTTP 5xx, but for a
    ``model_error``: the model's own failure on that prompt), or the connection failed
    after the endpoint had answered (before, :class:`LlmUnreachableError`). A planner
    whose every attempt at a decision ends so stops the run (:class:`LlmUnreachableError`)
    rather than scoring the outage as its own failure."""


@dataclass(frozen=True)
class ChatResult:
    text: str
    model: str
    latency_s: float
    prompt_tokens: int | None = None
    completion_tokens: int | None = None
    source: str = "endpoint"
    truncated_from: int | None = None  # the reply's length in characters when it was cut


class ChatClient(Protocol):
    model: str

    def complete(self, messages: list[Message]) -> ChatResult: ...


def complete_within(client: ChatClient, messages: list[Message], timeout_s: float,
                    constraint: Constraint | None = None) -> ChatResult:
    """``client.complete(messages)``, bounded by ``timeout_s`` when the client takes a
    per-request timeout (``takes_timeout``) and constrained by ``constraint`` when it takes
    one (``takes_constraint``); other clients (a replay) answer at once, as recorded."""
    kw: dict[str, Any] = {}
    if getattr(client, "takes_timeout", False):
        kw["timeout_s"] = timeout_s
    if constraint is not None and getattr(client, "takes_constraint", False):
        kw["constraint"] = constraint
    return client.complete(messages, **kw)


def cut_reply(text: str, limit: int = MAX_REPLY_CHARS) -> tuple[str, int | None]:
    """``text`` cut to ``limit`` characters, and its full length when it was cut."""
    return (text, None) if len(text) <= limit else (text[:limit], len(text))


@dataclass(frozen=True)
class LlmSettings:
    base_url: str | None
    model: str
    api_key: str | None
    timeout_s: float = DEFAULT_TIMEOUT_S
    # None: not sent (the server's default). Reasoning models such as gpt-5-mini refuse any
    # temperature but 1, so a fixed 0 would break them; pass 0 for local models.
    temperature: float | None = None
    max_tokens: int | None = None

    @classmethod
    def resolve(
        cls,
        base_url: str | None = None,
        model: str | None = None,
        api_key: str | None = None,
        timeout_s: float = DEFAULT_TIMEOUT_S,
        temperature: float | None = None,
        max_tokens: int | None = None,
    ) -> LlmSettings:
        env = os.environ
        base_url = base_url or env.get("SGTOOL_LLM_BASE_URL") or env.get("OPENAI_BASE_URL")
        model = model or env.get("SGTOOL_LLM_MODEL") or DEFAULT_MODEL
        api_key = api_key or env.get("SGTOOL_LLM_API_KEY") or env.get("OPENAI_API_KEY")
        # a key or URL read from a file keeps its newline ("$(cat key)" does not, a .env
        # file or KEY=$'...\n' does); an HTTP header cannot hold one, and the request
        # would fail as if the server were unreachable
        base_url = base_url.strip() if base_url else base_url
        model = model.strip()
        api_key = api_key.strip() if api_key else api_key
        if api_key and any(c.isspace() for c in api_key):
            raise LlmConfigError("the LLM API key holds white space (a key is one word): "
                                 "check SGTOOL_LLM_API_KEY / OPENAI_API_KEY or api_key")
        if base_url and not base_url.lower().startswith(("http://", "https://")):
            raise LlmConfigError(
                f"the LLM base URL {redact_text(base_url)!r} must start with http:// or "
                "https:// (an OpenAI-compatible API, e.g. http://127.0.0.1:8080/v1 for "
                "`sgtool llm serve`): check SGTOOL_LLM_BASE_URL / --llm-base-url / base_url")
        if base_url and (problem := _url_problem(base_url)):
            raise LlmConfigError(
                f"the LLM base URL {redact_text(base_url)!r}: {problem} (e.g. "
                "http://127.0.0.1:8080/v1): check SGTOOL_LLM_BASE_URL / --llm-base-url / "
                "base_url")
        if not base_url and not api_key:
            raise LlmConfigError(
                "no LLM endpoint configured: set SGTOOL_LLM_BASE_URL (and SGTOOL_LLM_API_KEY "
                "if it needs one) or give --llm-base-url URL; an LLM planner also takes -O "
                "PLANNER.base_url=URL, or a recorded transcript (--llm-replay FILE of bench, "
                "run and eval)"
            )
        try:
            timeout = float(timeout_s)
        except (TypeError, ValueError):
            raise LlmConfigError(f"LLM timeout must be a number of seconds, got {timeout_s!r}") \
                from None
        if not timeout > 0:
            raise LlmConfigError(f"LLM timeout must be > 0 s, got {timeout_s}")
        return cls(base_url, model, api_key, timeout, temperature, max_tokens)


def _url_problem(url: str) -> str | None:
    """What makes ``url`` (http or https) no URL an HTTP client can use: a port that is no
    number from 1 to 65535, no host, a bracket left open; None when it is one."""
    from urllib.parse import urlsplit

    try:
        parts = urlsplit(url)
        port = parts.port  # ValueError: a port that is no number, or out of range
    except ValueError as e:
        return f"not a valid URL ({e})"
    if not parts.hostname:
        return "no host in it"
    if port == 0:
        return "port 0 is no port"
    return None


# HTTP statuses of a first request that say the setup is wrong (key, path, model, method;
# 501: a server that takes no POST), not that the server is busy or failing (408, 429 and
# the other 5xx stay faults to retry around)
SETUP_STATUS = frozenset({401, 403, 404, 405, 501})


class OpenAIChatClient:
    """One chat-completion request per :meth:`complete` call."""

    source = "endpoint"
    takes_timeout = True
    takes_constraint = True

    def __init__(self, settings: LlmSettings) -> None:
        self.settings = settings
        self.model = settings.model
        self._client = self._new_client()
        self.replies = 0  # HTTP replies received (any status): the endpoint exists
        self.answers = 0  # replies with a usable answer

    def _new_client(self) -> Any:
        from openai import OpenAI

        return OpenAI(base_url=self.settings.base_url,
                      api_key=self.settings.api_key or "sk-no-key-needed",
                      timeout=self.settings.timeout_s, max_retries=0)

    def __getstate__(self) -> dict[str, Any]:
        """Pickled without its HTTP client (a planner sent to another process), which
        :meth:`__setstate__` makes anew."""
        return {k: v for k, v in self.__dict__.items() if k != "_client"}

    def __setstate__(self, state: dict[str, Any]) -> None:
        self.__dict__.update(state)
        self._client = self._new_client()

    @property
    def where(self) -> str:
        return redact_text(self.settings.base_url or "api.openai.com")

    def _short(self, e: BaseException) -> str:
        return redact_text(_short(e), [self.settings.api_key])

    def complete(self, messages: list[Message], timeout_s: float | None = None,
                 constraint: Constraint | None = None) -> ChatResult:
        """One request; ``timeout_s`` (at most the settings' timeout) bounds this one;
        ``constraint`` (:mod:`sgtool.llm.constraints`) restricts the answer."""
        import openai

        timeout = self.settings.timeout_s if timeout_s is None \
            else max(0.001, min(float(timeout_s), self.settings.timeout_s))
        kwargs: dict = {"model": self.model, "messages": messages, "timeout": timeout}
        if self.settings.temperature is not None:
            kwargs["temperature"] = self.settings.temperature
        if self.settings.max_tokens is not None:
            kwargs["max_tokens"] = self.settings.max_tokens
        if constraint is not None:
            kwargs.update(constraint.request_fields())
            if constraint.kind == "grammar" and self.settings.temperature == 0:
                # llama.cpp (the grammar's server) answers a prompt that reuses an earlier
                # one's cache with other text: computed whole, the same request gets the
                # same answer
                kwargs["extra_body"] = {**kwargs["extra_body"], "cache_prompt": False}
        t0 = time.perf_counter()
        try:
            resp = self._create_within(kwargs, timeout)
        except (openai.APITimeoutError, RequestDeadline) as e:
            raise LlmTransportError(
                f"{self.where}: no reply within {timeout:.3g} s") from e
        except openai.APIStatusError as e:
            self.replies += 1
            if not self.answers and e.status_code in SETUP_STATUS:
                # before any answer: a wrong key, path or model, not a fault to retry around
                raise LlmConfigError(
                    f"the LLM endpoint {self.where} refused the first request: HTTP "
                    f"{e.status_code}: {self._short(e)}; check the API key, the base URL "
                    f"and the model ({self.model}) with `sgtool llm check`") from e
            # a 5xx the model caused (OpenAI's "model_error": "The model produced invalid
            # content", the same for the same prompt) is the model's failure, not an
            # outage, and so is a gateway's timeout (504: the model too slow, as a timeout)
            down = e.status_code >= 500 and e.status_code != 504 and \
                getattr(e, "type", None) != "model_error"
            raise (LlmEndpointDown if down else LlmTransportError)(
                f"{self.where}: HTTP {e.status_code}: {self._short(e)}") from e
        except openai.APIConnectionError as e:
            why, closed = self._short(_root_cause(e)), _closed_without_reply(e)
            if not self.replies:
                # never answered at all: a wrong address, not a fault to retry around
                what = (f"the LLM endpoint {self.where} closed the connection without "
                        f"replying ({why}); is it an OpenAI-compatible server? check"
                        if closed else
                        f"cannot reach the LLM endpoint {self.where}: {why}; check")
                raise LlmUnreachableError(
                    f"{what} SGTOOL_LLM_BASE_URL / --llm-base-url / base_url (an LLM planner "
                    "also replays a recorded transcript: --llm-replay FILE of bench, run and "
                    "eval)") from e
            what = "closed the connection without replying" if closed else "connection failed"
            raise (LlmTransportError if closed else LlmEndpointDown)(
                f"{self.where}: {what}: {why}") from e
        except Exception as e:  # noqa: BLE001 - any malformed reply is a retryable fault
            raise LlmTransportError(
                f"{self.where}: unusable reply: {type(e).__name__}: {self._short(e)}"
            ) from e
        latency = time.perf_counter() - t0
        self.replies += 1
        text = reply_text(resp, self.where)
        self.answers += 1
        text, full = cut_reply(text)
        usage = _field(resp, "usage")
        return ChatResult(
            text=text,
            model=_text_or(_field(resp, "model"), self.model),
            latency_s=latency,
            prompt_tokens=_count(_field(usage, "prompt_tokens")),
            completion_tokens=_count(_field(usage, "completion_tokens")),
            truncated_from=full,
        )


    def _create_within(self, kwargs: dict[str, Any], timeout: float) -> Any:
        """``chat.completions.create(**kwargs)`` on a worker thread, waited for at most
        ``timeout`` wall seconds (module doc); :class:`RequestDeadline` when it is not done
        by then. An interrupt (Ctrl-C) while waiting abandons the request the same way."""
        client = self._client
        box: dict[str, Any] = {}

        def run() -> None:
            try:
                box["reply"] = client.chat.completions.create(**kwargs)
            except BaseException as e:  # noqa: BLE001 - handed to the waiting caller
                box["error"] = e

        worker = threading.Thread(target=run, name="sgtool-llm-request", daemon=True)
        worker.start()
        try:
            worker.join(timeout)
        except BaseException:
            self._abandon(client)
            raise
        if worker.is_alive():
            self._abandon(client)
            raise RequestDeadline(f"no reply within {timeout:.3g} s")
        if "error" in box:
            raise box["error"]
        return box["reply"]

    def _abandon(self, client: Any) -> None:
        """Leave ``client`` to its worker: later requests use a fresh one, and its
        connections are closed (on another thread: closing must not wait for the worker)."""
        if client is self._client:
            self._client = self._new_client()
        threading.Thread(target=_close_quietly, args=(client,), name="sgtool-llm-close",
                         daemon=True).start()


class RequestDeadline(Exception):
    """A request was not complete at its wall-clock deadline."""


def _close_quietly(client: Any) -> None:
    try:
        client.close()
    except Exception:  # noqa: BLE001, S110 - an abandoned client; nothing to report
        pass


def reply_text(resp: object, where: str = "the endpoint") -> str:
    """``choices[0].message.content`` of a chat reply (an object or plain dicts), or a
    :class:`LlmTransportError` naming what is missing."""
    if isinstance(resp, str | bytes):  # (the openai package hands back a body not JSON)
        text = resp[:4096] if isinstance(resp, str) else resp[:4096].decode("utf-8", "replace")
        head = " ".join(text.split())[:40]  # (a page may start with blank lines)
        raise LlmTransportError(f"{where}: unusable reply: not JSON (" + (
            f"it begins {head!r})" if head else "an empty body)"))
    choices = _field(resp, "choices")
    if not isinstance(choices, list | tuple):
        raise LlmTransportError(
            f"{where}: unusable reply: 'choices' is {_kind(choices)}, not a list")
    if not choices:
        raise LlmTransportError(f"{where}: unusable reply: 'choices' is empty")
    message = _field(choices[0], "message")
    if message is None:
        raise LlmTransportError(f"{where}: unusable reply: choices[0] has no message")
    text = _field(message, "content")
    if not isinstance(text, str):
        raise LlmTransportError(
            f"{where}: unusable reply: the message content is {_kind(text)}, not text")
    return text


def _field(obj: Any, name: str) -> Any:
    """``obj.name`` or ``obj[name]``; None when it has neither (or raises on access)."""
    if obj is None:
        return None
    try:
        if isinstance(obj, dict):
            return obj.get(name)
        return getattr(obj, name, None)
    except Exception:  # noqa: BLE001 - a property of a malformed reply
        return None


def _kind(v: Any) -> str:
    return "missing" if v is None else a_or_an(type(v).__name__)


def _count(v: Any) -> int | None:
    return v if isinstance(v, int) and not isinstance(v, bool) and v >= 0 else None


def _text_or(v: Any, default: str) -> str:
    return v if isinstance(v, str) and v else default


def _root_cause(e: BaseException) -> BaseException:
    """The innermost exception behind ``e`` (its causes and contexts): the openai client's
    "Connection error." says less than the socket's or the HTTP library's own."""
    seen = {id(e)}
    while True:
        inner = e.__cause__ or e.__context__
        if inner is None or id(inner) in seen or not str(inner).strip():
            return e
        seen.add(id(inner))
        e = inner


def _closed_without_reply(e: BaseException) -> bool:
    """Whether the server took the request and closed the connection without an answer
    (the HTTP library's RemoteProtocolError), rather than being out of reach."""
    return type(_root_cause(e)).__name__ == "RemoteProtocolError"


def _short(e: BaseException, limit: int = 200) -> str:
    s = " ".join(str(e).split())
    return s if len(s) <= limit else s[: limit - 3] + "..."
