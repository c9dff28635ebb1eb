"""Why the failed episodes of ``sgtool run-bench`` output folders failed: the planner's
search or the robot's eyes.

For every episode that did not find its target, from the log alone (its house spec, its
instance tables and its frames' instance images, the ground truth an analysis may read):
where the target is (room type, then ``inside``/``ontop`` of what, with the holder's
state), how many frames the robot spent in the target's room, whether the holder was
ever opened, and how many frames showed any pixel of the target (and the most pixels in
one). A target no frame ever showed behind a holder never opened was missed by the search
(the planner never brought the camera to it within its steps); behind a holder that was
opened, by looking in; one that frames showed but the map did not keep, by perception.
Beside it, what the robot's last scene graph named the target's room (the categories of
its room nodes that stand in it; none: the map has no room there): a room named wrongly
sends a prior-based planner elsewhere.

    .venv/bin/python tools/closed_loop_misses.py RUN_DIR [RUN_DIR ...] [--planner P]
"""

from __future__ import annotations

import argparse
import sys
from collections import Counter
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from sgtool.house.spec import room_at
from sgtool.log.reader import LogReader
from sgtool.log.records import InstanceItem, Instances, SceneGraphRecord
from sgtool.results import EpisodeResult, read_jsonl, source_log


@dataclass(frozen=True)
class Miss:
    """One failed episode, seen from the ground truth its log carries."""

    planner: str
    house: str
    episode: int
    query: str
    end: str
    # e.g. "kitchen: inside refrigerator (closed)", "bathroom: inside bathtub (x3)" for
    # three instances there; "" when not in the table
    where: str
    frames: int
    frames_in_room: int  # frames whose base stood in a room holding the target
    holder_opened: bool  # a closed piece holding the target was open in some table
    frames_showing: int  # frames with any pixel of the target
    most_pixels: int
    named: tuple[str, ...] = ()  # categories the last graph gave rooms in the target's room
    named_right: bool = False  # one of them is the target's room type


def _chain(item: InstanceItem, by_id: dict[int, InstanceItem]) -> str:
    """``inside refrigerator (closed) / ...`` from ``item`` up to its first-level piece."""
    parts: list[str] = []
    cur = item
    for _ in range(16):
        parent = by_id.get(cur.parent) if isinstance(cur.parent, int) else None
        if parent is None:
            break
        state = f" ({parent.state})" if isinstance(parent.state, str) else ""
        parts.append(f"{cur.relation} {parent.category}{state}")
        cur = parent
    return " / ".join(parts) or "stands alone"


def miss_of(log: Path, result: EpisodeResult) -> Miss:
    """The :class:`Miss` of the failed episode ``result`` whose log is ``log``."""
    with LogReader(log) as r:
        spec = r.house_spec()
        tables = [t for _, t in r.records(Instances)]
        first = {i.id: i for i in tables[0].instances} if tables else {}
        targets = [i for i in first.values() if i.category == result.query]
        ids = np.array(sorted(i.id for i in targets), dtype=np.int64)
        holders = {i.parent for i in targets if isinstance(i.parent, int)
                   and getattr(first.get(i.parent), "state", None) == "closed"}
        opened = any(i.id in holders and i.state == "open"
                     for t in tables for i in t.instances)
        room_of: dict[str, str] = {}
        if spec is not None:
            room_of = {o.id: o.room for o in spec.objects} | \
                {p.id: p.room for p in spec.furniture}
        categories = {rm.id: rm.category for rm in spec.rooms} if spec is not None else {}
        target_rooms = {room_of.get(str(i.spec_id)) for i in targets} - {None}
        last = None
        for _, g in r.records(SceneGraphRecord):
            last = g
        named: tuple[str, ...] = ()
        if last is not None and spec is not None:
            named = tuple(sorted({rm.category for rm in last.graph().rooms
                                  if room_at(spec, float(rm.position[0]),
                                             float(rm.position[1])) in target_rooms}))
        truth = {categories.get(str(t)) for t in target_rooms}
        n = in_room = showing = most = 0
        for f in r.frames():
            n += 1
            base = f.base_pose
            if spec is not None and base is not None and \
                    room_at(spec, float(base[0, 3]), float(base[1, 3])) in target_rooms:
                in_room += 1
            if f.ids is not None and ids.size:
                k = int(np.isin(f.ids, ids).sum())
                showing += k > 0
                most = max(most, k)
    places = Counter(f"{categories.get(room_of.get(str(i.spec_id), ''), '?')}: "
                     f"{_chain(i, first)}" for i in targets)
    where = "; ".join(p + (f" (x{k})" if k > 1 else "") for p, k in places.items())
    return Miss(result.planner, result.house, result.episode, result.query, result.end,
                where, n, in_room, opened, showing, most, named,
                any(c in truth for c in named))


def misses(folder: Path, planners: Sequence[str] = ()) -> list[Miss]:
    """The failed episodes of a run-bench folder whose logs are there."""
    out = []
    for r in read_jsonl(folder / "episodes.jsonl"):
        if r.success or (planners and r.planner not in planners):
            continue
        log = source_log(r, folder / "episodes.jsonl")
        if log is not None:
            out.append(miss_of(log, r))
    return out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("runs", nargs="+", type=Path, help="run-bench output folders")
    ap.add_argument("--planner", action="append", default=[],
                    help="only this planner's episodes (repeatable)")
    args = ap.parse_args(argv)
    rows: list[Miss] = []
    for run in args.runs:
        if not (run / "episodes.jsonl").is_file():
            print(f"{run}: no episodes.jsonl (not a finished run-bench folder)",
                  file=sys.stderr)
            return 1
        rows += misses(run, args.planner)
    print("| planner | house | ep | query | end | where | its room on the map | frames | "
          "in its room | holder opened | frames showing it | most pixels |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    for m in rows:
        print(f"| {m.planner} | {m.house} | {m.episode} | {m.query} | {m.end} | {m.where} | "
              f"{', '.join(m.named) or 'none'} | "
              f"{m.frames} | {m.frames_in_room} | {'yes' if m.holder_opened else 'no'} | "
              f"{m.frames_showing} | {m.most_pixels} |")
    seen = sum(1 for m in rows if m.frames_showing > 0)
    opened = sum(1 for m in rows if m.frames_showing == 0 and m.holder_opened)
    print(f"\n{len(rows)} failed episodes: the target in no frame's pixels in "
          f"{len(rows) - seen} (its holder never opened in {len(rows) - seen - opened}, "
          f"opened without the camera seeing in, in {opened}); in some frame's pixels in "
          f"{seen} (seen by the camera, not kept by the map); the target's room named "
          f"right on the map in {sum(m.named_right for m in rows)}, wrongly in "
          f"{sum(bool(m.named) and not m.named_right for m in rows)}, no room there in "
          f"{sum(not m.named for m in rows)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
