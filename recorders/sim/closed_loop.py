"""The closed loop: a planner searches a PyBullet house on the scene graph built live.

One episode (:func:`run_episode`), all of it into one MCAP log:

1. the simulation starts at the episode's start pose; the log gets the house attachment,
   an ``sgtool.Episode`` record "started" (query, planner, the camera, robot and mapping
   settings: ``extra.mapping`` is what ``sgtool replay`` rebuilds with by default) and the
   instances table;
2. every simulator tick the map needs is a logged frame (the camera moved
   ``render_step_m`` metres or turned ``turn_render_deg`` since the last frame, a door or
   container changed, a skill ended: :mod:`sgtool.recorders.sim.keyframes`,
   :class:`~sgtool.recorders.sim.live_recorder.LiveRecorder`) and is fed, *as the log
   holds it* (:func:`sgtool.log.echo.as_logged`, after the sensor faults), to a
   :class:`~sgtool.scenegraph.stream.SceneGraphStream`, the refresh schedule replay uses:
   a refresh every K frames, and one at every action record, each written as the derived
   channels ``/map/occupancy``, ``/map/voronoi``, ``/map/rooms`` and
   ``/sgtool/scene_graph`` right after the message that caused it. Instance tables (a door
   or container changed state) go to the stream as they are written. Since replay feeds
   the same stream the same messages in the same order, ``sgtool replay`` of the episode
   log rebuilds the live scene graphs byte for byte;
3. start: one frame, then ``look_around()``, logged as an action decided on no graph
   (``graph_time_ns: null``, planner null, step 0), so the first decision has a graph;
4. per high-level step: the planner decides on the graph in force
   (:attr:`SceneGraphStream.current`), its LLM exchanges (moma-llm) are logged as
   ``sgtool.LlmExchange`` records, the action is mapped to simulator skills
   (:func:`plan_skills`) and executed, and one ``sgtool.Action`` record is written when it
   ends (at the time of its last frame) with the outcome and reason of the simulator, the
   distance driven, the measured decision time, the planner, the step number and
   ``graph_time_ns``, the log time of the graph the decision was made on. The outcome
   goes back to the planner (:meth:`Planner.feedback`, the simulator's reason as message);
5. end: **success as soon as the graph refreshed at an action record (the graph the
   planner would decide on next) holds an object of the query category** (exact match
   after :func:`~sgtool.semantics.text.category_text`, as
   :func:`~sgtool.planning.candidates.find_target`), which is the rule of the symbolic
   benchmark (SymSearch: the episode ends when the target becomes visible; no ``done``
   needed); failure on ``done`` (end "gave_up", or "wrong_done" when ``done`` names a
   target), after ``max_steps`` high-level steps ("max_steps", default 50) or at the frame
   budget ("frames": the skill under way is cut and logged as a failure). The closing
   Episode record has status success/failure, steps, travelled_m, shortest_m (the
   episode's route pulled taut, :mod:`.spl_shortest`), frames and ``extra`` (query,
   planner, seed, end, n_open, mapping, episode). Under MoMa-LLM's success rule
   (``success="done"``, :func:`~sgtool.planning.episode.search_success`) the planner is
   asked once more on the graph that shows the target: that decision is logged as an
   action (not a step, nothing executed) and only ``done(<an object of the query>)``
   makes the episode a success, else it fails with end ``not_confirmed``; both Episode
   records then carry ``extra.success: "done"``.

Steps count every planner decision, invalid ones and ``done`` included (a step is spent),
but not the opening look-around nor the frontiers an explore went on to. Log time is the
simulator's (``tick * 1e9 / fps``), never the wall clock: the same house, episode,
options and planner seed give the same log except the measured fields,
``decision_time_s`` of the actions and ``latency_s`` of the LLM exchanges (so the file
bytes differ too, through the compressed chunks; every message on every other channel
is identical, the scene graphs included). The writer writes ``OUT.XXXXXXXX.partial``
and renames it at the end: an error leaves no half-written log.

Planner actions become simulator skills by :func:`sgtool.recorders.sim.skill_plan.plan_skills`.
With ``navigation="live"`` (the default) the robot runs them on its own map
(:mod:`sgtool.recorders.sim.live_skills`: the occupancy of the latest refresh, re-planned
at every refresh; a goal its map cannot reach is a failed skill whose reason goes to the
planner) and reaches the simulator only through a
:class:`~sgtool.recorders.sim.live_skills.RobotBody` (motion with contacts, opening and
closing). When the graph offers the planner nothing actionable (a cluttered start room
leaves no room, region or frontier node), or the planner gives up when every goal on offer
has failed before in the episode, while the robot's map still has reachable grid
frontiers, the robot explores those on its own until the graph
offers something new (:mod:`sgtool.recorders.sim.fallback_explore`: ``explore`` actions
with reason ``fallback: ...``, decided on no graph; their frames and metres count, they
are no steps). An ``explore`` of the planner that succeeds but leaves no object, door or
room on offer that was not when it was decided **goes on** (:meth:`_Search.go_on`): the
planner chooses again among the frontiers only and the robot explores the one chosen, at
most ``explore_on`` times (default 0: never) or until something new is on offer; each is logged
as an ``explore`` with reason :data:`WENT_ON` and its decision time, and counts no step.
So an explore reveals what lies there, as the symbolic environment's reveals a region's
furniture, and not one more metre of floor behind a chair. When the robot's bump
marks wall off every goal (:meth:`LiveSkills.forget_bumps`), they are dropped before the
hand-over, and so are marks that withheld goals the map without them reaches when the
planner gives up (its goals then on offer again; counted as ``extra.bumps_forgotten`` of
the closing Episode record).
``navigation="house"`` keeps the simulator's skills on the ground-truth occupancy (the
behaviour before, for comparison). ``extra.navigation`` of the started
Episode record says which, with the live settings.
"""

from __future__ import annotations

import copy
import dataclasses
import math
import os
import time
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any

from sgtool.arg_checks import function, of_type
from sgtool.datasets.episodes import Episode
from sgtool.datasets.episodes import list_episodes as list_episodes  # (imported from here)
from sgtool.datasets.episodes import pick_episode as pick_episode  # (its home before)
from sgtool.datasets.room_evidence import make_classifier
from sgtool.errors import SgtoolError
from sgtool.extras import require
from sgtool.house.spec import HouseSpec
from sgtool.llm.stats import answer_counts
from sgtool.log.records import WENT_ON, LlmExchange  # WENT_ON: the reason of a go-on explore
from sgtool.log.records import Episode as LoggedEpisode
from sgtool.log.writer import LogWriter, refused_number
from sgtool.planning.base import Action, Feedback, Outcome, Planner
from sgtool.planning.candidates import Candidate, actionable, find_target
from sgtool.planning.episode import (
    NOT_CONFIRMED,
    SearchStep,
    planner_seed,
    run_search,
    search_success,
)
from sgtool.planning.plugins import held_to_contract
from sgtool.planning.registry import make_planner
from sgtool.progress import Progress
from sgtool.recorders.sim.closed_loop_options import (  # noqa: F401 (re-exported)
    N_MAX,
    NAVIGATION,
    ClosedLoopOptions,
)
from sgtool.recorders.sim.closed_loop_report import ClosedLoopReport, episode_notes
from sgtool.recorders.sim.episode_extras import (
    options_record,
    shown_distances,
    started_extra,
    success_rule,
    withheld_extra,
)
from sgtool.recorders.sim.execution import Executed, execute_live, execute_privileged
from sgtool.recorders.sim.fallback_explore import (
    GAVE_UP,
    MARKED,
    NO_ACTIONABLE,
    Fallback,
    new_candidates,
)
from sgtool.recorders.sim.live_recorder import LiveRecorder
from sgtool.recorders.sim.live_skills import IN_VIEW, LiveSkills, RobotBody, camera_sight
from sgtool.recorders.sim.reachability import (
    FAILED_BEFORE,
    UNREACHABLE,
    FailedGoals,
    give_up_handed_over,
    not_seen_into,
    reachable_view,
    without_nodes,
)
from sgtool.recorders.sim.recording import SOURCE
from sgtool.recorders.sim.simulation import Simulation, SkillOutcome, StopSimulation
from sgtool.recorders.sim.skill_plan import (  # noqa: F401 (re-exported)
    DONE_MESSAGE,
    SKILLS,
    SkillCall,
    SkillPlan,
    plan_skills,
)
from sgtool.recorders.sim.spl_shortest import driven_shortest
from sgtool.scenegraph.build_options import MAX_DEPTH_M, builder_config, mapping_record
from sgtool.scenegraph.categories import RoomClassifier
from sgtool.scenegraph.graph import SceneGraph
from sgtool.scenegraph.stream import Refresh, SceneGraphStream


# ----------------------------------------------------------------------------------------
# one episode
# ----------------------------------------------------------------------------------------
class _Search:
    """The closed loop as a :class:`~sgtool.planning.episode.SearchEnvironment` and its
    :class:`~sgtool.planning.episode.SearchRecorder`: the graph in force is observed, an
    action runs as simulator skills and is logged when it ends, then the graph refreshed on
    it decides whether the query is found."""

    def __init__(self, sim: Simulation, rec: LiveRecorder, agent: Planner, query: str,
                 max_steps: int,
                 on_decision: Callable[[SceneGraph, Action], None] | None,
                 skills: LiveSkills | None = None, explore_on: int = 0) -> None:
        self.sim, self.rec, self.agent, self.query = sim, rec, agent, query
        self.explore_on = explore_on
        # after an explore: the non-frontier nodes on offer when it was decided (go_on)
        self._on_known: list[Candidate] | None = None
        self.skills = skills  # None: the simulator's privileged skills
        self.max_steps = max_steps
        self.on_decision = on_decision
        self.steps = self.n_open = self.last_t = 0
        self.end = ""
        self.decision_times: list[float] = []
        self.invalid: list[str] = []  # why each invalid action was (episode_notes)
        self.exchanges: list[dict[str, Any]] = []  # the planner's LLM exchanges, as logged
        self._graph_time_ns = 0
        self._shown: dict[str, Any] = {}  # the view's distances for the log (decided())
        self._decision_s = 0.0
        self._confirming = False  # the decision after the target came into view ("done")
        # live navigation: the planner sees the graph with the robot's reachability
        # (:mod:`.reachability`); failed goals are not offered again from the same place
        self.failed = FailedGoals()
        self.withheld: dict[str, int] = {}  # reason -> nodes withheld, summed over decisions
        self.forgot_bumps = 0  # times the bump marks were dropped (they withheld goals)
        self._seen: SceneGraph | None = None  # the graph the planner saw last
        self._failed_ever: set[str] = set()  # goals a skill failed on in this episode
        self._withheld_now: dict[str, str] = {}
        # the robot's own exploration when the graph offers nothing (live navigation only)
        self.fallback = None if skills is None else Fallback(skills, self._log_fallback,
                                                             view=self._view)

    def start(self) -> None:
        """One frame, then a look around (logged as decided on no graph), so the first
        decision has a graph."""
        cut = False
        try:
            self.sim.tick()
        except StopSimulation:
            cut = True
        if not cut:
            ex = self._run((SkillCall("look_around", 0),))
            cut = ex.cut
            self.last_t = self.rec.act(
                self.sim, SkillOutcome("look_around", None, ex.outcome, ex.reason,
                                       ex.travelled_m, ex.ticks), 0.0,
                {"graph_time_ns": None, "planner": None})
        self._check(self.rec.last_refresh, cut)

    def _check(self, refresh: Refresh | None, cut: bool) -> None:
        if _found(refresh, self.query):
            self.end = "found"
        elif cut:
            self.end = "frames"

    @property
    def ended(self) -> bool:
        if not self.end and self.rec.budget_spent:  # an action took the last frame: no
            self.end = "frames"  # step is asked for that could not render one
        if not self.end and self.steps >= self.max_steps:
            self.end = "max_steps"
        return bool(self.end)

    def observe(self) -> SceneGraph | None:
        cur = self.rec.stream.current
        if cur is None:  # no frame at all (cannot happen with a frame budget >= 1)
            self.end = "frames"
            return None
        graph = self._view(cur)
        if self._on_known is not None:
            graph = self.go_on(graph)
            if self.end:
                return None
            cur = self.rec.stream.current
            assert cur is not None
        if not self.end and self.skills is not None and not actionable(graph) and \
                self.skills.forget_bumps():
            self.forgot_bumps += 1
            graph = self._view(cur)  # the robot's bump marks walled off every goal
        if not self.end and self.fallback is not None and not actionable(graph):
            self._hand_over(NO_ACTIONABLE, ())
            if self.end:  # the target came into view, or the frame budget is spent
                return None
            cur = self.rec.stream.current
            assert cur is not None
            graph = self._view(cur)
        if not self.end and self.skills is not None and not actionable(graph) and \
                self.failed.release(n for n, why in self._withheld_now.items()
                                    if why == FAILED_BEFORE):
            graph = self._view(cur)  # a goal that failed is tried once more
        for why in self._withheld_now.values():
            self.withheld[why] = self.withheld.get(why, 0) + 1
        self._graph_time_ns = int(cur.time_ns)
        graph = graph.canonical()  # as a replay of the log will show it
        self._shown = shown_distances(graph, cur.graph)
        self._seen = graph
        return graph

    def _view(self, refresh: Refresh) -> SceneGraph:
        """The graph of ``refresh`` as the planner sees it: with live navigation, goals
        the robot's map cannot reach (or that failed from the same place) withheld
        (:func:`~sgtool.recorders.sim.reachability.reachable_view`; the reasons of the
        last view in ``_withheld_now``)."""
        if self.skills is None:
            return refresh.graph
        view = reachable_view(refresh, self.skills, self.failed)
        self._withheld_now = view.withheld
        return view.graph

    def _hand_over(self, why: str, known: Sequence[Candidate]) -> None:
        """The robot explores grid frontiers on its own (:mod:`.fallback_explore`) until
        the graph offers a node not in ``known``."""
        assert self.fallback is not None
        if self.fallback.explore(why, known).cut and not self.end:
            self.end = "frames"

    def _log_fallback(self, outcome: SkillOutcome) -> bool:
        """Log an action of the fallback (decided on no graph); True: the target is in
        view."""
        self.last_t = self.rec.act(self.sim, outcome, 0.0,
                                   {"graph_time_ns": None, "planner": None})
        if _found(self.rec.stream.current, self.query):
            self.end = "found"
        return self.end == "found"

    @property
    def success(self) -> bool:
        """The target came into view (the environment's verdict)."""
        return self.end == "found"

    def decided(self, index: int, graph: SceneGraph, action: Action,
                decision_s: float) -> None:
        self.decision_times.append(decision_s)
        self._decision_s = decision_s
        self._confirming = bool(self.end)  # asked once more after the end: not a step
        if not self._confirming:
            self.steps += 1
        self.exchanges += _log_exchanges(self.agent, self.rec.writer, self.rec.last_time_ns)
        if self.on_decision is not None:
            self.on_decision(graph, action)

    def execute(self, action: Action) -> Feedback:
        cur = self.rec.stream.current
        assert cur is not None
        plan = plan_skills(cur.graph, action)
        cut = False
        o: Outcome
        if plan.done and action.target is None and self.fallback is not None:
            if self._all_failed(self._seen) and self.fallback.can_explore():
                return self._give_up_handed_over(action, self._seen or cur.graph, GAVE_UP)
            if self._forgot_withholding_marks():  # the goals they withheld are on offer
                return self._give_up_handed_over(action, self._seen or cur.graph, MARKED)
        if plan.done:
            o, why, dist, ticks = "success", DONE_MESSAGE, 0.0, 0
            self.end = "gave_up" if action.target is None else "wrong_done"
        elif plan.invalid is not None:
            o, why, dist, ticks = "invalid", plan.invalid, 0.0, 0
            self.invalid.append(plan.invalid)
        else:
            before = self.sim.states
            ex = self._run(plan.calls)
            o, why, dist, ticks, cut = ex.outcome, ex.reason, ex.travelled_m, ex.ticks, ex.cut
            if action.skill == "open" and o == "success" and any(
                    v == "open" and before.get(k) != "open" for k, v in self.sim.states.items()):
                self.n_open += 1  # (not when the target came into view on the way to it)
            if o == "failure" and action.target is not None:
                self._failed_ever.add(str(action.target))
            if o == "failure" and not cut and action.target is not None:
                self.failed.failed(action.target)  # not offered again from the same place
            elif o == "success" and not cut and action.skill == "navigate" and \
                    not_seen_into(self.rec.stream.current, action.target):
                # stood at it and still did not see into it: not again from there
                self.failed.failed(str(action.target))
        outcome = SkillOutcome(action.skill, action.target, o, why, dist, ticks)
        self.last_t = self.rec.act(self.sim, outcome, self._decision_s,
                                   self._decided_fields(action, why))
        self._check(self.rec.stream.current, cut)  # found overrides a done
        if self.explore_on and self.skills is not None and action.skill == "explore" and \
                o == "success" and why != IN_VIEW and self._seen is not None:
            self._on_known = [c for c in actionable(self._seen) if c.kind != "frontier"]
        return Feedback(action, o, why, dist)

    def go_on(self, graph: SceneGraph) -> SceneGraph:
        """After a planner's explore (module doc): while the view ``graph`` offers no
        object, door or room that was not on offer when the explore was decided, up to
        ``explore_on`` times, the planner chooses among the frontiers only and the robot
        explores the one chosen, logged as an action with reason :data:`WENT_ON` and no
        step (a choice that is no frontier ends it). The view to decide on next."""
        known, self._on_known = self._on_known, None
        if known is None or self.skills is None:
            return graph
        for _ in range(self.explore_on):
            if self.end or new_candidates(graph, known, frontiers=False):
                break
            cur = self.rec.stream.current
            assert cur is not None
            drop = {c.node_id for c in actionable(graph) if c.kind != "frontier"}
            only = without_nodes(graph, drop)
            fronts = {c.node_id for c in actionable(only)}
            if not fronts:
                break
            only = only.canonical()  # as a replay of the log will show it
            t0 = time.perf_counter()
            action = self.agent.decide(only)
            dt = time.perf_counter() - t0
            self.decision_times.append(dt)
            self.exchanges += _log_exchanges(self.agent, self.rec.writer,
                                             self.rec.last_time_ns)
            if self.on_decision is not None:
                self.on_decision(only, action)
            if action.skill != "explore" or action.target not in fronts:
                break
            ex = self._run(plan_skills(cur.graph, action).calls)
            why = WENT_ON + (f"; {ex.reason}" if ex.outcome != "success" else "")
            self.last_t = self.rec.act(
                self.sim, SkillOutcome("explore", action.target, ex.outcome, why,
                                       ex.travelled_m, ex.ticks), dt,
                {"graph_time_ns": int(cur.time_ns), **shown_distances(only, cur.graph)})
            self.agent.feedback(Feedback(action, ex.outcome, ex.reason, ex.travelled_m))
            if ex.outcome == "failure":
                self._failed_ever.add(str(action.target))
            if ex.outcome == "failure" and not ex.cut:
                self.failed.failed(str(action.target))
            self._check(self.rec.stream.current, ex.cut)
            if self.end or ex.outcome != "success" or ex.reason == IN_VIEW:
                break
            now = self.rec.stream.current
            assert now is not None
            graph = self._view(now)
        return graph

    def _forgot_withholding_marks(self) -> bool:
        """Whether bump marks withheld goals of the last view as unreachable that the map
        without them reaches (a give-up then is the marks'): they are dropped, as at
        :meth:`observe`, and the freed goals are offered again; other marks stay."""
        cur, skills = self.rec.stream.current, self.skills
        if skills is None or cur is None or UNREACHABLE not in self._withheld_now.values():
            return False
        probe = copy.copy(skills)  # the same robot and map without its marks
        if not probe.forget_bumps():
            return False
        now = reachable_view(cur, probe, self.failed).withheld
        if all(why != UNREACHABLE or now.get(n) == UNREACHABLE
               for n, why in self._withheld_now.items()):
            return False
        self.forgot_bumps += skills.forget_bumps() > 0
        return True

    def _all_failed(self, graph: SceneGraph | None) -> bool:
        """:func:`give_up_handed_over` of the planner's last view."""
        offered = () if graph is None else [c.node_id for c in actionable(graph)]
        return give_up_handed_over(offered, self._failed_ever)

    def _give_up_handed_over(self, action: Action, graph: SceneGraph, reason: str) -> Feedback:
        """The planner gave up while the map has reachable frontiers (``reason`` GAVE_UP) or
        its marks withheld goals (MARKED): logged so, and the robot explores until the graph
        offers a node it did not offer before; the episode goes on."""
        why = f"{reason}: the robot explores {'them' if reason == GAVE_UP else 'on'} (fallback)"
        outcome = SkillOutcome("done", None, "success", why, 0.0, 0)
        self.last_t = self.rec.act(self.sim, outcome, self._decision_s,
                                   self._decided_fields(action, why))
        self._check(self.rec.stream.current, False)
        if not self.end:
            self._hand_over(reason, actionable(graph))
        return Feedback(action, "success", why, 0.0)

    def executed(self, step: SearchStep) -> None:
        """Log the confirmation decision (``done`` rule; nothing is executed) like any
        action, so the log's last action is the ``done()`` that confirms the find."""
        if not self._confirming:
            return
        fb = step.feedback
        outcome = SkillOutcome(step.action.skill, step.action.target, fb.outcome,
                               fb.message, 0.0, 0)
        self.last_t = self.rec.act(self.sim, outcome, self._decision_s,
                                   self._decided_fields(step.action, fb.message))

    def _decided_fields(self, action: Action, message: str) -> dict[str, Any]:
        """The record fields of an action the planner decided: the graph it decided on and
        the view it was shown, its own ``reason``, and the executor's ``message`` beside it
        (as the symbolic environment logs them; the robot's own actions carry the robot's
        reason and no message)."""
        return {"graph_time_ns": self._graph_time_ns, **self._shown,
                "reason": action.reason, "unknown": {"message": message}}

    def _run(self, calls: tuple[SkillCall, ...]) -> Executed:
        if self.skills is None:  # the skill ends at a refresh that holds the target
            self.rec.stop_when = lambda: _found(self.rec.stream.current, self.query)
            try:
                return execute_privileged(self.sim, calls)
            finally:
                self.rec.stop_when = None
        return execute_live(self.sim, self.skills, calls, self.rec.stream.current)


def run_episode(house: HouseSpec, episode: Episode, planner: Planner | str,
                output: str | os.PathLike[str], options: ClosedLoopOptions | None = None, *,
                house_id: str = "", episode_index: int = 0,
                overwrite: bool = False, progress: Progress | None = None,
                on_decision: Callable[[SceneGraph, Action], None] | None = None,
                planner_options: Mapping[str, Any] | None = None) -> ClosedLoopReport:
    """Run one closed-loop search episode into the log ``output`` (module doc) through
    :func:`sgtool.planning.episode.run_search`.

    ``planner`` is a planner (:func:`sgtool.planning.registry.make_planner`'s, with
    ``planner_options``: recorded in the episode records' ``extra.planner_options``, plain
    values only and secrets left out, so that the log's planner can be built again; when
    None, the options ``make_planner`` built it with), or a name ``make_planner`` builds
    here from ``planner_options`` (recorded as converted); it is closed here (its
    ``close()``, when it has one) when the episode ends or fails; its LLM exchanges, when
    it keeps them (``drain_exchanges()``, moma-llm), are logged after each decision. A
    user's planner object is held to a plug-in's contract
    (:func:`sgtool.planning.plugins.held_to_contract`); ``progress`` is anything with
    ``update(n)`` (a tqdm bar), advanced per frame; ``on_decision`` sees every graph and
    the action chosen on it.
    """
    of_type("house", house, HouseSpec, "a HouseSpec (sgtool.load_house(path))")
    of_type("episode", episode, Episode, "an Episode (sgtool.pick_episode(house))")
    function("on_decision", on_decision, ("graph", "action"))
    if options is not None:
        of_type("options", options, ClosedLoopOptions, "a ClosedLoopOptions")
    if Path(output).suffix != ".mcap":
        raise SgtoolError(f"{output}: the output is an MCAP log; name it *.mcap")
    require("pybullet", api="sgtool.run_closed_loop")  # one line on a core install
    if isinstance(planner, str):  # recorded as make_planner converted them
        planner, planner_options = make_planner(planner, **(planner_options or {})), None
    try:  # the planner is closed however the episode ends, a refused option too
        recorded = options_record(planner, planner_options)
        planner = held_to_contract(planner)  # a user's planner object: one line for its faults
        opts = options or ClosedLoopOptions()
        if bad := refused_number(recorded.get("planner_options", {})):  # now, not at the end
            raise SgtoolError(f"planner option {bad[0]}={bad[1]}: a finite number (the "
                              "episode's log records it)")
        mapping = opts.mapping()
        name = str(getattr(planner, "name", "planner"))
        classifier = _classifier(mapping.classifier)
        hid, query, t_wall = house_id or f"house-{house.seed}", episode.query, time.perf_counter()
        shortest = (driven_shortest(house, episode) if math.isfinite(episode.shortest_path)
                    else None)
        with Simulation(house, camera=opts.camera, robot=opts.robot, fps=opts.fps,
                        start=episode.start) as sim, \
                LogWriter(output, seed=opts.planner_seed, compression=opts.compression,
                          overwrite=overwrite,
                          metadata={"source": SOURCE, "house_id": hid, "planner": name,
                                    "query": query, "house_seed": str(house.seed)}) as writer:
            stream = SceneGraphStream(None, classifier, builder_config(mapping))
            rec = LiveRecorder(writer, sim, stream, noise=opts.noise, seed=opts.noise_seed,
                                max_frames=opts.frames, planner=name, progress=progress,
                                keyframes=opts.keyframes())
            sim.observers.append(rec)
            base = LoggedEpisode(kind="search", status="started", source=SOURCE,
                                 house_id=hid, query=query, planner=name)
            writer.attach_house(house.to_json())
            writer.write_record(dataclasses.replace(
                base, steps=0, travelled_m=0.0, shortest_m=shortest, frames=0,
                extra=started_extra(opts, sim, mapping, episode, episode_index)
                | recorded), 0)
            rec.write_instances(sim)
            skills = None if opts.navigation == "house" else LiveSkills(
                RobotBody(sim), lambda: stream.current, opts.live,
                sight=camera_sight(stream, sim.camera.mount_height))
            if skills is not None:  # end a skill as soon as the target is in the graph
                skills.stop_when = lambda: _found(stream.current, query)
            search = _Search(sim, rec, planner, query, opts.max_steps, on_decision, skills,
                             opts.explore_on)
            search.start()
            pseed = planner_seed(opts.planner_seed, house.seed, episode_index)
            trace = run_search(search, planner, query, seed=pseed,
                               recorder=search, success=opts.success)
            steps, n_open = search.steps, search.n_open
            success = search_success(search.success, trace, query, opts.success)
            end = search.end if success == search.success else NOT_CONFIRMED
            t_end = max(rec.last_time_ns, search.last_t)
            writer.write_record(dataclasses.replace(
                base, status="success" if success else "failure", steps=steps,
                travelled_m=sim.travelled_m, shortest_m=shortest,
                frames=rec.frames,
                extra={"query": query, "planner": name, "seed": opts.planner_seed,
                       "planner_seed": pseed,
                       "episode": int(episode_index), "episode_id": episode.id,
                       "end": end, "n_open": n_open, "mapping": mapping_record(mapping),
                       **withheld_extra(search.withheld, search.forgot_bumps),
                       **success_rule(opts), **recorded},
            ), t_end)
            rec.refreshed(stream.finish(t_end))  # as replay ends: only if anything is new
            travelled, frames, refreshes = sim.travelled_m, rec.frames, rec.refreshes
            last = stream.current
            notes = episode_notes(mapping.max_depth, MAX_DEPTH_M, opts.noise.depth_sigma,
                                  None if last is None else len(last.graph.rooms),
                                  answer_counts(search.exchanges), search.invalid)
    finally:
        closer = getattr(planner, "close", None)
        if callable(closer):
            closer()
    return ClosedLoopReport(
        output=Path(output), house_id=hid, planner=name, query=query, episode=episode.id,
        success=success, end=end, steps=steps, travelled_m=travelled, shortest_m=shortest,
        frames=frames, refreshes=refreshes, n_open=n_open,
        decision_times=tuple(search.decision_times), seconds=time.perf_counter() - t_wall,
        notes=notes)


# the room classifiers of this process by name: loading one (weights, room-type vectors)
# and its memoised per-category votes cost about a second per episode; answers never change
_CLASSIFIERS: dict[str, RoomClassifier | None] = {}


def _classifier(name: str) -> RoomClassifier | None:
    """The room classifier ``name`` (:func:`make_classifier`), one per process."""
    if name not in _CLASSIFIERS:
        _CLASSIFIERS[name] = make_classifier(name)
    return _CLASSIFIERS[name]


def _found(refresh: Refresh | None, query: str) -> bool:
    return refresh is not None and find_target(refresh.graph, query) is not None


def _log_exchanges(agent: Any, writer: LogWriter, t_ns: int) -> list[dict[str, Any]]:
    drain = getattr(agent, "drain_exchanges", None)
    done = list(drain()) if callable(drain) else []
    for ex in done:
        writer.write_record(LlmExchange.from_json(ex), t_ns)
    return done
