"""The symbolic object-search benchmark: SCOUT's SymSearch roll-out over generated houses.

SCOUT (sec. V) evaluates high-level search decisions on scene graphs without a simulator.
This package turns a :class:`~sgtool.house.spec.HouseSpec` into that environment:

- :mod:`~sgtool.recorders.symbolic_environment.furniture_regions`: a room's regions, its furniture
  clustered by k-means with k chosen by BIC (X-means);
- :mod:`~sgtool.recorders.symbolic_environment.house`: :class:`SymbolicHouse`, the house
  prepared once (regions, places, travel distances for any door states);
- :mod:`~sgtool.recorders.symbolic_environment.environment`: :class:`SymbolicEnv`, one
  episode's rules (start, what each action reveals, invalid and failed actions, the end);
- :mod:`~sgtool.recorders.symbolic_environment.observation`: :class:`ObservedGraph`, the
  episode's observed scene graph, updated with what each step changed (not rebuilt);
- :mod:`~sgtool.recorders.symbolic_environment.rollout`: :func:`run_episode`, one episode
  with a planner through :func:`sgtool.planning.episode.run_search`, optionally logged;
  :func:`run_one`, the same for a script: any house spec, a planner or its name, a query.
"""

from sgtool.recorders.symbolic_environment.environment import N_MAX, StepOutcome, SymbolicEnv
from sgtool.recorders.symbolic_environment.furniture_regions import (
    MAX_REGIONS,
    MIN_REGION_STD,
    cluster_regions,
)
from sgtool.recorders.symbolic_environment.house import Region, SymbolicHouse
from sgtool.recorders.symbolic_environment.observation import ObservedGraph
from sgtool.recorders.symbolic_environment.rollout import (
    EpisodeLog,
    RunOneError,
    planner_seed,
    run_episode,
    run_one,
)

__all__ = [
    "MAX_REGIONS",
    "MIN_REGION_STD",
    "N_MAX",
    "EpisodeLog",
    "ObservedGraph",
    "Region",
    "RunOneError",
    "StepOutcome",
    "SymbolicEnv",
    "SymbolicHouse",
    "cluster_regions",
    "planner_seed",
    "run_episode",
    "run_one",
]
