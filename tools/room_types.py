"""How the rooms of replayed logs are named, against the houses they were recorded in.

Each log (a recording of a house spec: ``sgtool record``, ``sgtool run``, a run-bench
episode) is replayed with its own options; for every explored room of the final graph
this prints its true type (the house room holding most of its Voronoi nodes), the type the
graph gives it, whether it is long and narrow (the corridor rule's shape,
:func:`sgtool.scenegraph.room_nodes.corridor_like`) and how many rooms it joins; then how
many rooms are named right, per true type.

    .venv/bin/python tools/room_types.py LOG [LOG ...] [--rooms]
"""

from __future__ import annotations

import argparse
import collections
import sys

import numpy as np

from sgtool.house.spec import room_at
from sgtool.log.reader import LogReader
from sgtool.replayers.derived_log import replay
from sgtool.scenegraph.builder_config import BuilderConfig
from sgtool.scenegraph.room_nodes import corridor_like


def room_rows(log: str) -> list[dict[str, object]]:
    """One row per explored room of ``log``'s final replayed graph (module doc)."""
    with LogReader(log) as r:
        spec = r.house_spec()
    if spec is None:
        raise SystemExit(f"room_types: {log} has no house spec: nothing to compare with")
    kind = {x.id: x.category for x in spec.rooms}
    rep = replay(log, None)
    if rep.last is None or rep.last.layers is None:
        return []
    layers, graph = rep.last.layers, rep.last.graph
    vg, cfg = layers.voronoi, BuilderConfig()
    rows: list[dict[str, object]] = []
    for room in graph.rooms:
        if not room.explored:
            continue
        nodes = np.asarray([i for i, rid in enumerate(layers.node_rooms) if rid == room.id],
                           dtype=np.int64)
        truth = collections.Counter(room_at(spec, *vg.positions[i]) for i in nodes)
        where = truth.most_common(1)[0][0] if truth else None
        true = kind.get(where) if where is not None else None
        rows.append({"log": log, "room": room.id, "true": true, "named": room.category,
                     "narrow": bool(len(nodes)) and corridor_like(vg, nodes, cfg),
                     "joins": len(room.neighbours)})
    return rows


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("logs", nargs="+")
    ap.add_argument("--rooms", action="store_true", help="print every room too")
    args = ap.parse_args(argv)
    rows = [row for log in args.logs for row in room_rows(log)]
    if args.rooms:
        for r in rows:
            print(f"{r['log']} {r['room']}: true {r['true']}, named {r['named']}, "
                  f"narrow {r['narrow']}, joins {r['joins']}")
    right = sum(r["true"] == r["named"] for r in rows)
    print(f"rooms named right: {right} of {len(rows)}")
    by_type: dict[str, collections.Counter[str]] = collections.defaultdict(collections.Counter)
    for r in rows:
        by_type[str(r["true"])][str(r["named"])] += 1
    for true, named in sorted(by_type.items(), key=lambda kv: -sum(kv[1].values())):
        n = sum(named.values())
        top = ", ".join(f"{k} {v}" for k, v in named.most_common(3))
        print(f"  {true}: {named[true]} of {n} ({top})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
