"""sgtool: language-grounded interactive object search on 3D scene graphs, built around logs.

The public Python API: every name of :data:`__all__` is importable from ``sgtool``
(``from sgtool import replay, SceneGraph``) and documented where it is defined; the guide
is ``docs/api.md``. ``import sgtool`` is light: it imports nothing but the version, and
each name is imported from its module when first used (:pep:`562`), so reading a log does
not load the simulator, the benchmark or the importers. The stage packages these names
come from (``sgtool.recorders``, ``sgtool.analysis``, ...) need their extras installed
only when their names are used (a closed-loop episode needs ``sgtool[sim]``).

=====================  =====================================================================
what                   names
=====================  =====================================================================
logs                   :class:`LogReader`, :class:`LogWriter`, :class:`Frame`,
                       :class:`CameraIntrinsics`, the typed records :class:`EpisodeRecord`,
                       :class:`ActionRecord`, :class:`Instances`, :class:`InstanceItem`,
                       :class:`SceneGraphRecord`, :class:`LlmExchange`, :class:`LogRecord`
replay                 :func:`replay` (a callback per refresh), :class:`ReplayOptions`,
                       :class:`ReplayReport`, :class:`SceneGraphStream`, :class:`Refresh`,
                       :class:`Progress` (what ``progress=`` takes: a tqdm bar)
scene graph            :class:`SceneGraph`, :class:`RoomNode`, :class:`RegionNode`,
                       :class:`ObjectNode`, :class:`DoorNode`, :class:`RobotState`
planners               the :class:`Planner` protocol, :class:`Action`, :class:`Feedback`,
                       :func:`make_planner`, :func:`planner_names`; for writing one:
                       :func:`actionable` (the nodes a planner may act on, as
                       :class:`Candidate` s with skill and distance), :func:`find_target`
houses                 :class:`HouseSpec`, :func:`load_house`, :func:`load_house_text`,
                       :func:`save_house`, :func:`generate_house`, :class:`SearchEpisode`,
                       :func:`list_episodes`
symbolic benchmark     :func:`run_one` (one episode), :class:`SymbolicHouse`,
                       :class:`EpisodeResult`, :class:`BenchConfig`, :func:`run_benchmark`,
                       :class:`BenchResult`, :func:`write_bench_outputs`
closed loop            :func:`run_closed_loop` (one PyBullet episode into a log),
                       :class:`ClosedLoopOptions`, :class:`ClosedLoopReport`,
                       :func:`pick_episode`
metrics                :func:`success_rate`, :func:`spl`, :func:`episode_spl`,
                       :func:`mean_steps`, :func:`mean_decision_time`, :func:`auc_e`,
                       :func:`efficiency_curve`, :class:`CostModel`, :func:`cost_models`,
                       :func:`metrics_of`, :func:`summarize`, :class:`PlannerSummary`,
                       :class:`Stat`, :func:`format_table`, :func:`read_results`,
                       :func:`write_results`
logged decisions       :func:`load_results`, :func:`read_log_episodes`,
                       :class:`LoggedEpisode`, :func:`replay_decisions`,
                       :class:`OfflineReport`, :func:`format_offline`
import and export      :func:`import_rgbd`, :class:`RgbdOptions` (:class:`PinholeParams`
                       from :func:`parse_intrinsics`), :class:`ImportReport`,
                       :func:`export_bag`, :class:`ExportReport`
errors                 :class:`SgtoolError` (every failure a user can cause),
                       :class:`LogFormatError`, :class:`SpecError`
=====================  =====================================================================

A few names differ from their defining module's to stay unambiguous at the top level:
:class:`EpisodeRecord` and :class:`ActionRecord` are ``sgtool.log.records.Episode`` and
``Action`` (the planner's :class:`Action` is another type), :class:`SearchEpisode` is
``sgtool.datasets.episodes.Episode``, :func:`run_closed_loop` is
``sgtool.recorders.sim.closed_loop.run_episode``, :func:`write_bench_outputs` is
``sgtool.analysis.bench.write_outputs``, :func:`read_results`/:func:`write_results` are
``sgtool.results.read_jsonl``/``write_jsonl``.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING

from sgtool.version import __version__ as __version__

if TYPE_CHECKING:  # the real types for mypy and IDEs; at run time __getattr__ imports them
    from sgtool.analysis.bench import BenchConfig, BenchResult, run_benchmark
    from sgtool.analysis.bench import write_outputs as write_bench_outputs
    from sgtool.analysis.metrics import (
        CostModel,
        PlannerSummary,
        Stat,
        auc_e,
        cost_models,
        efficiency_curve,
        episode_spl,
        mean_decision_time,
        mean_steps,
        metrics_of,
        spl,
        success_rate,
        summarize,
    )
    from sgtool.analysis.offline import (
        LoggedEpisode,
        OfflineReport,
        format_offline,
        load_results,
        read_log_episodes,
        replay_decisions,
    )
    from sgtool.analysis.report import format_table
    from sgtool.datasets.episodes import Episode as SearchEpisode
    from sgtool.datasets.episodes import list_episodes
    from sgtool.datasets.generator import generate_house
    from sgtool.errors import LogFormatError, SgtoolError, SpecError
    from sgtool.house.io import load_house, load_house_text, save_house
    from sgtool.house.spec import HouseSpec
    from sgtool.log.frame import CameraIntrinsics, Frame
    from sgtool.log.reader import LogReader
    from sgtool.log.records import Action as ActionRecord
    from sgtool.log.records import Episode as EpisodeRecord
    from sgtool.log.records import (
        InstanceItem,
        Instances,
        LlmExchange,
        LogRecord,
        SceneGraphRecord,
    )
    from sgtool.log.writer import LogWriter
    from sgtool.planning.base import Action, Feedback, Planner
    from sgtool.planning.candidates import Candidate, actionable, find_target
    from sgtool.planning.registry import make_planner
    from sgtool.progress import Progress
    from sgtool.recorders.exporters.bag_export import ExportReport, export_bag
    from sgtool.recorders.importers.rgbd import RgbdOptions, import_rgbd
    from sgtool.recorders.importers.sink import ImportReport
    from sgtool.recorders.importers.textformats import PinholeParams, parse_intrinsics
    from sgtool.recorders.sim.closed_loop import ClosedLoopOptions, pick_episode
    from sgtool.recorders.sim.closed_loop import run_episode as run_closed_loop
    from sgtool.recorders.sim.closed_loop_report import ClosedLoopReport
    from sgtool.recorders.symbolic_environment.house import SymbolicHouse
    from sgtool.recorders.symbolic_environment.rollout import run_one
    from sgtool.replayers.derived_log import ReplayOptions, ReplayReport, replay
    from sgtool.results import EpisodeResult
    from sgtool.results import read_jsonl as read_results
    from sgtool.results import write_jsonl as write_results
    from sgtool.scenegraph.graph import (
        DoorNode,
        ObjectNode,
        RegionNode,
        RobotState,
        RoomNode,
        SceneGraph,
    )
    from sgtool.scenegraph.stream import Refresh, SceneGraphStream

# public name -> "module:attribute" it is imported from on first use
_EXPORTS: dict[str, str] = {
    # errors
    "SgtoolError": "sgtool.errors:SgtoolError",
    "LogFormatError": "sgtool.errors:LogFormatError",
    "SpecError": "sgtool.errors:SpecError",
    # logs and their typed records
    "LogReader": "sgtool.log.reader:LogReader",
    "LogWriter": "sgtool.log.writer:LogWriter",
    "Frame": "sgtool.log.frame:Frame",
    "CameraIntrinsics": "sgtool.log.frame:CameraIntrinsics",
    "LogRecord": "sgtool.log.records:LogRecord",
    "EpisodeRecord": "sgtool.log.records:Episode",
    "ActionRecord": "sgtool.log.records:Action",
    "Instances": "sgtool.log.records:Instances",
    "InstanceItem": "sgtool.log.records:InstanceItem",
    "SceneGraphRecord": "sgtool.log.records:SceneGraphRecord",
    "LlmExchange": "sgtool.log.records:LlmExchange",
    # replay: a log into scene graphs
    "replay": "sgtool.replayers.derived_log:replay",
    "ReplayOptions": "sgtool.replayers.derived_log:ReplayOptions",
    "ReplayReport": "sgtool.replayers.derived_log:ReplayReport",
    "Progress": "sgtool.progress:Progress",
    "SceneGraphStream": "sgtool.scenegraph.stream:SceneGraphStream",
    "Refresh": "sgtool.scenegraph.stream:Refresh",
    # the scene graph
    "SceneGraph": "sgtool.scenegraph.graph:SceneGraph",
    "RoomNode": "sgtool.scenegraph.graph:RoomNode",
    "RegionNode": "sgtool.scenegraph.graph:RegionNode",
    "ObjectNode": "sgtool.scenegraph.graph:ObjectNode",
    "DoorNode": "sgtool.scenegraph.graph:DoorNode",
    "RobotState": "sgtool.scenegraph.graph:RobotState",
    # planners
    "Planner": "sgtool.planning.base:Planner",
    "Action": "sgtool.planning.base:Action",
    "Feedback": "sgtool.planning.base:Feedback",
    "make_planner": "sgtool.planning.registry:make_planner",
    "actionable": "sgtool.planning.candidates:actionable",
    "Candidate": "sgtool.planning.candidates:Candidate",
    "find_target": "sgtool.planning.candidates:find_target",
    # houses and their search episodes
    "HouseSpec": "sgtool.house.spec:HouseSpec",
    "load_house": "sgtool.house.io:load_house",
    "load_house_text": "sgtool.house.io:load_house_text",
    "save_house": "sgtool.house.io:save_house",
    "generate_house": "sgtool.datasets.generator:generate_house",
    "SearchEpisode": "sgtool.datasets.episodes:Episode",
    "list_episodes": "sgtool.datasets.episodes:list_episodes",
    # the symbolic benchmark
    "run_one": "sgtool.recorders.symbolic_environment.rollout:run_one",
    "SymbolicHouse": "sgtool.recorders.symbolic_environment.house:SymbolicHouse",
    "EpisodeResult": "sgtool.results:EpisodeResult",
    "BenchConfig": "sgtool.analysis.bench:BenchConfig",
    "BenchResult": "sgtool.analysis.bench:BenchResult",
    "run_benchmark": "sgtool.analysis.bench:run_benchmark",
    "write_bench_outputs": "sgtool.analysis.bench:write_outputs",
    # the closed loop (PyBullet: sgtool[sim])
    "run_closed_loop": "sgtool.recorders.sim.closed_loop:run_episode",
    "ClosedLoopOptions": "sgtool.recorders.sim.closed_loop:ClosedLoopOptions",
    "ClosedLoopReport": "sgtool.recorders.sim.closed_loop_report:ClosedLoopReport",
    "pick_episode": "sgtool.recorders.sim.closed_loop:pick_episode",
    # metrics
    "success_rate": "sgtool.analysis.metrics:success_rate",
    "spl": "sgtool.analysis.metrics:spl",
    "episode_spl": "sgtool.analysis.metrics:episode_spl",
    "mean_steps": "sgtool.analysis.metrics:mean_steps",
    "mean_decision_time": "sgtool.analysis.metrics:mean_decision_time",
    "auc_e": "sgtool.analysis.metrics:auc_e",
    "efficiency_curve": "sgtool.analysis.metrics:efficiency_curve",
    "CostModel": "sgtool.analysis.metrics:CostModel",
    "cost_models": "sgtool.analysis.metrics:cost_models",
    "metrics_of": "sgtool.analysis.metrics:metrics_of",
    "summarize": "sgtool.analysis.metrics:summarize",
    "PlannerSummary": "sgtool.analysis.metrics:PlannerSummary",
    "Stat": "sgtool.analysis.metrics:Stat",
    "format_table": "sgtool.analysis.report:format_table",
    "read_results": "sgtool.results:read_jsonl",
    "write_results": "sgtool.results:write_jsonl",
    # planners against logged decisions
    "load_results": "sgtool.analysis.offline:load_results",
    "read_log_episodes": "sgtool.analysis.offline:read_log_episodes",
    "LoggedEpisode": "sgtool.analysis.offline:LoggedEpisode",
    "replay_decisions": "sgtool.analysis.offline:replay_decisions",
    "OfflineReport": "sgtool.analysis.offline:OfflineReport",
    "format_offline": "sgtool.analysis.offline:format_offline",
    # import and export
    "import_rgbd": "sgtool.recorders.importers.rgbd:import_rgbd",
    "RgbdOptions": "sgtool.recorders.importers.rgbd:RgbdOptions",
    "PinholeParams": "sgtool.recorders.importers.textformats:PinholeParams",
    "parse_intrinsics": "sgtool.recorders.importers.textformats:parse_intrinsics",
    "ImportReport": "sgtool.recorders.importers.sink:ImportReport",
    "export_bag": "sgtool.recorders.exporters.bag_export:export_bag",
    "ExportReport": "sgtool.recorders.exporters.bag_export:ExportReport",
}

# every public name (the table's and planner_names), spelled out for tools that read
# __all__ without running the module; tests/test_public_api.py keeps it in step
__all__ = [
    "planner_names", "SgtoolError", "LogFormatError", "SpecError", "LogReader", "LogWriter",
    "Frame", "CameraIntrinsics", "LogRecord", "EpisodeRecord", "ActionRecord", "Instances",
    "InstanceItem", "SceneGraphRecord", "LlmExchange", "replay", "ReplayOptions",
    "ReplayReport", "Progress", "SceneGraphStream", "Refresh", "SceneGraph", "RoomNode",
    "RegionNode", "ObjectNode", "DoorNode", "RobotState", "Planner", "Action", "Feedback",
    "make_planner", "actionable", "Candidate", "find_target", "HouseSpec", "load_house",
    "load_house_text", "save_house", "generate_house", "SearchEpisode", "list_episodes",
    "run_one", "SymbolicHouse", "EpisodeResult", "BenchConfig", "BenchResult", "run_benchmark",
    "write_bench_outputs", "run_closed_loop", "ClosedLoopOptions", "ClosedLoopReport",
    "pick_episode", "success_rate", "spl", "episode_spl", "mean_steps", "mean_decision_time",
    "auc_e", "efficiency_curve", "CostModel", "cost_models", "metrics_of", "summarize",
    "PlannerSummary", "Stat", "format_table", "read_results", "write_results", "load_results",
    "read_log_episodes", "LoggedEpisode", "replay_decisions", "OfflineReport", "format_offline",
    "import_rgbd", "RgbdOptions", "PinholeParams", "parse_intrinsics", "ImportReport",
    "export_bag", "ExportReport",
]


def planner_names() -> tuple[str, ...]:
    """The built-in planner names :func:`make_planner` accepts, in the registry's order.
    A name not listed here may still be a planner: a plug-in ``module:Name`` or a name an
    installed package registers (entry-point group ``sgtool.planners``)."""
    from sgtool.planning.registry import PLANNER_NAMES

    return tuple(PLANNER_NAMES)


def __getattr__(name: str) -> object:
    """A public name, imported from its module on first use and kept in the package. A
    name whose stage needs an extra that is not installed raises
    :class:`~sgtool.extras.MissingExtraError` (an :class:`SgtoolError`), one line:
    ``sgtool.run_closed_loop needs PyBullet: pip install 'sgtool[sim]'``."""
    target = _EXPORTS.get(name)
    if target is None:
        raise AttributeError(f"module 'sgtool' has no attribute {name!r}")
    module, _, attribute = target.partition(":")
    try:
        value = getattr(importlib.import_module(module), attribute)
    except ModuleNotFoundError as e:
        from sgtool.extras import missing_extra

        missing = missing_extra(f"sgtool.{name}", e)
        if missing is None:
            raise
        raise missing from None
    globals()[name] = value  # later look-ups skip __getattr__
    return value


def __dir__() -> list[str]:
    """The module's own names and every public name (imported or not)."""
    return sorted({*globals(), *_EXPORTS})
