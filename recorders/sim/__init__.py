"""The PyBullet house simulation and its recording (``sgtool record``).

Modules, one job each:

- :mod:`~sgtool.recorders.sim.camera`: camera config, mounting, OpenGL matrices, depth
  from the depth buffer, instance ids from the segmentation mask (pure functions);
- :mod:`~sgtool.recorders.sim.body_instances`: the instance table (ids in spec order);
- :mod:`~sgtool.recorders.sim.articulation`: hinged door panels of doors and containers;
- :mod:`~sgtool.recorders.sim.build`: the house as PyBullet bodies;
- :mod:`~sgtool.recorders.sim.navigation`: occupancy in the current door states, goals,
  smoothed A* paths, per-frame poses;
- :mod:`~sgtool.recorders.sim.simulation`: :class:`Simulation` (render, skills, observers);
- :mod:`~sgtool.recorders.sim.explore`: the scripted whole-house exploration;
- :mod:`~sgtool.recorders.sim.noise`: seeded sensor faults;
- :mod:`~sgtool.recorders.sim.recording`: :class:`LogRecorder` and :func:`record_house`;
- :mod:`~sgtool.recorders.sim.live_skills`: the robot's skills on its own map and the
  :class:`RobotBody` guard (no house on the robot side); :mod:`.execution` runs an action's
  skill calls live or on the ground truth;
- :mod:`~sgtool.recorders.sim.frontier_explore`: frontier exploration on the robot's map
  (``sgtool record --explore frontier``), scored by :mod:`.coverage`;
- :mod:`~sgtool.recorders.sim.closed_loop`: a planner searching the house on the scene
  graph built live (``sgtool run``): :func:`run_closed_loop` (``closed_loop.run_episode``),
  :func:`plan_skills` (planner actions to skills).

Importing this package does not import PyBullet; building a :class:`Simulation` does.
"""

from __future__ import annotations

from sgtool.recorders.sim.body_instances import Instance, instance_table
from sgtool.recorders.sim.camera import CameraConfig
from sgtool.recorders.sim.closed_loop import (
    ClosedLoopOptions,
    ClosedLoopReport,
    SkillCall,
    SkillPlan,
    pick_episode,
    plan_skills,
)
from sgtool.recorders.sim.closed_loop import run_episode as run_closed_loop
from sgtool.recorders.sim.explore import ExplorationReport, ScriptOptions, explore_house
from sgtool.recorders.sim.navigation import RobotConfig
from sgtool.recorders.sim.noise import PROFILES, NoiseProfile, SensorFaults, parse_noise
from sgtool.recorders.sim.recording import (
    LogRecorder,
    RecordOptions,
    RecordReport,
    record_house,
)
from sgtool.recorders.sim.simulation import (
    SimObserver,
    Simulation,
    SkillOutcome,
    StopSimulation,
)

__all__ = [
    "PROFILES",
    "CameraConfig",
    "ClosedLoopOptions",
    "ClosedLoopReport",
    "ExplorationReport",
    "Instance",
    "LogRecorder",
    "NoiseProfile",
    "RecordOptions",
    "RecordReport",
    "RobotConfig",
    "ScriptOptions",
    "SensorFaults",
    "SimObserver",
    "Simulation",
    "SkillCall",
    "SkillOutcome",
    "SkillPlan",
    "StopSimulation",
    "explore_house",
    "instance_table",
    "parse_noise",
    "pick_episode",
    "plan_skills",
    "record_house",
    "run_closed_loop",
]
