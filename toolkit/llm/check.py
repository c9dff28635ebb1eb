"""Measure an endpoint: generation speed, and one MoMa-LLM decision on a scene.

:func:`generation_speed` times one plain request of ``max_tokens`` tokens
(``temperature`` 0); tokens/s is the reply's completion tokens over the request's wall time
(prompt processing included, as a planner sees it). :func:`decision_check` asks a
``moma-llm`` planner for one decision on a scene graph, with ``max_attempts`` requests, and
reports whether an answer parsed and grounded, and how long the decision took.
:func:`check_endpoint` runs both under one wall-clock deadline (``sgtool llm check``): a
request or decision still running at the deadline is cut, and the check fails with one
line (:class:`CheckFailed`) naming the deadline.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass

from sgtool.errors import SgtoolError
from sgtool.llm.client import ChatClient, LlmTransportError, complete_within
from sgtool.llm.constraints import REASON_CHARS
from sgtool.scenegraph.graph import SceneGraph

SPEED_PROMPT = "List the rooms of a house, one per line."


@dataclass(frozen=True)
class SpeedResult:
    completion_tokens: int | None
    latency_s: float
    model: str = ""  # the model the endpoint says answered ("": it did not say)

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
    return SpeedResult(r.completion_tokens, r.latency_s, r.model or "")


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


class CheckFailed(SgtoolError):
    """The check could not measure the endpoint (a fault, or its deadline passed)."""


def check_endpoint(client: ChatClient, decider: ChatClient, graph: SceneGraph, query: str,
                   deadline_s: float, constraint: str = "auto",
                   reason_chars: int = REASON_CHARS,
                   clock: Callable[[], float] = time.monotonic
                   ) -> tuple[SpeedResult, DecisionCheck]:
    """:func:`generation_speed` with ``client``, then :func:`decision_check` with
    ``decider``, both within ``deadline_s`` wall seconds from now; :class:`CheckFailed`
    (one line) when the speed request fails or either step is cut at the deadline."""
    deadline = clock() + float(deadline_s)
    why = f"the check's deadline of {deadline_s:g} s (--llm-timeout)"
    try:
        speed = generation_speed(client, timeout_s=max(deadline - clock(), 1e-3))
    except LlmTransportError as e:
        if clock() >= deadline:
            raise CheckFailed(f"llm check: no complete reply to the speed request within "
                              f"{why}: {e}") from None
        raise CheckFailed(f"llm check: the speed request failed: {e}") from None
    left = deadline - clock()
    if left <= 0:
        raise CheckFailed(f"llm check: {why} was spent by the speed request")
    dec = decision_check(decider, graph, query, constraint=constraint, timeout_s=left,
                         reason_chars=reason_chars)
    if not dec.parsed and clock() >= deadline:
        raise CheckFailed(f"llm check: no scene decision within {why}: {dec.action}")
    return speed, dec
