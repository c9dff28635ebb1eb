"""Golden logs: logs whose replayed scene graphs are pinned, and the readable diff of two.

``tests/golden/`` holds the project's own golden logs, one per case of :data:`CASES`: the
recorded log ``NAME.mcap`` (under 2 MB), pinned with the same code and format users pin
their own logs with (``sgtool golden pin``; :mod:`sgtool.replayers.golden_pins` is the
format, :mod:`sgtool.analysis.golden_check` pins and checks): ``NAME.graphs.jsonl.gz`` (the
canonical JSON of every scene graph of its replay, written deterministically) and
``expected.json`` with the digests: the sha256 of the log, of the final graph and of the
whole refresh sequence. A check replays each log and, on a mismatch, reports what differs
in the first refresh that differs (:func:`describe_mismatch`, :func:`diff_graphs`: rooms
added, removed, merged or split, categories, objects, doors, regions, frontiers, edges,
distances, Voronoi graph size), not just two hashes.

Regenerate on purpose only, and say why in the commit::

    .venv/bin/python tests/golden/regenerate.py            # re-pin from the logs
    .venv/bin/python tests/golden/regenerate.py --record   # re-record the logs first (PyBullet)

The first after a deliberate change of the replay pipeline or of the shipped weights;
the second after a change of the recorder or of the house generator.
"""

from __future__ import annotations

import gzip
import hashlib
import io
import math
import os
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Protocol

from sgtool.arg_checks import of_type
from sgtool.files import atomic_write
from sgtool.replayers.derived_log import ReplayOptions, replay
from sgtool.replayers.golden_layers import LayerSummary
from sgtool.scenegraph.graph import SceneGraph
from sgtool.scenegraph.stream import Refresh, SceneGraphStream

EXPECTED = "expected.json"  # the index of a pin folder (sgtool.replayers.golden_pins)
REPLAY = ReplayOptions(every=10, classifier="containment")


@dataclass(frozen=True)
class GoldenCase:
    name: str
    seed: int  # generated house (evaluation split)
    rooms: int
    width: int
    height: int
    fps: float
    frames: int | None  # frame budget (None: the whole scripted tour)
    why: str


CASES: tuple[GoldenCase, ...] = (
    GoldenCase("house6-tour", 6, 4, 128, 96, 2.0, None,
               "4 rooms: corridor, a bathroom behind a closed door the robot opens, an "
               "open-plan kitchen + living room; the whole scripted tour"),
    GoldenCase("house10-start", 10, 4, 128, 96, 3.0, 110,
               "4 rooms with a closed door and an open-plan passage; stops early, so the "
               "graph still has frontiers and rooms seen only in part"),
)


# ----- digests and files ---------------------------------------------------------------
def sequence_digest(graphs: Sequence[str]) -> str:
    """sha256 over the graphs' own sha256 digests, in order."""
    h = hashlib.sha256()
    for g in graphs:
        h.update(hashlib.sha256(g.encode()).digest())
    return h.hexdigest()


def replay_graphs(log: str | os.PathLike[str], options: ReplayOptions = REPLAY
                  ) -> list[tuple[Refresh, str]]:
    """Every refresh of a replay of ``log`` with the canonical JSON of its graph, by
    default with the golden tests' options, not ``replay``'s. Those (:data:`REPLAY`) use
    the ``containment`` room classifier the shipped golden logs were pinned with, not
    ``sgtool replay``'s ``frequency``: pass ``ReplayOptions()`` for the graphs ``replay``
    writes."""
    out: list[tuple[Refresh, str]] = []

    def keep(r: Refresh, _s: SceneGraphStream) -> None:
        out.append((r, r.graph.to_json()))

    replay(log, None, options, on_refresh=keep)
    return out


def write_graphs(path: Path, graphs: Sequence[str]) -> None:
    """Graphs as gzip-compressed JSON lines, byte-stable (no file name or time inside)."""
    buf = io.BytesIO()
    with gzip.GzipFile(fileobj=buf, mode="wb", mtime=0, filename="") as z:
        for g in graphs:
            z.write(g.encode() + b"\n")
    atomic_write(path, buf.getvalue())


def read_graphs(path: Path) -> list[str]:
    with gzip.open(path, "rb") as z:
        return [line.decode() for line in z.read().splitlines() if line]


# ----- readable differences --------------------------------------------------------------
def _fmt_list(xs: Sequence[str]) -> str:
    return "[" + ", ".join(xs) + "]"


def _scores(room: object) -> str:
    pairs = getattr(room, "category_scores", ())
    return "[" + ", ".join(f"{c} {p:.3f}" for c, p in pairs[:3]) + "]"


def _by_id(nodes: Sequence[Any]) -> dict[str, Any]:
    return {n.id: n for n in nodes}


def _added_removed(layer: str, expected: dict[str, Any], actual: dict[str, Any],
                   describe: Callable[[Any], str]) -> list[str]:
    """``layer: - id ...`` for nodes only expected, ``layer: + id ...`` for new ones."""
    return [f"{layer}: {'-' if k in expected else '+'} {k} "
            f"{describe(expected[k] if k in expected else actual[k])}"
            for k in sorted(expected.keys() ^ actual.keys())]


def _renumbered(expected: Mapping[str, Any], actual: Mapping[str, Any],
                tol: float = 1e-4) -> dict[str, str]:
    """Frontiers of ``expected`` (id -> node) that ``actual`` holds under another id: equal
    up to ``tol`` in position and length, in the same room and of the same kind. Frontier
    ids number frontiers as they are found, so a replay that refreshes at other times finds
    the same ones in another order. Ambiguous matches are left out (they read as removed
    and added), as is a new id that another of ``expected``'s frontiers keeps (until none
    is: leaving one out makes its frontier keep its id)."""
    def same(x: Any, y: Any) -> bool:
        return ((x.room, x.kind, x.frontier_type) == (y.room, y.kind, y.frontier_type)
                and _moved(x, y, tol) is None and not _beyond(abs(x.size - y.size), tol))

    kept = {k for k in expected.keys() & actual.keys() if same(expected[k], actual[k])}
    xs = [expected[k] for k in sorted(expected.keys() - kept)]
    ys = [actual[k] for k in sorted(actual.keys() - kept)]
    out = {}
    for x in xs:
        match = [y for y in ys if same(x, y)]
        if len(match) == 1 and match[0].id != x.id and sum(same(z, match[0]) for z in xs) == 1:
            out[x.id] = match[0].id
    while clash := [k for k, v in out.items() if v in expected.keys() - out.keys()]:
        for k in clash:
            del out[k]
    return out


def _beyond(d: float, tol: float) -> bool:
    """``d`` is more than ``tol``: a difference of exactly ``tol`` between values rounded to
    the canonical JSON's 4 decimals passes, whatever float subtraction makes of it."""
    return d > tol + 1e-9


def _moved(a: Any, b: Any, tol: float) -> float | None:
    d = math.dist(a.position, b.position)
    return d if _beyond(d, tol) else None


def _m(x: float) -> str:
    """A length as a report prints it: 3 decimals, or 2 significant digits below 1 mm (a
    change of 0.0001 m does not read as 0.000)."""
    return f"{x:.3f}" if abs(x) >= 0.001 or x == 0 else f"{x:.2g}"


def _pair(a: float, b: float, least: int = 2) -> tuple[str, str]:
    """``a`` and ``b`` with ``least`` decimals or as many more (up to 6) as they need to
    read differently."""
    for k in range(least, 7):
        x, y = f"{a:.{k}f}", f"{b:.{k}f}"
        if x != y:
            break
    return x, y


def _room_changes(a: Any, b: Any, tol: float) -> list[str]:
    out = []
    if a.category != b.category:
        out.append(f"rooms: {a.id} category {a.category} -> {b.category}")
    sa, sb = dict(a.category_scores), dict(b.category_scores)
    if sa.keys() != sb.keys() or any(_beyond(abs(sa[k] - sb[k]), tol) for k in sa):
        out.append(f"rooms: {a.id} category scores {_scores(a)} -> {_scores(b)}")
    if a.explored != b.explored:
        out.append(f"rooms: {a.id} explored {a.explored} -> {b.explored}")
    if sorted(a.neighbours) != sorted(b.neighbours):
        out.append(f"edges: {a.id} neighbours {_fmt_list(sorted(a.neighbours))} -> "
                   f"{_fmt_list(sorted(b.neighbours))}")
    if (d := _moved(a, b, tol)) is not None:
        out.append(f"rooms: {a.id} moved {_m(d)} m")
    return out


def _object_changes(a: Any, b: Any, tol: float) -> list[str]:
    out = [f"objects: {a.id} {a.category} {attr} {getattr(a, attr)} -> {getattr(b, attr)}"
           for attr in ("room", "parent", "relation", "state", "explored", "category",
                        "instance")
           if getattr(a, attr) != getattr(b, attr)]
    if sorted(a.affordances) != sorted(b.affordances):  # a set (the JSON sorts it)
        out.append(f"objects: {a.id} {a.category} affordances {sorted(a.affordances)} -> "
                   f"{sorted(b.affordances)}")
    if (d := _moved(a, b, tol)) is not None:
        out.append(f"objects: {a.id} {a.category} moved {_m(d)} m")
    return out


def _door_changes(a: Any, b: Any, tol: float) -> list[str]:
    out = []
    if a.state != b.state:
        out.append(f"doors: {a.id} state {a.state} -> {b.state}")
    if sorted(a.rooms) != sorted(b.rooms):
        out.append(f"edges: {a.id} joins {_fmt_list(sorted(a.rooms))} -> "
                   f"{_fmt_list(sorted(b.rooms))}")
    if a.instance != b.instance:
        out.append(f"doors: {a.id} instance {a.instance} -> {b.instance}")
    if (d := _moved(a, b, tol)) is not None:
        out.append(f"doors: {a.id} moved {_m(d)} m")
    return out


def _region_changes(a: Any, b: Any, tol: float) -> list[str]:
    layer = "frontiers" if a.kind == "frontier" else "regions"
    if (a.room, a.kind, a.frontier_type) != (b.room, b.kind, b.frontier_type):
        return [f"{layer}: {a.id} {_region_kind(a)} in {a.room} -> "
                f"{_region_kind(b)} in {b.room}"]
    out = []
    if (d := _moved(a, b, tol)) is not None:
        out.append(f"{layer}: {a.id} moved {_m(d)} m")
    if _beyond(abs(a.size - b.size), tol):
        x, y = _pair(a.size, b.size)
        out.append(f"{layer}: {a.id} length {x} -> {y} m")
    return out


def _region_kind(g: Any) -> str:
    return (g.frontier_type or "region") if g.kind == "frontier" else "region"


# layer name, nodes of a graph, how an added/removed node reads, what changed in a kept one
_LAYERS: tuple[tuple[str, Callable[[SceneGraph], Sequence[Any]], Callable[[Any], str],
                     Callable[[Any, Any, float], list[str]]], ...] = (
    ("rooms", lambda g: g.rooms, lambda n: f"({n.category})", _room_changes),
    ("objects", lambda g: g.objects, lambda n: f"{n.category} in {n.room}", _object_changes),
    ("doors", lambda g: g.doors, lambda n: f"({n.state}, {_fmt_list(sorted(n.rooms))})",
     _door_changes),
    ("regions", lambda g: [r for r in g.regions if r.kind != "frontier"],
     lambda n: f"(in {n.room})", _region_changes),
    ("frontiers", lambda g: [r for r in g.regions if r.kind == "frontier"],
     lambda n: f"({_region_kind(n)} in {n.room}, {n.size:.2f} m)", _region_changes),
)


def _distance_changes(expected: SceneGraph, actual: SceneGraph, tol: float,
                      renamed: Mapping[str, str]) -> list[str]:
    """One line: how many robot distances differ beyond ``tol``, how many nodes gained or
    lost one, and the largest change (a renumbered frontier's under its new id)."""
    worst, n, gone = (0.0, ""), 0, 0
    before = {renamed.get(k, k): d for k, d in expected.distances.items()}
    for k in sorted(before.keys() | actual.distances.keys()):
        a, b = before.get(k), actual.distances.get(k)
        if a is None or b is None:
            gone += 1
        elif _beyond(abs(a - b), tol):
            n += 1
            worst = max(worst, (abs(a - b), k))
    if not n and not gone:
        return []
    parts = [f"{n} differ" + (f", largest {_m(worst[0])} m ({worst[1]})" if n else "")]
    if gone:
        parts.append(f"{gone} new or gone")
    return ["distances: " + "; ".join(parts)]


ROUNDING = "the canonical JSON differs below the tolerance (rounding)"


def _members(g: SceneGraph) -> dict[str, str]:
    """Object, region and frontier id -> the room it lies in: what tells a merge or a
    split of rooms from a room that is simply gone or new."""
    out = {o.id: o.room for o in g.objects}
    out.update({r.id: r.room for r in g.regions})
    return out


def _area(s: LayerSummary | None, room: str) -> str:
    a = s.area(room) if s is not None else None
    return "" if a is None else f", {a:.2f} m²"


def _room_set_changes(expected: SceneGraph, actual: SceneGraph,
                      layers: tuple[LayerSummary | None, LayerSummary | None]) -> list[str]:
    """Rooms removed or added, told apart from rooms merged into a kept room or split off
    one (their objects and regions went to, or came from, that one room), with areas."""
    e, a = _by_id(expected.rooms), _by_id(actual.rooms)
    me, ma = _members(expected), _members(actual)
    both = me.keys() & ma.keys()
    out = []
    for k in sorted(e.keys() - a.keys()):
        into = {ma[m] for m in both if me[m] == k}
        if len(into) == 1 and (t := next(iter(into))) in e and t in a:
            out.append(f"rooms: {k} ({e[k].category}{_area(layers[0], k)}) merged into {t} "
                       f"({a[t].category}{_area(layers[1], t)})")
        else:
            out.append(f"rooms: - {k} ({e[k].category}{_area(layers[0], k)})")
    for k in sorted(a.keys() - e.keys()):
        came = {me[m] for m in both if ma[m] == k}
        if len(came) == 1 and (f := next(iter(came))) in e and f in a:
            out.append(f"rooms: {f} ({e[f].category}{_area(layers[0], f)}) split into {f} "
                       f"({a[f].category}{_area(layers[1], f)}) + {k} "
                       f"({a[k].category}{_area(layers[1], k)})")
        else:
            out.append(f"rooms: + {k} ({a[k].category}{_area(layers[1], k)})")
    return out


def _area_changes(expected: SceneGraph,
                  layers: tuple[LayerSummary | None, LayerSummary | None],
                  tol: float) -> list[str]:
    """Areas of the rooms in both refreshes (when both have a :class:`LayerSummary`)."""
    se, sa = layers
    if se is None or sa is None:
        return []
    out = []
    for r in expected.rooms:
        x, y = se.area(r.id), sa.area(r.id)
        if x is not None and y is not None and _beyond(abs(x - y), tol):
            out.append("rooms: {} area {} -> {} m²".format(r.id, *_pair(x, y)))
    return out


def _voronoi_changes(layers: tuple[LayerSummary | None, LayerSummary | None]) -> list[str]:
    se, sa = layers
    if se is None or sa is None or \
            (se.voronoi_nodes, se.voronoi_edges) == (sa.voronoi_nodes, sa.voronoi_edges):
        return []
    return [f"voronoi: {se.voronoi_nodes} nodes, {se.voronoi_edges} edges -> "
            f"{sa.voronoi_nodes} nodes, {sa.voronoi_edges} edges"]


def diff_graphs(expected: SceneGraph, actual: SceneGraph, tol: float = 1e-4,
                layers: tuple[LayerSummary | None, LayerSummary | None] = (None, None)
                ) -> list[str]:
    """What differs between two scene graphs, one line per difference, grouped by layer
    (empty when they are equal up to ``tol`` in positions (m), distances (m), category
    scores and room areas (m²)): rooms removed, added, merged or split (with their areas
    when ``layers``, the two refreshes' :class:`LayerSummary`, give them), categories,
    objects moved, assigned to another room or otherwise changed, doors (moved, state,
    rooms), edges, regions and frontiers, the robot (room, position, yaw), the graph's time
    and version, distances and the Voronoi graph size (every field of the graph is
    compared). Equal up to ``tol`` but not byte-equal:
    the one line :data:`ROUNDING`."""
    for name, graph in (("expected", expected), ("actual", actual)):
        of_type(name, graph, SceneGraph, "a SceneGraph")
    out: list[str] = _room_set_changes(expected, actual, layers)
    renamed: dict[str, str] = {}
    for layer, nodes, describe, changes in _LAYERS:
        e, a = _by_id(nodes(expected)), _by_id(nodes(actual))
        if layer == "frontiers":
            renamed = _renumbered(e, a, tol)
            out += [f"frontiers: {k} is {v} (renumbered)" for k, v in renamed.items()]
            e = {renamed.get(k, k): n for k, n in e.items()}
        if layer != "rooms":
            out += _added_removed(layer, e, a, describe)
        for k in sorted(e.keys() & a.keys()):
            out += changes(e[k], a[k], tol)
        if layer == "rooms":
            out += _area_changes(expected, layers, tol)
    out += _voronoi_changes(layers)
    er, ar = expected.robot, actual.robot
    if (er.room, er.region) != (ar.room, ar.region):
        out.append(f"robot: in {er.room}/{er.region} -> {ar.room}/{ar.region}")
    if (d := _moved(er, ar, tol)) is not None:
        out.append(f"robot: moved {_m(d)} m")
    turn = abs(math.remainder(er.yaw - ar.yaw, math.tau))
    if _beyond(turn, tol):
        out.append(f"robot: yaw {er.yaw:.4f} -> {ar.yaw:.4f} rad")
    if expected.time_ns != actual.time_ns:
        out.append(f"graph: time {expected.time_ns} -> {actual.time_ns} ns")
    if expected.version != actual.version:
        out.append(f"graph: version {expected.version} -> {actual.version}")
    out += _distance_changes(expected, actual, tol, renamed)
    if not out and expected.to_json() != actual.to_json():
        out.append(ROUNDING)
    return out


class RefreshInfo(Protocol):
    """What a report says of a refresh: :class:`~sgtool.scenegraph.stream.Refresh` or a
    pinned refresh's metadata."""

    @property
    def time_ns(self) -> int: ...
    @property
    def frames(self) -> int: ...
    @property
    def reason(self) -> str: ...


def refresh_head(i: int, ref: RefreshInfo) -> str:
    """``refresh 3 at 12.400 s (after 40 frames, every)``."""
    return f"refresh {i} at {ref.time_ns / 1e9:.3f} s (after {ref.frames} frames, {ref.reason})"


def describe_mismatch(expected: Sequence[str], actual: Sequence[tuple[RefreshInfo, str]],
                      limit: int = 40, tol: float = 1e-4, exact: bool = True,
                      layers: Sequence[tuple[LayerSummary | None, LayerSummary | None]] = (),
                      numbers: Sequence[int] = ()) -> list[str]:
    """The first refresh whose graph differs, with :func:`diff_graphs` of it; empty when
    none does. ``exact``: any byte of difference counts (below ``tol`` it reads
    :data:`ROUNDING`); else only differences beyond ``tol``. ``layers``: per refresh, the
    expected and actual :class:`LayerSummary` (areas, Voronoi graph size); ``numbers``:
    the actual refreshes' numbers in their log when they are not 0, 1, ... (a selection)."""
    for i, (exp, (ref, got)) in enumerate(zip(expected, actual, strict=False)):
        if exp == got and not (i < len(layers) and layers[i][0] != layers[i][1]):
            continue
        pair = layers[i] if i < len(layers) else (None, None)
        lines = diff_graphs(SceneGraph.from_json(exp), SceneGraph.from_json(got), tol, pair)
        if not exact:
            lines = [x for x in lines if x != ROUNDING]
        elif not lines and exp != got:  # bytes differ where the graph reads nothing
            lines = json_changes(exp, got)
        if not lines:
            continue
        head = refresh_head(numbers[i] if i < len(numbers) else i, ref) + " differs:"
        more = [f"  ... and {len(lines) - limit} more"] if len(lines) > limit else []
        return [head] + ["  " + x for x in lines[:limit]] + more
    if len(expected) != len(actual):
        return [f"{len(actual)} refreshes where {len(expected)} were expected; the first "
                f"{min(len(expected), len(actual))} agree"]
    return []


def json_changes(expected: str, actual: str, limit: int = 10) -> list[str]:
    """Where two graph JSON texts differ that :func:`diff_graphs` does not see (keys the
    scene graph does not read, added or removed, and their values; else the text's form):
    one line per difference, ``json: PATH: ...``."""
    import json

    out: list[str] = []

    def walk(a: Any, b: Any, path: str) -> None:
        if len(out) >= limit:
            return
        if isinstance(a, dict) and isinstance(b, dict):
            for k in sorted(a.keys() - b.keys()):
                out.append(f"json: {path}{k}: key removed")
            for k in sorted(b.keys() - a.keys()):
                out.append(f"json: {path}{k}: key added")
            for k in sorted(a.keys() & b.keys()):
                walk(a[k], b[k], f"{path}{k}.")
        elif isinstance(a, list) and isinstance(b, list) and len(a) == len(b):
            for i, (x, y) in enumerate(zip(a, b, strict=True)):
                walk(x, y, f"{path.removesuffix('.')}[{i}].")
        elif a != b or type(a) is not type(b):
            out.append(f"json: {path.removesuffix('.')}: {a!r} -> {b!r}")

    try:
        walk(json.loads(expected), json.loads(actual), "")
    except ValueError:
        return ["json: the text is not JSON"]
    return out[:limit] or ["json: the same fields and values, written otherwise (key order, "
                           "spacing or number form)"]


# quality figure, how a report names it, its format
QUALITY_FIGURES = (("purity", "purity", ".3f"), ("ari", "ARI", ".3f"), ("rooms", "rooms", "d"),
                   ("object_accuracy", "objects in the right room", ".1%"))


def _figure(x: Any, spec: str) -> str:
    """A figure as printed; ``-`` for one over nothing (None)."""
    return "-" if x is None else format(x, spec)


def quality_lines(before: dict[str, Any] | None, after: dict[str, Any] | None,
                  changed_only: bool = False) -> list[str]:
    """``quality (merged): purity 0.950 -> 0.910, ARI 0.900 (same), ...``: the figures
    before and after as printed (purity and ARI to 3 decimals, rooms, objects in the right
    room to 0.1%), per variant; ``changed_only``: only variants with a figure that differs
    as printed. Empty unless both are given."""
    if before is None or after is None:
        return []
    out = []
    for variant in sorted(before.keys() & after.keys()):
        b, a = before[variant], after[variant]
        pairs = [(label, _figure(b[k], spec), _figure(a[k], spec))
                 for k, label, spec in QUALITY_FIGURES if k in b and k in a]
        if changed_only and all(x == y for _, x, y in pairs):
            continue
        out.append(f"quality ({variant}): " + ", ".join(
            f"{label} {x} -> {y}" if x != y else f"{label} {x} (same)" for label, x, y in pairs))
    return out
