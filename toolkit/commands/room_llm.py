"""``sgtool replay --classifier llm``: the chat client, transcript and answer counts of
MoMa-LLM's room classification (:class:`sgtool.semantics.room_classification.LlmRoomClassifier`).

The client is an endpoint (``--llm-base-url`` / ``--llm-model`` / ``--llm-api-key``, or the
``SGTOOL_LLM_*`` variables) or, offline, the recorded transcripts of ``--llm-replay`` (JSONL or
an MCAP log's ``/sgtool/llm``): answers are served by prompt, so a replay with a transcript
rebuilds the same room categories, and the same derived bytes, every time. ``--llm-transcript``
writes every exchange as a fresh JSONL file (complete or absent). A replayed transcript that
lacks a prompt is one error line (the replay diverged), never a silent fallback.
"""

from __future__ import annotations

import contextlib
import sys
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from typing import Any

from sgtool.errors import SgtoolError

ANSWER_TOKENS = 32  # a room type; bounds a small model that does not stop


@dataclass
class RoomLlm:
    """What a replay needs of the LLM room classifier: the factory handed to
    :func:`sgtool.replayers.derived_log.replay` and the exchanges it made."""

    make: Callable[[str], Any]
    exchanges: list[dict[str, Any]] = field(default_factory=list)

    def stats(self) -> Any:
        from sgtool.llm.stats import answer_stats

        # every request is its own decision (one set of a room's objects)
        return answer_stats((str(i), r) for i, r in enumerate(self.exchanges))

    def lines(self) -> list[str]:
        if not self.exchanges:
            return []
        from sgtool.llm.stats import format_stats

        return [format_stats(self.stats(), "room classification")]


@dataclass(frozen=True)
class LlmOptions:
    base_url: str | None = None
    model: str | None = None
    api_key: str | None = None
    timeout_s: float = 60.0
    constraint: str = "auto"
    replay: tuple[str, ...] = ()
    transcript: str | None = None

    def given(self) -> bool:
        """Any --llm-* option other than the defaults."""
        return bool(self.base_url or self.model or self.api_key or self.replay
                    or self.transcript)

    def client(self) -> Any:
        from sgtool.llm.client import LlmSettings, OpenAIChatClient
        from sgtool.llm.recorded import ReplayChatClient

        if self.replay:
            if self.base_url:
                raise SgtoolError("--llm-replay answers offline; leave out --llm-base-url")
            return ReplayChatClient(list(self.replay), model=self.model)
        return OpenAIChatClient(LlmSettings.resolve(
            base_url=self.base_url, model=self.model, api_key=self.api_key,
            timeout_s=self.timeout_s, temperature=0.0, max_tokens=ANSWER_TOKENS))

    @contextlib.contextmanager
    def room_classifier(self) -> Iterator[RoomLlm]:
        """A :class:`RoomLlm` whose factory builds the named classifier (the LLM client only
        when the name is ``llm``); the transcript is written on success, removed on error."""
        from sgtool.datasets.room_evidence import make_classifier

        writer = None
        if self.transcript:  # the LLM modules (urllib, ssl) load only when asked for
            from sgtool.llm.recorded import TranscriptWriter

            writer = TranscriptWriter(self.transcript, append=False)
        out = RoomLlm(make=make_classifier)

        def log(rec: dict[str, Any]) -> None:
            out.exchanges.append(rec)
            if writer is not None:
                writer.write(rec)

        def make(name: str) -> Any:
            if name != "llm":
                if self.given():
                    raise SgtoolError(f"the --llm-* options are for --classifier llm; this "
                                      f"replay classifies rooms with {name}")
                return make_classifier(name)
            return make_classifier("llm", self.client(), constraint=self.constraint,
                                   on_exchange=log, timeout_s=self.timeout_s)

        out.make = make
        try:
            yield out
        except BaseException as e:
            if writer is not None:
                writer.abort()
            if _is_replay_miss(e):
                raise SgtoolError(f"--llm-replay: {e}") from None
            raise
        if writer is not None:
            writer.close()


def _is_replay_miss(e: BaseException) -> bool:
    """``e`` is the offline transcript's miss (:class:`sgtool.llm.recorded.ReplayMiss`);
    its module is imported only when the LLM classifier ran, so nothing else loads it."""
    recorded = sys.modules.get("sgtool.llm.recorded")
    return recorded is not None and isinstance(e, recorded.ReplayMiss)
