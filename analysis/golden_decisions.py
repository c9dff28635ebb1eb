"""The planner decisions a golden pin keeps for an episode log (a log whose
``sgtool.Episode`` records name a planner and a query, as ``sgtool run`` writes).

:func:`planner_decisions` asks the log's planner, built with the options the log records,
at every logged decision point on the *replayed* graph in force there (the last refresh at
or before the action's ``graph_time_ns``, else its log time) and tells it the logged
outcome (teacher forcing, as :func:`sgtool.analysis.offline.replay_decisions`). Two kinds
of planner are not asked again, and :func:`decisions_left_out` says which and why: an LLM
planner (it needs an endpoint) and a planner object of one's own given to
``sgtool.run_closed_loop`` (the log names its class, ``extra.planner_object``, not how to
build it)."""

from __future__ import annotations

import bisect
import dataclasses
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from sgtool.errors import SgtoolError
from sgtool.replayers.golden_pins import Decision, RefreshMeta


def _episode_planner(log: str | Path) -> tuple[list[Any], str | None, str | None]:
    """(the search episodes of ``log``, the one planner that decided them, why its
    decisions cannot be asked again); the planner is None when the log holds no decisions
    of exactly one planner."""
    from sgtool.analysis.offline import read_log_episodes
    from sgtool.log.records import given
    from sgtool.planning.registry import is_llm_planner

    episodes = [e for e in read_log_episodes(log) if given(e.episode.query)]
    names = {str(given(e.episode.planner)) for e in episodes if given(e.episode.planner)}
    if len(names) != 1 or not any(e.decisions for e in episodes):
        return episodes, None, None
    name = names.pop()
    if is_llm_planner(name):
        return episodes, name, "an LLM planner is not asked again (it needs an endpoint)"
    objects = sorted({str(e.episode.extras["planner_object"]) for e in episodes
                      if e.episode.extras.get("planner_object")})
    if objects:
        return episodes, name, (
            f"a planner object of one's own ({', '.join(objects)}) cannot be built again "
            "from the log (its options are unknown); record with "
            "sgtool.make_planner('module:Name', **options) to pin its decisions")
    return episodes, name, None


def decisions_left_out(log: str | Path) -> str | None:
    """``"PLANNER: why"`` when ``log`` is an episode log whose planner decisions a pin
    leaves out (module doc), else None (its decisions are pinned, or it has none)."""
    _, name, why = _episode_planner(log)
    return f"{name}: {why}" if name is not None and why is not None else None


def planner_decisions(log: str | Path, graphs: Sequence[str], refreshes: Sequence[RefreshMeta]
                      ) -> tuple[str | None, tuple[Decision, ...] | None]:
    """(planner, its decisions) at the decision points of an episode log, on the replayed
    graphs (module doc); (None, None) for a log that is no episode log, or whose planner
    is not asked again (:func:`decisions_left_out`); an :class:`SgtoolError` when its
    planner cannot be built here (a plug-in whose module is not on the path: silently
    leaving the decisions out would pin less than asked, and a check would call the log
    changed)."""
    from sgtool.analysis.offline import replay_decisions
    from sgtool.log.records import given
    from sgtool.planning.registry import make_planner
    from sgtool.scenegraph.graph import SceneGraph

    episodes, name, why = _episode_planner(log)
    if name is None or why is not None:
        return None, None
    times = [m.time_ns for m in refreshes]
    parsed: dict[int, SceneGraph] = {}

    def graph_at(t: int) -> SceneGraph | None:
        i = bisect.bisect_right(times, t) - 1
        if i < 0:
            return None
        if i not in parsed:
            parsed[i] = SceneGraph.from_json(graphs[i])
        return parsed[i]

    replayed = []
    for ep in episodes:
        ds = []
        for d in ep.decisions:
            gt = d.action.graph_time_ns
            t = gt if isinstance(gt, int) else d.t_ns
            ds.append(dataclasses.replace(d, graph=graph_at(t) if d.decided else None))
        replayed.append(dataclasses.replace(ep, decisions=tuple(ds)))
    extra = given(episodes[0].episode.extra) or {}
    logged = extra.get("planner_options")
    options = dict(logged) if isinstance(logged, dict) else {}  # as the run built it
    options["timed"] = False  # asked again, not timed (whatever the run chose)
    try:
        planner = make_planner(name, **options)
    except SgtoolError as e:  # a plug-in not importable here: its decisions cannot be asked
        raise SgtoolError(f"{log}: its planner cannot be built here ({e}); the decisions of "
                          "an episode log are pinned and checked by asking its planner again "
                          "(a plug-in's module on PYTHONPATH)") from None
    report = replay_decisions(planner, replayed, name)
    return name, tuple(Decision(c.episode, c.step, c.chosen[0], c.chosen[1])
                       for c in report.comparisons)
