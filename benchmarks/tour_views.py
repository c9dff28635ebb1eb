"""What the scripted tour's further look-arounds cost, and the weighing's bound.

1. Generated houses recorded by the scripted tour with the further look-arounds off
   (``ScriptOptions(views=0)``) and on (the default), in alternating rounds: frames,
   actions, the rooms looked at again, and the CPU seconds of each recording (medians).
2. :func:`~sgtool.recorders.sim.room_views.best_view` against weighing every place on
   random walled rooms: whether the answers agree, and the CPU seconds of each.

    .venv/bin/python benchmarks/tour_views.py --seeds 0,101,102,107 --rooms 4-12
    .venv/bin/python benchmarks/tour_views.py --seeds 107 --random-rooms 12 --json out.json
"""

from __future__ import annotations

import argparse
import tempfile
from functools import partial
from pathlib import Path

import numpy as np
from harness import add_output_options, alternate, emit, timed

from sgtool.datasets.generator import generate_house
from sgtool.recorders.sim import CameraConfig, RecordOptions, ScriptOptions, record_house
from sgtool.recorders.sim.recording import RecordReport
from sgtool.recorders.sim.room_views import best_view, places, visible


def _tours(seeds: list[int], rooms: tuple[int, int], size: tuple[int, int], rounds: int,
           tmp: Path) -> dict[str, object]:
    out: dict[str, object] = {}
    for seed in seeds:
        house = generate_house(seed, rooms=rooms)
        reports: dict[int, RecordReport] = {}

        def case(views: int, house=house, reports=reports) -> None:  # noqa: ANN001
            opts = RecordOptions(camera=CameraConfig(width=size[0], height=size[1]),
                                 script=ScriptOptions(views=views))
            reports[views] = record_house(house, tmp / f"v{views}.mcap", opts)

        timing = alternate({"off": lambda: case(0), "on": lambda: case(3)}, rounds)
        off, on = reports[0], reports[3]
        cpu = [timing["off"].cpu_s, timing["on"].cpu_s]
        out[str(seed)] = {"rooms": len(house.rooms), "frames": [off.frames, on.frames],
                          "actions": [off.actions, on.actions],
                          "looked_again": list(on.looked_again), "cpu_s": cpu}
        print(f"house {seed} ({len(house.rooms)} rooms): frames {off.frames} -> {on.frames}, "
              f"actions {off.actions} -> {on.actions}, looked again "
              f"{list(on.looked_again) or '-'}, CPU s {cpu[0]:.1f} -> {cpu[1]:.1f}")
    return out


def _plain_best(blocked: np.ndarray, floor: np.ndarray, seen: np.ndarray,
                cands: list[tuple[float, float]], reach: float) -> tuple[object, int]:
    todo = floor & ~seen
    gains = [int(np.count_nonzero(visible(blocked, (0.0, 0.0), 0.05, p, reach) & todo))
             for p in cands]
    i = int(np.argmax(gains))
    return cands[i], gains[i]


def _bound(n_rooms: int) -> dict[str, object]:
    rng = np.random.default_rng(0)
    agree, plain_s, bound_s = 0, 0.0, 0.0
    for _ in range(n_rooms):
        n = int(rng.integers(60, 200))
        blocked = np.zeros((n, n), bool)
        blocked[[0, -1], :] = blocked[:, [0, -1]] = True
        for _ in range(int(rng.integers(1, 6))):
            r0, c0 = rng.integers(0, n, 2)
            h, w = rng.integers(1, n // 2, 2)
            if rng.random() < 0.5:
                blocked[r0:r0 + h, c0:c0 + 2] = True
            else:
                blocked[r0:r0 + 2, c0:c0 + w] = True
        reach = float(rng.uniform(1.0, 4.5))
        cands = places(~blocked, (0.0, 0.0), 0.05, 0.5)
        seen = visible(blocked, (0.0, 0.0), 0.05, cands[0], reach)
        a, ta = timed(partial(_plain_best, blocked, ~blocked, seen, cands, reach))
        b, tb = timed(partial(best_view, blocked, (0.0, 0.0), 0.05, ~blocked, seen, cands,
                              reach))
        agree += int((a[0], a[1]) == (b[0], b[1]) if b is not None else False)
        plain_s += ta.cpu_s
        bound_s += tb.cpu_s
    print(f"best_view on {n_rooms} random rooms: {agree} answers agree; CPU s "
          f"{plain_s:.2f} weighing all, {bound_s:.2f} with the bound "
          f"({plain_s / max(bound_s, 1e-9):.1f}x)")
    return {"rooms": n_rooms, "agree": agree, "plain_cpu_s": plain_s, "bound_cpu_s": bound_s}


def main() -> None:
    ap = add_output_options(argparse.ArgumentParser(description=__doc__.splitlines()[0]))
    ap.add_argument("--seeds", default="0,101,102,107", help="house seeds, comma-separated")
    ap.add_argument("--rooms", default="4-12", help="room range MIN-MAX of the houses")
    ap.add_argument("--resolution", default="64x48", help="camera WIDTHxHEIGHT")
    ap.add_argument("--rounds", type=int, default=2, help="alternating rounds per house")
    ap.add_argument("--random-rooms", type=int, default=12,
                    help="random rooms of the best_view check (0: none)")
    a = ap.parse_args()
    lo, hi = (int(v) for v in a.rooms.split("-"))
    w, h = (int(v) for v in a.resolution.split("x"))
    with tempfile.TemporaryDirectory() as tmp:
        tours = _tours([int(s) for s in a.seeds.split(",")], (lo, hi), (w, h), a.rounds,
                       Path(tmp))
    bound = _bound(a.random_rooms) if a.random_rooms > 0 else None
    emit({"tours": tours, "best_view": bound}, a.json_out)


if __name__ == "__main__":
    main()
