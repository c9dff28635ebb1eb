"""Chat completions over any OpenAI-compatible endpoint, and the settings to reach one.

:class:`OpenAIChatClient` wraps the ``openai`` package. It makes exactly one HTTP attempt
per call (the package's own retries are off) so the caller decides about retries and every
attempt is logged. Transport faults (timeout, connection refused, HTTP 5xx/4xx, a reply
without text) raise :class:`LlmTransportError` with a message naming the endpoint; they are
expected at run time and handled by the planner, unlike configuration mistakes, which raise
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
"""

from __future__ import annotations

import os
import time
from dataclasses import dataclass
from typing import Protocol

from sgtool.errors import SgtoolError
from sgtool.llm.exchange import Message

DEFAULT_MODEL = "gpt-5-mini"  # SCOUT's choice for its MoMa-LLM baseline (sec. VI-D)


class LlmConfigError(SgtoolError):
    """The LLM endpoint is not configured or configured wrongly."""


class LlmUnreachableError(LlmConfigError):
    """The endpoint never answered (connection refused, unknown host): a configuration
    problem, reported at once instead of retried episode after episode."""


class LlmTransportError(Exception):
    """One request failed (timeout, HTTP error, unusable reply); retrying may help."""


@dataclass(frozen=True)
class ChatResult:
    text: str
    model: str
    latency_s: float
    prompt_tokens: int | None = None
    completion_tokens: int | None = None
    source: str = "endpoint"


class ChatClient(Protocol):
    model: str

    def complete(self, messages: list[Message]) -> ChatResult: ...


@dataclass(frozen=True)
class LlmSettings:
    base_url: str | None
    model: str
    api_key: str | None
    timeout_s: float = 60.0
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
        timeout_s: float = 60.0,
        temperature: float | None = None,
        max_tokens: int | None = None,
    ) -> LlmSettings:
        env = os.environ
        base_url = base_url or env.get("SGTOOL_LLM_BASE_URL") or env.get("OPENAI_BASE_URL")
        model = model or env.get("SGTOOL_LLM_MODEL") or DEFAULT_MODEL
        api_key = api_key or env.get("SGTOOL_LLM_API_KEY") or env.get("OPENAI_API_KEY")
        if not base_url and not api_key:
            raise LlmConfigError(
                "no LLM endpoint configured: set SGTOOL_LLM_BASE_URL (and SGTOOL_LLM_API_KEY "
                "if it needs one) or give the base URL (-O moma-llm.base_url=URL for bench, "
                "eval and run; --llm-base-url for distill), or replay a recorded transcript "
                "with --llm-replay FILE"
            )
        if timeout_s <= 0:
            raise LlmConfigError(f"LLM timeout must be > 0 s, got {timeout_s}")
        return cls(base_url, model, api_key, float(timeout_s), temperature, max_tokens)


class OpenAIChatClient:
    """One chat-completion request per :meth:`complete` call."""

    source = "endpoint"

    def __init__(self, settings: LlmSettings) -> None:
        from openai import OpenAI

        self.settings = settings
        self.model = settings.model
        self._client = OpenAI(
            base_url=settings.base_url,
            api_key=settings.api_key or "sk-no-key-needed",
            timeout=settings.timeout_s,
            max_retries=0,
        )
        self.replies = 0  # HTTP replies received (any status): the endpoint exists

    @property
    def where(self) -> str:
        return self.settings.base_url or "api.openai.com"

    def complete(self, messages: list[Message]) -> ChatResult:
        import openai

        kwargs: dict = {"model": self.model, "messages": messages}
        if self.settings.temperature is not None:
            kwargs["temperature"] = self.settings.temperature
        if self.settings.max_tokens is not None:
            kwargs["max_tokens"] = self.settings.max_tokens
        t0 = time.perf_counter()
        try:
            resp = self._client.chat.completions.create(**kwargs)
        except openai.APITimeoutError as e:
            raise LlmTransportError(
                f"{self.where}: no reply within {self.settings.timeout_s:g} s"
            ) from e
        except openai.APIStatusError as e:
            self.replies += 1
            raise LlmTransportError(f"{self.where}: HTTP {e.status_code}: {_short(e)}") from e
        except openai.APIConnectionError as e:
            if not self.replies:
                # never reached at all: a wrong address, not a fault to retry around
                raise LlmUnreachableError(
                    f"cannot reach the LLM endpoint {self.where}: {_short(e)}; check "
                    "SGTOOL_LLM_BASE_URL / base_url, or replay a transcript with --llm-replay"
                ) from e
            raise LlmTransportError(f"{self.where}: connection failed: {_short(e)}") from e
        except (openai.OpenAIError, ValueError, KeyError, TypeError) as e:
            # malformed JSON body (ValueError from the decoder), unexpected structure
            raise LlmTransportError(
                f"{self.where}: unusable reply: {type(e).__name__}: {_short(e)}"
            ) from e
        latency = time.perf_counter() - t0
        self.replies += 1
        try:
            text = resp.choices[0].message.content
        except (AttributeError, IndexError, TypeError) as e:
            raise LlmTransportError(f"{self.where}: reply has no choices/message") from e
        if not isinstance(text, str):
            raise LlmTransportError(f"{self.where}: reply has no text content")
        usage = getattr(resp, "usage", None)
        return ChatResult(
            text=text,
            model=str(getattr(resp, "model", None) or self.model),
            latency_s=latency,
            prompt_tokens=getattr(usage, "prompt_tokens", None) if usage else None,
            completion_tokens=getattr(usage, "completion_tokens", None) if usage else None,
        )


def _short(e: BaseException, limit: int = 200) -> str:
    s = " ".join(str(e).split())
    return s if len(s) <= limit else s[: limit - 3] + "..."
