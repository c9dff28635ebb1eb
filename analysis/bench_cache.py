"""The caches of a bench worker process: the houses it built (with their episodes) and the
planners of the run it works for, so a worker that runs many tasks of one run builds
each once.
"""

from __future__ import annotations

import hashlib
import json
import threading
from collections import OrderedDict
from collections.abc import Mapping
from typing import Any

from sgtool.analysis.bench_houses import BenchHouse, bench_episodes

# a house and its episodes, by everything they depend on: the draw of ``bench_episodes``
# depends on how many episodes are drawn, so N episodes are not the first N of a larger draw
_HOUSES: OrderedDict[tuple[str, str, str, tuple[int, int], str, int], Any] = OrderedDict()
# the planners of the latest runs, by run token (runs in two threads keep their own)
_PLANNERS: OrderedDict[str, dict[tuple[str, str], Any]] = OrderedDict()
_PLANNERS_LOCK = threading.Lock()


def cached_house(ref: BenchHouse, rooms: tuple[int, int], episodes: int,
                 preset: str = "default") -> tuple[Any, list[Any]]:
    """The symbolic house of ``ref`` and its ``episodes`` bench episodes, built once per
    process for the last three houses asked for."""
    from sgtool.recorders.symbolic_environment.house import SymbolicHouse

    # a given house by its content: a file rewritten between two runs of one process is
    # another house
    what = ref.seed if ref.spec is None else hashlib.sha256(
        ref.spec.to_json().encode()).hexdigest()
    key = (ref.id, ref.source, str(what), (int(rooms[0]), int(rooms[1])), preset, episodes)
    hit = _HOUSES.get(key)
    if hit is not None:
        _HOUSES.move_to_end(key)
        return hit
    spec = ref.load(rooms, preset)
    # the preset's episode mix (furniture-level targets) is for generated houses; a given
    # house file is searched for its small objects, as list_episodes lists them
    mix = preset if ref.spec is None else "default"
    house = SymbolicHouse(spec)
    house.prepare()  # its geodesics now, not in the first planner's first (timed) episode
    entry = (house, bench_episodes(spec, episodes, mix))
    _HOUSES[key] = entry
    while len(_HOUSES) > 3:
        _HOUSES.popitem(last=False)
    return entry


def cached_planner(name: str, options: Mapping[str, Any], run: str = "") -> Any:
    """The planner ``make_planner(name, **options)`` builds, built once per run (``run``:
    the run's token; the planners of another run are dropped first, so a plug-in class
    redefined or reloaded between runs, or a plug-in's own state, never carries into the
    next) for each name and options (compared by type and repr) and handed out again
    after; a bad name or option raises as
    :func:`~sgtool.planning.registry.make_planner` does. A plug-in is built afresh at each
    call (each task of a house): what it keeps between episodes stays within the task, so
    its results do not depend on how tasks share workers, nor on a failed attempt."""
    from sgtool.planning.registry import REGISTRY, make_planner

    if name.strip().lower() not in REGISTRY or options.get("replay"):
        # a replaying LLM planner's place in its transcript is state: a retried task
        # must start from the transcript's beginning, as the first attempt did
        return make_planner(name, **dict(options))
    key = (name, json.dumps({k: [type(v).__name__, repr(v)] for k, v in
                             sorted(options.items())}))
    with _PLANNERS_LOCK:
        built = _PLANNERS.setdefault(run, {})
        _PLANNERS.move_to_end(run)
        if len(_PLANNERS) > 2:  # this run and one of another thread
            _PLANNERS.popitem(last=False)
        p = built.get(key)
        if p is None:
            p = make_planner(name, **dict(options))
            built[key] = p
    return p
