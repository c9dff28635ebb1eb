"""The perception-noise study (``sgtool study noise``): scene-graph quality against sensor
noise, one fault at a time and as whole profiles.

A study crosses houses with *conditions*. A condition is one noise setting in the syntax of
``sgtool record --noise`` (:func:`sgtool.recorders.sim.noise.parse_noise`):

- ``none`` (the noise-free baseline, level 0 of every factor);
- a factor at a level: one field of :class:`~sgtool.recorders.sim.noise.NoiseProfile`
  (:data:`FACTORS`) set to that level, every other fault off (``none,holes=0.01``);
- a profile (``mild``, ``strong``) as it is.

Each (house, noise) pair is one :class:`StudyTask`: record the scripted exploration of the
house with that noise (:func:`sgtool.recorders.sim.record_house`, what ``sgtool record``
runs), or reuse the log of the cache folder recorded with the same key (:func:`cache_key`:
the house, the noise, its seed and the recording settings; the recorder's output depends on
those only), then replay it and score the final graph against the house (what ``sgtool
replay --score`` runs). Conditions sharing a noise setting (``none`` for every factor)
share the task. Tasks are independent and deterministic, so they run on any executor
(:mod:`sgtool.analysis.executor`) with the same results, in task order.

The scores of a cell are :class:`~sgtool.scenegraph.quality.Quality` figures, ``merged``
(rooms joined by doorless passages count as one) and ``strict``, plus the room count
error against every true room (``rooms - gt_rooms``; the quality's own error counts only
the true rooms the Voronoi graph covers, so a graph collapsed to one room scores 0 there).
Tables and plots: :mod:`sgtool.analysis.noise_study_tables`,
:mod:`sgtool.analysis.noise_study_plots`.
"""

from __future__ import annotations

import hashlib
import json
import math
from collections.abc import Mapping, Sequence
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from sgtool.analysis.bench_houses import BenchHouse
from sgtool.errors import SgtoolError
from sgtool.files import atomic_write

if TYPE_CHECKING:
    from sgtool.analysis.closed_loop_bench import ClosedLoopBenchResult

# the factors of the study: the noise profile's fields, in the order tables list them
FACTORS: tuple[str, ...] = ("depth_sigma", "holes", "label_swap", "label_dropout",
                            "drift_xy", "drift_yaw", "flying")
FACTOR_UNITS: Mapping[str, str] = {
    "depth_sigma": "m of std at 1 m", "holes": "share of depth pixels",
    "label_swap": "per object and frame", "label_dropout": "per object and frame",
    "drift_xy": "m of std after 1 m", "drift_yaw": "rad of std after 1 m or 1 rad",
    "flying": "share of depth-edge pixels",
}
# levels of each factor when none are chosen: mild's and strong's values, and the
# label-fault levels of the issue that found the one-room collapse
DEFAULT_LEVELS: Mapping[str, tuple[float, ...]] = {
    "depth_sigma": (0.0015, 0.006),
    "holes": (0.01, 0.08),
    "label_swap": (0.01, 0.05),
    "label_dropout": (0.01, 0.05, 0.1),
    "drift_xy": (0.0018, 0.007),
    "drift_yaw": (0.0027, 0.011),
    "flying": (0.1, 0.5),
}
DEFAULT_PROFILES: tuple[str, ...] = ("mild", "strong")
NONE = "none"
PROFILE = "profile"  # the factor name of a whole-profile condition
# bump when what a cached log holds changes: 2 since the scripted tour's further
# look-arounds (6aa451c) and walls blocking by exact distance (7983b7e); 3 since pose
# drift is a random walk in the distance (not in the frames); 4 since a drifted log holds
# the true base pose, by which its map is aligned before it is scored
CACHE_FORMAT = 4


def level_text(value: float) -> str:
    """The canonical text of a level (``repr`` of the float: ``1e-3`` -> ``0.001``), used in
    noise settings, cache keys and tables."""
    return repr(float(value))


def parse_factor(text: str) -> tuple[str, tuple[float, ...]]:
    """``NAME=L1,L2,...`` (``--factor``) -> (name, levels in the order given, duplicates
    dropped); one line naming the problem otherwise (an unknown factor, a level that is not
    a number, negative, not finite, or above 1 for a probability)."""
    from dataclasses import replace

    from sgtool.recorders.sim.noise import PROFILES

    name, eq, rest = text.partition("=")
    name = name.strip()
    if not eq:
        raise SgtoolError(f"--factor {text!r}: give NAME=L1,L2,... (factors: "
                          f"{', '.join(FACTORS)})")
    if name not in FACTORS:
        raise SgtoolError(f"--factor {text!r}: unknown factor {name!r} (one of "
                          f"{', '.join(FACTORS)})")
    levels: list[float] = []
    for part in rest.split(","):
        p = part.strip()
        try:
            v = float(p)
        except ValueError:
            raise SgtoolError(f"--factor {text!r}: level {p!r} is not a number") from None
        kw: dict[str, Any] = {name: v}
        try:
            replace(PROFILES[NONE], name="", **kw)  # its checks: >= 0, finite, <= 1
        except SgtoolError as e:
            why = str(e).split(": ", 1)[-1]  # (the profile's message names --noise)
            raise SgtoolError(f"--factor {text!r}: level {p}: {why}") from None
        if v not in levels:
            levels.append(v)
    return name, tuple(levels)


@dataclass(frozen=True)
class Condition:
    """One noise setting of the study: ``factor`` is a :data:`FACTORS` name, ``profile``
    or ``none``; ``level`` the factor's level as text (:func:`level_text`), the profile's
    name, or ``0``; ``noise`` the ``--noise`` text it records with."""

    factor: str
    level: str
    noise: str

    @property
    def value(self) -> float | None:
        """The level as a number (0 for ``none``; None for a profile)."""
        if self.factor == PROFILE:
            return None
        return float(self.level)


def conditions_of(factors: Mapping[str, Sequence[float]],
                  profiles: Sequence[str]) -> tuple[Condition, ...]:
    """``none`` first, then each factor's levels (factors in :data:`FACTORS` order, levels
    ascending; a level 0 is ``none``), then the profiles as given."""
    from sgtool.recorders.sim.noise import PROFILES, names_file, parse_noise

    out = [Condition(NONE, "0", NONE)]
    for f in FACTORS:
        for v in sorted(set(factors.get(f, ()))):
            if v != 0:
                out.append(Condition(f, level_text(v), f"none,{f}={level_text(v)}"))
    for p in profiles:
        if p not in PROFILES and not names_file(p):
            raise SgtoolError(f"--profile {p!r}: unknown profile (one of "
                              f"{', '.join(PROFILES)}, or a JSON profile's file)")
        label = p if p in PROFILES else parse_noise(p).name  # a file: its profile's name
        same = next((c for c in out if c.factor == PROFILE and c.level == label), None)
        if same is not None and same.noise != p and \
                parse_noise(same.noise).to_dict() != parse_noise(p).to_dict():
            raise SgtoolError(f"--profile {p}: named {label!r} as {same.noise} is, with other "
                              "faults; give each profile a name of its own")
        if p != NONE and all(c.noise != p and c.level != label for c in out):
            out.append(Condition(PROFILE, label, p))
    return tuple(out)


@dataclass(frozen=True)
class RecordingSettings:
    """What a recording depends on besides the house and the noise."""

    width: int = 160
    height: int = 120
    fps: float = 4.0
    frames: int | None = None  # None: until the scripted exploration ends
    noise_seed: int = 0

    def check(self) -> None:
        from sgtool.recorders.sim.camera import SIDE_RANGE
        from sgtool.recorders.sim.simulation import FPS_RANGE

        lo, hi = SIDE_RANGE  # the camera's own rule, as record's
        if not (lo <= self.width <= hi and lo <= self.height <= hi):
            raise SgtoolError(f"--resolution {self.width}x{self.height}: each side {lo}..{hi} "
                              "pixels")

        if not (math.isfinite(self.fps) and FPS_RANGE[0] <= self.fps <= FPS_RANGE[1]):
            raise SgtoolError(f"--fps {self.fps}: must be {FPS_RANGE[0]:g}..{FPS_RANGE[1]:g}")
        if self.frames is not None and self.frames < 1:
            raise SgtoolError(f"--frames {self.frames}: must be >= 1")


@dataclass(frozen=True)
class StudyTask:
    """Record (or reuse) one house's log under one noise setting, replay it and score it.
    ``spec_text`` is the house spec as JSON (a worker needs nothing else)."""

    house: str
    noise: str
    spec_text: str
    settings: RecordingSettings
    log: str  # the cached log's path
    key_json: str = ""  # what the log is recorded from, written beside it as KEY.json


@dataclass(frozen=True)
class CellScores:
    """What a task returns: the log's frame count, whether it was recorded now, and the
    figures of the final graph (``merged`` and ``strict``: field -> value, as
    :class:`~sgtool.scenegraph.quality.Quality`, plus ``room_error_vs_true``)."""

    frames: int
    recorded: bool
    merged: Mapping[str, float | int]
    strict: Mapping[str, float | int]


def house_key(house: BenchHouse, spec_text: str, rooms: tuple[int, int]) -> dict[str, Any]:
    """The house part of a cache key: seed and room range of a generated house, the spec's
    sha256 for a given one."""
    if house.seed is not None and house.spec is None:
        return {"generated": house.seed, "rooms": list(rooms)}
    return {"spec_sha256": hashlib.sha256(spec_text.encode()).hexdigest()}


def noise_key(noise: str) -> dict[str, Any]:
    """The noise part of a cache key: the faults as they are (a JSON profile's file by
    what it holds, so an edited file records anew; a profile's name by its values, so a
    preset changed by a new sgtool does too) and how drift accrues."""
    from sgtool.recorders.sim.noise import parse_noise

    profile = parse_noise(noise)
    return {**profile.to_dict(), "drift_model": profile.drift_model}


def cache_key(house: Mapping[str, Any], noise: str, settings: RecordingSettings) -> str:
    """The hex sha256 (first 20 digits) of everything a recording depends on."""
    doc = {"format": CACHE_FORMAT, "house": dict(house), "noise": noise_key(noise),
           "settings": asdict(settings)}
    text = json.dumps(doc, sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(text.encode()).hexdigest()[:20]


def record_task_log(task: StudyTask) -> bool:
    """Record ``task.log`` unless it is there (a log only appears once complete; one that
    no longer opens, cut off or damaged in the cache, is recorded again); True when
    recorded now."""
    out = Path(task.log)
    if out.is_file() and complete_log(out):
        return False
    from sgtool.datasets.start_poses import with_start_poses
    from sgtool.house.io import load_house_text
    from sgtool.log.writer import partial_files
    from sgtool.recorders.sim import CameraConfig, RecordOptions, parse_noise, record_house

    spec = load_house_text(task.spec_text)
    if not spec.starts:
        spec = with_start_poses(spec, spec.seed)
    s = task.settings
    opts = RecordOptions(fps=s.fps, frames=s.frames,
                         camera=CameraConfig(width=s.width, height=s.height),
                         noise=parse_noise(task.noise), seed=s.noise_seed)
    out.parent.mkdir(parents=True, exist_ok=True)
    before = set(partial_files(out))
    try:
        record_house(spec, out, opts, house_id=task.house)
    except KeyboardInterrupt:  # Ctrl-C or a kill: no partial file of ours stays behind
        for p in set(partial_files(out)) - before:
            p.unlink(missing_ok=True)
        raise
    if task.key_json:
        atomic_write(out.with_suffix(".json"), task.key_json)
    return True


def complete_log(log: Path) -> bool:
    """Whether ``log`` is a complete MCAP file: it opens (its start and end magic and
    summary) and every CRC it carries is right (``sgtool doctor``'s "complete")."""
    from sgtool.log import LogReader
    from sgtool.log.recover import scan

    try:
        with LogReader(log):
            pass
        return scan(log).status == "complete"
    except (SgtoolError, OSError):
        return False


def score_log(log: str | Path) -> tuple[int, dict[str, dict[str, float | int]]]:
    """Replay ``log`` (its own options) and score the final graph against the house in it:
    (frames, {"merged": ..., "strict": ...}), the figures of ``sgtool replay --score``."""
    from sgtool.house.io import load_house_text
    from sgtool.log import LogReader
    from sgtool.replayers.derived_log import ReplayOptions, replay
    from sgtool.replayers.score import score, truth_alignment

    with LogReader(Path(log)) as r:
        house = r.house_json()
        align = truth_alignment(r)
    if house is None:
        raise SgtoolError(f"{log}: no house spec attachment; cannot score it")
    final: dict[str, Any] = {}

    def keep(ref: Any, stream: Any) -> None:
        final["refresh"], final["stream"] = ref, stream

    report = replay(log, None, ReplayOptions(), on_refresh=keep)
    if "refresh" not in final or final["refresh"].layers is None:
        raise SgtoolError(f"{log}: the replay produced no scene graph to score")
    spec = load_house_text(house)
    ref, stream = final["refresh"], final["stream"]
    q = score(spec, stream.builder.instances, ref.layers, ref.graph, stream.builder.trajectory,
              align)
    out: dict[str, dict[str, float | int]] = {}
    for name, v in q.items():
        d: dict[str, float | int] = dict(asdict(v))
        d["room_error_vs_true"] = v.rooms - v.gt_rooms
        # a share over nothing is no figure (NaN: "-" in the tables, null in the JSON),
        # not a 0 % that would enter the medians and plots
        if not v.objects:
            d["object_accuracy"] = d["object_ari"] = math.nan
        if not v.rooms:
            d["category_accuracy"] = math.nan
        if not v.gt_rooms_with_nodes:
            d["purity"] = d["ari"] = math.nan
        out[name] = d
    return report.frames, out


def run_task(task: StudyTask) -> CellScores:
    """One task (module doc): record or reuse, replay, score."""
    recorded = record_task_log(task)
    frames, q = score_log(task.log)
    return CellScores(frames, recorded, q["merged"], q["strict"])


@dataclass(frozen=True)
class ClosedLoopSettings:
    """The closed-loop part: ``planners`` (none: skipped) on the first ``houses`` houses
    (0: all), ``episodes`` each, under each of ``noise``, with a frame budget of
    ``frames_per_room`` x the house's rooms."""

    planners: tuple[str, ...] = ()
    noise: tuple[str, ...] = ("none", "mild")
    episodes: int = 3
    houses: int = 0
    frames_per_room: int | None = 60
    max_steps: int = 50


@dataclass(frozen=True)
class StudyConfig:
    """A noise study: ``houses`` (generated or from files), each recorded once per noise
    setting of ``conditions`` (generated ones with ``rooms`` (MIN, MAX) rooms) with the
    recording ``settings``; ``closed_loop``: the closed-loop runs under noise (none by
    default). :func:`sgtool.noise_study_config` builds one from plain values; :meth:`check`
    says in one line what cannot work."""

    houses: tuple[BenchHouse, ...]
    conditions: tuple[Condition, ...]
    rooms: tuple[int, int] = (8, 8)
    settings: RecordingSettings = field(default_factory=RecordingSettings)
    closed_loop: ClosedLoopSettings = field(default_factory=ClosedLoopSettings)

    def check(self) -> None:
        self.settings.check()
        if not self.houses:
            raise SgtoolError("no houses: give --houses N or --house FILE (houses=, house_files=)")
        cl = self.closed_loop
        if cl.planners:
            if cl.episodes < 1:
                raise SgtoolError(f"--episodes {cl.episodes}: must be >= 1")
            if cl.houses < 0:
                raise SgtoolError(f"--closed-loop-houses {cl.houses}: must be >= 0")
            if cl.max_steps < 1:
                raise SgtoolError(f"--max-steps {cl.max_steps}: must be >= 1")


def plan_tasks(cfg: StudyConfig, cache: Path) -> tuple[list[StudyTask], dict[str, str]]:
    """The study's tasks, one per (house, noise setting), houses outer; and the house id
    -> spec JSON text. Logs live in ``cache/HOUSE/KEY.mcap`` beside ``KEY.json`` (the
    key's contents, for whoever looks), both written by the task that records the log."""
    tasks: list[StudyTask] = []
    specs: dict[str, str] = {}
    noises = list(dict.fromkeys(c.noise for c in cfg.conditions))
    for h in cfg.houses:
        text = h.load(cfg.rooms).to_json()
        specs[h.id] = text
        hk = house_key(h, text, cfg.rooms)
        for n in noises:
            key = cache_key(hk, n, cfg.settings)
            doc = {"format": CACHE_FORMAT, "house_id": h.id, "house": hk, "noise": n,
                   "noise_key": noise_key(n),
                   "settings": asdict(cfg.settings)}
            tasks.append(StudyTask(h.id, n, text, cfg.settings,
                                   str(cache / h.id / f"{key}.mcap"),
                                   json.dumps(doc, indent=2, sort_keys=True) + "\n"))
    return tasks, specs


@dataclass(frozen=True)
class Cell:
    """One row of the results: a house under a condition."""

    house: str
    condition: Condition
    frames: int
    merged: Mapping[str, float | int]
    strict: Mapping[str, float | int]


@dataclass(frozen=True)
class StudyResult:
    """What a noise study found: per house and condition a :class:`Cell` (the final
    graph's scores, merged and strict, as ``sgtool replay --score`` gives them), how many
    logs this run recorded, the houses' specs and, when the study ran them, the
    closed-loop runs' result."""

    config: StudyConfig
    cells: tuple[Cell, ...]  # houses outer, conditions in config order
    recorded: int  # logs recorded by this run (the others came from the cache)
    specs: Mapping[str, str] = field(default_factory=dict)  # house id -> spec JSON
    closed_loop: ClosedLoopBenchResult | None = None

    def cell(self, house: str, noise: str) -> Cell | None:
        for c in self.cells:
            if c.house == house and c.condition.noise == noise:
                return c
        return None


def run_study(cfg: StudyConfig, cache: str | Path, executor: Any,
              progress: bool = False) -> StudyResult:
    """Every task on ``executor`` (an :mod:`sgtool.analysis.executor` executor), the cells
    in house x condition order. A task that fails twice stops the study with one line
    naming it (the logs recorded so far stay in the cache)."""
    from sgtool.analysis.executor import Task, failure_lines

    cfg.check()
    root = Path(cache)
    tasks, specs = plan_tasks(cfg, root)
    outcomes = executor.run(run_task, [Task(f"{t.house} {t.noise}", t) for t in tasks],
                            progress=progress, desc="study noise")
    failed = failure_lines(outcomes)
    if failed:
        raise SgtoolError(f"{len(failed)} of {len(tasks)} recording(s) failed; the first: "
                          f"{failed[0]}")
    by_key = {(t.house, t.noise): o.value for t, o in zip(tasks, outcomes, strict=True)}
    cells = []
    for h in cfg.houses:
        for c in cfg.conditions:
            v: CellScores = by_key[(h.id, c.noise)]
            cells.append(Cell(h.id, c, v.frames, v.merged, v.strict))
    recorded = sum(1 for o in outcomes if o.value.recorded)
    return StudyResult(cfg, tuple(cells), recorded, specs)


def run_closed_loop(cfg: StudyConfig, specs: Mapping[str, str], out_dir: Path,
                    runner: Any = map, progress: Any = None) -> Any:
    """The closed-loop part (:class:`ClosedLoopSettings`) with
    :mod:`sgtool.analysis.closed_loop_bench`: the study's houses (their specs written to
    ``out_dir/houses``), the bench's episodes of each, logs in ``out_dir/logs``."""
    from sgtool.analysis.closed_loop_bench import ClosedLoopBenchConfig, run_closed_loop_bench
    from sgtool.recorders.sim import CameraConfig
    from sgtool.recorders.sim.closed_loop import ClosedLoopOptions

    cl = cfg.closed_loop
    houses = [h.id for h in cfg.houses][: cl.houses or None]
    files = []
    for hid in houses:
        files.append(str(atomic_write(out_dir / "houses" / f"{hid}.json", specs[hid])))
    s = cfg.settings
    opts = ClosedLoopOptions(camera=CameraConfig(width=s.width, height=s.height),
                             max_steps=cl.max_steps, noise_seed=s.noise_seed)
    bench = ClosedLoopBenchConfig(planners=cl.planners, houses=0, house_files=tuple(files),
                                  episodes=cl.episodes, rooms=cfg.rooms, noise=cl.noise,
                                  options=opts, frames_per_room=cl.frames_per_room)
    return run_closed_loop_bench(bench, out_dir, progress=progress, runner=runner)
