"""One symbolic benchmark episode with a planner, and its optional log.

:func:`run_episode` runs the episode through :func:`sgtool.planning.episode.run_search` in a
:class:`~sgtool.recorders.symbolic_environment.environment.SymbolicEnv` and returns its
:class:`~sgtool.results.EpisodeResult`; with a log it is also recorded the way the closed
loop records one (:class:`EpisodeLog`), so ``sgtool eval`` reads both alike.
:func:`run_one` is the same for a user's script: any house spec, a planner or its name, a
query, and optionally a start.
"""

from __future__ import annotations

import dataclasses
import os
import time
from collections.abc import Mapping, Sequence
from typing import Any

from sgtool.errors import SgtoolError
from sgtool.house.spec import HouseSpec, StartPose
from sgtool.llm.stats import answer_counts
from sgtool.log.records import Episode, LlmExchange, SceneGraphRecord
from sgtool.log.writer import LogWriter
from sgtool.planning.base import Action, Planner
from sgtool.planning.episode import (
    NOT_CONFIRMED,
    SearchStep,
    planner_seed,
    run_search,
    search_success,
)
from sgtool.recorders.symbolic_environment.environment import N_MAX, SymbolicEnv
from sgtool.recorders.symbolic_environment.house import SymbolicHouse
from sgtool.redact import recorded_options
from sgtool.results import EpisodeResult, Step
from sgtool.scenegraph.graph import SceneGraph
from sgtool.semantics.text import category_text

SECOND_NS = 1_000_000_000


class EpisodeLog:
    """Records a symbolic episode into an open log: an ``sgtool.Episode`` record "started"
    at t = 0, then per step k (t = k s) the ``sgtool.SceneGraph`` the planner saw and the
    ``sgtool.Action`` it took (the planner's :class:`~sgtool.log.records.Action`,
    executed), and (:meth:`close`) the closing Episode record at t = (steps + 1) s.
    Distances are rounded by the records themselves."""

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
        fb = step.feedback
        self.log.write_record(SceneGraphRecord.of_graph(step.graph), t_ns)
        for ex in step.exchanges:  # the LLM exchanges of the decision (/sgtool/llm)
            self.log.write_record(LlmExchange.from_json(ex), t_ns)
        # the executor's message (what the planner was told) beside the planner's reason
        self.log.write_record(step.action.executed(
            fb.outcome, fb.travelled_m, decision_time_s=step.decision_s,
            planner=self.planner, step=step.index, unknown={"message": fb.message}), t_ns)

    def close(self, steps: int, env: SymbolicEnv, shortest: float | None,
              extra: dict[str, object], success: bool | None = None) -> None:
        ok = env.success if success is None else success
        self.log.write_record(dataclasses.replace(
            self.base, status="success" if ok else "failure", steps=env.steps,
            travelled_m=env.travelled,
            shortest_m=shortest, extra=extra,
        ), (steps + 1) * SECOND_NS)


def run_episode(house: SymbolicHouse, planner: Planner, query: str, targets: Sequence[str],
                seed: int = 0, episode_index: int = 0, avoid_rooms: Sequence[str] = (),
                max_steps: int = N_MAX, seen: bool | None = None, house_id: str = "",
                planner_name: str | None = None, log: LogWriter | None = None,
                start_region: str | None = None, success: str = "observed",
                planner_options: Mapping[str, Any] | None = None) -> EpisodeResult:
    """Roll out one episode: observe, decide, act, feed back, until it ends.

    ``targets`` (spec ids of the query's instances) only serve the shortest path of SPL;
    success is decided by category (:mod:`~sgtool.recorders.symbolic_environment.environment`).
    Decision time is the wall time of each ``decide`` call (kept in the record's ``wall``
    figures only).

    With ``log`` (an open :class:`sgtool.log.writer.LogWriter`) the episode is also
    recorded (:class:`EpisodeLog`); the closing record's ``extra`` holds seed,
    planner_seed, episode, seen, end, n_open, start_region. ``start_region`` (a region id,
    ``region:<room>.<k>``) fixes the start instead of drawing it. ``success`` is the
    success rule (:func:`sgtool.planning.episode.search_success`: ``observed`` or ``done``).
    """
    name = planner_name or str(getattr(planner, "name", "planner"))
    hid = house_id or f"house-{house.spec.seed}"
    env = SymbolicEnv(house, query, seed=seed, episode_index=episode_index,
                      avoid_rooms=avoid_rooms, max_steps=max_steps, start_region=start_region)
    t_start = time.perf_counter()
    pseed = planner_seed(seed, house.spec.seed, episode_index)
    recorder = None
    if log is not None:
        recorder = EpisodeLog(log, Episode(kind="search", status="started", source="symbolic",
                                           house_id=hid, query=query, planner=name,
                                           frames=0), name)
        recorder.started()
    steps = run_search(env, planner, query, seed=pseed, recorder=recorder, success=success)
    ok = search_success(env.success, steps, query, success)
    end = env.end_reason if ok == env.success else NOT_CONFIRMED
    trace = tuple(Step(s.action.skill, s.action.target, s.feedback.outcome,
                       s.feedback.travelled_m) for s in steps)
    shortest = env.shortest_path(targets)
    result = EpisodeResult(
        planner=name, seed=int(seed), house=hid,
        episode=int(episode_index), query=query, success=ok, steps=env.steps,
        travelled_m=env.travelled, shortest_m=shortest,
        n_open=env.n_open, n_invalid=env.n_invalid, n_failure=env.n_failure, seen=seen,
        end=end, source="symbolic", trace=trace,
        wall={"decision_s": sum(s.decision_s for s in steps), "decisions": float(len(steps)),
              "episode_s": time.perf_counter() - t_start},
        llm_answers=answer_counts(ex for s in steps for ex in s.exchanges),
        options=recorded_options(planner_options) if planner_options else {},
    )
    if recorder is not None:
        recorder.close(len(steps), env, shortest, {
            "seed": int(seed), "planner_seed": pseed, "episode": int(episode_index),
            "seen": seen, "end": end, "n_open": env.n_open,
            "start_region": env.start_region,
            **({"planner_options": recorded_options(planner_options)} if planner_options
               else {})}, success=ok)
    return result


class RunOneError(SgtoolError):
    """A query or a start that does not fit the house of :func:`run_one`."""


def run_one(house: HouseSpec | SymbolicHouse | str | os.PathLike[str], planner: Planner | str,
            query: str, *,
            start: str | StartPose | None = None, seed: int = 0, episode_index: int = 0,
            max_steps: int = N_MAX, house_id: str = "", seen: bool | None = None,
            log: LogWriter | None = None) -> EpisodeResult:
    """One SymSearch episode on any house with one planner, for scripting your own runs.

    ``house`` is a spec, or the path of a spec file (prepared here; pass a
    :class:`SymbolicHouse` to reuse one for many episodes) and ``planner`` a planner or a
    registry name (:func:`sgtool.planning.registry.make_planner`). Every instance of
    ``query`` in the house (furniture or small object, by
    :func:`~sgtool.semantics.text.category_text`) is a
    target. ``start``: None draws a start region from (seed, house seed, episode index)
    outside the target rooms, as the benchmark does; a region id fixes it; a
    :class:`~sgtool.house.spec.StartPose` (e.g. from
    :func:`sgtool.datasets.start_poses.start_poses`) starts in the region of its room
    nearest to it. Raises :class:`RunOneError` for a query with no instance in the house,
    a start that is not in it, or ``max_steps`` below 1; a planner object is held to the
    contract a plug-in is (:class:`~sgtool.planning.timing.TimedPlanner`: what its methods
    raise, an action with no skill or a target that is not text, is one
    :class:`~sgtool.planning.timing.PlannerContractError` naming it; a text target that
    names no node of the graph is an invalid action and spends a step, as in the bench).
    """
    from sgtool.arg_checks import of_type, whole
    from sgtool.planning.plugins import held_to_contract
    from sgtool.planning.registry import make_planner

    of_type("house", house, (HouseSpec, SymbolicHouse, str, os.PathLike),
            "a HouseSpec, a SymbolicHouse or a house spec file's path")
    of_type("query", query, str, "the target's category name (text)")
    for arg, value in (("max_steps", max_steps), ("seed", seed),
                       ("episode_index", episode_index)):
        whole(arg, value)
    if start is not None:
        of_type("start", start, (str, StartPose), "a region id or a StartPose")
    if log is not None:
        of_type("log", log, LogWriter, "an open sgtool.LogWriter")
    if max_steps < 1:
        raise RunOneError(f"max_steps {max_steps}: must be >= 1")
    if isinstance(house, str | os.PathLike):
        from sgtool.house.io import load_house

        house = load_house(house)
    h = house if isinstance(house, SymbolicHouse) else SymbolicHouse(house)
    spec = h.spec
    text = category_text(query)
    targets = [o.id for o in spec.objects if category_text(o.category) == text] + \
        [f.id for f in spec.furniture if category_text(f.category) == text]
    if not targets:
        raise RunOneError(f"query {query!r}: no object of that category in the house")
    p = make_planner(planner) if isinstance(planner, str) else held_to_contract(planner)
    name = planner if isinstance(planner, str) else None
    rooms = sorted({o.room for o in spec.objects if o.id in targets} |
                   {f.room for f in spec.furniture if f.id in targets})
    return run_episode(h, p, query, targets, seed=seed, episode_index=episode_index,
                       avoid_rooms=rooms, max_steps=max_steps, seen=seen,
                       house_id=house_id, planner_name=name, log=log,
                       start_region=_start_region(h, start))


def _start_region(h: SymbolicHouse, start: str | StartPose | None) -> str | None:
    if start is None:
        return None
    if isinstance(start, str):
        if not any(r.id == start for r in h.regions):
            raise RunOneError(f"start: no region {start!r} in the house (regions: "
                              f"{', '.join(r.id for r in h.regions)})")
        return start
    ri = h.room_index.get(start.room)
    if ri is None:
        raise RunOneError(f"start.room: no room {start.room!r} in the house")
    regs = h.room_regions[ri]
    best = min(regs, key=lambda k: (h.regions[k].center[0] - start.x) ** 2 +
               (h.regions[k].center[1] - start.y) ** 2)
    return h.regions[best].id
