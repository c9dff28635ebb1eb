"""Reading many episode files for ``sgtool eval`` on an executor.

Each input (an MCAP log or an ``episodes.jsonl``) is read by one task of
:mod:`sgtool.analysis.executor` with :func:`sgtool.analysis.offline.load_results`, and the
episodes, logged decision points and notes are put back together in input order, so the
metrics are those of one sequential read whatever the executor. A file that cannot be read
(after a retry) is left out with a note naming it and its error; :func:`load_many` returns
the notes of the files that failed so the command can say so once its output is written. Asking
planners at the logged decision points stays in the calling process: one planner sees
every episode in input order, as without an executor.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

from sgtool.analysis.executor import Executor, Task
from sgtool.analysis.offline import load_results


def load_one(path: str) -> tuple[list[Any], list[Any], list[str]]:
    """(episode results, logged episodes, notes) of one file."""
    notes: list[str] = []
    results, logged = load_results([path], notes)
    return results, logged, notes


NOT_READ = ": not read ("  # a failed file's note: "PATH: not read (WHY)"


def unread_path(note: str) -> str:
    """The file a failure note of :func:`load_many` names."""
    return note.split(NOT_READ, 1)[0]


def load_many(paths: Sequence[Path], executor: Executor, *, progress: bool = False
              ) -> tuple[list[Any], list[Any], list[str], list[str]]:
    """(results, logged episodes, notes, the notes of the files that failed) of every
    file, in input order."""
    tasks = [Task(str(p), str(p)) for p in paths]
    results: list[Any] = []
    logged: list[Any] = []
    notes: list[str] = []
    failed: list[str] = []
    for o in executor.run(load_one, tasks, progress=progress, desc="eval"):
        if not o.ok:
            notes.append(f"{o.id}{NOT_READ}{o.error})")
            failed.append(notes[-1])
            continue
        r, lg, n = o.value
        results.extend(r)
        logged.extend(lg)
        notes.extend(n)
    return results, logged, notes, failed
