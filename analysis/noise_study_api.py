"""The noise study as Python calls: what `sgtool study noise` does without its closed-loop
part.

:func:`noise_study_config` builds a :class:`~sgtool.analysis.noise_study.StudyConfig` from
plain values (generated houses by count and first seed, house files, noise factors and
their levels, whole profiles, the recording's camera and frame rate);
:func:`run_noise_study` records every (house, noise setting) once into a cache folder
(PyBullet: ``sgtool[sim]``), replays each log and scores its final scene graph against
the house; :func:`write_noise_study_outputs` writes the command's tables and plots. A
second run with the same cache records nothing: a log is keyed by the house, the noise
and the recording settings. The closed-loop runs under noise (``--closed-loop``) stay the
command's.
"""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence
from pathlib import Path

from sgtool.analysis.noise_study import (
    DEFAULT_LEVELS,
    DEFAULT_PROFILES,
    RecordingSettings,
    StudyConfig,
    StudyResult,
    conditions_of,
    run_study,
)
from sgtool.arg_checks import of_type, whole
from sgtool.errors import SgtoolError
from sgtool.extras import require


def noise_study_config(houses: int = 4, *, house_seed: int = 0,
                       house_files: str | os.PathLike[str]
                       | Sequence[str | os.PathLike[str]] = (),
                       rooms: tuple[int, int] = (8, 8),
                       factors: Mapping[str, Sequence[float]] | None = None,
                       profiles: str | Sequence[str] | None = None,
                       camera: tuple[int, int] = (160, 120), fps: float = 4.0,
                       frames: int | None = None, noise_seed: int = 0) -> StudyConfig:
    """A study of ``houses`` generated houses (seeds ``house_seed``, +1, ...; ``rooms``
    (MIN, MAX) rooms each) and the ``house_files`` after them (one path or several), under
    no noise, each factor of ``factors`` at each of its levels (name -> levels, names of
    :data:`~sgtool.analysis.noise_study.FACTORS`; None or empty: the command's default
    levels) and each whole profile of ``profiles`` (None: ``mild`` and ``strong`` unless
    factors are given); recorded at ``camera`` (width, height) and ``fps``, ``frames`` at
    most (None: the whole scripted tour). Every value is checked here: a one-line
    :class:`SgtoolError` names the parameter."""
    from sgtool.analysis.bench_houses import generated_houses, load_house_files

    _count("houses", houses, 0)
    _count("house_seed", house_seed, 0)
    _count("noise_seed", noise_seed, 0)
    lo, hi = _pair("rooms", rooms, 1)
    from sgtool.datasets.generator import MAX_ROOMS

    if not 4 <= lo <= hi <= MAX_ROOMS:
        raise SgtoolError(f"rooms={rooms!r}: need 4 <= MIN <= MAX <= {MAX_ROOMS}")
    width, height = _pair("camera", camera, 16)
    if isinstance(fps, bool) or not isinstance(fps, (int, float)):
        raise SgtoolError(f"fps={fps!r}: a number of frames per second")
    if frames is not None:
        _count("frames", frames, 1)
    try:
        conditions = conditions_of(_levels(factors), _profiles(profiles, factors))
    except SgtoolError as e:  # the command's words: --profile 'x' -> profiles: 'x'
        raise SgtoolError(str(e).replace("--profile ", "profiles: ")) from None
    settings = RecordingSettings(width, height, float(fps), frames, noise_seed)
    try:
        settings.check()
    except SgtoolError as e:  # the command's words: --fps 999 -> fps=999
        raise SgtoolError(str(e).replace("--fps ", "fps=")) from None
    if house_files is None:
        house_files = ()
    elif isinstance(house_files, (str, os.PathLike)):
        house_files = (house_files,)
    elif not isinstance(house_files, Sequence):
        raise SgtoolError(f"house_files={house_files!r}: a path or a list of paths")
    files = [str(p) for p in house_files]
    gen = generated_houses(houses, house_seed)
    given = load_house_files(files, taken=[h.id for h in gen]) if files else ()
    cfg = StudyConfig(gen + tuple(given), conditions, (lo, hi), settings)
    cfg.check()
    return cfg


def _count(name: str, value: object, least: int) -> int:
    """``value`` as a whole number >= ``least``, else one line naming ``name``."""
    return int(whole(name, value, least))  # type: ignore[arg-type]


def _pair(name: str, value: object, least: int) -> tuple[int, int]:
    """``value`` as two whole numbers >= ``least`` (a tuple or list), else one line."""
    if isinstance(value, (str, bytes)) or not isinstance(value, Sequence) or len(value) != 2:
        raise SgtoolError(f"{name}={value!r}: give two whole numbers, e.g. ({least}, {least})")
    a, b = value
    return _count(name, a, least), _count(name, b, least)


def _levels(factors: Mapping[str, Sequence[float]] | None) -> dict[str, tuple[float, ...]]:
    """The factors' levels, each checked as ``--factor`` checks it (a known factor, numbers
    the profile accepts); None or empty: the default levels."""
    from sgtool.analysis.noise_study import FACTORS, parse_factor

    if not factors:
        return dict(DEFAULT_LEVELS)
    if not isinstance(factors, Mapping):
        raise SgtoolError(f"factors={factors!r}: a mapping of factor name -> levels")
    out: dict[str, tuple[float, ...]] = {}
    for name, levels in factors.items():
        if name not in FACTORS:
            raise SgtoolError(f"factors: {name!r} is not a noise factor (one of "
                              f"{', '.join(FACTORS)})")
        if isinstance(levels, (str, bytes)) or not isinstance(levels, Sequence) or not levels \
                or not all(isinstance(v, (int, float)) and not isinstance(v, bool)
                           for v in levels):
            raise SgtoolError(f"factors[{name!r}]: a list of numbers, got {levels!r}")
        try:
            out[name] = parse_factor(f"{name}=" + ",".join(repr(float(v)) for v in levels))[1]
        except SgtoolError as e:
            raise SgtoolError(f"factors[{name!r}]: " + str(e).partition(": ")[2]) from None
    return out


def _profiles(profiles: str | Sequence[str] | None,
              factors: Mapping[str, Sequence[float]] | None) -> tuple[str, ...]:
    """The whole profiles studied (None: the defaults unless factors are given)."""
    if profiles is None:
        return () if factors else DEFAULT_PROFILES
    if isinstance(profiles, str):
        return (profiles,)
    if not isinstance(profiles, Sequence) or not all(isinstance(p, str) for p in profiles):
        raise SgtoolError(f"profiles={profiles!r}: a profile name or a list of them")
    return tuple(profiles)


def run_noise_study(config: StudyConfig, cache: str | os.PathLike[str], *,
                    workers: int = 1, progress: bool = False) -> StudyResult:
    """Record (into ``cache``, or take from it) and score every (house, noise setting) of
    ``config`` with ``workers`` local processes; the cells in house x condition order."""
    from sgtool.analysis.executor import make_executor

    of_type("config", config, StudyConfig, "a StudyConfig")
    if config.closed_loop.planners:
        raise SgtoolError("run_noise_study: the closed-loop part is `sgtool study noise "
                          "--closed-loop`'s; leave config.closed_loop.planners empty")
    if isinstance(workers, bool) or not isinstance(workers, int) or workers < 1:
        raise SgtoolError(f"workers={workers!r}: a count, >= 1")
    root = Path(cache)
    if root.exists() and not root.is_dir():
        raise SgtoolError(f"cache={str(root)!r}: is a file, not a folder")
    require("pybullet", api="sgtool.run_noise_study")
    return run_study(config, root, make_executor("local", workers, None), progress=progress)


def write_noise_study_outputs(result: StudyResult,
                              folder: str | os.PathLike[str]) -> list[Path]:
    """summary.md, results.json, results.csv and plots/ (one figure per factor) into
    ``folder`` (made if missing), each file written whole."""
    from sgtool.analysis.noise_study_plots import plot_study
    from sgtool.analysis.noise_study_tables import results_csv, results_json, summary_md
    from sgtool.files import atomic_write, output_dir

    out = output_dir(folder)
    paths = [atomic_write(out / "summary.md", summary_md(result)),
             atomic_write(out / "results.json", results_json(result)),
             atomic_write(out / "results.csv", results_csv(result))]
    return paths + list(plot_study(result, out / "plots"))
