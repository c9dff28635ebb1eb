"""MoMa-LLM as a planner: structured scene text -> chat model -> grounded command.

Per decision (MoMa-LLM sec. III-C/D; reference notes):

1. encode the scene graph (:mod:`~sgtool.planning.moma.scene_text`) and the history of
   executed actions, *realigned* to the current graph: a past action keeps its node and
   position; it is shown with the room that node (or, if the node is gone, the graph node
   nearest to the position) belongs to *now* (``explore(living room)`` becomes
   ``explore(kitchen)`` once the room is reclassified);
2. ask the model (system: role, task, skill API, answer format; user: scene, history);
3. parse "Analysis / Reasoning / Command" and ground the command
   (:mod:`~sgtool.planning.moma.commands`);
4. on a transport fault retry the same prompt; on an unusable or invalid command append
   the answer and a feedback message naming the problem and the valid choices, and ask
   again. This feedback reaches the model (MoMa-LLM's own feedback strings were dropped by
   a role filter: the defect noted in the reference notes). At most ``max_attempts``
   requests per decision, all within ``decision_timeout_s`` (60 s by default, wall-clock:
   each request, a slow or trickled reply included, is cut at what is left of it,
   :mod:`sgtool.llm.client`); then the decision fails clearly (``done`` without target,
   reason "llm failure: ...");
5. stuck detector: the same grounded action chosen ``stuck_repeats`` times in a row ends
   the episode (``done`` without target, reason "stuck: ...").

The outcome of executed actions (:meth:`MomaLlmPlanner.feedback`) goes into the history as
``success``, ``failure`` or ``invalid argument`` with the executor's message; commands the
planner rejected stay in the history as written, with ``invalid argument`` and the reason.
Every request is logged as an ``sgtool.LlmExchange`` record: kept in
:attr:`MomaLlmPlanner.exchanges`, passed to ``on_exchange`` and appended to ``transcript``
(JSONL, replayable), with the answer's ``verdict`` (``ok`` or ``invalid: reason``) and the
``constraint`` it was generated under. ``constraint`` (:mod:`sgtool.llm.constraints`):
``grammar`` or ``json_schema`` restrict the answer to the valid commands of the current
scene (:func:`~sgtool.planning.moma.choices.valid_commands`), ``auto`` asks the endpoint
which it supports, ``none`` parses plain answers. :attr:`MomaLlmPlanner.invalid_commands`
counts the rejected answers of the episode (MoMa-LLM's invalid actions).
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from sgtool.llm.client import (
    ChatClient,
    LlmEndpointDown,
    LlmTransportError,
    LlmUnreachableError,
    complete_within,
)
from sgtool.llm.constraints import REASON_CHARS, Constraint, check_kind, detect_kind
from sgtool.llm.exchange import Message, exchange_record
from sgtool.llm.recorded import ReplayMiss, TranscriptWriter
from sgtool.planning.base import Action, Feedback, Outcome
from sgtool.planning.moma.choices import valid_commands
from sgtool.planning.moma.commands import InvalidCommand, ground, parse_response
from sgtool.planning.moma.scene_text import EncodedScene, encode_scene, nearest_room, room_of
from sgtool.scenegraph.graph import SceneGraph
from sgtool.semantics.text import category_text

OUTCOME_TEXT: dict[Outcome, str] = {"success": "success", "failure": "failure",
                                    "invalid": "invalid argument"}


def with_article(noun: str) -> str:
    """"a mug", "an apple", "some short pants" (a plural-looking last word: -s but not
    -ss, -us or -is)."""
    q = noun.strip()
    last = q.split()[-1].lower() if q else ""
    if last.endswith("s") and not last.endswith(("ss", "us", "is")):
        return f"some {q}"
    return f"{'an' if q[:1].lower() in 'aeiou' and q else 'a'} {q}"


def system_prompt(query: str) -> str:
    q = query.strip()
    aq = with_article(q)
    return (
        f"You are a robot in an unexplored house. Your task is to find {aq}.\n"
        "You can call these functions:\n"
        "1. navigate(room, object): go to an object in a room and look at it and on it.\n"
        "2. go_to_and_open(room, object): go to an object or a door in a room and open it "
        "to see what is inside or behind it.\n"
        "3. close(room, object): close an open object or door in a room.\n"
        "4. explore(room): explore the unexplored area of a room, the space leading out of "
        "it, or an unexplored room.\n"
        f"5. done(): finish; call it only when {aq} is among the observed objects.\n"
        "Use room and object names exactly as the scene description writes them.\n"
        "Answer in exactly this format:\n"
        f"Analysis: <where {aq} is likely to be and which actions could reveal it>\n"
        "Reasoning: <why your next command is the best one now>\n"
        "Command: <one function call>"
    )


@dataclass
class HistoryEntry:
    command: str  # navigate | go_to_and_open | close | explore
    target: str | None
    position: tuple[float, float] | None
    label: str  # object words at decision time ("" for explore)
    room_name: str  # as shown then (used only if nothing better is known now)
    outcome: Outcome | None = None
    message: str = ""
    text: str = ""  # a rejected command as the model wrote it (no node to realign)


DECISION_TIMEOUT_S = 60.0  # wall seconds for all the requests of one decision


class MomaLlmPlanner:
    name = "moma-llm"

    def __init__(
        self,
        client: ChatClient,
        max_attempts: int = 5,
        stuck_repeats: int = 3,
        history_limit: int = 30,
        on_exchange: Callable[[dict[str, Any]], None] | None = None,
        transcript: str | Path | None = None,
        decision_timeout_s: float = DECISION_TIMEOUT_S,
        constraint: str = "none",
        reason_chars: int = REASON_CHARS,
    ) -> None:
        if max_attempts < 1:
            raise ValueError("max_attempts must be >= 1")
        if not decision_timeout_s > 0:
            raise ValueError("decision_timeout_s must be > 0")
        self.decision_timeout_s = float(decision_timeout_s)
        self.constraint = check_kind(constraint)
        if self.constraint == "auto":
            settings = getattr(client, "settings", None)
            self.constraint = detect_kind(getattr(settings, "base_url", None),
                                          api_key=getattr(settings, "api_key", None)) \
                if getattr(client, "takes_constraint", False) else "none"
        self.reason_chars = int(reason_chars)
        self.invalid_commands = 0  # answers rejected (unparsable or not groundable)
        self.replay_miss: str | None = None  # the recorded transcript ran out (this episode)
        self.client = client
        self.max_attempts = int(max_attempts)
        self.stuck_repeats = int(stuck_repeats)
        self.history_limit = int(history_limit)
        self.on_exchange = on_exchange
        self._transcript = TranscriptWriter(transcript) if transcript else None
        self.exchanges: list[dict[str, Any]] = []
        self.query = ""
        self.step = 0
        self.history: list[HistoryEntry] = []
        self._repeat: tuple[tuple[str, str | None], int] | None = None

    # ----- Planner protocol -------------------------------------------------------------
    def reset(self, query: str, seed: int = 0) -> None:
        self.invalid_commands = 0
        self.replay_miss = None
        self.query = query
        self.step = 0
        self.history = []
        self._repeat = None

    def feedback(self, fb: Feedback) -> None:
        if not self.history or fb.action.skill == "done":
            return
        last = next((h for h in reversed(self.history) if not h.text), None)
        if last is not None and last.target == fb.action.target and last.outcome is None:
            last.outcome = fb.outcome
            last.message = fb.message

    def decide(self, graph: SceneGraph) -> Action:
        if not self.query:
            raise RuntimeError("moma-llm: reset(query) must be called before decide()")
        self.step += 1
        scene = encode_scene(graph)
        constraint = self._constraint(graph, scene)
        messages: list[Message] = [
            {"role": "system", "content": system_prompt(self.query)},
            {"role": "user", "content": self.user_prompt(graph, scene.text)},
        ]
        problems: list[str] = []
        deadline = time.monotonic() + self.decision_timeout_s
        attempts = down = 0
        for attempt in range(self.max_attempts):
            left = deadline - time.monotonic()
            if left <= 0:
                problems.append(f"the decision deadline of {self.decision_timeout_s:g} s "
                                "is spent")
                break
            attempts += 1
            t_ask = time.perf_counter()
            try:
                result = complete_within(self.client, messages, left, constraint)
            except ReplayMiss as e:
                self._log(messages, None, 0.0, None, None, str(e), attempt)
                self.replay_miss = str(e)
                return Action("done", None, reason=f"llm failure: {e}")
            except LlmTransportError as e:  # its latency: the time spent until it failed
                self._log(messages, None, time.perf_counter() - t_ask, None, None, str(e),
                          attempt)
                problems.append(str(e))
                down += isinstance(e, LlmEndpointDown)
                continue
            cmd = None
            try:
                cmd = parse_response(result.text)
                action = ground(cmd, graph, scene, self.query)
            except InvalidCommand as e:
                self.invalid_commands += 1
                self._log(messages, result.text, result.latency_s, result.prompt_tokens,
                          result.completion_tokens, None, attempt, result.model, result.source,
                          getattr(result, "truncated_from", None), f"invalid: {e}")
                problems.append(str(e))
                if cmd is not None:  # MoMa-LLM keeps "invalid argument" in the history
                    self.history.append(HistoryEntry(cmd.name, None, None, "", "",
                                                     "invalid", str(e), cmd.text()))
                messages = [
                    *messages,
                    {"role": "assistant", "content": result.text},
                    {"role": "user", "content": (
                        f"Your command could not be executed: invalid argument: {e}. "
                        "Answer again in the same format with a valid command."
                    )},
                ]
                continue
            self._log(messages, result.text, result.latency_s, result.prompt_tokens,
                      result.completion_tokens, None, attempt, result.model, result.source,
                      getattr(result, "truncated_from", None), "ok")
            return self._accept(cmd.name, action, graph, scene.name_by_room)
        last = problems[-1] if problems else "no answer"
        if attempts and down == attempts:  # the endpoint's outage, not the planner's answer
            raise LlmUnreachableError(
                f"the LLM endpoint failed at all {attempts} attempts of a decision ({last}): "
                "an outage, not scored as the planner giving up; restart or fix it and run "
                "again (run-bench keeps the episodes logged)")
        return Action(
            "done", None,
            reason=f"llm failure: no valid command after {attempts} attempt"
                   f"{'' if attempts == 1 else 's'}: {last}",
        )

    def _constraint(self, graph: SceneGraph, scene: EncodedScene) -> Constraint | None:
        """The valid commands of this decision as a grammar or schema (``constraint``)."""
        if self.constraint not in ("grammar", "json_schema"):
            return None
        commands = valid_commands(graph, scene, self.query)
        return Constraint(self.constraint, commands, self.reason_chars) if commands else None

    # ----- pieces -----------------------------------------------------------------------
    def _accept(self, command: str, action: Action, graph: SceneGraph,
                names: dict[str, str]) -> Action:
        key = (action.skill, action.target)
        if self._repeat is not None and self._repeat[0] == key:
            self._repeat = (key, self._repeat[1] + 1)
        else:
            self._repeat = (key, 1)
        if self.stuck_repeats > 0 and self._repeat[1] >= self.stuck_repeats:
            return Action(
                "done", None,
                reason=f"stuck: {action.skill}({action.target}) chosen "
                       f"{self._repeat[1]} times in a row",
            )
        if action.skill != "done":
            node = graph.node(action.target) if action.target else None
            pos = (float(node.position[0]), float(node.position[1])) if node else None
            label = category_text(getattr(node, "category", "")) if command != "explore" else ""
            if not label and command != "explore":
                label = "door"
            room = room_of(graph, action.target) if action.target else None
            self.history.append(
                HistoryEntry(command, action.target, pos, label, names.get(room or "", "?"))
            )
        return action

    def user_prompt(self, graph: SceneGraph, scene_text: str) -> str:
        parts = [scene_text]
        hist = self.render_history(graph)
        parts.append("Previous actions:\n" + ("\n".join(hist) if hist else "- none"))
        parts.append("What is your next command?")
        return "\n\n".join(parts)

    def render_history(self, graph: SceneGraph) -> list[str]:
        """History lines realigned to the rooms of ``graph`` (module doc)."""
        from sgtool.planning.moma.scene_text import room_names

        names = room_names(graph)
        out = []
        entries = self.history[-self.history_limit:] if self.history_limit > 0 else []
        for e in entries:
            if e.text:
                out.append(f"- {e.text} - invalid argument: {e.message}")
                continue
            room = None
            if e.target is not None and graph.node(e.target) is not None:
                room = room_of(graph, e.target)
            elif e.position is not None:
                room = nearest_room(graph, e.position)
            room_name = names.get(room or "", e.room_name)
            if e.command == "explore":
                call = f"explore({room_name})"
            else:
                call = f"{e.command}({room_name}, {e.label})"
            if e.outcome is None:
                out.append(f"- {call}")
            else:
                tail = f": {e.message}" if e.message else ""
                out.append(f"- {call} - {OUTCOME_TEXT.get(e.outcome, e.outcome)}{tail}")
        return out

    def _log(self, messages: list[Message], response: str | None, latency: float,
             ptok: int | None, ctok: int | None, error: str | None, attempt: int,
             model: str | None = None, source: str | None = None,
             truncated_from: int | None = None, verdict: str | None = None) -> None:
        extra: dict[str, Any] = {}
        if self.constraint in ("grammar", "json_schema"):
            extra["constraint"] = self.constraint
        if verdict is not None:
            extra["verdict"] = verdict
        rec = exchange_record(
            model=model or self.client.model, messages=messages, response=response,
            latency_s=latency, prompt_tokens=ptok, completion_tokens=ctok, error=error,
            attempt=attempt, step=self.step, query=self.query,
            source=source or str(getattr(self.client, "source", "endpoint")),
            truncated_from=truncated_from, extra=extra,
        )
        self.exchanges.append(rec)
        if self._transcript is not None:
            self._transcript.write(rec)
        if self.on_exchange is not None:
            self.on_exchange(rec)

    def drain_exchanges(self) -> list[dict[str, Any]]:
        """Exchanges since the last call (for a log writer), oldest first."""
        out, self.exchanges = self.exchanges, []
        return out

    def close(self) -> None:
        if self._transcript is not None:
            self._transcript.close()


def replay_miss_of(planner: object) -> str | None:
    """What made ``planner`` (or the planner a wrapper holds as ``inner``) leave its
    recorded transcript in the episode just run (``--llm-replay`` of another run), or
    None; a run that meets one is no replay and must say so, not score a give-up."""
    inner = getattr(planner, "inner", planner)
    miss = getattr(inner, "replay_miss", None)
    return miss if isinstance(miss, str) else None

