"""Where ``sgtool run-bench`` keeps its episode logs: ``logs/NOISE/PLANNER/HOUSE/ep-K.mcap``
(:func:`log_path`), the noise profile's folder (:func:`noise_folder`) and how a table row
names its log (:func:`log_source`)."""

from __future__ import annotations

import functools
import re
from pathlib import Path

from sgtool.analysis.bench_houses import output_path
from sgtool.recorders.sim.noise import parse_noise


@functools.lru_cache(maxsize=64)
def noise_folder(noise: str) -> str:
    """The log folder of a ``--noise`` profile: its name (a built-in profile's; with
    overrides, one spelling of them, so ``mild, holes=0.050`` is ``mild,holes=0.05``; a
    JSON file's ``name`` field, else the file's stem; the file read once per process, so a
    run's folders and tables keep one name however long it runs)."""
    return parse_noise(noise).name


def log_source(log: Path) -> str:
    """How a row names its log (``logs/NOISE/PLANNER/HOUSE/ep-K.mcap`` of
    :func:`log_path`): relative to the run's folder, which holds ``episodes.jsonl``, so two
    runs (in a staging folder, elsewhere, on another machine) name their logs alike."""
    return Path(*log.parts[-5:]).as_posix()


def log_path(root: Path, noise: str, planner: str, house: str, episode: int) -> Path:
    """``root/NOISE/PLANNER/HOUSE/ep-K.mcap`` (NOISE: :func:`noise_folder`, or the text as
    given when a run made before profiles had one spelling has that folder; a plug-in
    ``module:Name`` as ``module__Name``: :func:`sgtool.planning.registry.planner_file_name`);
    a name that would leave ``root`` (or is no file name) is refused
    (:func:`~sgtool.analysis.bench_houses.output_path`)."""
    from sgtool.planning.registry import planner_file_name

    folder = noise_folder(noise)
    older = re.sub(r"\s*([,=])\s*", r"\1", noise.strip())  # the spelling before one spelling
    if older != folder and not (root / folder).exists() and (root / older).is_dir():
        folder = older  # a run made before: its logs where they are
    return output_path(root, folder, planner_file_name(planner), house, f"ep-{episode:03d}.mcap")
