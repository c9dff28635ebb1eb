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
from sgtool.errors import SgtoolError
from sgtool.extras import require


def noise_study_config(houses: int = 4, *, house_seed: int = 0,
                       house_files: Sequence[str | os.PathLike[str]] = (),
                       rooms: tuple[int, int] = (8, 8),
                       factors: Mapping[str, Sequence[float]] | None = None,
                       profiles: Sequence[str] | None = None,
                       camera: tuple[int, int] = (160, 120), fps: float = 4.0,
                       frames: int | None = None, noise_seed: int = 0) -> StudyConfig:
    """A study of ``houses`` generated houses (seeds ``house_seed``, +1, ...; ``rooms``
    (MIN, MAX) rooms each) and the ``house_files`` after them, under no noise, each
    factor of ``factors`` at each of its levels (name -> levels, names of
    :data:`~sgtool.analysis.noise_study.FACTORS`; None: the command's default levels) and
    each whole profile of ``profiles`` (None: ``mild`` and ``strong`` unless factors are
    given); recorded at ``camera`` (width, height) and ``fps``, ``frames`` at most (None:
    the whole scripted tour). Checked: a one-line :class:`SgtoolError` names what cannot
    work."""
    from sgtool.analysis.bench_houses import generated_houses, load_house_files
    from sgtool.analysis.noise_study import FACTORS

    if isinstance(houses, bool) or not isinstance(houses, int) or houses < 0:
        raise SgtoolError(f"houses={houses!r}: a count, >= 0")
    chosen = dict(DEFAULT_LEVELS) if factors is None else dict(factors)
    unknown = sorted(set(chosen) - set(FACTORS))
    if unknown:
        raise SgtoolError(f"factors: {unknown[0]!r} is not a noise factor (one of "
                          f"{', '.join(FACTORS)})")
    for name, levels in chosen.items():
        if isinstance(levels, (str, bytes)) or not all(
                isinstance(v, (int, float)) and not isinstance(v, bool) and v >= 0
                for v in levels):
            raise SgtoolError(f"factors[{name!r}]: a list of levels >= 0, got {levels!r}")
    if profiles is None:
        profiles = () if factors else DEFAULT_PROFILES
    if isinstance(profiles, str):
        profiles = (profiles,)
    conditions = conditions_of(chosen, tuple(profiles))
    settings = RecordingSettings(int(camera[0]), int(camera[1]), float(fps), frames,
                                 noise_seed)
    settings.check()
    gen = generated_houses(houses, house_seed)
    files = [str(p) for p in house_files]
    given = load_house_files(files, taken=[h.id for h in gen]) if files else ()
    cfg = StudyConfig(gen + tuple(given), conditions, (int(rooms[0]), int(rooms[1])),
                      settings)
    cfg.check()
    return cfg


def run_noise_study(config: StudyConfig, cache: str | os.PathLike[str], *,
                    workers: int = 1, progress: bool = False) -> StudyResult:
    """Record (into ``cache``, or take from it) and score every (house, noise setting) of
    ``config`` with ``workers`` local processes; the cells in house x condition order."""
    from sgtool.analysis.executor import make_executor

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
