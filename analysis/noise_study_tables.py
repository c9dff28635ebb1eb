"""Tables of the perception-noise study (:mod:`sgtool.analysis.noise_study`):
``summary.md``, ``results.json`` and ``results.csv``.

Every number comes from the cells (and the closed-loop rows) only, never from the wall
clock or the cache state, so the same study gives byte-identical tables. Figures are the
``merged`` scores unless a column says ``strict``; "rooms" is found vs true (every true room
of the house, merged), the room error ``rooms - true``. Medians and ranges are over houses.
A level's "vs none" columns are the median over houses of its difference to the house's
noise-free cell, in points (purity x 100, objects in the right room in %).
"""

from __future__ import annotations

import csv
import io
import json
import math
import statistics
from collections.abc import Callable, Mapping, Sequence
from dataclasses import asdict
from pathlib import Path
from typing import Any

from sgtool.analysis.noise_study import (
    FACTOR_UNITS,
    FACTORS,
    NONE,
    PROFILE,
    Cell,
    Condition,
    StudyResult,
)
from sgtool.analysis.report import pipe_table

SCORE_FIELDS: tuple[str, ...] = ("gt_rooms", "gt_rooms_seen", "rooms", "room_count_error",
                                 "room_error_vs_true", "purity", "ari", "objects",
                                 "object_accuracy", "categorised", "category_accuracy",
                                 "gt_rooms_with_nodes", "house_objects", "objects_seen",
                                 "object_ari")


def _num(x: float | int) -> float | int | None:
    """A JSON-safe number: NaN and infinities as None."""
    if isinstance(x, float) and not math.isfinite(x):
        return None
    return x


def cell_record(c: Cell) -> dict[str, Any]:
    """One cell as a plain dict (``results.json``)."""
    return {"house": c.house, "factor": c.condition.factor, "level": c.condition.level,
            "noise": c.condition.noise, "frames": c.frames,
            "merged": {k: _num(c.merged[k]) for k in SCORE_FIELDS},
            "strict": {k: _num(c.strict[k]) for k in SCORE_FIELDS}}


def results_json(res: StudyResult) -> str:
    cfg = res.config
    doc: dict[str, Any] = {
        "houses": [h.id for h in cfg.houses],
        "rooms": list(cfg.rooms),
        "recording": asdict(cfg.settings),
        "conditions": [asdict(c) for c in cfg.conditions],
        "cells": [cell_record(c) for c in res.cells],
    }
    if res.closed_loop is not None:
        doc["closed_loop"] = closed_loop_records(res.closed_loop)
    return json.dumps(doc, indent=1, sort_keys=True, allow_nan=False) + "\n"


def results_csv(res: StudyResult) -> str:
    """One row per house x condition: the merged figures, then the strict ones."""
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(["house", "factor", "level", "noise", "frames",
                *(f"merged_{k}" for k in SCORE_FIELDS), *(f"strict_{k}" for k in SCORE_FIELDS)])
    for c in res.cells:
        w.writerow([c.house, c.condition.factor, c.condition.level, c.condition.noise, c.frames,
                    *(_csv(c.merged[k]) for k in SCORE_FIELDS),
                    *(_csv(c.strict[k]) for k in SCORE_FIELDS)])
    return buf.getvalue()


def _csv(x: float | int) -> str:
    return "" if _num(x) is None else repr(x)


# ----- summary.md -------------------------------------------------------------------------
def _pct(x: float) -> str:
    return "-" if not math.isfinite(x) else f"{100 * x:.1f}%"


def _f3(x: float) -> str:
    return "-" if not math.isfinite(x) else f"{x:.3f}"


def _median_range(xs: Sequence[float], fmt: Callable[[float], str]) -> str:
    xs = [x for x in xs if math.isfinite(x)]
    if not xs:
        return "-"
    if len(xs) == 1:
        return fmt(xs[0])
    return f"{fmt(statistics.median(xs))} [{fmt(min(xs))}, {fmt(max(xs))}]"


def _signed(x: float) -> str:
    return "-" if not math.isfinite(x) else f"{x + 0.0:+.1f}".replace("-0.0", "+0.0")


def cell_text(c: Cell) -> str:
    """``found/true purity objects% of n``: ``6/6 1.000 100.0% of 38``."""
    m = c.merged
    return (f"{m['rooms']}/{m['gt_rooms']} {_f3(float(m['purity']))} "
            f"{_pct(float(m['object_accuracy']))} of {m['objects']}")


def condition_label(c: Condition) -> str:
    if c.factor == NONE:
        return "none"
    if c.factor == PROFILE:
        return c.level
    return f"{c.factor}={c.level}"


def _cells_of(res: StudyResult, cond: Condition) -> list[Cell]:
    return [c for c in res.cells if c.condition == cond]


def _baseline(res: StudyResult) -> dict[str, Cell]:
    return {c.house: c for c in res.cells if c.condition.factor == NONE}


def condition_row(res: StudyResult, cond: Condition, first: str) -> list[str]:
    """The columns of one condition in the factor tables."""
    cells = _cells_of(res, cond)
    base = _baseline(res)

    def vals(key: str) -> list[float]:
        return [float(c.merged[key]) for c in cells]

    def delta(key: str) -> float:
        d = [100 * (float(c.merged[key]) - float(base[c.house].merged[key]))
             for c in cells if c.house in base]
        d = [x for x in d if math.isfinite(x)]
        return statistics.median(d) if d else math.nan

    def kept() -> list[float]:  # objects in the graph, share of the noise-free graph's
        return [float(c.merged["objects"]) / float(base[c.house].merged["objects"])
                for c in cells if c.house in base and base[c.house].merged["objects"]]

    found = " ".join(f"{c.merged['rooms']}/{c.merged['gt_rooms']}" for c in cells)
    return [first, found,
            _median_range(vals("room_error_vs_true"), lambda x: f"{x:+g}"),
            _median_range(vals("purity"), _f3),
            _median_range(vals("object_accuracy"), _pct),
            _median_range(kept(), _pct),
            _median_range(vals("object_ari"), _f3),
            _median_range(vals("ari"), _f3),
            _median_range(vals("category_accuracy"), _pct),
            _signed(delta("purity")), _signed(delta("object_accuracy"))]


FACTOR_HEADER = ["level", "rooms found/true per house", "room error vs true",
                 "purity", "objects right", "objects kept vs none", "objects' rooms ARI",
                 "ARI", "categories right", "purity vs none (pts)", "objects vs none (pts)"]


# under pose drift the map lies in the drifted frame: the position-based scores count that
DRIFT_NOTE = ("Under pose drift the map lies in the drifted odometry frame; before it is "
              "scored it is carried onto the house by the rotation and shift that best fit "
              "the logged poses to the true ones, so purity, ARI, objects right and "
              "categories still count the map's warp (what no rigid shift removes) as well "
              "as how it is cut into rooms; the objects' rooms ARI asks only which objects "
              "share a room, not where.")


def summary_md(res: StudyResult) -> str:
    from sgtool.recorders.sim.noise import parse_noise

    cfg = res.config
    s = cfg.settings
    houses = [h.id for h in cfg.houses]
    out = ["# Perception-noise study", ""]
    frames = "until the scripted tour ends" if s.frames is None else f"at most {s.frames}"
    named = [h.id if h.spec is None else f"{h.id} (file {Path(h.source).name})"
             for h in cfg.houses]
    gen = (f"; generated with {cfg.rooms[0]}-{cfg.rooms[1]} rooms as `sgtool record --seed`"
           if any(h.spec is None for h in cfg.houses) else "")
    out += [f"Houses: {', '.join(named)}{gen}. Recording: {s.width}x{s.height}, "
            f"{s.fps:g} fps, noise seed "
            f"{s.noise_seed}, frames {frames}. Replay with the log's options; scores of the "
            "final graph, merged (rooms joined by a doorless passage count as one).", "",
            "Medians over houses, [min, max] after them; 'rooms found/true': explored rooms "
            "of the graph vs every true room of the house; 'vs none': median over houses of "
            "the difference to the house's noise-free cell, in points; 'objects kept vs "
            "none': the objects in the graph, as a share of those in the house's noise-free "
            "graph (objects right counts only those kept); 'categories right': the "
            "explored rooms named with their true room's type.", ""]
    out += ["## Every house and condition", "",
            "Cell: rooms found/true, Voronoi purity, objects in the right room of the "
            "objects in the graph.", ""]
    rows = []
    for cond in cfg.conditions:
        by_house = {c.house: c for c in _cells_of(res, cond)}
        rows.append([condition_label(cond), *(cell_text(by_house[h]) for h in houses)])
    out += [pipe_table(["condition", *houses], rows), ""]
    none = next(c for c in cfg.conditions if c.factor == NONE)
    for f in FACTORS:
        conds = [c for c in cfg.conditions if c.factor == f]
        if not conds:
            continue
        out += [f"## {f} ({FACTOR_UNITS[f]})", ""]
        rows = [condition_row(res, none, "0 (none)")]
        rows += [condition_row(res, c, c.level) for c in conds]
        out += [pipe_table(FACTOR_HEADER, rows), ""]
        if f in ("drift_xy", "drift_yaw"):
            out += [DRIFT_NOTE, ""]
    profiles = [c for c in cfg.conditions if c.factor == PROFILE]
    if profiles:
        out += ["## Profiles", ""]
        rows = [condition_row(res, none, "none")]
        rows += [condition_row(res, c, c.level) for c in profiles]
        out += [pipe_table(["profile", *FACTOR_HEADER[1:]], rows), ""]
        if any(parse_noise(c.noise).drift_model for c in profiles):
            out += [DRIFT_NOTE, ""]
    if res.closed_loop is not None:
        out += closed_loop_md(res.closed_loop)
    return "\n".join(out).rstrip("\n") + "\n"


# ----- closed loop ------------------------------------------------------------------------
def closed_loop_records(cl: Any) -> list[dict[str, Any]]:
    """One record per closed-loop episode: planner, noise, house, episode, query, success,
    SPL, steps, frames, end."""
    from sgtool.analysis.search_metrics import episode_spl

    out = []
    for r in cl.rows:
        e = r.result
        spl = episode_spl(e.success, e.shortest_m, e.travelled_m)
        out.append({"planner": e.planner, "noise": r.task.noise, "house": e.house,
                    "episode": e.episode, "query": e.query, "success": bool(e.success),
                    "spl": _num(float(spl)), "steps": e.steps, "frames": r.frames,
                    "end": e.end})
    return out


def closed_loop_md(cl: Any) -> list[str]:
    """SR and SPL per planner and noise profile, and the paired difference of SR to the
    first profile (the same episodes), with its 95 % interval (normal approximation of the
    paired differences, clipped to [-1, 1])."""
    from sgtool.analysis.search_metrics import episode_spl

    cfg = cl.config
    recs: dict[tuple[str, str], dict[tuple[str, int], Any]] = {}
    for r in cl.rows:
        recs.setdefault((r.task.planner, r.task.noise), {})[(r.result.house,
                                                            r.result.episode)] = r.result
    rows = []
    first = cfg.noise[0]
    for p in cfg.planners:
        for n in cfg.noise:
            eps = recs.get((p, n), {})
            if not eps:
                continue
            sr = sum(e.success for e in eps.values()) / len(eps)
            spls = [episode_spl(e.success, e.shortest_m, e.travelled_m) for e in eps.values()]
            spls = [x for x in spls if math.isfinite(x)]
            spl = statistics.mean(spls) if spls else math.nan
            diff = "-"
            base = recs.get((p, first), {})
            pairs = [(float(e.success) - float(base[k].success)) for k, e in sorted(eps.items())
                     if k in base]
            if n != first and pairs:
                diff = _paired_text(pairs)
            rows.append([p, n, str(len(eps)), f"{sr:.3f}", _f3(spl), diff])
    budget = (f"{cfg.frames_per_room} frames per room" if cfg.frames_per_room
              else "no frame budget")
    return ["## Closed loop", "",
            f"{cfg.episodes} episode(s) per house on {len(cfg.house_files)} house(s), "
            f"{budget}, at most {cfg.options.max_steps} steps; the same episodes under "
            f"every profile. SR difference to {first!r}: paired over episodes, mean with a "
            "95 % interval (normal approximation).", "",
            pipe_table(["planner", "noise", "episodes", "SR", "SPL", f"SR - SR({first})"],
                       rows), ""]


def _paired_text(d: Sequence[float]) -> str:
    m = statistics.mean(d)
    if len(d) < 2:
        return f"{m:+.3f}"
    half = 1.96 * statistics.stdev(d) / math.sqrt(len(d))
    return f"{m:+.3f} [{max(-1.0, m - half):+.3f}, {min(1.0, m + half):+.3f}]"


def by_factor(res: StudyResult) -> Mapping[str, list[Condition]]:
    """Factor -> its conditions with ``none`` first (the plots' x axes); ``profile`` holds
    none and the profiles."""
    none = [c for c in res.config.conditions if c.factor == NONE]
    out: dict[str, list[Condition]] = {}
    for f in (*FACTORS, PROFILE):
        conds = [c for c in res.config.conditions if c.factor == f]
        if conds:
            out[f] = none + conds
    return out
