"""The report of one closed-loop episode (``sgtool run`` prints its :meth:`lines`)."""

from __future__ import annotations

import statistics
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

from sgtool.results import episode_spl


@dataclass(frozen=True)
class ClosedLoopReport:
    """What one closed-loop episode did
    (:func:`sgtool.recorders.sim.closed_loop.run_episode`): its log ``output``, house,
    planner, query and episode id, ``success`` and why it ended, steps, metres travelled,
    the shortest path (None when unknown), frames, refreshes, opens, the wall-clock
    decision times and run seconds (reported, never logged) and ``notes``
    (:func:`episode_notes`); :meth:`lines` is what ``sgtool run`` prints."""

    output: Path
    house_id: str
    planner: str
    query: str
    episode: str
    success: bool
    end: str
    steps: int
    travelled_m: float
    shortest_m: float | None
    frames: int
    refreshes: int
    n_open: int
    decision_times: tuple[float, ...]  # wall clock per decision (reported and logged)
    seconds: float  # wall clock of the run (reported, never logged)
    notes: tuple[str, ...] = ()  # what the user should know about the run (episode_notes)

    @property
    def spl(self) -> float | None:
        if self.shortest_m is None:
            return None
        return episode_spl(self.success, self.shortest_m, self.travelled_m)  # as eval scores

    @property
    def frames_per_s(self) -> float:
        return self.frames / self.seconds if self.seconds > 0 else 0.0

    def lines(self) -> list[str]:
        out = []
        if self.output.exists():
            out.append(f"wrote {self.output} ({self.output.stat().st_size / 1e6:.1f} MB)")
        verdict = (f"found after {self.steps} steps" if self.success
                   else f"not found ({self.end}) after {self.steps} steps")
        out.append(f"{self.planner} searching for {self.query!r} in {self.house_id} "
                   f"({self.episode}): {verdict}")
        short = "unknown" if self.shortest_m is None else f"{self.shortest_m:.2f} m"
        spl = "-" if self.spl is None else f"{self.spl:.3f}"
        out.append(f"{self.travelled_m:.1f} m driven (shortest {short}, SPL {spl}), "
                   f"{self.n_open} opened, {self.frames} frames, {self.refreshes} graph "
                   "refreshes")
        dt = self.decision_times
        med = f"{statistics.median(dt):.4f} s" if dt else "-"
        mx = f"{max(dt):.4f} s" if dt else "-"
        out.append(f"{self.seconds:.1f} s ({self.frames_per_s:.1f} frames/s); decision "
                   f"time median {med}, max {mx}")
        return out + [f"note: {n}" for n in self.notes]


def episode_notes(max_depth: float, default_depth: float, depth_sigma: float,
                  rooms: int | None, llm_answers: Mapping[str, int] | None = None,
                  invalid: Sequence[str] = ()) -> tuple[str, ...]:
    """The notes of an episode whose live map kept depth to ``max_depth`` (the default
    ``default_depth`` lowered for the sensor's ``depth_sigma``, or chosen), whose last
    scene graph has ``rooms`` rooms (None: no graph) and whose planner's LLM answers are
    counted in ``llm_answers`` (:func:`~sgtool.llm.stats.answer_counts`; empty: it asked
    none), and why each of the planner's ``invalid`` actions was."""
    notes = []
    if invalid:
        notes.append(f"{len(invalid)} of the planner's actions were invalid and spent a step "
                     f"each (the first: {invalid[0]})")
    llm = llm_answers or {}
    if llm.get("requests") and not llm.get("valid"):
        notes.append(f"none of the planner's {llm['requests']} LLM requests got a valid answer "
                     f"({llm.get('invalid', 0)} rejected, {llm.get('faults', 0)} faults): check "
                     "the endpoint and model with `sgtool llm check`")
    if max_depth < default_depth and depth_sigma > 0:
        notes.append(f"the sensor's depth noise ({depth_sigma:g} z^2 m) would read far floor "
                     f"as obstacles: the live map kept depth to {max_depth:g} m "
                     "(--max-depth to choose)")
    if not rooms:
        notes.append("the live map ended without a room (no free floor for its Voronoi "
                     "graph): the planner had little to decide on; with sensor faults, see "
                     "`sgtool replay LOG --score` and --max-depth")
    return tuple(notes)
