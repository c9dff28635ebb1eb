"""Is an episode result worth scoring? Checks of the figures ``sgtool eval`` reads.

A result whose figures cannot be true is refused (left out of every metric) with a note
naming the field, instead of being scored into nonsense (a negative distance gives SPL 1,
a success that travelled nothing towards a target 9 m away gives SPL 1). The checks are one
table, :data:`RULES`, applied in order; the first rule an episode breaks is its problem:

- ``steps``, ``n_open``, ``n_invalid``, ``n_failure``: whole numbers >= 0;
- ``travelled_m``: a finite number >= 0;
- ``shortest_m``: unknown (None) or a finite number >= 0. Zero is a target seen from the
  start: SPL is then 1 for a success that travelled nothing, else 0;
- no steps, no travel: ``steps`` 0 needs ``travelled_m`` 0 (not in the closed loop,
  :func:`closed_loop`, whose robot explores on its own between steps);
- every successful open is a step: ``n_open`` <= ``steps``;
- the figures agree with the actions (when the episode lists them: a log's Action records,
  a result's ``trace``): every step is an action (``steps`` <= the actions), and
  ``travelled_m`` is at least what the actions travelled (less :data:`ROUNDING_M` per
  action: each is rounded on write). A closed-loop robot may drive more than its actions
  (a look-around is not a step);
- a success came within sight of the target (symbolic episodes; the closed loop's camera
  sees over furniture the path goes round): its ``travelled_m`` is at least its
  ``shortest_m`` less the tolerance :func:`shortfall_tolerance_m`. The shortest path ends
  within reach (:data:`~sgtool.datasets.episodes.REACH`, 1 m) of the target, while a
  camera may see it from up to :data:`SIGHT_M` away, so a success may stop short by the
  difference; on top of that :data:`SHORTFALL_M` plus :data:`SHORTFALL_SHARE` of the
  shortest path (a geodesic on a grid; a robot's path is not, so it may come out a little
  shorter). A success that travelled nothing towards a target 9.48 m away is refused.

Only search episodes are scored: a log whose Episode records have another kind
(``recording``, ``import``) holds no search and is skipped with a note.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

from sgtool.datasets.episodes import REACH
from sgtool.results import EpisodeResult

SEARCH_KIND = "search"
COUNTS = ("steps", "n_open", "n_invalid", "n_failure")
DISTANCES = ("travelled_m", "shortest_m")
SIGHT_M = 6.0  # metres: the farthest a target is seen from (the simulator camera's range)
SHORTFALL_M = 0.5  # metres a success may travel less than the shortest path, plus ...
SHORTFALL_SHARE = 0.1  # ... this share of the shortest path (and the sight beyond reach)
NO_TRAVEL_M = 1e-6  # metres that count as no travel (rounding of a sum of zero moves)
ROUNDING_M = 1e-4  # metres of rounding per action a sum of actions' travel may be off by


@dataclass(frozen=True)
class Rule:
    """One check of :data:`RULES`: ``holds`` says what must be true (for the docs and
    the help); ``problem`` returns what breaks it in an episode (naming the fields and
    their values), or None."""

    holds: str
    problem: Callable[[EpisodeResult], str | None]


def shortfall_tolerance_m(shortest_m: float) -> float:
    """How much less than ``shortest_m`` (metres) a success may have travelled: the sight
    beyond the reach the shortest path ends at, plus :data:`SHORTFALL_M` and
    :data:`SHORTFALL_SHARE` of ``shortest_m`` (module doc)."""
    return (SIGHT_M - REACH) + SHORTFALL_M + SHORTFALL_SHARE * shortest_m


def _count(name: str) -> Rule:
    def problem(r: EpisodeResult) -> str | None:
        v = getattr(r, name)
        return f"{name} {v} is negative" if v < 0 else None

    return Rule(f"{name} >= 0", problem)


def _distance(name: str) -> Rule:
    def problem(r: EpisodeResult) -> str | None:
        v = getattr(r, name)
        if v is None and name == "shortest_m":
            return None
        if not math.isfinite(v):
            return f"{name} {v} is not a finite number"
        if v < 0:
            return f"{name} {v:g} m is negative"
        return None

    known = " (or unknown)" if name == "shortest_m" else ""
    return Rule(f"{name} a finite number >= 0{known}", problem)


def closed_loop(r: EpisodeResult) -> bool:
    """Whether ``r`` is a closed-loop episode (it names its sensor's noise profile; a
    symbolic one names none, or ``symbolic`` once eval labels it): the robot drives on its
    own between steps (its fallback exploration: metres, no step) and sees the target
    across furniture its path goes round, so the two rules of travel below do not hold."""
    return bool(r.noise) and r.noise != "symbolic"


def _travel_without_steps(r: EpisodeResult) -> str | None:
    if r.steps == 0 and r.travelled_m > NO_TRAVEL_M and not closed_loop(r):
        return f"steps 0 but travelled_m {r.travelled_m:g} m: no step, no travel"
    return None


def _opens_beyond_steps(r: EpisodeResult) -> str | None:
    if r.n_open > r.steps:
        return f"n_open {r.n_open} is more than steps {r.steps}: every open is a step"
    return None


def _steps_beyond_actions(r: EpisodeResult) -> str | None:
    if r.trace and r.steps > len(r.trace):
        return (f"steps {r.steps} but {len(r.trace)} action(s) listed: every step is an "
                "action")
    return None


def _travel_below_actions(r: EpisodeResult) -> str | None:
    moved = math.fsum(s.travelled_m for s in r.trace)
    if r.trace and r.travelled_m < moved - ROUNDING_M * len(r.trace):
        return (f"travelled_m {r.travelled_m:g} m is less than the {moved:.4g} m its "
                f"{len(r.trace)} action(s) travelled")
    return None


def _success_short_of_target(r: EpisodeResult) -> str | None:
    if not r.success or r.shortest_m is None or closed_loop(r):
        return None
    tol = shortfall_tolerance_m(r.shortest_m)
    if r.travelled_m < r.shortest_m - tol:
        return (f"a success with travelled_m {r.travelled_m:g} m, less than shortest_m "
                f"{r.shortest_m:g} m by more than the tolerance of {tol:.3g} m (a target "
                f"seen from {SIGHT_M:g} m, {REACH:g} m from the path's end; {SHORTFALL_M:g} m "
                f"+ {SHORTFALL_SHARE:.0%} of the shortest path)")
    return None


RULES: tuple[Rule, ...] = (
    *(_count(n) for n in COUNTS),
    *(_distance(n) for n in DISTANCES),
    Rule("steps 0 needs travelled_m 0", _travel_without_steps),
    Rule("n_open <= steps", _opens_beyond_steps),
    Rule("steps <= the actions listed", _steps_beyond_actions),
    Rule("travelled_m >= what the actions travelled", _travel_below_actions),
    Rule(f"a success travelled at least shortest_m less {SIGHT_M - REACH + SHORTFALL_M:g} m "
         f"+ {SHORTFALL_SHARE:.0%} of it", _success_short_of_target),
)


def episode_problem(r: EpisodeResult) -> str | None:
    """What makes ``r`` impossible (the first rule of :data:`RULES` it breaks, naming the
    fields), or None when it can be scored."""
    for rule in RULES:
        problem = rule.problem(r)
        if problem is not None:
            return problem
    return None
