"""GODHS's ranker as in the original: an LLM scores rooms and carriers (``godhs-llm``).

:class:`LlmRanker` implements :class:`sgtool.planning.godhs.Ranker`. GODHS (Zhang et al.
2025) asks a language model which visited rooms are most relevant to the target and which
carriers in a room are likely to hold it; our prompts ask for a JSON object mapping each
name to a likelihood in [0, 1] (JSON mode is requested from endpoints that take it,
:mod:`sgtool.llm.constraints`):

- rooms: the explored rooms by their MoMa-LLM display names
  (:func:`~sgtool.planning.moma.scene_text.room_names`, "bedroom 2"), mapped back to ids;
- carriers: the distinct carrier categories in words.

Answers are memoised per (query, names), so a ranking is asked once per new set of rooms
or carriers. A name the answer leaves out gets the mean of the scored ones; a fault or an
answer that is no usable JSON object falls back to ``fallback`` (the priors'
:class:`~sgtool.planning.godhs.PriorRanker` in the registry), else to 0.5 for all. Every
request is an ``sgtool.LlmExchange`` record (``exchanges``, ``transcript``; ``purpose``
``godhs_rooms`` or ``godhs_carriers``, ``verdict``), so a transcript replays the ranking.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from sgtool.llm.client import ChatClient, LlmTransportError, complete_within
from sgtool.llm.constraints import Constraint
from sgtool.llm.exchange import Message, exchange_record
from sgtool.llm.recorded import TranscriptWriter
from sgtool.planning.moma.scene_text import room_names
from sgtool.scenegraph.graph import SceneGraph
from sgtool.semantics.llm_knowledge import extract_json
from sgtool.semantics.text import category_text

if TYPE_CHECKING:
    from sgtool.planning.godhs import Ranker

SYSTEM = ("You are a robot searching a house for an object. Answer only with JSON, no prose.")
TIMEOUT_S = 60.0


def likelihood_prompt(query: str, what: str, names: Sequence[str]) -> list[Message]:
    return [
        {"role": "system", "content": SYSTEM},
        {"role": "user", "content": (
            f"I am looking for a {query}. For each of these {what}, give the likelihood "
            f"(0 to 1) that the {query} is {'in it' if what == 'rooms' else 'inside or on it'}"
            f": {', '.join(names)}. Answer with a JSON object mapping each name to its "
            "likelihood.")},
    ]


def read_likelihoods(text: str, names: Sequence[str]) -> dict[str, float] | None:
    """name -> likelihood in [0, 1] from a JSON answer (names compared as words); None when
    the answer is no JSON object or scores none of ``names``."""
    try:
        data = extract_json(text)
    except ValueError:
        return None
    if not isinstance(data, dict):
        return None
    by_words = {category_text(str(k)): v for k, v in data.items()}
    out: dict[str, float] = {}
    for n in names:
        v = by_words.get(category_text(n))
        if not isinstance(v, (int, float, str)):  # a JSON value that is no number or text
            continue
        try:
            p = float(v)
        except ValueError:
            continue
        if math.isfinite(p):
            out[n] = min(max(p, 0.0), 1.0)
    return out or None


class LlmRanker:
    """Rooms and carriers ranked by an LLM (module doc)."""

    def __init__(self, client: ChatClient, fallback: Ranker | None = None,
                 transcript: str | Path | None = None) -> None:
        self.client = client
        self.fallback = fallback
        self.name = f"llm({getattr(client, 'model', 'model')})"
        self.exchanges: list[dict[str, Any]] = []
        self._transcript = TranscriptWriter(transcript) if transcript else None
        self._memo: dict[tuple[str, str, tuple[str, ...]], dict[str, float] | None] = {}

    def rooms(self, graph: SceneGraph, query: str) -> dict[str, float]:
        names = room_names(graph)
        explored = {r.id: names[r.id] for r in graph.rooms if r.explored}
        scored = self._ask("rooms", query, tuple(sorted(set(explored.values()))))
        if scored is None:
            if self.fallback is not None:
                return self.fallback.rooms(graph, query)
            return {rid: 0.5 for rid in explored}
        mean = float(np.mean(list(scored.values())))
        return {rid: scored.get(n, mean) for rid, n in explored.items()}

    def carriers(self, categories: Sequence[str], query: str) -> np.ndarray:
        words = [category_text(c) for c in categories]
        scored = self._ask("carriers", query, tuple(sorted(set(words) - {""})))
        if scored is None:
            if self.fallback is not None:
                return np.asarray(self.fallback.carriers(categories, query), np.float64)
            return np.full(len(words), 0.5)
        mean = float(np.mean(list(scored.values())))
        return np.array([scored.get(w, mean) for w in words], dtype=np.float64)

    def _ask(self, what: str, query: str, names: tuple[str, ...]) -> dict[str, float] | None:
        if not names:
            return None
        key = (what, category_text(query), names)
        if key not in self._memo:
            self._memo[key] = self._request(what, category_text(query), names)
        return self._memo[key]

    def _request(self, what: str, query: str, names: tuple[str, ...]
                 ) -> dict[str, float] | None:
        messages = likelihood_prompt(query, what, names)
        json_mode = Constraint("json_object", ()) \
            if getattr(self.client, "takes_constraint", False) else None
        extra: dict[str, Any] = {"purpose": f"godhs_{what}"}
        try:
            r = complete_within(self.client, messages, TIMEOUT_S, json_mode)
        except LlmTransportError as e:
            self._log(exchange_record(model=str(getattr(self.client, "model", "")),
                                      messages=messages, response=None, latency_s=0.0,
                                      error=str(e), query=query, extra=extra))
            return None
        scored = read_likelihoods(r.text, names)
        extra["verdict"] = "ok" if scored else "invalid: no likelihoods"
        self._log(exchange_record(
            model=r.model, messages=messages, response=r.text, latency_s=r.latency_s,
            prompt_tokens=r.prompt_tokens, completion_tokens=r.completion_tokens,
            query=query, source=r.source, extra=extra))
        return scored

    def _log(self, rec: dict[str, Any]) -> None:
        self.exchanges.append(rec)
        if self._transcript is not None:
            self._transcript.write(rec)

    def close(self) -> None:
        if self._transcript is not None:
            self._transcript.close()
