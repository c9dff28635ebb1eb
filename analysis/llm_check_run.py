"""The work of `sgtool llm check`: one speed request and one scene decision of the
``moma-llm`` prompt against an endpoint (or a local llama.cpp server started for the
check), as figures and report lines.
"""

from __future__ import annotations

import os
from contextlib import ExitStack
from dataclasses import dataclass, replace
from pathlib import Path
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from sgtool.scenegraph.graph import SceneGraph


@dataclass(frozen=True)
class LlmCheckRequest:
    """A checked `sgtool llm check`: the endpoint (None: ``SGTOOL_LLM_BASE_URL``, else a
    local server of the GGUF model ``gguf`` with ``threads`` threads), the deadline of the
    whole check (wall-clock s), the speed request's tokens and the decision's answer
    constraint and reasoning length (characters)."""

    base_url: str | None = None
    model: str | None = None
    api_key: str | None = None
    timeout_s: float = 300.0
    gguf: Path | None = None
    threads: int = 1
    max_tokens: int = 48
    constraint: str = "auto"
    reason_chars: int = 40


@dataclass(frozen=True)
class LlmCheckResult:
    """The figures of a check (JSON-ready) and its report lines."""

    figures: dict[str, Any]
    lines: list[str]


def check_scene() -> tuple[SceneGraph, str]:
    """The first graph of the first episode of generated house 0 (a fixed scene) and its
    query."""
    from sgtool.datasets.episodes import list_episodes
    from sgtool.datasets.generator import generate_house
    from sgtool.recorders.symbolic_environment import SymbolicEnv, SymbolicHouse

    spec = generate_house(0)
    ep = list_episodes(spec, n=1, seed=0)[0]
    env = SymbolicEnv(SymbolicHouse(spec), ep.query, avoid_rooms=ep.target_rooms)
    return env.observe(), ep.query


def run_check(request: LlmCheckRequest) -> LlmCheckResult:
    """Measure tokens/s of the endpoint and ask it for one decision on :func:`check_scene`
    within the request's deadline."""
    from sgtool.llm.check import check_endpoint
    from sgtool.llm.client import LlmSettings, OpenAIChatClient

    model = request.model
    with ExitStack() as stack:
        url = request.base_url or os.environ.get("SGTOOL_LLM_BASE_URL")
        if url is None:
            from sgtool.llm.server import start_server

            server = stack.enter_context(start_server(request.gguf, threads=request.threads))
            url, model = server.base_url, model or server.alias
        settings = LlmSettings.resolve(base_url=url, model=model, api_key=request.api_key,
                                       timeout_s=request.timeout_s, temperature=0.0,
                                       max_tokens=request.max_tokens)
        client = OpenAIChatClient(settings)
        graph, query = check_scene()
        # room for both reasoning lines (a token per character at worst) and the command
        decider = OpenAIChatClient(replace(settings, max_tokens=2 * request.reason_chars + 60))
        speed, dec = check_endpoint(client, decider, graph, query, request.timeout_s,
                                    constraint=request.constraint,
                                    reason_chars=request.reason_chars)
    figures = {
        "endpoint": client.where, "model": speed.model or settings.model,
        "completion_tokens": speed.completion_tokens,
        "tokens_per_s": None if speed.tokens_per_s is None else round(speed.tokens_per_s, 2),
        "decision_parsed": dec.parsed, "decision": dec.action, "requests": dec.requests,
        "decision_s": round(dec.decision_s, 3), "constraint": dec.constraint,
        "query": query,
    }
    generation = (f"{speed.completion_tokens} tokens in {speed.latency_s:.2f} s = "
                  f"{speed.tokens_per_s:.1f} tokens/s" if speed.tokens_per_s is not None
                  else f"{speed.latency_s:.2f} s (the reply counted no tokens: no speed)")
    asked = f" (asked for {settings.model})" if figures["model"] != settings.model else ""
    lines = [f"endpoint {figures['endpoint']}, model {figures['model']}{asked}",
             f"generation: {generation}",
             f"scene decision (find {query}, constraint {dec.constraint}): "
             f"{'parsed' if dec.parsed else 'NOT parsed'}: {dec.action} "
             f"({dec.decision_s:.2f} s)"]
    return LlmCheckResult(figures=figures, lines=lines)
