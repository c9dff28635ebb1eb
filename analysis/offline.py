"""Offline evaluation from recorded episodes: metrics from logs, planners against logs.

**Episodes in a log.** A closed-loop log holds, on sgtool's JSON channels, ``sgtool.Episode``
records (``/sgtool/episode``), one ``sgtool.Action`` record per executed action
(``/sgtool/action``) and ``sgtool.SceneGraph`` records (``/sgtool/scene_graph``, the
canonical JSON of :class:`~sgtool.scenegraph.graph.SceneGraph`). Episodes are cut by their
Episode records in log-time order: a record with status "started" opens an episode, a
record with status "success", "failure" or "ended" closes it (it carries the final figures;
see :func:`sgtool.results.result_from_log_records` for the fields read); the
actions in between belong to it. A log without a "started" record has one episode from its
start; an episode still open at the end of the log (a killed run) is closed as "ended"
(not a success) with the figures derived from its actions. An episode's result is numbered
by its closing record's ``extra`` (``episode``, ``seed``), else by its place in the log and
the log's metadata seed.

**Decision points.** Every Action record is a decision point, except one decided on no
graph. An action with ``graph_time_ns`` (``sgtool.Action`` 1.1) was decided on the last
SceneGraph record at or before that log time; one with ``graph_time_ns: null`` on no graph
(the closed loop's opening look-around): it is no decision point, so a planner is neither
asked nor told about it and it counts in no decision time; an action without the field
(1.0 logs), on the last SceneGraph record at or before the action's own log time. The
closed loop needs the field: it writes an action when its skill ends, and the graph
refreshes during the skill. At equal log times a closing Episode record comes after the
actions (the closed loop closes an episode at the time of its last action).

**A planner against a log** (:func:`replay_decisions`): the planner is reset with the
episode's query and seed, then at every decision point it decides on the logged graph as
the live planner was shown it (:meth:`~sgtool.log.records.Action.shown`: the Action
record's ``view_distances`` when it has them, which the closed loop's live navigation
writes) and its choice is compared with the logged action; then it is told the logged
outcome and the executor's message (:func:`executor_message`; teacher forcing: its
memory follows what was really done, not what it would have done). An LLM planner
replaying the log's own exchanges therefore sees the prompts of the run and matches every
decision.
Reported: exact agreement (same skill and target), same target, same room (the chosen and
the logged node lie in the same room), and choices that name no node of the graph.

**What is scored** (:func:`load_results`): search episodes whose figures pass
:func:`sgtool.analysis.validity.episode_problem`. Episodes of other kinds (recordings,
imports) are skipped and impossible ones refused, each with a one-line note naming the
file (and the field).
"""

from __future__ import annotations

import bisect
import dataclasses
import math
import os
import time
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from sgtool.analysis.validity import SEARCH_KIND, episode_problem
from sgtool.errors import SgtoolError
from sgtool.log.inspect import foreign_log_problem
from sgtool.log.records import ABSENT, Absent, Episode, LogRecord, SceneGraphRecord, given
from sgtool.planning.base import Action, Feedback, Planner
from sgtool.planning.episode import NOT_CONFIRMED, check_success_rule
from sgtool.results import EpisodeResult, decision_wall, read_jsonl, result_from_log_records
from sgtool.scenegraph.graph import DoorNode, SceneGraph

_TERMINAL = ("success", "failure", "ended")


class EvalInputError(SgtoolError):
    """An input of ``sgtool eval`` that is neither an MCAP log nor an episode JSONL file."""


@dataclass(frozen=True)
class Decision:
    t_ns: int
    graph: SceneGraph | None
    action: Action

    @property
    def decided(self) -> bool:
        """False for an action decided on no graph (``graph_time_ns: null``)."""
        return self.action.decided


@dataclass(frozen=True)
class LoggedEpisode:
    """One episode of an MCAP log (:func:`read_log_episodes`): the ``source`` file, its
    ``index`` in the log, its closing ``sgtool.Episode`` record (the opening record's
    fields merged in; made up for a killed run) and its decision points in log order;
    :meth:`result` is its :class:`~sgtool.results.EpisodeResult`."""

    source: str
    index: int  # episode number within its log
    episode: Episode  # the closing Episode record (synthesised when missing)
    decisions: tuple[Decision, ...]
    closed: bool = True  # False: the log has no closing record (a run cut short)
    log_seed: int | None = None  # the log's metadata seed: the result's when extras lack one

    def __repr__(self) -> str:  # (the decisions hold every graph: a repr of megabytes)
        e = self.episode
        return (f"LoggedEpisode(source={self.source!r}, index={self.index}, "
                f"planner={e.planner!r}, query={e.query!r}, "
                f"decisions={len(self.decisions)}, closed={self.closed})")

    def result(self) -> EpisodeResult:
        r = result_from_log_records(self.episode, [d.action for d in self.decisions],
                                    source=self.source)
        if not all(d.decided for d in self.decisions):  # decision time over decisions only
            decided = [d.action for d in self.decisions if d.decided]
            r = _replace(r, wall=decision_wall(decided))
        if "episode" not in self.episode.extras:
            r = _replace(r, episode=self.index)
        if "seed" not in self.episode.extras and self.log_seed is not None:
            r = _replace(r, seed=self.log_seed)
        noise = self.episode.extras.get("noise")
        if isinstance(noise, dict) and isinstance(noise.get("name"), str):
            r = _replace(r, noise=noise["name"])
        return r


def _replace(r: EpisodeResult, **kw: Any) -> EpisodeResult:
    return dataclasses.replace(r, **kw)


def read_log_episodes(path: str | os.PathLike[str]) -> list[LoggedEpisode]:
    """The episodes of one MCAP log (module doc for how they are cut)."""
    from sgtool.log.reader import LogReader

    p = Path(path)
    with LogReader(p) as log:
        seed = log.seed
        stream: list[tuple[int, int, LogRecord]] = []
        kinds: tuple[type[LogRecord], ...] = (SceneGraphRecord, Episode, Action)
        for order, kind in enumerate(kinds):
            for t, rec in log.records(kind):
                stream.append((t, order, rec))
    # at equal times: the graph first, then opening episode records, then actions, then
    # closing episode records
    def tie_order(x: tuple[int, int, LogRecord]) -> tuple[int, int]:
        closing = isinstance(x[2], Episode) and x[2].status in _TERMINAL
        return (x[0], 3 if closing else x[1])

    stream.sort(key=tie_order)
    episodes: list[LoggedEpisode] = []
    graph: SceneGraph | None = None
    graph_times: list[int] = []  # every graph so far, in stream order (non-decreasing times)
    graphs: list[SceneGraph] = []
    opened: Episode | None = None
    decisions: list[Decision] = []

    def close(record: Episode, closed: bool = True) -> None:
        nonlocal decisions, opened
        episodes.append(LoggedEpisode(str(p), len(episodes), record, tuple(decisions),
                                      closed, seed))
        decisions = []
        opened = None

    for t, _, rec in stream:
        if isinstance(rec, SceneGraphRecord):
            try:
                graph = rec.graph()
            except (KeyError, TypeError, ValueError) as e:
                raise EvalInputError(f"{p}: unreadable scene graph record at {t} ns: {e}") \
                    from None
            graph_times.append(t)
            graphs.append(graph)
        elif isinstance(rec, Episode):
            if rec.status == "started":
                if opened is not None or decisions:
                    close(_ended(opened), closed=False)
                opened = rec
            elif rec.status in _TERMINAL:
                close(rec if opened is None else opened.merged(rec))
        else:
            assert isinstance(rec, Action)
            decisions.append(Decision(t, _decided_on(rec, graph, graph_times, graphs), rec))
    if opened is not None or decisions:
        close(_ended(opened), closed=False)
    return episodes


def _ended(opened: Episode | None) -> Episode:
    """The closing record of an episode that has none (a killed run): the opening record's
    fields, but its steps, distance and frames (zero when it opened) are left to be derived
    from the actions logged until the run stopped."""
    return dataclasses.replace(opened or Episode(kind="search", status="ended"),
                               status="ended", steps=ABSENT, travelled_m=ABSENT,
                               frames=ABSENT)


def _decided_on(action: Action, latest: SceneGraph | None, times: list[int],
                graphs: list[SceneGraph]) -> SceneGraph | None:
    """The graph an action was decided on (module doc): by its ``graph_time_ns`` when it
    has the field, else ``latest`` (the last graph at or before the action)."""
    t = action.graph_time_ns
    if isinstance(t, Absent):
        return latest
    if t is None:
        return None
    i = bisect.bisect_right(times, int(t))
    return graphs[i - 1] if i else None


def load_results(paths: Iterable[str | os.PathLike[str]], notes: list[str] | None = None
                 ) -> tuple[list[EpisodeResult], list[LoggedEpisode]]:
    """Episode results from MCAP logs and/or episode JSONL files (``sgtool bench``
    output); the logged episodes (with their decision points) of the MCAP inputs. Episodes
    that are no search or whose figures are impossible are left out, with a one-line note
    each appended to ``notes`` (module doc)."""
    results: list[EpisodeResult] = []
    logged: list[LoggedEpisode] = []
    notes = [] if notes is None else notes
    if isinstance(paths, (str, os.PathLike)):  # one path, not a list of its letters
        paths = [paths]
    for path in paths:
        p = Path(path)
        if not p.exists():
            raise EvalInputError(f"{p}: no such file")
        if p.is_dir():
            raise EvalInputError(f"{p} is a folder; give MCAP logs or episodes.jsonl files")
        with open(p, "rb") as f:
            head = f.read(8)
        if head == b"\x89MCAP0\r\n":
            foreign = foreign_log_problem(p)  # e.g. a bag exported from a derived log
            if foreign is not None:
                raise EvalInputError(foreign)
            for e in _search_episodes(p, read_log_episodes(p), notes):
                r = with_seen(e.result())
                if not e.closed:  # no closing record: cut short
                    notes.append(f"{p}: episode {e.index} has no closing record (the run was "
                                 "interrupted or killed): scored from the actions logged "
                                 f"until it stopped{'' if r.success else ', as a failure'}")
                if _accepted(r, f"{p}: episode {e.index}", notes):
                    logged.append(e)
                    results.append(r)
        elif p.suffix in (".jsonl", ".json") or head[:1] == b"{":
            ran = _table_options(p)
            results.extend(r if r.options or not ran.get(r.planner) else
                           dataclasses.replace(r, options=ran[r.planner])
                           for i, r in enumerate(read_jsonl(p))
                           if _accepted(r, f"{p}: record {i + 1}", notes))
        else:
            raise EvalInputError(f"{p}: neither an MCAP log nor an episode JSONL file")
    return results, logged


def _table_options(table: Path) -> dict[str, dict[str, Any]]:
    """The ``-O`` options per planner that the ``summary.json`` beside a bench table
    records: those of its rows written before rows kept their options."""
    from sgtool.analysis.eval_settings import run_settings
    from sgtool.redact import is_secret_name

    s = run_settings(table.parent / "summary.json") or {}
    given = s.get("planner_options")
    out = {}
    for k, v in given.items() if isinstance(given, dict) else ():
        # those a record keeps (sgtool.redact.recorded_options): no secret, no Python object
        kept = {o: x for o, x in v.items() if not is_secret_name(str(o))
                and str(o) not in _python_only(str(k))} if isinstance(v, dict) else {}
        if kept:
            out[str(k)] = kept
    return out


def _python_only(planner: str) -> frozenset[str]:
    """The options of ``planner`` given from Python only (an encoder): none recorded."""
    from sgtool.planning.option_fields import option_infos
    from sgtool.planning.registry import options_of

    try:
        cls = options_of(planner)
    except Exception:  # noqa: BLE001 - a plug-in not importable here
        return frozenset()
    return frozenset(i.name for i in option_infos(cls) if not i.meta.cli) if cls else frozenset()


def _search_episodes(p: Path, episodes: list[LoggedEpisode], notes: list[str]
                     ) -> list[LoggedEpisode]:
    """The search episodes of a log; a note for the others (recordings, imports)."""
    other = sorted({e.episode.kind for e in episodes if e.episode.kind != SEARCH_KIND})
    if other:
        n = sum(1 for e in episodes if e.episode.kind != SEARCH_KIND)
        notes.append(f"{p}: skipped {n} episode record(s) of kind {', '.join(other)} "
                     "(not a search episode)")
    return [e for e in episodes if e.episode.kind == SEARCH_KIND]


def _accepted(r: EpisodeResult, where: str, notes: list[str]) -> bool:
    problem = episode_problem(r)
    if problem is not None:
        notes.append(f"{where}: refused: {problem}")
    return problem is None


def with_seen(r: EpisodeResult) -> EpisodeResult:
    """A log that does not say whether its query is seen: decide it as `sgtool bench`
    does (seen when it is one of the shipped priors' training queries,
    :func:`sgtool.analysis.bench_priors.training_vocabulary`), so a house file's own
    names ("yoga mat") are unseen in both."""
    if r.seen is not None or not r.query:
        return r
    from sgtool.analysis.bench_priors import training_vocabulary
    from sgtool.semantics.text import category_text

    return _replace(r, seen=category_text(r.query) in training_vocabulary(None))


# ----------------------------------------------------------------------------------------
# a planner against the logged decisions
# ----------------------------------------------------------------------------------------
@dataclass(frozen=True)
class DecisionComparison:
    source: str
    episode: int
    step: int
    logged: tuple[str, str | None]
    chosen: tuple[str, str | None]
    valid: bool  # the chosen target is a node of the graph (or a done without one)
    same_room: bool
    decision_s: float


@dataclass(frozen=True)
class OfflineReport:
    """A planner's choices against the logged decisions (:func:`replay_decisions`): one
    :class:`DecisionComparison` per decision point, and the points ``skipped`` for want
    of a logged graph. :meth:`rate` is the share of decisions that ``agree`` (same skill
    and target), have the same ``target``, the same ``room``, or are ``invalid`` (name no
    node of the graph); NaN without decisions."""

    planner: str
    comparisons: tuple[DecisionComparison, ...]
    skipped: int  # decision points without a logged scene graph

    @property
    def decisions(self) -> int:
        return len(self.comparisons)

    def rate(self, what: str) -> float:
        if not self.comparisons:
            return math.nan
        if what == "agree":
            hits = sum(c.chosen == c.logged for c in self.comparisons)
        elif what == "target":
            hits = sum(c.chosen[1] == c.logged[1] for c in self.comparisons)
        elif what == "room":
            hits = sum(c.same_room for c in self.comparisons)
        elif what == "invalid":
            hits = sum(not c.valid for c in self.comparisons)
        else:
            raise ValueError(what)
        return hits / len(self.comparisons)

    def mean_decision_s(self) -> float:
        if not self.comparisons:
            return math.nan
        return sum(c.decision_s for c in self.comparisons) / len(self.comparisons)


def node_rooms(graph: SceneGraph, node_id: str | None) -> frozenset[str]:
    """The room(s) a node lies in: a room is its own, a door joins two."""
    if node_id is None:
        return frozenset()
    n = graph.node(node_id)
    if n is None:
        return frozenset()
    if isinstance(n, DoorNode):
        return frozenset(n.rooms)
    room = getattr(n, "room", None)
    return frozenset([room]) if room else frozenset([n.id])


def executor_message(action: Action) -> str:
    """What the executor told the planner about ``action``: the ``message`` a log records
    beside the planner's ``reason``; without one (the robot's own actions, closed-loop
    logs written before they kept the planner's reason) the ``reason``, the robot's."""
    msg = action.unknown.get("message")
    return str(msg) if isinstance(msg, str) else str(given(action.reason, ""))


def with_success_rule(r: EpisodeResult, rule: str | None) -> EpisodeResult:
    """``r`` judged by the success rule ``rule`` (None: as recorded). ``done``: a success
    needs the last action to be ``done()`` naming an object (the episode loop's
    confirmation, :mod:`sgtool.planning.episode`); ``observed``: the target came into view,
    which an episode ended unconfirmed under ``done`` also means."""
    if rule is None:
        return r
    check_success_rule(rule)
    if rule == "observed":
        return _replace(r, success=True, end="found") if r.end == NOT_CONFIRMED else r
    last = r.trace[-1] if r.trace else None
    if r.success and not (last is not None and last.skill == "done" and last.target):
        return _replace(r, success=False, end=NOT_CONFIRMED)
    return r


def log_exchanges(paths: Iterable[str | os.PathLike[str]]) -> list[tuple[str, dict[str, Any]]]:
    """(file, exchange record) of the ``/sgtool/llm`` channels of the MCAP logs among
    ``paths``, file by file in log-time order."""
    from sgtool.llm.recorded import is_mcap_file, read_transcript

    out: list[tuple[str, dict[str, Any]]] = []
    for path in map(Path, paths):
        if is_mcap_file(path):
            out.extend((str(path), rec) for rec in read_transcript(path))
    return out


def replay_decisions(planner: Planner | str, episodes: Sequence[LoggedEpisode],
                     name: str | None = None) -> OfflineReport:
    """Ask ``planner`` (or the planner of that name, with its default options) at every
    logged decision point of ``episodes`` (module doc: it decides on the logged graph,
    then is told the logged outcome) and compare its choices with the logged actions;
    ``name`` labels the report (default: the planner's name). An LLM planner that leaves
    its recorded transcript (another run's) is an error."""
    from sgtool.planning.moma.planner import replay_miss_of

    if isinstance(planner, str):
        from sgtool.planning.registry import make_planner

        name = name or planner
        planner = make_planner(planner)
    else:  # a user's object: what it returns wrongly or raises is one line, as run_one's
        from sgtool.planning.plugins import held_to_contract

        planner = held_to_contract(planner)

    out: list[DecisionComparison] = []
    skipped = 0
    for ep in episodes:
        extra = ep.episode.extras
        query = given(ep.episode.query)
        if not query:
            skipped += len(ep.decisions)
            continue
        planner.reset(str(query), seed=int(extra.get("planner_seed", extra.get("seed", 0))))
        for step, d in enumerate(ep.decisions):
            if not d.decided:
                continue
            # the logged action is compared and fed back as logged (its skill need not be a
            # planner's: a recorded tour logs look_around)
            logged = d.action
            if d.graph is not None:
                t0 = time.perf_counter()
                chosen = planner.decide(logged.shown(d.graph))
                dt = time.perf_counter() - t0
                if miss := replay_miss_of(planner):  # --llm-replay of other logs
                    raise SgtoolError(f"{name or getattr(planner, 'name', 'planner')}: {miss} "
                                      f"({ep.source}, decision {step})")
                # done without a target gives up; with one it names a node, as the others
                valid = chosen.target in d.graph.node_ids() if chosen.target is not None \
                    else chosen.skill == "done"
                lr = node_rooms(d.graph, logged.target)
                same_room = bool(lr & node_rooms(d.graph, chosen.target)) or (
                    chosen.skill == logged.skill == "done")
                out.append(DecisionComparison(
                    ep.source, ep.index, step, (logged.skill, logged.target),
                    (chosen.skill, chosen.target), valid, same_room, dt))
            else:
                skipped += 1
            planner.feedback(Feedback(
                logged, logged.result, executor_message(logged),
                float(given(d.action.travelled_m, 0.0))))
    return OfflineReport(name or str(getattr(planner, "name", "planner")), tuple(out), skipped)


def format_offline(reports: Sequence[OfflineReport]) -> str:
    """The table ``sgtool eval -p`` prints: one row per report (decisions, the rates of
    :meth:`OfflineReport.rate` in percent, mean decision time, skipped points)."""
    from sgtool.analysis.report import pipe_table

    def pct(x: float) -> str:
        return "-" if math.isnan(x) else f"{100 * x:.1f}%"

    rows = [[r.planner, str(r.decisions), pct(r.rate("agree")), pct(r.rate("target")),
             pct(r.rate("room")), pct(r.rate("invalid")),
             "-" if math.isnan(r.mean_decision_s()) else f"{r.mean_decision_s():.4f}",
             str(r.skipped)]
            for r in reports]
    head = ["Planner", "Decisions", "Same action", "Same target", "Same room",
            "Not in graph", "Decision time (s)", "Skipped"]
    return ("Planners against the logged decisions (teacher-forced: each is told what was "
            "really done)\n" + pipe_table(head, rows) + "\n")
