"""Room categories from room contents with the distilled containment model.

SCOUT infers room categories "from the objects they contain" (sec. IV-A); MoMa-LLM asks an
LLM. Offline we combine the containment model's p_contains(r, o) over the objects seen in a
room, naive-Bayes style: each object votes with its distribution over room types
p(r | o) = p_contains(r, o) / sum_r' p_contains(r', o), and the room's posterior with a
uniform prior is proportional to the product of the votes (a sum of logs). An object found
everywhere (a chair) has a flat distribution and barely votes; a toilet votes hard for the
bathroom. The label set is the room types of the training knowledge (stored with the
weights), so classification needs no data at run time.

Same interface as the frequency classifier of :mod:`sgtool.scenegraph.categories`:
``classify(object_categories) -> [(room type, probability), ...]`` best first.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from sgtool.semantics.priors import LearnedPriors, default_priors
from sgtool.semantics.text import category_text

if TYPE_CHECKING:
    from sgtool.llm.client import ChatClient
    from sgtool.scenegraph.categories import RoomClassifier

EPS = 1e-3  # floor of p_contains so that one unusual object cannot veto a room


class ContainmentRoomClassifier:
    """Room type posterior from contained object categories (module doc)."""

    name = "containment"

    def __init__(self, priors: LearnedPriors | None = None,
                 room_types: Sequence[str] | None = None, temperature: float = 1.0) -> None:
        self.priors = priors or default_priors()
        types = tuple(room_types) if room_types is not None else self.priors.room_types
        if not types:
            raise ValueError("no room types: the weights' metadata lists none and none given")
        # keep the spelling of the knowledge ("living_room"), embed the words
        self.room_types = tuple(sorted(set(types)))
        self.temperature = float(temperature)
        self._votes: dict[str, np.ndarray] = {}
        enc = self.priors.encoder
        self._room_vecs = enc.encode([category_text(t) for t in self.room_types])

    def votes(self, category: str) -> np.ndarray:
        """log p(r | o) over :attr:`room_types` for one object category (memoised)."""
        key = category_text(category)
        v = self._votes.get(key)
        if v is None:
            q = self.priors.encoder.encode([key])[0]
            p = np.maximum(self.priors.containment(self._room_vecs, q), EPS)
            v = np.log(p / p.sum())
            self._votes[key] = v
        return v

    def classify(self, object_categories: list[str]) -> list[tuple[str, float]]:
        """[(room type, probability)] best first; [] for an empty room (unknown)."""
        cats = [c for c in object_categories if category_text(c)]
        if not cats:
            return []
        total = np.zeros(len(self.room_types))
        for c in cats:
            total += self.votes(c)
        z = total / self.temperature
        z -= z.max()
        p = np.exp(z)
        p /= p.sum()
        order = sorted(range(len(p)), key=lambda i: (-p[i], self.room_types[i]))
        return [(self.room_types[i], float(p[i])) for i in order]


ROOM_SYSTEM = ("You are an expert on the layout of houses. You name the type of a room from "
               "the objects in it.")


def room_prompt(objects: Sequence[str], room_types: Sequence[str]) -> list[dict[str, str]]:
    """MoMa-LLM's room classification prompt: the room's object categories (Fig. 3, "room-0:
    armchairs, carpet, table-lamp") and the room types to choose from."""
    return [
        {"role": "system", "content": ROOM_SYSTEM},
        {"role": "user", "content": (
            f"A room contains: {', '.join(objects)}.\n"
            f"Which type of room is it? Choose one of: {', '.join(room_types)}.\n"
            "Answer with the room type only.")},
    ]


class LlmRoomClassifier:
    """Room types named by an LLM from a room's objects (MoMa-LLM, "LLM-based room
    classification"): one request per distinct set of object categories (cached, so a room
    whose objects did not change is not asked again at the next refresh), answered within
    ``room_types`` (a grammar or JSON schema when the client takes one,
    :mod:`sgtool.llm.constraints`; else the answer is matched to the nearest type name).
    Every request is logged as an ``sgtool.LlmExchange`` record (``exchanges``,
    ``on_exchange``) with ``purpose: room_classification``, so a transcript replays it
    (:class:`sgtool.llm.recorded.ReplayChatClient`). A fault or an answer that names no
    room type falls back to ``fallback`` (e.g. :class:`ContainmentRoomClassifier`), else
    to unknown ([]). A prompt a replayed transcript does not hold
    (:class:`~sgtool.llm.recorded.ReplayMiss`) is raised instead: an offline replay either
    matches its recording or says that it diverged.
    """

    name = "llm"

    def __init__(self, client: ChatClient, room_types: Sequence[str], *,
                 constraint: str = "auto", fallback: RoomClassifier | None = None,
                 on_exchange: Callable[[dict[str, Any]], object] | None = None,
                 timeout_s: float = 60.0) -> None:
        from sgtool.llm.constraints import check_kind, detect_kind

        self.client = client
        # asked in words ("living room"), answered in the given spelling ("living_room")
        self._spelling = {category_text(t): t for t in sorted(set(room_types))}
        self.room_types = tuple(sorted(self._spelling))
        if not self.room_types:
            raise ValueError("no room types to choose from")
        kind = check_kind(constraint)
        if kind == "auto":
            settings = getattr(client, "settings", None)
            kind = detect_kind(getattr(settings, "base_url", None),
                               api_key=getattr(settings, "api_key", None)) \
                if getattr(client, "takes_constraint", False) else "none"
        self.constraint = kind
        self.fallback = fallback
        self.on_exchange = on_exchange
        self.timeout_s = float(timeout_s)
        self.exchanges: list[dict[str, Any]] = []
        self._cache: dict[tuple[str, ...], list[tuple[str, float]]] = {}

    def classify(self, object_categories: list[str]) -> list[tuple[str, float]]:
        """[(room type, 1.0)] as the model named it; [] for an empty room."""
        key = tuple(sorted({category_text(c) for c in object_categories if category_text(c)}))
        if not key:
            return []
        hit = self._cache.get(key)
        if hit is None:
            hit = self._ask(key, object_categories)
            self._cache[key] = hit
        return list(hit)

    def _ask(self, objects: tuple[str, ...], raw: list[str]) -> list[tuple[str, float]]:
        from sgtool.llm.client import LlmTransportError, complete_within
        from sgtool.llm.constraints import Constraint
        from sgtool.llm.exchange import exchange_record
        from sgtool.llm.recorded import ReplayMiss

        messages = room_prompt(objects, self.room_types)
        constraint = Constraint(self.constraint, self.room_types, bare=True) \
            if self.constraint in ("grammar", "json_schema") else None
        try:
            r = complete_within(self.client, messages, self.timeout_s, constraint)
        except ReplayMiss:
            raise  # an offline replay that diverged: no silent fallback
        except LlmTransportError as e:
            self._log(exchange_record(model=str(getattr(self.client, "model", "")),
                                      messages=messages, response=None, latency_s=0.0,
                                      error=str(e), extra={"purpose": "room_classification",
                                                           "constraint": self.constraint}))
            return self._fall_back(raw)
        room = match_room_type(r.text, self.room_types)
        self._log(exchange_record(
            model=r.model, messages=messages, response=r.text, latency_s=r.latency_s,
            prompt_tokens=r.prompt_tokens, completion_tokens=r.completion_tokens,
            source=r.source, extra={"purpose": "room_classification",
                                    "constraint": self.constraint,
                                    "verdict": "ok" if room else "invalid: no room type"}))
        return [(self._spelling[room], 1.0)] if room else self._fall_back(raw)

    def _fall_back(self, raw: list[str]) -> list[tuple[str, float]]:
        return list(self.fallback.classify(raw)) if self.fallback is not None else []

    def _log(self, rec: dict[str, Any]) -> None:
        self.exchanges.append(rec)
        if callable(self.on_exchange):
            self.on_exchange(rec)


def match_room_type(text: str, room_types: Sequence[str]) -> str | None:
    """The room type an answer names: a JSON ``{"answer": ...}``, the whole answer, else the
    longest type name in it (``"It is a living room."`` -> living room)."""
    import json

    answer = text.strip()
    if answer.startswith("{"):
        try:
            answer = str(json.loads(answer).get("answer", ""))
        except (ValueError, AttributeError):
            pass
    words = category_text(answer.strip().strip(".").lower())
    if words in room_types:
        return words
    found = [t for t in room_types if f" {t} " in f" {words} "]
    return max(found, key=len) if found else None
