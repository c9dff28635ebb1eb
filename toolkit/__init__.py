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
                       :class:`Progress` (what ``progress=`` takes: a tqdm bar);
                       :func:`replay_logs` (many logs into a folder, on an executor: a
                       :class:`BatchReport` of :class:`LogResult` s)
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
closed loop            :func:`record_house` (a scripted tour into a log, with
                       :class:`RecordOptions`, :class:`CameraConfig`: a
                       :class:`RecordReport`), :func:`run_closed_loop` (one PyBullet
                       episode into a log),
                       :class:`ClosedLoopOptions`, :class:`ClosedLoopReport`,
                       :func:`pick_episode`, :class:`NoiseProfile` (sensor faults, from
                       :func:`parse_noise`: ``"strong"``, ``"mild,holes=0.05"``); the
                       closed-loop benchmark: :class:`ClosedLoopBenchConfig`,
                       :func:`run_closed_loop_bench` (runs or resumes into a folder),
                       :class:`ClosedLoopBenchResult`,
                       :func:`write_closed_loop_bench_outputs`; :func:`logged_run` (the
                       episode a closed-loop log ran, to run it again: a
                       :class:`LoggedRun`)
noise study            :func:`noise_study_config` (a :class:`NoiseStudyConfig`),
                       :func:`run_noise_study` (records into a cache, scores each final
                       graph: a :class:`NoiseStudyResult`),
                       :func:`write_noise_study_outputs`
viewers                :func:`write_rerun` (a log as a Rerun recording)
metrics                :func:`success_rate`, :func:`spl`, :func:`episode_spl`,
                       :func:`mean_steps`, :func:`mean_decision_time`, :func:`auc_e`,
                       :func:`efficiency_curve`, :class:`CostModel`, :func:`cost_models`,
                       :func:`metrics_of`, :func:`summarize`, :class:`PlannerSummary`,
                       :class:`Stat`, :func:`format_table`, :func:`read_results`,
                       :func:`write_results`, :func:`planner_intervals`,
                       :func:`paired_comparison` (bootstrap :class:`Interval` s over houses:
                       :class:`PlannerIntervals`, :class:`PairedComparison`)
logged decisions       :func:`load_results`, :func:`read_log_episodes`,
                       :class:`LoggedEpisode`, :func:`replay_decisions`,
                       :class:`OfflineReport`, :func:`format_offline`
import and export      :func:`import_rgbd`, :class:`RgbdOptions` (:class:`PinholeParams`
                       from :func:`parse_intrinsics`), :class:`ImportReport`,
                       :func:`export_bag`, :class:`ExportReport`
golden logs            :func:`pin_logs`, :func:`check_pins` (a :class:`CheckReport` of
                       :class:`LogCheck` s; ``executor=``:func:`make_executor` runs
                       logs in parallel), :func:`update_pins`, :func:`read_pins`
                       (:class:`PinSet` of :class:`Pinned`), :func:`diff_logs`
                       (:class:`LogDiff`), :func:`diff_graphs`, :func:`describe_mismatch`,
                       :func:`replay_graphs`
errors                 :class:`SgtoolError` (every failure a user can cause),
                       :class:`LogFormatError`, :class:`SpecError`, :class:`BenchError`
=====================  =====================================================================

A few names differ from their defining module's to stay unambiguous at the top level:
:class:`EpisodeRecord` and :class:`ActionRecord` are ``sgtool.log.records.Episode`` and
``Action`` (:class:`ActionRecord` is the planner's :class:`Action`: one type),
:class:`SearchEpisode` is ``sgtool.datasets.episodes.Episode``, :func:`run_closed_loop` is
``sgtool.recorders.sim.closed_loop.run_episode``, :func:`write_bench_outputs` is
``sgtool.analysis.bench.write_outputs``, :func:`write_closed_loop_bench_outputs` is
``sgtool.analysis.closed_loop_bench.write_outputs``, :class:`NoiseStudyConfig` and
:class:`NoiseStudyResult` are ``sgtool.analysis.noise_study.StudyConfig`` and
``StudyResult``, :func:`read_results`/:func:`write_results` are
``sgtool.results.read_jsonl``/``write_jsonl``.
"""

from __future__ import annotations

import ast
import importlib
from pathlib import Path

from sgtool.version import __version__ as __version__


def _read_stub() -> dict[str, str]:
    """public name -> "module:attribute", from the ``from M import A as NAME`` lines of
    ``__init__.pyi`` (the one list of public names; ``sgtool.version`` is imported above)."""
    tree = ast.parse((Path(__file__).parent / "__init__.pyi").read_text(encoding="utf-8"))
    return {alias.asname or alias.name: f"{node.module}:{alias.name}"
            for node in tree.body if isinstance(node, ast.ImportFrom)
            and node.module is not None and node.module != "sgtool.version"
            for alias in node.names}


# public name -> "module:attribute" it is imported from on first use
_EXPORTS: dict[str, str] = _read_stub()
__all__ = ["planner_names", *_EXPORTS]


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
