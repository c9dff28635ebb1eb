"""What the simulation tells the outside: skill outcomes, observer callbacks, and the
signal an observer raises to stop a run."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

from sgtool.planning.base import Outcome

if TYPE_CHECKING:
    from sgtool.recorders.sim.simulation import Simulation


class StopSimulation(Exception):  # noqa: N818 (a control-flow signal, not an error)
    """Raised by an observer to end the current run (frame budget reached)."""


class TargetInView(Exception):  # noqa: N818 (a control-flow signal, not an error)
    """Raised by the closed loop's recorder at a refresh whose graph holds the target,
    to end the skill running (the ground-truth skills of ``navigation="house"``; the live
    skills ask at every refresh themselves)."""


@dataclass(frozen=True)
class SkillOutcome:
    """What a skill did: the log's ``sgtool.Action`` fields."""

    skill: str
    target: str | None
    outcome: Outcome
    reason: str = ""
    travelled_m: float = 0.0
    ticks: int = 0

    @property
    def success(self) -> bool:
        return self.outcome == "success"


class SimObserver:
    """Receives the simulation's events; override what you need."""

    def on_tick(self, sim: Simulation) -> None:
        """A new frame: the base and the doors are where they are at ``sim.tick_index``."""

    def on_state(self, sim: Simulation, spec_id: str, state: str) -> None:
        """A door or container changed to ``state`` (at the current tick)."""

    def on_skill(self, sim: Simulation, outcome: SkillOutcome) -> None:
        """A top-level skill finished (at the last tick it took)."""
