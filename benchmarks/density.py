"""Generator presets side by side: density, unseen queries, furniture targets, and the SR of
the symbolic roll-out (the protocol of ``sgtool bench``) on each preset's houses.

Run by hand (not part of the test suite)::

    .venv/bin/python benchmarks/density.py [--houses 10] [--episodes 20] [--seeds 3]
        [--presets default,symsearch] [--planners random,greedy,sbert,scout] [--no-bench]

Per preset: house seeds 0..H-1 (``--rooms``, default the bench's 12-16 for "default" and
the generator's 4-12 for "symsearch", whose rooms are denser), generation ms/house, the
Table I figures, and the episodes: ``list_episodes`` for "default" (as the bench), the
SymSearch mix (:func:`sgtool.datasets.episode_mix.symsearch_episodes`, a third furniture
targets) for "symsearch"; unseen = :func:`sgtool.datasets.split.unseen_queries` (the
bench's proxy). Then every planner runs every (seed, house, episode) with N_max = 50 as
``sgtool bench`` does, and SR is printed overall, for seen / unseen queries and for
furniture / small-object targets.
"""

from __future__ import annotations

import argparse
import statistics
import time

from harness import add_output_options, emit, timed

from sgtool.commands.options import parse_rooms
from sgtool.datasets.episode_mix import symsearch_episodes
from sgtool.datasets.episodes import list_episodes
from sgtool.datasets.generator import generate_house
from sgtool.datasets.scene_stats import house_stats
from sgtool.datasets.split import unseen_queries
from sgtool.planning.registry import make_planner
from sgtool.recorders.symbolic_environment import SymbolicHouse, run_episode
from sgtool.semantics.text import category_text

ROOMS = {"default": (12, 16), "symsearch": (4, 12)}


def _rate(xs: list[bool]) -> str:
    return f"{sum(xs) / len(xs):.3f} (n={len(xs)})" if xs else "n/a"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--houses", type=int, default=10)
    ap.add_argument("--episodes", type=int, default=20)
    ap.add_argument("--seeds", type=int, default=3)
    ap.add_argument("--presets", default="default,symsearch")
    ap.add_argument("--planners", default="random,greedy,sbert,scout")
    ap.add_argument("--rooms", default=None, help="MIN-MAX for every preset")
    ap.add_argument("--no-bench", action="store_true", help="figures only, no roll-outs")
    a = add_output_options(ap).parse_args()
    doc: dict[str, dict] = {}
    unseen = frozenset(category_text(q) for q in unseen_queries())
    planners = {n: make_planner(n) for n in a.planners.split(",") if n}
    for preset in a.presets.split(","):
        rooms = parse_rooms(a.rooms) if a.rooms else ROOMS[preset]
        specs, gen = timed(lambda rooms=rooms, preset=preset: [
            generate_house(s, rooms=rooms, preset=preset) for s in range(a.houses)])
        ms = gen.wall_s / a.houses * 1000
        doc[preset] = {"rooms": list(rooms), "generation": gen, "ms_per_house": ms,
                       "sr": {}}
        st = house_stats(specs)
        eps = {s.seed: (symsearch_episodes(s, a.episodes, seed=s.seed) if preset == "symsearch"
                        else list_episodes(s, a.episodes, seed=s.seed)) for s in specs}
        flat = [e for es in eps.values() for e in es]
        furn = [e.targets[0].startswith("furn_") for e in flat]
        small = [category_text(e.query) in unseen for e, f in zip(flat, furn, strict=True) if not f]
        print(f"\n== preset {preset}: {a.houses} houses, rooms {rooms[0]}-{rooms[1]}, "
              f"{ms:.0f} ms/house")
        print(f"objects/scene {st.objects_per_scene:.1f}, categories/scene "
              f"{st.object_categories_per_scene:.1f}, contained/scene "
              f"{st.contained_per_scene:.1f}, furniture/scene {st.furniture_per_scene:.1f}")
        n_unseen = sum(category_text(e.query) in unseen for e in flat)
        doc[preset]["episodes"] = len(flat)
        doc[preset]["unseen_share"] = n_unseen / len(flat)
        print(f"episodes {len(flat)}: unseen queries {n_unseen / len(flat):.3f} "
              f"(small-object episodes: {sum(small) / max(len(small), 1):.3f}), furniture "
              f"targets {sum(furn) / len(flat):.3f}, hidden "
              f"{sum(e.hidden for e in flat) / len(flat):.3f}")
        if a.no_bench:
            continue
        houses = {s.seed: SymbolicHouse(s) for s in specs}
        for name, planner in planners.items():
            t1 = time.perf_counter()
            rows: list[tuple[bool, bool, bool]] = []  # success, seen, furniture target
            per_seed: list[float] = []
            for seed in range(a.seeds):
                ok = []
                for spec in specs:
                    house = houses[spec.seed]
                    for i, ep in enumerate(eps[spec.seed]):
                        seen = category_text(ep.query) not in unseen
                        r = run_episode(house, planner, ep.query, ep.targets, seed=seed,
                                        episode_index=i, avoid_rooms=ep.target_rooms,
                                        seen=seen, house_id=f"house-{spec.seed}",
                                        planner_name=name)
                        rows.append((r.success, seen, ep.targets[0].startswith("furn_")))
                        ok.append(r.success)
                per_seed.append(sum(ok) / len(ok))
            sd = statistics.pstdev(per_seed) if len(per_seed) > 1 else 0.0
            doc[preset]["sr"][name] = {"per_seed": per_seed, "mean": statistics.mean(per_seed)}
            print(f"  {name:<8} SR {statistics.mean(per_seed):.3f} ± {sd:.3f}  seen "
                  f"{_rate([s for s, se, _ in rows if se])}  unseen "
                  f"{_rate([s for s, se, _ in rows if not se])}  furniture "
                  f"{_rate([s for s, _, f in rows if f])}  small "
                  f"{_rate([s for s, _, f in rows if not f])}  "
                  f"[{time.perf_counter() - t1:.0f} s]", flush=True)
    emit(doc, a.json_out)


if __name__ == "__main__":
    main()
