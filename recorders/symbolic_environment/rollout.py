"""One symbolic benchmark episode with a planner, and its optional log.

:func:`run_episode` runs the episode through :func:`sgtool.planning.episode.run_search` in a
:class:`~sgtool.recorders.symbolic_environment.environment.SymbolicEnv` and returns its
:class:`~sgtool.results.EpisodeResult`; with a log it is also recorded the way the closed
loop records one (:class:`EpisodeLog`), so ``sgtool eval`` reads both alike.
"""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Sequence

import numpy as np

from sgtool.log.records import Action as LoggedAction
from sgtool.log.records import Episode, SceneGraphRecord
from sgtool.log.writer import LogWriter
from sgtool.planning.base import Action, Planner
from sgtool.planning.episode import SearchStep, run_search
from sgtool.recorders.symbolic_environment.environment import N_MAX, SymbolicEnv
from sgtool.recorders.symbolic_environment.house import SymbolicHouse
from sgtool.results import EpisodeResult, Step
from sgtool.scenegraph.graph import SceneGraph

SECOND_NS = 1_000_000_000


def planner_seed(seed: int, house_seed: int, episode_index: int) -> int:
    """The planner's seed for an episode (a 32-bit draw from the three numbers)."""
    ss = np.random.SeedSequence([int(seed), int(house_seed), int(episode_index), 1])
    return int(ss.generate_state(1)[0])


class EpisodeLog:
    """Records a symbolic episode into an open log: an ``sgtool.Episode`` record "started"
    at t = 0, then per step k (t = k s) the ``sgtool.SceneGraph`` the planner saw and the
    ``sgtool.Action`` it took, and (:meth:`close`) the closing Episode record at
    t = (steps + 1) s. Distances are rounded by the records themselves
    (:class:`sgtool.log.records.Action`)."""

    def __init__(self, log: LogWriter, base: Episode, planner: str) -> None:
        self.log = log
        self.base = base
        self.planner = planner

    def started(self) -> None:
        self.log.write_record(dataclasses.replace(
            self.base, status="started", steps=0, travelled_m=0.0, shortest_m=None,
            extra={}), 0)

    def decided(self, index: int, graph: SceneGraph, action: Action,
                decision_s: float) -> None:
        pass

    def executed(self, step: SearchStep) -> None:
        t_ns = step.index * SECOND_NS
        a, fb = step.action, step.feedback
        self.log.write_record(SceneGraphRecord.of_graph(step.graph), t_ns)
        self.log.write_record(LoggedAction(
            skill=a.skill, target=a.target, outcome=fb.outcome, reason=a.reason,
            travelled_m=fb.travelled_m, decision_time_s=step.decision_s,
            planner=self.planner, step=step.index), t_ns)

    def close(self, steps: int, env: SymbolicEnv, shortest: float | None,
              extra: dict[str, object]) -> None:
        self.log.write_record(dataclasses.replace(
            self.base, status="success" if env.success else "failure", steps=env.steps,
            travelled_m=env.travelled,
            shortest_m=shortest, extra=extra,
        ), (steps + 1) * SECOND_NS)


def run_episode(house: SymbolicHouse, planner: Planner, query: str, targets: Sequence[str],
                seed: int = 0, episode_index: int = 0, avoid_rooms: Sequence[str] = (),
                max_steps: int = N_MAX, seen: bool | None = None, house_id: str = "",
                planner_name: str | None = None, log: LogWriter | None = None
                ) -> EpisodeResult:
    """Roll out one episode: observe, decide, act, feed back, until it ends.

    ``targets`` (spec ids of the query's instances) only serve the shortest path of SPL;
    success is decided by category (:mod:`~sgtool.recorders.symbolic_environment.environment`).
    Decision time is the wall time of each ``decide`` call (kept in the record's ``wall``
    figures only).

    With ``log`` (an open :class:`sgtool.log.writer.LogWriter`) the episode is also
    recorded (:class:`EpisodeLog`); the closing record's ``extra`` holds seed,
    planner_seed, episode, seen, end, n_open, start_region.
    """
    name = planner_name or getattr(planner, "name", "planner")
    hid = house_id or f"house-{house.spec.seed}"
    env = SymbolicEnv(house, query, seed=seed, episode_index=episode_index,
                      avoid_rooms=avoid_rooms, max_steps=max_steps)
    t_start = time.perf_counter()
    pseed = planner_seed(seed, house.spec.seed, episode_index)
    recorder = None
    if log is not None:
        recorder = EpisodeLog(log, Episode(kind="search", status="started", source="symbolic",
                                           house_id=hid, query=query, planner=name,
                                           frames=0), name)
        recorder.started()
    steps = run_search(env, planner, query, seed=pseed, recorder=recorder)
    trace = tuple(Step(s.action.skill, s.action.target, s.feedback.outcome,
                       s.feedback.travelled_m) for s in steps)
    shortest = env.shortest_path(targets)
    result = EpisodeResult(
        planner=name, seed=int(seed), house=hid,
        episode=int(episode_index), query=query, success=env.success, steps=env.steps,
        travelled_m=env.travelled, shortest_m=shortest,
        n_open=env.n_open, n_invalid=env.n_invalid, n_failure=env.n_failure, seen=seen,
        end=env.end_reason, source="symbolic", trace=trace,
        wall={"decision_s": sum(s.decision_s for s in steps), "decisions": float(len(steps)),
              "episode_s": time.perf_counter() - t_start},
    )
    if recorder is not None:
        recorder.close(len(steps), env, shortest, {
            "seed": int(seed), "planner_seed": pseed, "episode": int(episode_index),
            "seen": seen, "end": env.end_reason, "n_open": env.n_open,
            "start_region": env.start_region})
    return result
