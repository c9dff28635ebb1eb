"""Does a close view of a carrier show what it holds? The examined rules against the frames.

For every container or supporter that holds something in generated houses (closed ones
opened in the spec), the robot stands at each distance x angle off the piece's front
(local +y) facing its centre, where it does not touch anything, and one frame is rendered.
Per view: whether a held object is in view (at least ``--pixels`` pixels), whether the
older rule counts the piece examined (a close view, :func:`~sgtool.scenegraph.examined.
close_views`), and whether the frame saw into it (:func:`~sgtool.scenegraph.examined.
look_into` and :meth:`~sgtool.scenegraph.examined.PieceView.searched` at each
``--share``, on top of the close view). Printed per kind (C container, S supporter, CS
both): *recall*, the share of views showing the contents that count the piece examined,
and *searched but unseen*, the share of views not showing them that count it examined
anyway (a piece a planner then never looks at again). Each is given over views (the
contents: any held object in view) and over (view, held object) pairs: a search is for one
object, and a carrier that shows one of its things may hide another (the peach on a
refrigerator's top shelf while those on its middle one are in view).

One frame is the hardest case: the live graph adds up the frames, so recall there is
higher for long pieces only partly in one frame.

With ``--log LOG`` it also times what the rule costs the builder: the frames of the log
integrated with ``BuilderConfig.look_inside`` on and off, in alternating rounds (CPU
milliseconds per frame, medians, and their ratio).

    .venv/bin/python benchmarks/examined_views.py --houses 2 --share 0.3,0.5
    .venv/bin/python benchmarks/examined_views.py --houses 0 --log LOG --rounds 3
"""

from __future__ import annotations

import argparse
import collections
import dataclasses
import itertools
import math
from typing import Any

import numpy as np
from harness import add_output_options, alternate, emit

from sgtool.datasets.generator import generate_house
from sgtool.recorders.sim import CameraConfig
from sgtool.recorders.sim.simulation import Simulation
from sgtool.scenegraph.examined import (
    FramePoints,
    PieceView,
    carrier_kinds,
    close_views,
    examinable,
    look_into,
)

DISTANCES = (0.7, 1.0, 1.5, 2.0)  # m from the piece's front face
ANGLES = (0, 30, 60, 90)  # degrees off its front, both sides


def _held(spec: Any) -> dict[str, list[str]]:
    """Furniture id -> the objects it holds (through nested objects)."""
    objs = {o.id: o for o in spec.objects}
    out: dict[str, list[str]] = collections.defaultdict(list)
    for o in spec.objects:
        p = o.parent
        while p in objs:
            p = objs[p].parent
        if p:
            out[p].append(o.id)
    return out


def views(seed: int, rooms: tuple[int, int], pixels: int, shares: list[float],
          size: tuple[int, int]) -> list[View]:
    """Every view of house ``seed``."""
    spec = generate_house(seed, rooms, preset="symsearch")
    held = _held(spec)
    spec = dataclasses.replace(spec, furniture=tuple(
        dataclasses.replace(f, state="open") if f.state == "closed" else f
        for f in spec.furniture))
    out = []
    with Simulation(spec, camera=CameraConfig(width=size[0], height=size[1])) as sim:
        by_spec = {i.spec_id: i.id for i in sim.instances if i.spec_id}
        for f in spec.furniture:
            if f.id not in held or not examinable(f.affordances) or f.id not in by_spec:
                continue
            piece = by_spec[f.id]
            content = [by_spec[o] for o in held[f.id] if o in by_spec]
            cont, sup = carrier_kinds(f.affordances)
            kind = ("C" if cont else "") + ("S" if sup else "")
            c, s = math.cos(f.yaw), math.sin(f.yaw)
            for d, th in itertools.product(DISTANCES, ANGLES):
                for sign in ((1,) if th == 0 else (1, -1)):
                    a = math.radians(th) * sign
                    lx, ly = d * math.sin(a), d * math.cos(a) + f.size[1] / 2
                    x, y = f.center[0] + c * lx - s * ly, f.center[1] + s * lx + c * ly
                    pose = (x, y, math.atan2(f.center[1] - y, f.center[0] - x))
                    if sim.in_contact(pose):
                        continue
                    sim.teleport(pose)
                    fr = sim.render()
                    ids, depth = np.asarray(fr.ids), np.asarray(fr.depth)
                    each = [int((ids == i).sum()) >= pixels for i in content]
                    old = piece in close_views(ids, depth, 50)
                    v = PieceView()
                    look_into(v, piece, FramePoints.of(ids, depth, fr.pose, fr.intrinsics,
                                                       0.05))
                    out.append(View(kind, any(each), tuple(each), old,
                                    tuple(old and v.searched(cont, sup, sh) for sh in shares)))
    return out


@dataclasses.dataclass(frozen=True)
class View:
    """One view of a carrier: its kind, whether any / each held object is in view, and
    whether the old rule and the new one at each share count it examined."""

    kind: str
    any_in_view: bool
    each_in_view: tuple[bool, ...]
    old: bool
    new: tuple[bool, ...]


def _rates(seen: list[Any], unseen: list[Any], pick: Any) -> dict[str, float | None]:
    """Recall over the views showing the contents, searched-but-unseen over the others."""
    return {"recall": sum(map(pick, seen)) / len(seen) if seen else None,
            "searched_unseen": sum(map(pick, unseen)) / len(unseen) if unseen else None}


def _rules(rows: list[View], shares: list[float], per_object: bool) -> dict[str, Any]:
    """Recall and searched-but-unseen of the old rule and the new ones, over views (the
    contents: any held object in view) or, with ``per_object``, over (view, held object)
    pairs (that object in view: a search for it)."""
    items = [(r, vis) for r in rows for vis in (r.each_in_view if per_object
                                                 else (r.any_in_view,))]
    seen = [r for r, vis in items if vis]
    unseen = [r for r, vis in items if not vis]
    return {"pairs" if per_object else "views": len(items), "in_view": len(seen),
            "old": _rates(seen, unseen, lambda r: r.old),
            "new": {f"{sh:g}": _rates(seen, unseen, lambda r, i=i: r.new[i])
                    for i, sh in enumerate(shares)}}


def table(rows: list[View], shares: list[float]) -> dict[str, dict[str, Any]]:
    """Per kind and "all": over views and over (view, held object) pairs, the rates of
    the old rule and of the new one at each share."""
    out: dict[str, dict[str, Any]] = {}
    for kind in sorted({r.kind for r in rows}) + ["all"]:
        sel = [r for r in rows if kind in ("all", r.kind)]
        out[kind] = {"views": _rules(sel, shares, False),
                     "objects": _rules(sel, shares, True)}
    return out


def integrate_cost(log: str, rounds: int) -> dict[str, Any]:
    """CPU ms per frame of integrating ``log``'s frames with the rule on and off."""
    from sgtool.log import LogReader
    from sgtool.scenegraph.builder import SceneGraphBuilder
    from sgtool.scenegraph.builder_config import BuilderConfig
    from sgtool.scenegraph.instances import instances_from_record

    with LogReader(log) as r:
        rec = r.last_record("instances")
        table = instances_from_record(rec) if rec else {}
        frames = list(r.frames())

    def run(flag: bool) -> Any:
        def go() -> None:
            b = SceneGraphBuilder(table, None, BuilderConfig(look_inside=flag))
            for f in frames:
                b.integrate(f)
        return go
    t = alternate({"look_inside": run(True), "close view only": run(False)}, rounds)
    ms = {k: v.cpu_s * 1e3 / max(1, len(frames)) for k, v in t.items()}
    return {"log": log, "frames": len(frames), "rounds": rounds, "cpu_ms_per_frame": ms,
            "ratio": ms["look_inside"] / ms["close view only"]}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--houses", type=int, default=2,
                    help="generated houses 0..N-1 (0: none, e.g. with --log)")
    ap.add_argument("--rooms", default="8-16", help="room count range MIN-MAX")
    ap.add_argument("--pixels", type=int, default=10, help="pixels of a held object in view")
    ap.add_argument("--share", default="0.3,0.5", help="inner shares to try, comma-separated")
    ap.add_argument("--resolution", default="160x120")
    ap.add_argument("--log", help="also time the builder's integration of this log")
    ap.add_argument("--rounds", type=int, default=3, help="rounds of --log")
    add_output_options(ap)
    args = ap.parse_args()
    doc: dict[str, Any] = {}
    if args.log:
        cost = integrate_cost(args.log, args.rounds)
        for k, v in cost["cpu_ms_per_frame"].items():
            print(f"{k:<16} {v:.3f} CPU ms per frame")
        print(f"ratio {cost['ratio']:.2f} ({cost['frames']} frames, {args.rounds} rounds)")
        doc["cost"] = cost
    if args.houses > 0:
        doc.update(measure(args))
    emit(doc, args.json_out)


def measure(args: argparse.Namespace) -> dict[str, Any]:
    """The views of ``args.houses`` houses: the table printed, its document returned."""
    lo, hi = (int(x) for x in args.rooms.split("-"))
    shares = [float(x) for x in args.share.split(",")]
    w, h = (int(x) for x in args.resolution.split("x"))
    rows = [r for seed in range(args.houses)
            for r in views(seed, (lo, hi), args.pixels, shares, (w, h))]
    doc = table(rows, shares)

    def pct(x: float | None) -> str:
        return "-" if x is None else f"{x:.2f}"

    def pair(r: dict[str, Any]) -> str:
        return f"{pct(r['recall'])} / {pct(r['searched_unseen'])}"
    print("recall / searched but unseen; per view (any held object in view) and per held "
          "object")
    print("kind  over     n      in view  old            "
          + "  ".join(f"share {s:g}    " for s in shares))
    for kind, t in doc.items():
        for over in ("views", "objects"):
            r = t[over]
            n = r["views" if over == "views" else "pairs"]
            cells = [pair(r["new"][f"{s:g}"]) for s in shares]
            print(f"{kind:<5} {over:<7} {n:>6} {r['in_view']:>7}  {pair(r['old'])}  "
                  + "  ".join(cells))
    return {"houses": args.houses, "rooms": args.rooms, "pixels": args.pixels,
            "resolution": args.resolution, "kinds": doc}


if __name__ == "__main__":
    main()
