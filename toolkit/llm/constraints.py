"""Answers constrained to a list of valid commands: a llama.cpp grammar or a JSON schema.

A planner that knows which commands are valid now (MoMa-LLM: the skills applied to the
rooms and objects of the current scene) can have the endpoint generate only those:

- ``grammar``: llama.cpp's GBNF, sent per request as the ``grammar`` field (llama.cpp's
  server, xllamacpp, ``sgtool llm serve``): the answer keeps MoMa-LLM's text format,
  ``Analysis: ...`` / ``Reasoning: ...`` (one line each, at most ``reason_chars``
  characters) / ``Command: <one of the commands>``;
- ``json_schema``: OpenAI structured outputs (``response_format``; also vLLM, Ollama): an
  object ``{"analysis", "reasoning", "command"}`` whose ``command`` is one of the commands;
- ``none``: nothing is sent; the answer is parsed as written (the fallback).

``auto`` (:func:`detect_kind`) asks the endpoint: a server that answers llama.cpp's
``GET /props`` gets a grammar, OpenAI's own API a JSON schema, anything else nothing.
"""

from __future__ import annotations

import json
import urllib.parse
import urllib.request
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

from sgtool.errors import SgtoolError

KINDS = ("auto", "grammar", "json_schema", "none")
REASON_CHARS = 160  # one line of analysis or reasoning in a constrained answer


class ConstraintError(SgtoolError):
    """An unknown constraint kind."""


def check_kind(kind: str) -> str:
    k = str(kind).strip().lower().replace("-", "_")
    if k not in KINDS:
        raise ConstraintError(f"unknown answer constraint {kind!r}; choose one of: "
                              f"{', '.join(KINDS)}")
    return k


def gbnf_literal(s: str) -> str:
    """``s`` as a GBNF string literal."""
    out = s.replace("\\", "\\\\").replace('"', '\\"').replace("\n", "\\n")
    return f'"{out}"'


def command_grammar(commands: Sequence[str], reason_chars: int = REASON_CHARS) -> str:
    """GBNF for "Analysis: ...\\nReasoning: ...\\nCommand: <one of commands>"."""
    if not commands:
        raise ValueError("no commands to constrain to")
    n = max(1, int(reason_chars))
    alts = " | ".join(gbnf_literal(c) for c in commands)  # one line: a rule ends at a newline
    return (
        'root ::= "Analysis: " line "\\nReasoning: " line "\\nCommand: " command\n'
        f"line ::= [^\\n]{{1,{n}}}\n"
        f"command ::= {alts}\n"
    )


def command_schema(commands: Sequence[str], reason_chars: int = REASON_CHARS) -> dict[str, Any]:
    """JSON schema of ``{"analysis", "reasoning", "command"}`` with ``command`` in
    ``commands``."""
    if not commands:
        raise ValueError("no commands to constrain to")
    text = {"type": "string", "maxLength": max(1, int(reason_chars))}
    return {
        "type": "object",
        "properties": {"analysis": text, "reasoning": text,
                       "command": {"type": "string", "enum": list(commands)}},
        "required": ["analysis", "reasoning", "command"],
        "additionalProperties": False,
    }


def choice_grammar(choices: Sequence[str]) -> str:
    """GBNF whose only sentences are the ``choices``."""
    if not choices:
        raise ValueError("no choices to constrain to")
    return f"root ::= {' | '.join(gbnf_literal(c) for c in choices)}\n"


def choice_schema(choices: Sequence[str]) -> dict[str, Any]:
    """JSON schema of ``{"answer": <one of choices>}``."""
    if not choices:
        raise ValueError("no choices to constrain to")
    return {"type": "object",
            "properties": {"answer": {"type": "string", "enum": list(choices)}},
            "required": ["answer"], "additionalProperties": False}


@dataclass(frozen=True)
class Constraint:
    """What one request is constrained by: ``kind`` and the commands allowed; ``bare``: the
    answer is one of ``commands`` and nothing else (no analysis or reasoning lines)."""

    kind: str  # grammar | json_schema
    commands: tuple[str, ...]
    reason_chars: int = REASON_CHARS
    bare: bool = False

    def request_fields(self) -> dict[str, Any]:
        """Keyword arguments for ``openai`` ``chat.completions.create``; kind
        ``json_object``: a JSON object (llama.cpp, vLLM, OpenAI JSON mode; never an array)."""
        if self.kind == "json_object":
            return {"response_format": {"type": "json_object"}}
        if self.bare and self.kind == "grammar":
            return {"extra_body": {"grammar": choice_grammar(self.commands)}}
        if self.bare and self.kind == "json_schema":
            return {"response_format": {"type": "json_schema", "json_schema": {
                "name": "answer", "strict": True, "schema": choice_schema(self.commands)}}}
        if self.kind == "grammar":
            return {"extra_body": {"grammar": command_grammar(self.commands,
                                                              self.reason_chars)}}
        if self.kind == "json_schema":
            return {"response_format": {"type": "json_schema", "json_schema": {
                "name": "command", "strict": True,
                "schema": command_schema(self.commands, self.reason_chars)}}}
        raise ConstraintError(f"no request fields for constraint kind {self.kind!r}")


def server_root(base_url: str) -> str:
    """``http://host:port/v1`` -> ``http://host:port``."""
    u = base_url.rstrip("/")
    return u[:-3] if u.endswith("/v1") else u


def detect_kind(base_url: str | None, timeout_s: float = 3.0,
                api_key: str | None = None) -> str:
    """``grammar`` for a llama.cpp server, ``json_schema`` for api.openai.com (no base URL),
    else ``none`` (module doc); ``api_key`` goes with the request (a server started with a
    key answers nothing without it). Never raises: an endpoint that does not answer gets
    ``none`` and the planner parses plain answers."""
    if not base_url:
        return "json_schema"
    host = urllib.parse.urlsplit(base_url).hostname or ""
    if host == "api.openai.com":
        return "json_schema"
    req = urllib.request.Request(server_root(base_url) + "/props", headers={
        "Authorization": f"Bearer {api_key}"} if api_key else {})
    try:
        with urllib.request.urlopen(req, timeout=timeout_s) as resp:  # noqa: S310
            props = json.loads(resp.read(1 << 20))
    except Exception:  # noqa: BLE001 - not llama.cpp, or not reachable: plain parsing
        return "none"
    if isinstance(props, dict) and "default_generation_settings" in props:
        return "grammar"
    return "none"
