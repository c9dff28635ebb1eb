"""Measure an endpoint: generation speed, and one MoMa-LLM decision on a scene.

:func:`generation_speed` times one plain request of ``max_tokens`` tokens
(``temperature`` 0); tokens/s is the reply's completion tokens over the request's wall time
(prompt processing included, as a planner sees it). :func:`decision_check` asks a
``moma-llm`` planner for one decision on a scene graph, with ``max_attempts`` requests, and
reports whether an answer parsed and grounded, and how long the decision took.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

from sgtool.llm.client import ChatClient, LlmTransportError, complete_within
from sgtool.llm.constraints import REASON_CHARS
from sgtool.scenegraph.graph import SceneGraph

SPEED_PROMPT = "List the rooms of a house, one per line."


@dataclass(frozen=True)
class SpeedResult:
    completion_tokens: int | None
    latency_s: float

    @property
    def tokens_per_s(self) -> float | None:
        if not self.completion_tokens or self.latency_s <= 0:
            return None
        return self.completion_tokens / self.latency_s


@dataclass(frozen=True)
class DecisionCheck:
    parsed: bool  # an answer parsed and grounded in the scene
    action: str  # "explore(room:3)", or the failure reason
    requests: int
    decision_s: float
    constraint: str


def generation_speed(client: ChatClient, timeout_s: float = 120.0) -> SpeedResult:
    """One timed request (module doc); a transport fault is raised as is."""
    r = complete_within(client, [{"role": "user", "content": SPEED_PROMPT}], timeout_s)
    return SpeedResult(r.completion_tokens, r.latency_s)


def decision_check(client: ChatClient, graph: SceneGraph, query: str,
                   constraint: str = "auto", max_attempts: int = 1,
                   timeout_s: float = 120.0, reason_chars: int = REASON_CHARS) -> DecisionCheck:
    """One decision of a ``moma-llm`` planner on ``graph`` (module doc)."""
    from sgtool.planning.moma.planner import MomaLlmPlanner

    planner = MomaLlmPlanner(client, max_attempts=max_attempts, constraint=constraint,
                             decision_timeout_s=timeout_s, reason_chars=reason_chars)
    planner.reset(query)
    t0 = time.perf_counter()
    try:
        action = planner.decide(graph)
    except LlmTransportError as e:  # a replay miss or a fault the planner passed on
        return DecisionCheck(False, str(e), len(planner.exchanges),
                             time.perf_counter() - t0, planner.constraint)
    dt = time.perf_counter() - t0
    ok = any(e.get("verdict") == "ok" for e in planner.exchanges)
    text = f"{action.skill}({action.target or ''})" if ok else action.reason
    return DecisionCheck(ok, text, len(planner.exchanges), dt, planner.constraint)
