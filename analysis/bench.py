"""The symbolic benchmark run: houses x episodes x seeds x planners -> records, table, curves.

Protocol (SCOUT sec. VI, Table VII; MoMa-LLM's AUC-E):

- houses ``generate_house(house_seed + i, rooms=rooms, split="eval")`` for i < ``houses``:
  furnished from the evaluation part of the knowledge only (``rooms`` defaults to
  :data:`DEFAULT_ROOMS`, chosen for scene size, see there);
- per house, ``episodes`` search episodes from :func:`sgtool.datasets.episodes.list_episodes`
  (seeded by the house seed, so the episode set is the same for every bench seed);
- per bench seed (0 .. ``seeds`` - 1): the start region of every episode and the planner's
  own seed are drawn from (seed, house seed, episode index)
  (:class:`sgtool.recorders.symbolic_environment.SymbolicEnv`,
  :func:`~sgtool.recorders.symbolic_environment.planner_seed`);
- every planner runs every (seed, house, episode) with at most ``max_steps`` actions;
- a query is "unseen" when it is one of :func:`sgtool.datasets.split.unseen_queries` (it
  occurs nowhere in the knowledge the planners were trained on), "seen" otherwise.

Outputs (in ``out_dir``): ``episodes.jsonl`` (one :class:`EpisodeResult` per line, ordered
by planner, seed, house, episode), ``summary.md`` (Table VII-shaped table, seen/unseen
table, AUC-E budgets, settings, digest), ``summary.json``, and the efficiency curves
``efficiency_distance.png`` and ``efficiency_steps.png``. Every file is written to a temp
file and renamed. Records are identical between runs except their ``wall`` figures; the
digest in the summary leaves those out.

``--workers N`` runs (house, planner) tasks in a process pool (spawned processes, each
keeping its last houses and its planners); results are put back in the fixed order, so the
output does not depend on N.
"""

from __future__ import annotations

import json
import math
import os
import sys
import time
from collections import OrderedDict
from collections.abc import Mapping, Sequence
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

from sgtool import __version__
from sgtool.analysis.metrics import CostModel, cost_models, seen_unseen, summarize
from sgtool.analysis.report import format_seen_unseen, format_table, summary_dict
from sgtool.canonical import strict_json
from sgtool.errors import SgtoolError
from sgtool.files import atomic_write
from sgtool.results import EpisodeResult, results_digest, write_jsonl

DEFAULT_PLANNERS: tuple[str, ...] = (
    "random", "greedy", "sbert-noroom", "sbert", "scout-noroom", "scout-delta0", "scout",
)
BENCH_VERSION = "1.0"
# Room-count range of the benchmark houses. 12-16 rooms give ~48 furniture pieces (the
# first-level objects) per house, the closest the generator comes to SymSearch's InteriorGS
# scenes (SCOUT Table I: 52.4 object instances per scene); with the generator's default
# 4-12 (~33 pieces) every planner, random included, reaches SR ~0.99 within N_max = 50
# (measured), so SR no longer separates planners.
DEFAULT_ROOMS: tuple[int, int] = (12, 16)


class BenchError(SgtoolError):
    """A benchmark option that cannot work (unknown planner, bad range, missing transcript)."""


@dataclass(frozen=True)
class BenchConfig:
    planners: tuple[str, ...] = DEFAULT_PLANNERS
    houses: int = 10
    episodes: int = 20  # per house
    seeds: int = 5
    rooms: tuple[int, int] = DEFAULT_ROOMS
    house_seed: int = 0  # first house seed
    max_steps: int = 50  # SymSearch's N_max
    workers: int = 1
    distance_budget: float = 5000.0  # MoMa-LLM low-level budget (0.1 m steps + 30 per open)
    step_budget: float = 50.0  # MoMa-LLM high-level budget
    planner_options: Mapping[str, Mapping[str, Any]] = field(default_factory=dict)
    log_dir: str | None = None  # also record every episode as an MCAP log here

    def check(self) -> None:
        from sgtool.planning.registry import PLANNER_NAMES

        if not self.planners:
            raise BenchError("--planners: name at least one planner")
        for p in self.planners:
            if p not in PLANNER_NAMES:
                raise BenchError(f"--planners: unknown planner {p!r}; choose from "
                                 f"{', '.join(PLANNER_NAMES)}")
        if len(set(self.planners)) != len(self.planners):
            raise BenchError("--planners: a planner is named twice")
        for name, value in (("--houses", self.houses), ("--episodes", self.episodes),
                            ("--seeds", self.seeds), ("--max-steps", self.max_steps),
                            ("--workers", self.workers)):
            if value < 1:
                raise BenchError(f"{name}: must be >= 1, got {value}")
        if self.house_seed < 0:
            raise BenchError(f"--house-seed: must be >= 0, got {self.house_seed}")
        lo, hi = self.rooms
        if not 4 <= lo <= hi <= 16:
            raise BenchError(f"--rooms: need 4 <= MIN <= MAX <= 16, got {lo}-{hi}")
        if "moma-llm" in self.planners:
            opts = self.planner_options.get("moma-llm", {})
            replay = opts.get("replay")
            if replay is not None and not Path(replay).is_file():
                raise BenchError(f"--llm-replay: no such transcript {replay}")
            if opts.get("transcript") and self.workers > 1:
                raise BenchError("--llm-transcript needs --workers 1 (one file, one writer)")

    def models(self) -> tuple[CostModel, CostModel]:
        return cost_models(self.distance_budget, self.step_budget)

    def settings(self) -> dict[str, Any]:
        d = asdict(self)
        d["planners"] = list(self.planners)
        d["rooms"] = list(self.rooms)
        d["planner_options"] = {k: {kk: str(vv) for kk, vv in v.items()}
                                for k, v in sorted(self.planner_options.items())}
        d.pop("workers")  # does not change the results
        d.pop("log_dir")
        return d


@dataclass(frozen=True)
class BenchResult:
    config: BenchConfig
    results: tuple[EpisodeResult, ...]
    throughput: dict[str, float]  # planner -> episodes per second of one core (wall-clock)
    table: str
    seen_table: str
    digest: str
    wall_s: float


# ----------------------------------------------------------------------------------------
# one worker task: one house, one planner, every seed and episode
# ----------------------------------------------------------------------------------------
_HOUSES: OrderedDict[tuple[int, tuple[int, int]], Any] = OrderedDict()
_PLANNERS: dict[tuple[str, str], Any] = {}


def _house(seed: int, rooms: tuple[int, int], episodes: int) -> tuple[Any, list[Any]]:
    from sgtool.datasets.episodes import list_episodes
    from sgtool.datasets.generator import generate_house
    from sgtool.recorders.symbolic_environment.house import SymbolicHouse

    key = (seed, rooms)
    hit = _HOUSES.get(key)
    if hit is not None and len(hit[1]) >= episodes:
        _HOUSES.move_to_end(key)
        return hit[0], hit[1][:episodes]
    spec = generate_house(seed, rooms=rooms, split="eval")
    entry = (SymbolicHouse(spec), list_episodes(spec, episodes, seed=seed))
    _HOUSES[key] = entry
    while len(_HOUSES) > 3:
        _HOUSES.popitem(last=False)
    return entry


def _planner(name: str, options: Mapping[str, Any]) -> Any:
    from sgtool.planning.registry import make_planner

    key = (name, json.dumps({k: str(v) for k, v in sorted(options.items())}))
    p = _PLANNERS.get(key)
    if p is None:
        p = make_planner(name, **dict(options))
        _PLANNERS[key] = p
    return p


def _unseen() -> frozenset[str]:
    from sgtool.datasets.split import unseen_queries
    from sgtool.semantics.text import category_text

    return frozenset(category_text(q) for q in unseen_queries())


def _task(args: tuple[BenchConfig, int, str]) -> list[EpisodeResult]:
    from sgtool.recorders.symbolic_environment.rollout import run_episode
    from sgtool.semantics.text import category_text

    cfg, house_i, name = args
    house_seed = cfg.house_seed + house_i
    house, episodes = _house(house_seed, cfg.rooms, cfg.episodes)
    planner = _planner(name, cfg.planner_options.get(name, {}))
    unseen = _unseen()
    out = []
    for seed in range(cfg.seeds):
        for i, ep in enumerate(episodes):
            kw = dict(seed=seed, episode_index=i, avoid_rooms=ep.target_rooms,
                      max_steps=cfg.max_steps, seen=category_text(ep.query) not in unseen,
                      house_id=f"house-{house_seed}", planner_name=name)
            if cfg.log_dir is None:
                out.append(run_episode(house, planner, ep.query, ep.targets, **kw))
                continue
            from sgtool.log.writer import LogWriter

            path = Path(cfg.log_dir) / name / f"house-{house_seed}" / f"seed{seed}-ep{i}.mcap"
            path.parent.mkdir(parents=True, exist_ok=True)
            with LogWriter(path, seed=seed) as log:
                out.append(run_episode(house, planner, ep.query, ep.targets, log=log, **kw))
    return out


# ----------------------------------------------------------------------------------------
# the run
# ----------------------------------------------------------------------------------------
def run_benchmark(cfg: BenchConfig, progress: bool | None = None) -> BenchResult:
    """Run every planner on every episode (module doc); nothing is written."""
    cfg.check()
    tasks = [(cfg, h, p) for h in range(cfg.houses) for p in cfg.planners]
    show = sys.stderr.isatty() if progress is None else progress
    t0 = time.perf_counter()
    chunks: list[list[EpisodeResult]] = []
    try:
        from tqdm import tqdm
    except ImportError:  # pragma: no cover - tqdm is a dependency
        tqdm = None  # type: ignore[assignment]
    bar = tqdm(total=len(tasks), desc="bench", unit="task", disable=not show,
               file=sys.stderr) if tqdm else None
    if cfg.workers == 1:
        for t in tasks:
            chunks.append(_task(t))
            if bar:
                bar.update(1)
    else:
        import multiprocessing as mp
        from concurrent.futures import ProcessPoolExecutor

        ctx = mp.get_context("spawn")
        with ProcessPoolExecutor(max_workers=cfg.workers, mp_context=ctx) as pool:
            for chunk in pool.map(_task, tasks, chunksize=1):
                chunks.append(chunk)
                if bar:
                    bar.update(1)
    if bar:
        bar.close()
    wall = time.perf_counter() - t0
    order = {p: i for i, p in enumerate(cfg.planners)}
    # through the JSONL form, so the summary is exactly what `sgtool eval` recomputes from
    # episodes.jsonl (figures rounded as written)
    results = sorted((EpisodeResult.from_dict(r.to_dict()) for c in chunks for r in c),
                     key=lambda r: (order[r.planner], r.seed, int(r.house.split("-")[-1]),
                                    r.episode))
    spent: dict[str, float] = {}
    count: dict[str, int] = {}
    for r in results:
        spent[r.planner] = spent.get(r.planner, 0.0) + float(r.wall.get("episode_s", 0.0))
        count[r.planner] = count.get(r.planner, 0) + 1
    throughput = {p: (count[p] / spent[p] if spent.get(p) else math.nan) for p in count}
    models = cfg.models()
    sums = summarize(results, models, planners=cfg.planners)
    title = (f"Symbolic benchmark (SymSearch roll-out): {cfg.houses} houses x {cfg.episodes} "
             f"episodes x {cfg.seeds} seeds, N_max = {cfg.max_steps}, rooms "
             f"{cfg.rooms[0]}-{cfg.rooms[1]}")
    table = format_table(sums, throughput=throughput, models=models, title=title)
    seen_table = format_seen_unseen(seen_unseen(results, cfg.planners),
                                    title="Seen vs unseen queries (SCOUT Table IX), "
                                          "episodes pooled over seeds")
    return BenchResult(cfg, tuple(results), throughput, table, seen_table,
                       results_digest(results), wall)


def priors_fingerprint() -> str:
    """SHA-256 (first 16 hex digits) of the shipped relational-prior weights the sbert/scout
    planners load, so a table can be traced to the priors that produced it."""
    import hashlib

    from sgtool.semantics.priors import WEIGHTS_DIR

    h = hashlib.sha256()
    for p in sorted(Path(WEIGHTS_DIR).glob("*")):
        if p.is_file() and (p.suffix == ".safetensors" or p.name == "metadata.json"):
            h.update(p.name.encode())
            h.update(p.read_bytes())
    return h.hexdigest()[:16]


def write_outputs(res: BenchResult, out_dir: str | os.PathLike[str],
                  command: str = "") -> list[Path]:
    """episodes.jsonl, summary.md, summary.json and the two efficiency PNGs."""
    from sgtool.analysis.curves import plot_efficiency

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    cfg = res.config
    paths = [write_jsonl(res.results, out / "episodes.jsonl")]
    by_planner = [(p, [r for r in res.results if r.planner == p]) for p in cfg.planners]
    for model in cfg.models():
        paths.append(plot_efficiency(by_planner, model, out / f"efficiency_{model.name}.png"))
    md = [res.table, res.seen_table,
          f"Episodes per second: one core, episode roll-outs only (house preparation "
          f"excluded); whole run {res.wall_s:.1f} s with {cfg.workers} worker(s).",
          f"Digest of episodes.jsonl without wall-clock fields: {res.digest}",
          f"sgtool {__version__}; relational priors {priors_fingerprint()}"]
    if command:
        md.append(f"Command: `{command}`")
    paths.append(atomic_write(out / "summary.md", "\n".join(md) + "\n"))
    summary = {
        "version": BENCH_VERSION,
        "settings": cfg.settings(),
        "budgets": {m.name: {"max": m.max_cost, "cost": m.label} for m in cfg.models()},
        "planners": summary_dict(summarize(res.results, cfg.models(), cfg.planners)),
        "seen_unseen": [asdict(s) for s in seen_unseen(res.results, cfg.planners)],
        "digest": res.digest,
        "sgtool_version": __version__,
        "priors_sha256_16": priors_fingerprint(),
        "wall": {"seconds": round(res.wall_s, 3), "workers": cfg.workers,
                 "episodes_per_s": {k: round(v, 3) for k, v in res.throughput.items()}},
    }
    paths.append(atomic_write(
        out / "summary.json",
        json.dumps(strict_json(summary), indent=1, sort_keys=True, allow_nan=False) + "\n"))
    return paths


def run_bench(planners: Sequence[str] = DEFAULT_PLANNERS, houses: int = 10, episodes: int = 20,
              seeds: int = 5, workers: int = 1, out_dir: str | os.PathLike[str] | None = None,
              rooms: tuple[int, int] = DEFAULT_ROOMS, max_steps: int = 50, house_seed: int = 0,
              planner_options: Mapping[str, Mapping[str, Any]] | None = None,
              progress: bool | None = None) -> str:
    """Run the benchmark and return its table text (Table VII shape, then Table IX);
    with ``out_dir``, also write the outputs there (see :func:`write_outputs`)."""
    cfg = BenchConfig(planners=tuple(planners), houses=houses, episodes=episodes, seeds=seeds,
                      rooms=(int(rooms[0]), int(rooms[1])), house_seed=house_seed,
                      max_steps=max_steps, workers=workers,
                      planner_options=dict(planner_options or {}))
    res = run_benchmark(cfg, progress=progress)
    if out_dir is not None:
        write_outputs(res, out_dir)
    return res.table + "\n" + res.seen_table
