"""Is an episode result worth scoring? Checks of the figures ``sgtool eval`` reads.

A result whose figures cannot be true is refused (left out of every metric) with a note
naming the field, instead of being scored into nonsense (a negative distance gives SPL 1):

- ``steps``, ``n_open``, ``n_invalid``, ``n_failure``: whole numbers >= 0;
- ``travelled_m``: a finite number >= 0;
- ``shortest_m``: unknown (None) or a finite number >= 0. Zero is a target seen from the
  start: SPL is then 1 for a success that travelled nothing, else 0.

Only search episodes are scored: a log whose Episode records have another kind
(``recording``, ``import``) holds no search and is skipped with a note.
"""

from __future__ import annotations

import math

from sgtool.results import EpisodeResult

SEARCH_KIND = "search"
COUNTS = ("steps", "n_open", "n_invalid", "n_failure")
DISTANCES = ("travelled_m", "shortest_m")


def episode_problem(r: EpisodeResult) -> str | None:
    """What makes ``r`` impossible (naming the field), or None when it can be scored."""
    for name in COUNTS:
        v = getattr(r, name)
        if v < 0:
            return f"{name} {v} is negative"
    for name in DISTANCES:
        v = getattr(r, name)
        if v is None and name == "shortest_m":
            continue
        if not math.isfinite(v):
            return f"{name} {v} is not a finite number"
        if v < 0:
            return f"{name} {v:g} m is negative"
    return None
