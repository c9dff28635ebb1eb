"""What the inputs of ``sgtool eval`` say about the settings they ran under: runs made
apart (a lab's planner, a stored run of the baselines) are paired on their episodes, so a
step budget that differs between them would decide a comparison without a word.
:func:`settings_notes` reads the ``summary.json`` beside each ``episodes.jsonl`` input
(``sgtool bench`` writes both) and names what differs (a planner's options that differ are
told apart by :func:`sgtool.analysis.eval_run.per_options`).
"""

from __future__ import annotations

import json
from collections.abc import Sequence
from pathlib import Path
from typing import Any

COMPARED = ("max_steps", "priors_dir",  # bench settings that change what an episode scores
            "distance_budget", "step_budget")  # and the AUC-E curves
# what a generated house of a given id is made from (its seed is in the id)
HOUSE_MAKING = ("rooms", "preset")


def recorded_budgets(files: Sequence[str]) -> tuple[float | None, float | None]:
    """(distance, step) AUC-E budgets the bench runs among ``files`` were made with, each
    None when no run records it or the runs differ (a note says so)."""
    found: dict[str, set[float]] = {"distance_budget": set(), "step_budget": set()}
    for f in files:
        p = Path(f)
        if p.name == "episodes.jsonl" and (s := run_settings(p.parent / "summary.json")):
            for key, seen in found.items():
                if isinstance(s.get(key), int | float) and not isinstance(s[key], bool):
                    seen.add(float(s[key]))
    dist, steps = (next(iter(v)) if len(v) == 1 else None for v in found.values())
    return dist, steps


def run_settings(summary: Path) -> dict[str, Any] | None:
    """The ``settings`` a bench run's ``summary.json`` records; None when it has none."""
    try:
        doc = json.loads(summary.read_text())
    except (OSError, ValueError):
        return None
    settings = doc.get("settings") if isinstance(doc, dict) else None
    return settings if isinstance(settings, dict) else None


def settings_notes(files: Sequence[str]) -> list[str]:
    """One note per setting of :data:`COMPARED` whose value differs between the bench
    runs among ``files`` (runs of one planner with other options are told apart by
    :func:`sgtool.analysis.eval_run.per_options`)."""
    runs: dict[str, dict[str, Any]] = {}
    for f in files:
        p = Path(f)
        if p.name == "episodes.jsonl" and (s := run_settings(p.parent / "summary.json")):
            runs[str(p.parent)] = s
    notes = []
    for key in COMPARED:
        values = {run: s[key] for run, s in runs.items() if key in s}
        if len({json.dumps(v) for v in values.values()}) > 1:
            shown = ", ".join(f"{v} in {run}" for run, v in values.items())
            notes.append(f"the runs given ran with different {key} ({shown}): their rows and "
                         "paired comparisons mix them")
    generated = {run: s for run, s in runs.items() if s.get("houses")}
    ids = {run: _house_ids(Path(run) / "episodes.jsonl") for run in generated}
    for key in HOUSE_MAKING:
        values = {run: s[key] for run, s in generated.items() if key in s}
        if len({json.dumps(v) for v in values.values()}) > 1 and _share_an_id(
                [ids[run] for run in values]):
            shown = ", ".join(f"{v} in {run}" for run, v in values.items())
            notes.append(f"the runs given generated their houses with different {key} "
                         f"({shown}): a house id names other houses in them, and their rows, "
                         "intervals and paired comparisons mix them")
    return notes


def _house_ids(episodes: Path) -> set[str]:
    """The house ids of a bench run's ``episodes.jsonl`` (empty when it does not read)."""
    out: set[str] = set()
    try:
        with open(episodes, encoding="utf-8") as f:
            for line in f:
                try:
                    house = json.loads(line).get("house")
                except (ValueError, AttributeError):
                    continue
                if isinstance(house, str):
                    out.add(house)
    except OSError:
        pass
    return out


def _share_an_id(sets: Sequence[set[str]]) -> bool:
    """Whether two of ``sets`` have an id in common."""
    seen: set[str] = set()
    for ids in sets:
        if seen & ids:
            return True
        seen |= ids
    return False
