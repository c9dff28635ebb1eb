"""Transcripts of LLM exchanges (JSONL) and a client that serves them back.

A run against a live endpoint writes every exchange record (:mod:`sgtool.llm.exchange`) as
one JSON line. ``--llm-replay FILE`` then answers each prompt with the response recorded for
the identical prompt (matched by ``prompt_sha256``; several answers to one prompt are served
in recorded order), including recorded faults, which are raised again. A deterministic
planner fed the same scene graphs therefore makes the same decisions without any endpoint.
A prompt the transcript does not hold raises :class:`ReplayMiss`, which the planner turns
into a clear failure instead of a guess. An MCAP log with an ``/sgtool/llm`` channel is a
transcript too, and several transcripts can be served as one (the logs of a bench run).
"""

from __future__ import annotations

import contextlib
import json
import logging
import os
import stat
import time
from collections import deque
from collections.abc import Iterator, Sequence
from pathlib import Path
from typing import Any

from sgtool.errors import LogFormatError, SgtoolError
from sgtool.files import output_error, temp_beside
from sgtool.llm.client import ChatResult, LlmTransportError
from sgtool.llm.exchange import Message, prompt_key
from sgtool.log.records import LlmExchange

log = logging.getLogger(__name__)


MCAP_MAGIC = b"\x89MCAP0\r\n"
FIRST_LINE_MAX = 64 << 20  # bytes of a transcript's first line read to judge it


class TranscriptError(SgtoolError):
    """A transcript file is missing or malformed."""


class ReplayMiss(LlmTransportError):
    """The transcript has no (more) responses for this prompt."""


@contextlib.contextmanager
def transcript_run(path: str | Path | None) -> Iterator[None]:
    """A command's run writing the transcript at ``path``: emptied (created) when the run
    starts, since a transcript holds one run, so that a replay of it cannot serve an
    earlier run's answers to the same prompts first (the planner's writer then appends the
    run's exchanges). The transcript that was there is put back when the run is
    interrupted (Ctrl-C, SIGTERM: the run's other outputs are left as they were too) or
    fails before its first exchange (a setup mistake); a run that ends, or fails after
    asking, keeps its own. While the run lasts, the earlier transcript is kept beside it as
    ``NAME.XXXXXXXX.previous``, where a killed run (SIGKILL) leaves it in sight."""
    if path is None:
        yield
        return
    p = Path(path)
    not_a_transcript(p)
    previous: Path | None = None
    try:
        p.parent.mkdir(parents=True, exist_ok=True)
        if p.exists():
            fd, previous = temp_beside(p, ".previous", hidden=False)
            os.close(fd)
            os.replace(p, previous)
        with open(p, "w", encoding="utf-8"):
            pass
    except OSError as e:
        raise output_error(e, p) from None
    restore = False
    try:
        yield
    except KeyboardInterrupt:
        restore = True
        raise
    except BaseException:
        restore = not p.exists() or p.stat().st_size == 0
        raise
    finally:
        with contextlib.suppress(OSError):
            if restore and previous is not None:
                os.replace(previous, p)
            elif restore:
                p.unlink()
            elif previous is not None:
                previous.unlink()


def not_a_transcript(path: Path) -> None:
    """Refuse (one line) to write a transcript over a regular file that is not one: an
    MCAP log, or a file whose first non-blank line is no exchange record (a JSON object
    with ``model`` and ``messages``; a file of blank lines is empty). A missing file, or
    one that is no regular file (a FIFO, ``/dev/stdout``), is never read here."""
    try:
        if not stat.S_ISREG(path.stat().st_mode):
            return
        with open(path, "rb") as fh:
            if fh.read(len(MCAP_MAGIC)) == MCAP_MAGIC:
                raise TranscriptError(f"transcript {path}: an MCAP log, not a JSONL "
                                      "transcript; not writing over it")
            fh.seek(0)
            first = b""
            while not first and (line := fh.readline(FIRST_LINE_MAX)):
                first = line.strip()
    except FileNotFoundError:
        return
    except OSError as e:
        raise output_error(e, path) from None
    if not first:
        return
    try:
        d = json.loads(first)
        ok = isinstance(d, dict) and "model" in d and "messages" in d
    except ValueError:  # (a first line cut at FIRST_LINE_MAX is no transcript's either)
        ok = False
    if not ok:
        raise TranscriptError(f"transcript {path}: exists and is not a JSONL transcript "
                              "of LLM exchanges; not writing over it")


class TranscriptWriter:
    """Writes records as JSON lines, one ``write`` + flush per record.

    ``append=True`` (what planners use) adds to an existing transcript, so the episodes of
    a benchmark run collect in one file and a crash loses at most the line being written.
    ``append=False`` writes a fresh file through a uniquely named ``.NAME.XXXXXXXX.partial``
    beside it (:func:`sgtool.files.temp_beside`), renamed on :meth:`close`, so an
    interrupted run never leaves a file that looks complete; an exception inside ``with``
    removes it. A destination that cannot be written is an :class:`~sgtool.files.OutputError`.
    """

    def __init__(self, path: str | Path, append: bool = True) -> None:
        self.path = Path(path)
        self.append = append
        not_a_transcript(self.path)  # a log or another file is never written over
        try:
            self.path.parent.mkdir(parents=True, exist_ok=True)
            if append:
                self._tmp = self.path
                self._fh = open(self.path, "a", encoding="utf-8")  # noqa: SIM115
            else:
                fd, self._tmp = temp_beside(self.path)
                self._fh = os.fdopen(fd, "w", encoding="utf-8")
        except OSError as e:
            raise output_error(e, self.path) from None
        self.count = 0

    def __getstate__(self) -> None:
        """Refused in one line: a writer in two processes would interleave one file."""
        raise SgtoolError(f"an LLM planner writing the transcript {self.path} cannot be "
                          "copied to another process (both would write that file); give "
                          "each process its own transcript")

    def write(self, record: dict[str, Any]) -> None:
        try:
            self._fh.write(json.dumps(record, sort_keys=True, ensure_ascii=False) + "\n")
            self._fh.flush()
        except OSError as e:
            raise output_error(e, self.path, "the transcript keeps the lines before") from None
        self.count += 1

    def close(self) -> None:
        if not self._fh.closed:
            try:
                self._fh.close()
                if not self.append:
                    os.replace(self._tmp, self.path)
            except OSError as e:
                self.abort()
                raise output_error(e, self.path) from None

    def abort(self) -> None:
        """Close; a fresh transcript (``append=False``) is removed."""
        with contextlib.suppress(OSError):
            self._fh.close()
        if not self.append:
            self._tmp.unlink(missing_ok=True)

    def __enter__(self) -> TranscriptWriter:
        return self

    def __exit__(self, exc_type: object, *exc: object) -> None:
        if exc_type is None:
            self.close()
        else:
            self.abort()


def is_mcap_file(path: str | Path) -> bool:
    """``path`` starts with the MCAP magic (a log, not a JSONL transcript)."""
    with open(path, "rb") as fh:
        return fh.read(len(MCAP_MAGIC)) == MCAP_MAGIC


def read_transcript(path: str | Path) -> list[dict[str, Any]]:
    """The exchange records of a JSONL transcript, or of the ``/sgtool/llm`` channel of an
    MCAP log (a closed-loop log, a bench ``--log-dir`` log), in recorded order."""
    path = Path(path)
    if not path.is_file():
        raise TranscriptError(f"LLM transcript not found: {path}")
    if is_mcap_file(path):
        return _log_exchanges(path)
    out = []
    with open(path, encoding="utf-8") as fh:
        lines = fh.readlines()
    for n, line in enumerate(lines, 1):
        if not line.strip():
            continue
        try:
            rec = json.loads(line)
        except json.JSONDecodeError as e:
            if n == len(lines) and not line.endswith("\n"):
                log.warning("%s:%d: incomplete last line (interrupted run) ignored", path, n)
                continue
            raise TranscriptError(f"{path}:{n}: not a JSON line ({e.msg})") from e
        try:
            LlmExchange.check(rec, "the line")
        except LogFormatError as e:
            raise TranscriptError(f"{path}:{n}: not an sgtool.LlmExchange record ({e})") \
                from None
        rec.setdefault("prompt_sha256", prompt_key(rec["messages"]))
        out.append(rec)
    return out


def _log_exchanges(path: Path) -> list[dict[str, Any]]:
    from sgtool.log.reader import LogReader

    with LogReader(path) as log:
        out = [rec.to_json() for _, rec in log.records(LlmExchange)]
    for rec in out:
        rec.setdefault("prompt_sha256", prompt_key(rec["messages"]))
    return out


class ReplayChatClient:
    """Serves recorded responses by prompt; see the module doc. ``path`` is one transcript
    (JSONL or MCAP log) or several, read in the order given."""

    source = "replay"

    def __init__(self, path: str | Path | Sequence[str | Path], model: str | None = None
                 ) -> None:
        paths = [Path(path)] if isinstance(path, str | Path) else [Path(p) for p in path]
        self.path = paths[0] if len(paths) == 1 else Path(f"{paths[0]} (+{len(paths) - 1})")
        records = []
        for p in paths:
            got = read_transcript(p)
            if not got and is_mcap_file(p):
                raise TranscriptError(
                    f"{p} holds no LLM exchanges (/sgtool/llm): the derived log of `replay "
                    "--classifier llm` does not log them; give the --llm-transcript that "
                    "replay wrote, or a log of an LLM planner's run")
            records += got
        self.model = model or (records[0]["model"] if records else "replay")
        self._queues: dict[str, deque[dict[str, Any]]] = {}
        for rec in records:
            self._queues.setdefault(rec["prompt_sha256"], deque()).append(rec)
        self.served = 0

    def remaining(self) -> int:
        return sum(len(q) for q in self._queues.values())

    def complete(self, messages: list[Message]) -> ChatResult:
        t0 = time.perf_counter()
        q = self._queues.get(prompt_key(messages))
        if not q:
            raise ReplayMiss(
                f"transcript {self.path} holds no (more) responses for this prompt; "
                "the run diverged from the recorded one"
            )
        rec = q.popleft()
        self.served += 1
        if rec.get("error") or rec.get("response") is None:
            raise LlmTransportError(f"(replayed) {rec.get('error') or 'no response'}")
        return ChatResult(
            text=str(rec["response"]),
            model=str(rec.get("model", self.model)),
            latency_s=time.perf_counter() - t0,
            prompt_tokens=rec.get("prompt_tokens"),
            completion_tokens=rec.get("completion_tokens"),
            source="replay",
        )
