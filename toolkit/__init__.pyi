"""The public names of ``sgtool`` and their types: one line per name, ``from MODULE import
ATTRIBUTE as NAME``. Type checkers and IDEs read this stub; at run time ``sgtool/__init__.py``
reads the same lines to import each name from its module on first use (:pep:`562`), the
lazy-loading stub pattern of scientific Python (SPEC 1). A new public name is one line here
and one entry of ``__all__``; ``tests/test_public_api.py`` checks both.
"""

# ruff: noqa: I001  (grouped by topic, in the order of __all__ and help(sgtool))

from sgtool.version import __version__ as __version__

# errors
from sgtool.errors import SgtoolError as SgtoolError
from sgtool.errors import LogFormatError as LogFormatError
from sgtool.errors import SpecError as SpecError
from sgtool.analysis.bench_planner_checks import BenchError as BenchError
# logs and their typed records
from sgtool.log.reader import LogReader as LogReader
from sgtool.log.writer import LogWriter as LogWriter
from sgtool.log.frame import Frame as Frame
from sgtool.log.frame import CameraIntrinsics as CameraIntrinsics
from sgtool.log.records import LogRecord as LogRecord
from sgtool.log.records import Episode as EpisodeRecord
from sgtool.log.records import Action as ActionRecord
from sgtool.log.records import Instances as Instances
from sgtool.log.records import InstanceItem as InstanceItem
from sgtool.log.records import SceneGraphRecord as SceneGraphRecord
from sgtool.log.records import LlmExchange as LlmExchange
# replay: a log into scene graphs
from sgtool.replayers.derived_log import replay as replay
from sgtool.replayers.derived_log import ReplayOptions as ReplayOptions
from sgtool.replayers.derived_log import ReplayReport as ReplayReport
from sgtool.analysis.batch_replay import replay_logs as replay_logs
from sgtool.analysis.batch_replay import BatchReport as BatchReport
from sgtool.analysis.batch_replay import LogResult as LogResult
from sgtool.progress import Progress as Progress
from sgtool.scenegraph.stream import SceneGraphStream as SceneGraphStream
from sgtool.scenegraph.stream import Refresh as Refresh
# the scene graph
from sgtool.scenegraph.graph import SceneGraph as SceneGraph
from sgtool.scenegraph.graph import RoomNode as RoomNode
from sgtool.scenegraph.graph import RegionNode as RegionNode
from sgtool.scenegraph.graph import ObjectNode as ObjectNode
from sgtool.scenegraph.graph import DoorNode as DoorNode
from sgtool.scenegraph.graph import RobotState as RobotState
# planners
from sgtool.planning.base import Planner as Planner
from sgtool.planning.base import Action as Action
from sgtool.planning.base import Feedback as Feedback
from sgtool.planning.registry import make_planner as make_planner
from sgtool.planning.candidates import actionable as actionable
from sgtool.planning.candidates import Candidate as Candidate
from sgtool.planning.candidates import find_target as find_target
# houses and their search episodes
from sgtool.house.spec import HouseSpec as HouseSpec
from sgtool.house.io import load_house as load_house
from sgtool.house.io import load_house_text as load_house_text
from sgtool.house.io import save_house as save_house
from sgtool.datasets.generator import generate_house as generate_house
from sgtool.datasets.episodes import Episode as SearchEpisode
from sgtool.datasets.episodes import list_episodes as list_episodes
# the symbolic benchmark
from sgtool.recorders.symbolic_environment.rollout import run_one as run_one
from sgtool.recorders.symbolic_environment.house import SymbolicHouse as SymbolicHouse
from sgtool.results import EpisodeResult as EpisodeResult
from sgtool.analysis.bench import BenchConfig as BenchConfig
from sgtool.analysis.bench import BenchResult as BenchResult
from sgtool.analysis.bench import run_benchmark as run_benchmark
from sgtool.analysis.bench import write_outputs as write_bench_outputs
# the closed loop (PyBullet: sgtool[sim])
from sgtool.recorders.sim.recording import record_house as record_house
from sgtool.recorders.sim.recording import RecordOptions as RecordOptions
from sgtool.recorders.sim.recording import RecordReport as RecordReport
from sgtool.recorders.sim.closed_loop import run_episode as run_closed_loop
from sgtool.recorders.sim.closed_loop import ClosedLoopOptions as ClosedLoopOptions
from sgtool.recorders.sim.camera import CameraConfig as CameraConfig
from sgtool.recorders.sim.closed_loop_report import ClosedLoopReport as ClosedLoopReport
from sgtool.recorders.sim.closed_loop import pick_episode as pick_episode
from sgtool.recorders.sim.noise import NoiseProfile as NoiseProfile
from sgtool.recorders.sim.noise import parse_noise as parse_noise
from sgtool.analysis.closed_loop_bench import ClosedLoopBenchConfig as ClosedLoopBenchConfig
from sgtool.analysis.closed_loop_bench import ClosedLoopBenchResult as ClosedLoopBenchResult
from sgtool.analysis.closed_loop_bench import run_closed_loop_bench as run_closed_loop_bench
from sgtool.analysis.closed_loop_bench import write_outputs as write_closed_loop_bench_outputs
from sgtool.analysis.logged_run import logged_run as logged_run
from sgtool.analysis.logged_run import LoggedRun as LoggedRun
# the noise study (recording: PyBullet, sgtool[sim])
from sgtool.analysis.noise_study import StudyConfig as NoiseStudyConfig
from sgtool.analysis.noise_study import StudyResult as NoiseStudyResult
from sgtool.analysis.noise_study_api import noise_study_config as noise_study_config
from sgtool.analysis.noise_study_api import run_noise_study as run_noise_study
from sgtool.analysis.noise_study_api import write_noise_study_outputs as write_noise_study_outputs
# viewers
from sgtool.analysis.view_run import write_rerun as write_rerun
# metrics
from sgtool.analysis.intervals import Interval as Interval
from sgtool.analysis.intervals import PairedComparison as PairedComparison
from sgtool.analysis.intervals import PlannerIntervals as PlannerIntervals
from sgtool.analysis.intervals import paired_comparison as paired_comparison
from sgtool.analysis.intervals import planner_intervals as planner_intervals
from sgtool.analysis.search_metrics import success_rate as success_rate
from sgtool.analysis.search_metrics import spl as spl
from sgtool.analysis.search_metrics import episode_spl as episode_spl
from sgtool.analysis.search_metrics import mean_steps as mean_steps
from sgtool.analysis.search_metrics import mean_decision_time as mean_decision_time
from sgtool.analysis.search_metrics import auc_e as auc_e
from sgtool.analysis.search_metrics import efficiency_curve as efficiency_curve
from sgtool.analysis.search_metrics import CostModel as CostModel
from sgtool.analysis.search_metrics import cost_models as cost_models
from sgtool.analysis.search_metrics import metrics_of as metrics_of
from sgtool.analysis.search_metrics import summarize as summarize
from sgtool.analysis.search_metrics import PlannerSummary as PlannerSummary
from sgtool.analysis.search_metrics import Stat as Stat
from sgtool.analysis.report import format_table as format_table
from sgtool.results import read_jsonl as read_results
from sgtool.results import write_jsonl as write_results
# planners against logged decisions
from sgtool.analysis.offline import load_results as load_results
from sgtool.analysis.offline import read_log_episodes as read_log_episodes
from sgtool.analysis.offline import LoggedEpisode as LoggedEpisode
from sgtool.analysis.offline import replay_decisions as replay_decisions
from sgtool.analysis.offline import OfflineReport as OfflineReport
from sgtool.analysis.offline import format_offline as format_offline
# import and export
from sgtool.recorders.importers.rgbd import import_rgbd as import_rgbd
from sgtool.recorders.importers.rgbd import RgbdOptions as RgbdOptions
from sgtool.recorders.importers.textformats import PinholeParams as PinholeParams
from sgtool.recorders.importers.textformats import parse_intrinsics as parse_intrinsics
from sgtool.recorders.importers.sink import ImportReport as ImportReport
from sgtool.recorders.exporters.bag_export import export_bag as export_bag
from sgtool.recorders.exporters.bag_export import ExportReport as ExportReport
# golden logs: pin a log's replay, check it after a change, diff two logs
from sgtool.analysis.golden_check import pin_logs as pin_logs
from sgtool.analysis.golden_check import check_pins as check_pins
from sgtool.analysis.golden_check import update_pins as update_pins
from sgtool.analysis.golden_check import CheckReport as CheckReport
from sgtool.analysis.golden_check import LogCheck as LogCheck
from sgtool.analysis.executor import make_executor as make_executor
from sgtool.replayers.golden_pins import read_pins as read_pins
from sgtool.replayers.golden_pins import PinSet as PinSet
from sgtool.replayers.golden_pins import Pinned as Pinned
from sgtool.replayers.golden_diff import diff_logs as diff_logs
from sgtool.replayers.golden_diff import LogDiff as LogDiff
from sgtool.replayers.golden import replay_graphs as replay_graphs
from sgtool.replayers.golden import diff_graphs as diff_graphs
from sgtool.replayers.golden import describe_mismatch as describe_mismatch


def planner_names() -> tuple[str, ...]: ...
def __dir__() -> list[str]: ...

__all__ = [
    "planner_names", "SgtoolError", "LogFormatError", "SpecError", "BenchError", "LogReader",
    "LogWriter",
    "Frame", "CameraIntrinsics", "LogRecord", "EpisodeRecord", "ActionRecord", "Instances",
    "InstanceItem", "SceneGraphRecord", "LlmExchange", "replay", "ReplayOptions",
    "ReplayReport", "replay_logs", "BatchReport", "LogResult", "Progress", "SceneGraphStream",
    "Refresh", "SceneGraph", "RoomNode",
    "RegionNode", "ObjectNode", "DoorNode", "RobotState", "Planner", "Action", "Feedback",
    "make_planner", "actionable", "Candidate", "find_target", "HouseSpec", "load_house",
    "load_house_text", "save_house", "generate_house", "SearchEpisode", "list_episodes",
    "run_one", "SymbolicHouse", "EpisodeResult", "BenchConfig", "BenchResult", "run_benchmark",
    "write_bench_outputs", "record_house", "RecordOptions", "RecordReport",
    "run_closed_loop", "ClosedLoopOptions", "CameraConfig",
    "ClosedLoopReport",
    "pick_episode", "NoiseProfile", "parse_noise", "ClosedLoopBenchConfig",
    "ClosedLoopBenchResult", "run_closed_loop_bench", "write_closed_loop_bench_outputs",
    "logged_run", "LoggedRun",
    "NoiseStudyConfig", "NoiseStudyResult", "noise_study_config", "run_noise_study",
    "write_noise_study_outputs",
    "write_rerun", "Interval", "PairedComparison",
    "PlannerIntervals", "paired_comparison", "planner_intervals", "success_rate", "spl",
    "episode_spl", "mean_steps", "mean_decision_time",
    "auc_e", "efficiency_curve", "CostModel", "cost_models", "metrics_of", "summarize",
    "PlannerSummary", "Stat", "format_table", "read_results", "write_results", "load_results",
    "read_log_episodes", "LoggedEpisode", "replay_decisions", "OfflineReport", "format_offline",
    "import_rgbd", "RgbdOptions", "PinholeParams", "parse_intrinsics", "ImportReport",
    "export_bag", "ExportReport", "pin_logs", "check_pins", "update_pins", "CheckReport",
    "LogCheck", "make_executor", "read_pins", "PinSet", "Pinned", "diff_logs", "LogDiff",
    "replay_graphs", "diff_graphs", "describe_mismatch",
]
