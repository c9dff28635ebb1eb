"""Executors side by side (issue 19): the same `sgtool bench` on local -w 1, local -w 2 and Ray
(2 CPUs), a batch replay of many logs, and Ray's fixed start-up cost.

    .venv/bin/python benchmarks/ray_scale.py bench [--repeat 3] [--houses 4 --episodes 5 ...]
    .venv/bin/python benchmarks/ray_scale.py replay LOG_DIR [--repeat 1]
    .venv/bin/python benchmarks/ray_scale.py startup [--repeat 3]

Each command runs as a subprocess; its CPU time is the sum over the process tree (the
command, pool workers, Ray's raylet, GCS and workers), sampled every 0.1 s with psutil, so
a process's last 0.1 s may be missed (the harness's in-process timing cannot see the tree).
Runs of one repeat are interleaved, the order reversed every other repeat
(:func:`harness.round_order`), so a load that changes over time hits every variant alike;
medians are printed. `bench` then compares the outputs byte for byte (wall-clock fields
aside), `replay` compares every derived log with a one-by-one `sgtool replay LOG -o`. Every
command takes ``--json PATH`` (the figures as JSON).
"""

from __future__ import annotations

import argparse
import json
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

import psutil
from harness import add_output_options, emit, round_order, timed

SGTOOL = str(Path(sys.executable).with_name("sgtool"))
VARIANTS = {"local -w 1": ["--executor", "local", "-w", "1"],
            "local -w 2": ["--executor", "local", "-w", "2"],
            "ray (2 CPUs)": ["--executor", "ray", "-w", "2"]}


def measured(cmd: list[str]) -> tuple[float, float, str]:
    """(wall s, CPU s of the process tree, stdout) of ``cmd``."""
    t0 = time.perf_counter()
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    root = psutil.Process(proc.pid)
    cpu: dict[tuple[int, float], float] = {}
    while proc.poll() is None:
        try:
            tree = [root, *root.children(recursive=True)]
        except psutil.Error:
            tree = []
        for p in tree:
            try:
                t = p.cpu_times()
                cpu[p.pid, p.create_time()] = t.user + t.system
            except psutil.Error:
                pass
        time.sleep(0.1)
    out, err = proc.communicate()
    if proc.returncode != 0:
        sys.exit(f"{' '.join(cmd)} failed ({proc.returncode}): {err.strip()[-500:]}")
    return time.perf_counter() - t0, sum(cpu.values()), out


def _without_wall(path: Path) -> str:
    if path.name == "episodes.jsonl":
        rows = [json.loads(line) for line in path.read_text().splitlines()]
        for r in rows:
            r.pop("wall")
        return json.dumps(rows, sort_keys=True)
    if path.name == "summary.json":
        d = json.loads(path.read_text())
        d.pop("wall")
        for row in d["planners"].values():
            row.pop("decision_s")  # timed per decision: wall clock
        return json.dumps(d, sort_keys=True)
    return path.read_text()


def bench(a: argparse.Namespace) -> None:
    args = ["bench", "--houses", str(a.houses), "--episodes", str(a.episodes), "--seeds",
            str(a.seeds), "--planners", a.planners, "--no-progress"]
    n_eps = a.houses * a.episodes * a.seeds * len(a.planners.split(","))
    work = Path(tempfile.mkdtemp(prefix="ray-scale-"))
    figures: dict[str, list[tuple[float, float]]] = {k: [] for k in VARIANTS}
    for rep in range(a.repeat):
        for name in round_order(list(VARIANTS), rep):
            extra = VARIANTS[name]
            out = work / f"{rep}-{name.split()[0]}{extra[-1]}"
            wall, cpu, _ = measured([SGTOOL, *args, *extra, "-o", str(out)])
            figures[name].append((wall, cpu))
            print(f"repeat {rep}: {name}: {wall:.1f} s wall, {cpu:.1f} CPU-s", flush=True)
    print(f"\n`sgtool {' '.join(args)}`: {n_eps} episodes per run, {a.repeat} repeat(s)")
    base = statistics.median(c for _, c in figures["local -w 1"])
    print("| executor | wall s (median) | CPU-s (median) | CPU-s per episode | CPU vs -w 1 |")
    print("|---|---|---|---|---|")
    table: dict[str, dict[str, Any]] = {}
    for name, runs in figures.items():
        wall = statistics.median(w for w, _ in runs)
        cpu = statistics.median(c for _, c in runs)
        print(f"| {name} | {wall:.1f} | {cpu:.1f} | {cpu / n_eps:.3f} | {cpu / base:.2f} |")
        table[name] = {"wall_s": wall, "cpu_s": cpu, "cpu_s_per_episode": cpu / n_eps,
                       "cpu_vs_w1": cpu / base,
                       "runs": [{"wall_s": w, "cpu_s": c} for w, c in runs]}
    ref = work / "0-local1"
    identical: dict[str, bool] = {}
    for out in sorted(work.iterdir()):
        same = []
        for f in sorted(ref.iterdir()):
            if f.name in ("run.md", "run.json"):  # wall clock and the command, on purpose
                continue
            if f.name in ("summary.md", "summary.json"):
                same.append((f.name + " (bytes)", f.read_bytes() == (out / f.name).read_bytes()))
            elif f.suffix in (".md", ".json", ".jsonl"):
                same.append((f.name, _without_wall(f) == _without_wall(out / f.name)))
        print(f"{out.name} vs {ref.name}: " + ", ".join(
            f"{n} {'identical' if s else 'DIFFERS'}" for n, s in same)
            + " (episodes.jsonl without its wall-clock fields)")
        identical[out.name] = all(s for _, s in same)
    shutil.rmtree(work)
    emit({"command": ["sgtool", *args], "episodes_per_run": n_eps, "executors": table,
          "identical_to_local1": identical}, a.json_out)


def replay(a: argparse.Namespace) -> None:
    logs = sorted(Path(a.log_dir).glob("*.mcap"))
    work = Path(tempfile.mkdtemp(prefix="ray-scale-replay-"))
    one = work / "one"
    one.mkdir()

    def one_by_one() -> None:
        for p in logs:
            subprocess.run([SGTOOL, "replay", str(p), "-o", str(one / p.name), "--no-progress"],
                           check=True, capture_output=True)

    _, took = timed(one_by_one)
    print(f"one by one: {len(logs)} logs in {took.wall_s:.1f} s "
          "(one process each)", flush=True)
    runs: list[dict[str, Any]] = []
    for rep in range(a.repeat):
        for name in round_order(list(VARIANTS), rep):
            extra = VARIANTS[name]
            out = work / f"{rep}-{name.split()[0]}{extra[-1]}"
            wall, cpu, text = measured([SGTOOL, "replay", str(a.log_dir), "--out-dir", str(out),
                                        "--no-progress", *extra])
            same = all((out / p.name).read_bytes() == (one / p.name).read_bytes()
                       for p in logs)
            print(f"repeat {rep}: {name}: {len(logs)} logs, {wall:.1f} s wall "
                  f"({len(logs) / wall * 60:.1f} logs/minute), {cpu:.1f} CPU-s; "
                  f"{'all byte-identical' if same else 'OUTPUTS DIFFER'} to one-by-one; "
                  f"{text.splitlines()[-1]}", flush=True)
            runs.append({"repeat": rep, "executor": name, "wall_s": wall, "cpu_s": cpu,
                         "logs_per_minute": len(logs) / wall * 60, "identical": same})
    shutil.rmtree(work)
    emit({"logs": len(logs), "one_by_one_wall_s": took.wall_s, "runs": runs}, a.json_out)


STARTUP = """
import os, time
os.environ.setdefault("RAY_USAGE_STATS_ENABLED", "0")
t0 = time.perf_counter()
import ray
t1 = time.perf_counter()
ray.init(address="local", num_cpus=2, include_dashboard=False, log_to_driver=False,
         configure_logging=False)
t2 = time.perf_counter()
ray.get(ray.remote(lambda: 1).remote())
t3 = time.perf_counter()
ray.shutdown()
print(t1 - t0, t2 - t1, t3 - t2, time.perf_counter() - t3)
"""


def startup(a: argparse.Namespace) -> None:
    runs = []
    for _ in range(a.repeat):
        wall, cpu, out = measured([sys.executable, "-c", STARTUP])
        runs.append([*map(float, out.split()), wall, cpu])
    names = ["import ray", "ray.init", "first task", "shutdown", "whole process", "CPU-s"]
    print("Ray fixed cost, local instance of 2 CPUs (medians of "
          f"{a.repeat}): " + ", ".join(f"{n} {statistics.median(r[i] for r in runs):.2f} s"
                                        for i, n in enumerate(names)))
    emit({"repeat": a.repeat, "medians_s": {n: statistics.median(r[i] for r in runs)
                                            for i, n in enumerate(names)},
          "runs": [dict(zip(names, r, strict=True)) for r in runs]}, a.json_out)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = ap.add_subparsers(dest="what", required=True)
    b = sub.add_parser("bench")
    b.add_argument("--houses", type=int, default=4)
    b.add_argument("--episodes", type=int, default=5)
    b.add_argument("--seeds", type=int, default=2)
    b.add_argument("--planners", default="random,greedy,scout")
    b.add_argument("--repeat", type=int, default=3)
    r = sub.add_parser("replay")
    r.add_argument("log_dir")
    r.add_argument("--repeat", type=int, default=1)
    s = sub.add_parser("startup")
    s.add_argument("--repeat", type=int, default=3)
    for sp in (b, r, s):
        add_output_options(sp)
    a = ap.parse_args()
    {"bench": bench, "replay": replay, "startup": startup}[a.what](a)


if __name__ == "__main__":
    main()
