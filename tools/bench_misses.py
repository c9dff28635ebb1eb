"""Where the failed episodes of ``sgtool bench`` output folders went wrong: rooms never
entered, or holders never checked.

For every episode of the chosen planners that did not find its target, from the folder's
``episodes.jsonl`` and the houses its ``summary.json`` settings rebuild (generated houses
and house files alike, as the bench drew them): the target's rooms, whether any action of
the trace touched a node in one of them (an explore of one of its regions, a check of one
of its pieces), and the categories of the pieces that hold the target (its carriers: the
piece a small object stands in or on, or the piece itself) beside those the planner
checked in the target's rooms. A target whose rooms were never entered was lost to the
room order; one whose room was entered but whose holder was never checked, to the order
of the pieces in the room (often an unlikely holder for the priors).

    .venv/bin/python tools/bench_misses.py OUT [OUT ...] [--planner P] [--list]
"""

from __future__ import annotations

import argparse
import json
import sys
from collections import Counter
from pathlib import Path

from sgtool.analysis.bench import BenchConfig, prepare_houses
from sgtool.analysis.bench_houses import bench_episodes, symbolic_house
from sgtool.results import read_jsonl


def house_nodes(spec, house) -> tuple[dict[str, tuple[str, int]], dict[str, str]]:  # noqa: ANN001
    """Node id -> (category, room index) of every piece and object, and spec id -> the
    node id of the piece that holds it (for a piece: itself)."""
    nodes, holder = {}, {}
    for i, f in enumerate(spec.furniture):
        nodes[house.furn_ids[i]] = (f.category, house.room_index[f.room])
        holder[f.id] = house.furn_ids[i]
    for j, o in enumerate(spec.objects):
        piece = house.obj_furn[j]
        nodes[house.obj_ids[j]] = (o.category, house.room_index[spec.furniture[piece].room])
        holder[o.id] = house.furn_ids[piece]
    return nodes, holder


def misses(out: Path, planners: set[str] | None) -> list[dict]:
    settings = json.loads((out / "summary.json").read_text())["settings"]
    cfg = BenchConfig(planners=tuple(settings["planners"]), houses=settings["houses"],
                      episodes=settings["episodes"], rooms=tuple(settings["rooms"]),
                      preset=settings["preset"], house_seed=settings["house_seed"],
                      house_files=tuple(settings["house_files"]))
    houses = {h.id: h for h in prepare_houses(cfg)}
    built: dict[str, tuple] = {}
    rows = []
    for r in read_jsonl(out / "episodes.jsonl"):
        if r.success or (planners and r.planner not in planners):
            continue
        if r.house not in built:
            ref = houses[r.house]
            spec = ref.load(cfg.rooms, cfg.preset)
            house, _ = symbolic_house(spec, ref.source)
            mix = cfg.preset if ref.spec is None else "default"
            built[r.house] = (spec, house, bench_episodes(spec, cfg.episodes, mix),
                              *house_nodes(spec, house))
        spec, house, episodes, nodes, holder = built[r.house]
        ep = episodes[r.episode]
        rooms = {house.room_index[x] for x in ep.target_rooms}
        carriers = {holder[t] for t in ep.targets}
        acted = []
        for step in r.trace:
            target = step.target or ""
            room = int(target.split(":")[1].split(".")[0]) if target.startswith("region:") \
                else nodes.get(target, ("", None))[1]
            if room in rooms:
                acted.append(nodes.get(target, ("region", room))[0])
        rows.append({"planner": r.planner, "house": r.house, "episode": r.episode,
                     "seed": r.seed, "query": r.query, "entered": bool(acted),
                     "holders": sorted(nodes[c][0] for c in carriers), "checked": acted})
    return rows


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("outs", nargs="+", type=Path)
    ap.add_argument("--planner", action="append", default=None)
    ap.add_argument("--list", action="store_true", help="one line per failed episode")
    args = ap.parse_args()
    for out in args.outs:
        if not (out / "summary.json").is_file():
            sys.exit(f"bench_misses: {out} holds no summary.json of `sgtool bench`")
        rows = misses(out, set(args.planner) if args.planner else None)
        print(f"{out}: {len(rows)} failed episodes")
        for planner, n in sorted(Counter(r["planner"] for r in rows).items()):
            mine = [r for r in rows if r["planner"] == planner]
            entered = sum(r["entered"] for r in mine)
            print(f"  {planner}: {n} failed; target's room never entered {n - entered}, "
                  f"entered without checking the holder {entered}")
            held = Counter(h for r in mine if r["entered"] for h in set(r["holders"]))
            print(f"    holders left unchecked: {dict(held.most_common(8))}")
        if args.list:
            for r in rows:
                print(f"  {r['planner']} {r['house']} ep {r['episode']} seed {r['seed']} "
                      f"{r['query']!r}: holders {r['holders']}; in its rooms "
                      f"{r['checked'] if r['entered'] else 'never'}")


if __name__ == "__main__":
    main()
