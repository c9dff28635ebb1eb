"""One LLM exchange as a plain record: the ``sgtool.LlmExchange`` log record and a transcript line.

:func:`exchange_record` gives the JSON form of an :class:`sgtool.log.records.LlmExchange`:
the same dict goes to the MCAP log (``LogWriter.write_record(LlmExchange.from_json(d), t)``)
and, one JSON object per line, to a transcript file that ``--llm-replay`` serves back. The
fields required by the log schema are ``model`` and ``messages``; ``prompt_sha256`` keys a
response to its prompt for replay (:mod:`sgtool.llm.recorded`). A reply the client cut
(:data:`sgtool.llm.client.MAX_REPLY_CHARS`) records its full length in
``response_truncated_from``; messages are redacted of the secrets the caller names.
"""

from __future__ import annotations

import hashlib
import json
from typing import Any

from sgtool.log.records import ABSENT, LlmExchange

Message = dict[str, str]


def prompt_key(messages: list[Message]) -> str:
    """SHA-256 of the canonical JSON of the messages (role and content only)."""
    canon = [{"role": m["role"], "content": m["content"]} for m in messages]
    text = json.dumps(canon, sort_keys=True, separators=(",", ":"), ensure_ascii=False)
    return hashlib.sha256(text.encode()).hexdigest()


def exchange_record(
    *,
    model: str,
    messages: list[Message],
    response: str | None,
    latency_s: float,
    prompt_tokens: int | None = None,
    completion_tokens: int | None = None,
    error: str | None = None,
    attempt: int = 0,
    step: int | None = None,
    query: str | None = None,
    source: str = "endpoint",
    truncated_from: int | None = None,
    extra: dict[str, Any] | None = None,
) -> dict[str, Any]:
    """A JSON-serialisable ``sgtool.LlmExchange`` record.

    ``attempt`` counts retries within one decision (0 = first try); ``step`` is the decision
    number within the episode; ``source`` is ``endpoint`` or ``replay``;
    ``truncated_from`` the length of a reply that was cut to ``response``; ``extra``
    adds fields beyond the schema (the planner's ``constraint``), but its ``verdict`` (the
    planner's judgement of the answer: ``ok`` or ``invalid: reason``) is the record's own.
    """
    unknown = dict(extra or {})
    verdict = unknown.pop("verdict", ABSENT)
    if truncated_from is not None:
        unknown["response_truncated_from"] = int(truncated_from)
    return LlmExchange(
        model=str(model),
        messages=tuple({"role": m["role"], "content": m["content"]} for m in messages),
        prompt_sha256=prompt_key(messages),
        response=response,
        latency_s=float(latency_s),
        prompt_tokens=None if prompt_tokens is None else int(prompt_tokens),
        completion_tokens=None if completion_tokens is None else int(completion_tokens),
        error=error,
        attempt=int(attempt),
        step=step,
        query=query,
        source=source,
        verdict=verdict if verdict is ABSENT or verdict is None else str(verdict),
        unknown=unknown,
    ).to_json()
