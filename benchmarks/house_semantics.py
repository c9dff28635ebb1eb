"""How realistic the small objects of generated houses are, judged by the knowledge split
that furnished them (no planner involved).

For every small object of a generated house, the pair (its category ``c``, the type ``T``
of its room) is looked up in the same split's knowledge (``knowledge_for(split)``):

- **stated here**: an activity of the split relates ``c`` ``inside``/``ontop`` the
  object's parent (its synset or a hypernym) with that parent in a room of type ``T``;
- **room evidence**: ``c`` is in ``Knowledge.room_objects[T]``, i.e. a real room of type
  ``T`` holds it, or an activity puts it in a room of type ``T`` (``inroom`` or a relation
  whose parent is in ``T``);
- **other rooms only**: neither; the object can only have been placed through evidence of
  other room types (the parent relation stated elsewhere). Its share is the main figure;
- **atypical**: room evidence exists but ``c`` is rarer in ``T`` than in rooms in general
  (lift < 1, lift = share of ``c`` in ``T``'s evidence / share of ``c`` in all evidence of
  ``room_objects``), e.g. a bowl that one scanned bathroom holds against dozens of kitchen
  statements;
- **tableware** (glasses, cups, mugs, plates, bowls, cutlery, shakers, ...; WordNet
  hypernyms of the synset catalogue) counted in bathrooms and bedrooms.

Printed per split (10 evaluation houses, seeds 0..9, and 10 training houses, seeds
1000..1009, 12-16 rooms by default): the shares above, small objects per house, the share
of small objects per room type, small objects per room of each type, and the most
frequent categories of bathrooms, kitchens and bedrooms.

Usage: ``HF_HUB_OFFLINE=1 .venv/bin/python benchmarks/house_semantics.py [--houses 10]
[--rooms 12-16] [--top 10] [--json PATH]`` (``--json -``: the figures as JSON on stdout
instead of the table)
"""

from __future__ import annotations

import argparse
from collections import Counter, defaultdict

from harness import add_output_options, emit

from sgtool.datasets.generator import generate_house
from sgtool.datasets.knowledge import Knowledge, ancestors, readable_name
from sgtool.datasets.split import knowledge_for

# hypernyms (in bddl's synsets.csv) whose descendants are tableware, and single synsets
TABLEWARE_ROOTS = frozenset({"glass.n.02", "drinking_vessel.n.01", "flatware.n.01",
                             "spoon.n.01", "fork.n.01", "cutlery.n.02", "tableware.n.01"})
TABLEWARE_EXTRA = frozenset({
    "bowl.n.01", "mug.n.04", "coffee_cup.n.01", "teacup.n.02", "dixie_cup.n.01",
    "salt__shaker.n.01", "pepper__shaker.n.01", "table_knife.n.01", "teapot.n.01",
    "pewter_teapot.n.01", "pitcher.n.02", "cream_pitcher.n.02", "gravy_boat.n.01",
    "casserole.n.02", "ramekin.n.01", "chopstick.n.01", "sugar_bowl.n.01",
})
SHOWN_ROOMS = ("bathroom", "kitchen", "bedroom")
EVAL_SEEDS = range(0, 10)
TRAIN_SEEDS = range(1000, 1010)


def is_tableware(synset: str) -> bool:
    return synset in TABLEWARE_EXTRA or bool(ancestors(synset) & TABLEWARE_ROOTS)


class Evidence:
    """Room-type evidence of one knowledge split."""

    def __init__(self, k: Knowledge) -> None:
        self.room = {rt: dict(rows) for rt, rows in k.room_objects.items()}
        self.stated: set[tuple[str, str, str, str]] = {
            (r.child, r.relation, r.parent, r.room_type) for r in k.relations
            if r.room_type is not None}
        per_c: Counter[str] = Counter()
        for rows in self.room.values():
            per_c.update(rows)
        self.per_c = per_c
        self.total = sum(per_c.values())
        self.per_t = {rt: sum(rows.values()) for rt, rows in self.room.items()}

    def lift(self, c: str, t: str) -> float:
        n = self.room.get(t, {}).get(c, 0)
        if not n:
            return 0.0
        return (n / self.per_t[t]) / (self.per_c[c] / self.total)

    def classify(self, c: str, relation: str, parent: str, t: str) -> str:
        if any((c, relation, p, t) in self.stated for p in ancestors(parent)):
            return "stated here"
        if self.room.get(t, {}).get(c, 0):
            return "room evidence"
        return "other rooms only"


def measure(split: str, seeds: range, rooms: tuple[int, int], top: int) -> dict:
    ev = Evidence(knowledge_for(split))
    kinds: Counter[str] = Counter()
    atypical = 0
    per_room: Counter[str] = Counter()
    n_rooms: Counter[str] = Counter()
    cats: dict[str, Counter[str]] = defaultdict(Counter)
    tableware: Counter[str] = Counter()
    n_inside = 0
    n = 0
    for s in seeds:
        h = generate_house(s, rooms=rooms, split=split)
        rt = {r.id: r.category for r in h.rooms}
        n_rooms.update(rt.values())
        furn = h.furniture_by_id()
        for o in h.objects:
            t = rt[o.room]
            n += 1
            n_inside += o.relation == "inside"
            kind = ev.classify(o.synset, o.relation, furn[o.parent].synset, t)
            kinds[kind] += 1
            if kind != "other rooms only" and ev.lift(o.synset, t) < 1.0:
                atypical += 1
            per_room[t] += 1
            cats[t][readable_name(o.synset)] += 1
            if t in ("bathroom", "bedroom") and is_tableware(o.synset):
                tableware[t] += 1
    share = {k: kinds[k] / n if n else 0.0
             for k in ("stated here", "room evidence", "other rooms only")}
    return {
        "split": split, "seeds": [seeds.start, seeds.stop - 1], "rooms": list(rooms),
        "objects": n, "objects_per_house": n / len(seeds),
        "inside_per_house": n_inside / len(seeds),
        "share": share, "share_atypical": atypical / n if n else 0.0,
        "tableware": {t: tableware[t] for t in ("bathroom", "bedroom")},
        "room_share": {t: c / n for t, c in per_room.most_common()},
        "per_room": {t: per_room[t] / c for t, c in n_rooms.most_common()},
        "top": {t: cats[t].most_common(top) for t in SHOWN_ROOMS},
    }


def _print(m: dict) -> None:
    s = m["share"]
    print(f"== {m['split']} houses, seeds {m['seeds'][0]}..{m['seeds'][1]}, "
          f"rooms {m['rooms'][0]}-{m['rooms'][1]}")
    print(f"  small objects: {m['objects']} ({m['objects_per_house']:.1f} per house, "
          f"{m['inside_per_house']:.1f} inside)")
    print(f"  stated for this parent in this room type: {s['stated here']:6.1%}")
    print(f"  room-type evidence only:                  {s['room evidence']:6.1%}")
    print(f"  evidence of OTHER room types only:        {s['other rooms only']:6.1%}")
    print(f"  atypical for the room type (lift < 1):    {m['share_atypical']:6.1%}")
    print(f"  tableware in bathrooms: {m['tableware']['bathroom']}, "
          f"in bedrooms: {m['tableware']['bedroom']}")
    print("  share of small objects per room type: " + ", ".join(
        f"{t} {v:.1%}" for t, v in m["room_share"].items()))
    print("  small objects per room: " + ", ".join(
        f"{t} {v:.1f}" for t, v in m["per_room"].items()))
    for t, rows in m["top"].items():
        print(f"  {t}: " + ", ".join(f"{c} {k}" for c, k in rows))


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--houses", type=int, default=10)
    ap.add_argument("--rooms", default="12-16")
    ap.add_argument("--top", type=int, default=10)
    add_output_options(ap)
    a = ap.parse_args(argv)
    lo, _, hi = a.rooms.partition("-")
    rooms = (int(lo), int(hi or lo))
    out = [measure("eval", range(EVAL_SEEDS.start, EVAL_SEEDS.start + a.houses), rooms, a.top),
           measure("train", range(TRAIN_SEEDS.start, TRAIN_SEEDS.start + a.houses), rooms,
                   a.top)]
    if a.json_out != "-":
        for m in out:
            _print(m)
    emit({"splits": out}, a.json_out)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
