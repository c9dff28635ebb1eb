"""``--llm-replay`` of the commands: the transcripts a repeatable flag names, and the note
for endpoint settings a replay does not use."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from sgtool.errors import SgtoolError


def replay_files(given: Sequence[str]) -> str | list[str]:
    """The transcripts of a repeatable ``--llm-replay``: files as given, a folder's
    ``*.jsonl`` and the ``*.mcap`` logs that hold LLM exchanges (recursively, sorted: a
    ``--log-dir`` of a run that mixed LLM and other planners); one file as itself. A path
    that is neither, or a folder without one, is a one-line error."""
    from sgtool.log import schemas as S
    from sgtool.log.reader import LogReader

    def exchanges(f: Path) -> bool:
        if f.suffix != ".mcap":
            return True
        with LogReader(f) as r:
            return r.has(S.RECORDS["llm_exchange"].topic)

    out: list[str] = []
    for g in given:
        p = Path(g)
        if p.is_dir():
            found = sorted(str(f) for f in p.rglob("*") if f.suffix in (".mcap", ".jsonl")
                           and f.is_file() and exchanges(f))
            if not found:
                raise SgtoolError(f"--llm-replay {g}: no transcripts there (*.jsonl, or *.mcap "
                                  "logs holding LLM exchanges)")
            out += found
        elif p.is_file():
            out.append(str(p))
        else:
            raise SgtoolError(f"--llm-replay: no such transcript {g}")
    return out[0] if len(out) == 1 else out


def replay_sampling_note(name: str, options: Mapping[str, Any]) -> str | None:
    """A note for an LLM planner that replays a transcript (``replay``) and is given an
    endpoint's sampling settings (``temperature``, ``max_tokens``): the transcript's
    answers are served whatever they say, and the log records them as given."""
    given = [f"-O {name}.{k}={options[k]}" for k in ("temperature", "max_tokens")
             if options.get(k) is not None]
    if not options.get("replay") or not given:
        return None
    return (f"sgtool: note: {', '.join(given)}: --llm-replay serves the transcript's "
            "answers, which an endpoint's sampling settings do not change (the log records "
            "them as given)")
