"""``sgtool diff A B``: what differs, layer by layer, between the scene graphs of two logs.

A log with ``/sgtool/scene_graph`` records (a derived log, a closed-loop log) is read as it
is: its graphs in log-time order, the room areas and Voronoi graph size from its
``/map/rooms`` and ``/map/voronoi`` messages at the same log times
(:func:`~sgtool.replayers.golden_layers.summary_of_messages`), the frames of a refresh
counted from its depth images. Any other log is replayed with the options given
(:func:`~sgtool.replayers.golden_pins.capture`, which also scores it when it carries its
house; with ``max_frames``, its actions up to the last refresh count). The report is
:func:`~sgtool.replayers.golden.describe_mismatch` of the two sequences (the first refresh
that differs), the quality figures of both when both have them, and the first logged
action (skill and target) that differs.
"""

from __future__ import annotations

import bisect
import os
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from sgtool.errors import ArgumentError, SgtoolError
from sgtool.log import schemas as S
from sgtool.log.reader import LogReader
from sgtool.log.records import Action, SceneGraphRecord, given
from sgtool.replayers.derived_log import ReplayOptions
from sgtool.replayers.golden import describe_mismatch, quality_lines
from sgtool.replayers.golden_layers import summary_of_messages
from sgtool.replayers.golden_pins import RefreshMeta, capture


@dataclass(frozen=True)
class LogGraphs:
    """The scene graphs of one log: canonical JSON and refresh metadata, in order; how they
    were obtained (``"logged"`` or ``"replayed"``), quality figures, logged actions."""

    path: str
    source: str
    graphs: list[str]
    refreshes: list[RefreshMeta]
    quality: dict[str, Any] | None = None
    actions: list[tuple[str, str | None]] = field(default_factory=list)


def log_graphs(path: str | os.PathLike[str], options: ReplayOptions | None = None
               ) -> LogGraphs:
    """The graphs of ``path`` (module doc: logged when it has them, else replayed)."""
    p = Path(path)
    if not p.is_file():
        raise SgtoolError(f"{p}: no such file")
    with LogReader(p) as r:
        actions = [(a.skill, given(a.target)) for _, a in r.records(Action)]
        logged = r.has(S.RECORDS["scene_graph"].topic)
        if logged:
            frames = [d.log_time_ns for d in r.messages([S.DEPTH])] if r.has(S.DEPTH) else []
            graphs: list[str] = []
            metas: list[RefreshMeta] = []
            maps: dict[str, dict[int, Any]] = {S.VORONOI: {}, S.ROOMS: {}}
            for topic, by_time in maps.items():
                if r.has(topic):
                    for d in r.messages([topic]):
                        by_time[d.log_time_ns] = d.message
            for t, rec in r.records(SceneGraphRecord):
                try:
                    graphs.append(rec.graph().to_json())
                except ArgumentError as e:  # a foreign graph: which log, which record
                    raise ArgumentError(f"{p}: scene graph record at {t} ns: {e}") from None
                layers = summary_of_messages(maps[S.VORONOI].get(t), maps[S.ROOMS].get(t))
                metas.append(RefreshMeta(t, bisect.bisect_right(frames, t), "logged", layers))
            return LogGraphs(str(p), "logged", graphs, metas, None, actions)
    opts = options or ReplayOptions()
    cap = capture(p, opts)
    if opts.max_frames is not None and cap.refreshes:  # the actions the replay got to
        with LogReader(p) as r:
            end = cap.refreshes[-1].time_ns
            actions = [(a.skill, given(a.target)) for t, a in r.records(Action) if t <= end]
    return LogGraphs(str(p), "replayed", cap.graphs, cap.refreshes, cap.quality, actions)


@dataclass(frozen=True)
class LogDiff:
    """:func:`diff_logs`' result: ``lines`` (the first refresh that differs, layer by
    layer; empty when the sequences agree), quality lines, the first action that differs."""

    a: LogGraphs = field(repr=False)  # whole graph sequences: report() sums them up
    b: LogGraphs = field(repr=False)
    lines: list[str]
    quality: list[str]
    action: str | None

    quality_changed: bool = False

    @property
    def same(self) -> bool:
        return not self.lines and self.action is None and not self.quality_changed

    def report(self) -> list[str]:
        head = (f"{self.a.path} ({self.a.source}, {len(self.a.graphs)} refreshes) vs "
                f"{self.b.path} ({self.b.source}, {len(self.b.graphs)} refreshes): "
                + ("the same scene graphs" if self.same else "they differ"))
        return [head, *self.lines, *self.quality, *([self.action] if self.action else [])]

    def to_dict(self) -> dict[str, Any]:
        counts: dict[str, int] = {}
        for x in self.lines[1:]:
            k = x.strip().split(":", 1)[0]
            counts[k] = counts.get(k, 0) + 1
        return {"a": self.a.path, "b": self.b.path, "same": self.same,
                "sources": [self.a.source, self.b.source],
                "refreshes": [len(self.a.graphs), len(self.b.graphs)],
                "first": self.lines[0].removesuffix(" differs:") if self.lines else None,
                "differences": [x.strip() for x in self.lines[1:]], "layers": counts,
                "quality": self.quality, "action": self.action}


def first_action_change(a: list[tuple[str, str | None]], b: list[tuple[str, str | None]]
                        ) -> str | None:
    for i, (x, y) in enumerate(zip(a, b, strict=False)):
        if x != y:
            return f"actions: {i} {x[0]}({x[1] or ''}) -> {y[0]}({y[1] or ''})"
    if len(a) != len(b):
        return (f"actions: {len(b)} where {len(a)} were logged; the first "
                f"{min(len(a), len(b))} agree")
    return None


def paired_refreshes(ta: Sequence[int], tb: Sequence[int]
                     ) -> tuple[list[int], list[int], str | None]:
    """The refreshes of two logs to compare, by index into each: all of them, in order,
    when both refresh at the same times; else those at a time both refresh at, and the
    last of each (the final graphs) unless one of them is among those already (a log that
    ends earlier), with a note saying so (two replays at other ``--every`` compared
    refresh by refresh would set a graph at 3 s against one at 33 s)."""
    if list(ta) == list(tb):
        return list(range(len(ta))), list(range(len(tb))), None
    where_b = {t: j for j, t in enumerate(tb)}
    pairs = [(i, where_b[t]) for i, t in enumerate(ta) if t in where_b]
    # the final graphs, unless one of them is paired already (a log that ends earlier: its
    # last graph is compared at its own time, not set against the other's later one)
    finals = bool(ta and tb and (not pairs or (pairs[-1][0] != len(ta) - 1
                                              and pairs[-1][1] != len(tb) - 1)))
    if finals:
        pairs.append((len(ta) - 1, len(tb) - 1))
    common = sum(1 for i, j in pairs if ta[i] == tb[j])
    note = (f"the logs refresh at other times ({len(ta)} and {len(tb)} refreshes, {common} "
            "at the same time): compared where both refresh"
            + (", and the final graphs" if finals else ""))
    return [i for i, _ in pairs], [j for _, j in pairs], note


def diff_logs(a: str | os.PathLike[str], b: str | os.PathLike[str],
              options: ReplayOptions | None = None, tolerance: float = 0.0) -> LogDiff:
    """What differs between the scene graphs of ``a`` and ``b`` (module doc); ``options``
    replay the logs that hold no graphs; ``tolerance`` as in ``sgtool golden check``. A
    recording that is not an sgtool log is refused in one line naming what it is."""
    from sgtool.arg_checks import number
    from sgtool.log.inspect import foreign_log_problem

    number("tolerance", tolerance, 0.0)
    for log in (a, b):
        if (foreign := foreign_log_problem(log)) is not None:
            raise SgtoolError(foreign)
    ga, gb = log_graphs(a, options), log_graphs(b, options)
    ia, ib, note = paired_refreshes([r.time_ns for r in ga.refreshes],
                                    [r.time_ns for r in gb.refreshes])
    layers = [(ga.refreshes[i].layers, gb.refreshes[j].layers) for i, j in zip(ia, ib,
                                                                                strict=True)]
    lines = describe_mismatch([ga.graphs[i] for i in ia],
                              [(gb.refreshes[j], gb.graphs[j]) for j in ib],
                              tol=tolerance, exact=tolerance <= 0, layers=layers,
                              numbers=ib)
    if note and (lines or len(ga.graphs) != len(gb.graphs)):
        lines = [note, *(x for x in lines if "refreshes where" not in x)]
    return LogDiff(ga, gb, lines, quality_lines(ga.quality, gb.quality),
                   first_action_change(ga.actions, gb.actions),
                   bool(quality_lines(ga.quality, gb.quality, changed_only=True)))
