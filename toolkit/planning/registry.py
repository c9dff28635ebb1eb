"""Planners by name: :data:`REGISTRY` is a table of name -> :class:`Entry` (factory, options
dataclass, one-line summary), :func:`make_planner` builds one from a name and options.

The options of a planner are the fields of its family's dataclass
(:mod:`sgtool.planning.planner_options`), checked and converted by
:mod:`sgtool.planning.option_fields`; ``sgtool bench --list-planners`` prints them
(:func:`describe_planners`). A name ``module:Name`` or one an installed package registers
in the entry-point group ``sgtool.planners`` is a plug-in (:mod:`sgtool.planning.plugins`).
Every planner comes wrapped in :class:`~sgtool.planning.timing.TimedPlanner` (option
``timed``, default true), so each action carries its measured decision time.
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Any

from sgtool.arg_checks import of_type
from sgtool.errors import SgtoolError
from sgtool.planning import plugins
from sgtool.planning.base import Planner
from sgtool.planning.option_fields import (
    OptionInfo,
    OptionMeta,
    PlannerOptionError,
    UnknownPlannerError,
    build_options,
    convert_options,
    convert_value,
    option_infos,
    parse_text,
)
from sgtool.planning.planner_options import (
    BayesSearchOptions,
    EscOptions,
    GodhsLlmOptions,
    GodhsOptions,
    LlmEndpointOptions,
    MomaOptions,
    NodeOptions,
    SbertOptions,
    ScoutOptions,
    VoiOptions,
)

__all__ = ["REGISTRY", "PLANNER_NAMES", "Entry", "UnknownPlannerError", "PlannerOptionError",
           "make_planner", "options_of", "parse_option", "describe_planners", "is_llm_planner",
           "check_planner_name", "planner_file_name"]

TIMED = OptionMeta("fill each action's decision_time_s as make_planner returns it (off: the "
                   "planner's own value; bench, run and their logs time every decision "
                   "either way)", "bool")


@dataclass(frozen=True)
class Entry:
    """A registered planner: ``factory(name, options)`` builds it from an instance of
    ``options`` (the family's dataclass); ``fixed`` are options the name sets itself (not
    settable)."""

    factory: Callable[[str, Any], Planner]
    options: type
    summary: str
    fixed: Mapping[str, Any] = field(default_factory=dict)


# --------------------------------------------------------------------------------------
# factories: each builds its planner from the family's options, as before the table
# --------------------------------------------------------------------------------------
def _node(name: str, o: NodeOptions) -> Planner:
    from sgtool.planning import planners

    cls = planners.RandomPlanner if name == "random" else planners.GreedyPlanner
    return cls(max_failures=o.max_failures)


def _utility(name: str, o: ScoutOptions | SbertOptions) -> Planner:
    from sgtool.planning.planners import UtilityPlanner
    from sgtool.planning.utility import UtilityParams
    from sgtool.semantics.priors import CosinePriors, LearnedPriors, default_priors

    params = UtilityParams(default_room=o.default_room, default_frontier=o.default_frontier,
                           delta=0.0 if name == "scout-delta0" else o.delta,
                           room_weight=o.room_weight, room_influence=not name.endswith("-noroom"),
                           frontier_radius=o.frontier_radius)
    scorer: Any
    if isinstance(o, SbertOptions):
        scorer = CosinePriors(o.encoder)
    elif o.encoder is None and o.weights_dir is None:
        scorer = default_priors()
    else:
        scorer = LearnedPriors(o.encoder, o.weights_dir)
    return UtilityPlanner(name, scorer, params, max_failures=o.max_failures)


def _priors(encoder: Any, weights_dir: str | None, blend: bool) -> Any:
    """The learned priors (``encoder``/``weights_dir``), optionally blended with the cosine
    by query novelty (:mod:`sgtool.planning.calibration`)."""
    from sgtool.semantics.encoder import default_encoder
    from sgtool.semantics.priors import CosinePriors, LearnedPriors, default_priors

    learned = default_priors() if encoder is None and weights_dir is None \
        else LearnedPriors(encoder, weights_dir)
    if not blend:
        return learned
    from sgtool.planning.calibration import BlendedPriors

    enc = encoder or default_encoder()
    return BlendedPriors(learned, CosinePriors(enc), learned.metadata.get("training_queries"),
                         enc)


def _furniture_levels(value: Any) -> Any:
    """A mapping, a table's path, "none"/"off", or None (the shipped table,
    :mod:`sgtool.planning.furniture_prior`)."""
    from sgtool.planning.furniture_prior import load_levels

    if value is None:
        return load_levels()
    if isinstance(value, str):
        if value.strip().lower() in ("none", "off", "false", "0", ""):
            return None
        return load_levels(value)
    return value


BAYES_ROOMS_SEEN_TYPE_WEIGHT = 0.3  # eta of (B7) for bayes-rooms
BAYES_ROOMS_INSTANCE_EXPONENT = 0.5  # gamma of (B8) for bayes-rooms


def _bayes(name: str, o: BayesSearchOptions) -> Planner:
    from sgtool.planning.belief import BeliefParams
    from sgtool.planning.search_theory import SearchParams, SearchTheoryPlanner

    belief = BeliefParams(room_floor=o.room_floor, object_floor=o.object_floor,
                          sharpness=o.sharpness, object_sharpness=o.object_sharpness,
                          beyond=o.beyond, miss=o.miss, region_weight=o.region_weight,
                          seen_type_weight=(BAYES_ROOMS_SEEN_TYPE_WEIGHT
                                            if name == "bayes-rooms" else o.seen_type_weight),
                          instance_exponent=(BAYES_ROOMS_INSTANCE_EXPONENT
                                             if name == "bayes-rooms" else o.instance_exponent),
                          leading_out_exponent=o.leading_out_exponent)
    params = SearchParams(step_cost=o.step_cost, open_cost=o.open_cost,
                          reveal_cost=o.reveal_cost, top_k=o.top_k, horizon=o.horizon,
                          step_budget=o.step_budget, belief=belief)
    scorer = _priors(o.encoder, o.weights_dir, blend=o.blend)
    return SearchTheoryPlanner(scorer, params, name=name, max_failures=o.max_failures,
                               furniture_levels=_furniture_levels(o.furniture_levels))


def _voi(name: str, o: VoiOptions) -> Planner:
    from sgtool.planning.belief import BeliefParams
    from sgtool.planning.voi import VoiParams, VoiPlanner

    belief = BeliefParams(room_floor=o.room_floor, object_floor=o.object_floor,
                          sharpness=o.sharpness, object_sharpness=o.object_sharpness,
                          beyond=o.beyond, miss=o.miss, region_weight=o.region_weight,
                          seen_type_weight=o.seen_type_weight,
                          instance_exponent=o.instance_exponent,
                          leading_out_exponent=o.leading_out_exponent)
    params = VoiParams(step_cost=o.step_cost, open_cost=o.open_cost,
                       follow_steps=o.follow_steps, follow_rule=o.follow_rule,
                       top_k=o.top_k, horizon=o.horizon,
                       step_budget=o.step_budget, step_rule=o.step_rule, belief=belief)
    return VoiPlanner(_priors(o.encoder, o.weights_dir, blend=o.blend), params, name=name,
                      max_failures=o.max_failures,
                      furniture_levels=_furniture_levels(o.furniture_levels))


def _esc(name: str, o: EscOptions) -> Planner:
    from sgtool.planning.esc import EscParams, EscPlanner

    return EscPlanner(_priors(o.encoder, o.weights_dir, blend=False),
                      EscParams(w_obj=o.w_obj, w_room=o.w_room, w_dist=o.w_dist,
                                radius=o.radius), max_failures=o.max_failures)


def _godhs(name: str, o: GodhsOptions) -> Planner:
    from sgtool.planning.godhs import GodhsPlanner, PriorRanker

    ranker = o.ranker or PriorRanker(_priors(o.encoder, o.weights_dir, blend=False))
    return GodhsPlanner(ranker, o.carrier_threshold, max_failures=o.max_failures)


def _llm_client(o: LlmEndpointOptions) -> Any:
    """The chat client of an LLM planner: ``client``, else a ``replay`` transcript, else an
    endpoint from ``base_url``/``model``/``api_key``/... (:mod:`sgtool.llm.client`)."""
    from sgtool.llm.client import LlmSettings, OpenAIChatClient
    from sgtool.llm.recorded import ReplayChatClient

    if o.client is not None:
        return o.client
    if o.replay:
        return ReplayChatClient(o.replay, model=o.model)
    return OpenAIChatClient(LlmSettings.resolve(
        base_url=o.base_url, model=o.model, api_key=o.api_key, timeout_s=o.timeout_s,
        temperature=o.temperature, max_tokens=o.max_tokens))


def _godhs_llm(name: str, o: GodhsLlmOptions) -> Planner:
    from sgtool.planning.godhs import GodhsPlanner, PriorRanker
    from sgtool.planning.llm_ranker import LlmRanker

    client = _llm_client(o)
    ranker = LlmRanker(client, fallback=PriorRanker(_priors(o.encoder, o.weights_dir,
                                                            blend=False)),
                       transcript=o.transcript)
    return GodhsPlanner(ranker, o.carrier_threshold, name="godhs-llm",
                        max_failures=o.max_failures)


def _moma(name: str, o: MomaOptions) -> Planner:
    from sgtool.planning.moma.planner import MomaLlmPlanner
    from sgtool.planning.moma.unstructured import UnstructuredLlmPlanner

    cls = UnstructuredLlmPlanner if name == "unstructured-llm" else MomaLlmPlanner
    return cls(_llm_client(o), max_attempts=o.max_attempts, stuck_repeats=o.stuck_repeats,
               history_limit=o.history_limit, on_exchange=o.on_exchange,
               transcript=o.transcript, decision_timeout_s=o.decision_timeout_s,
               constraint=o.constraint, reason_chars=o.reason_chars)


REGISTRY: Mapping[str, Entry] = MappingProxyType({
    "random": Entry(_node, NodeOptions, "uniform over actionable nodes (SCOUT's random agent)"),
    "greedy": Entry(_node, NodeOptions, "nearest actionable node"),
    "sbert": Entry(_utility, SbertOptions,
                   "SBERT cosine utilities with room influence (SCOUT Table VI defaults)"),
    "sbert-noroom": Entry(_utility, SbertOptions, "sbert without room influence ('w/o RI')"),
    "scout": Entry(_utility, ScoutOptions, "SCOUT: distilled containment/co-occurrence "
                   "priors, Eqs. 1-4, 12-13 (Table II defaults)"),
    "scout-noroom": Entry(_utility, ScoutOptions, "SCOUT without room influence"),
    "scout-delta0": Entry(_utility, ScoutOptions, "SCOUT with delta = 0 (greedy on "
                          "utility, Eq. 13)", fixed={"delta": 0.0}),
    "godhs": Entry(_godhs, GodhsOptions, "GODHS: explore everything, then rooms by "
                   "relevance, then identified carriers (sgtool.planning.godhs)"),
    "esc": Entry(_esc, EscOptions, "ESC-Interactive: soft commonsense rules over frontiers "
                 "and carriers (sgtool.planning.esc)"),
    "bayes-search": Entry(_bayes, BayesSearchOptions, "search theory: Bayes belief over "
                          "places, p/c rule with a look-ahead (sgtool.planning.search_theory)"),
    "bayes-rooms": Entry(_bayes, BayesSearchOptions, "bayes-search whose unexplored rooms "
                         "discount the room types already explored and whose like carriers "
                         "share their category's mass, (B7)-(B8) of sgtool.planning.belief",
                         fixed={"seen_type_weight": BAYES_ROOMS_SEEN_TYPE_WEIGHT,
                                "instance_exponent": BAYES_ROOMS_INSTANCE_EXPONENT}),
    "voi": Entry(_voi, VoiOptions, "value of information: bayes-rooms' belief, each action "
                 "valued by what it finds per cost, a reveal priced with the checks it "
                 "needs (sgtool.planning.voi)"),
    "moma-llm": Entry(_moma, MomaOptions, "MoMa-LLM over an OpenAI-compatible chat endpoint "
                      "or a transcript"),
    "unstructured-llm": Entry(_moma, MomaOptions, "MoMa-LLM's ablation: shown the raw JSON "
                              "scene graph (sgtool.planning.moma.unstructured)"),
    "godhs-llm": Entry(_godhs_llm, GodhsLlmOptions, "GODHS with an LLM ranking rooms and "
                       "carriers (sgtool.planning.llm_ranker; the priors when it fails)"),
})
PLANNER_NAMES: tuple[str, ...] = tuple(REGISTRY)


def is_llm_planner(name: str) -> bool:
    """A built-in planner that talks to a chat endpoint (its options hold one)."""
    entry = REGISTRY.get(name.strip().lower())
    return entry is not None and issubclass(entry.options, LlmEndpointOptions)


def _unknown(name: str) -> UnknownPlannerError:
    import difflib

    installed = sorted(set(plugins.entry_points()) - set(PLANNER_NAMES))  # (shadowed)
    near = difflib.get_close_matches(name.strip().lower(), [*PLANNER_NAMES, *installed], n=1)
    hint = f"did you mean {near[0]!r}? " if near else ""
    return UnknownPlannerError(
        f"unknown planner {name!r}; {hint}choose one of: "
        f"{', '.join([*PLANNER_NAMES, *installed])}, a name "
        f"registered in the entry-point group {plugins.GROUP}, or module:Name (a plug-in)")


def check_planner_name(name: str) -> None:
    """``name`` is a built-in planner, a registered plug-in, or ``module:Name`` (written
    right; not imported here); else one :class:`UnknownPlannerError` line."""
    if name.strip().lower() in REGISTRY:
        return
    if plugins.is_spec(name):
        plugins.check_spec(name)
        return
    if name not in plugins.entry_points():
        raise _unknown(name)


def planner_file_name(name: str) -> str:
    """The folder or file-name component of planner ``name`` in log paths
    (:func:`sgtool.planning.plugins.file_name`)."""
    return plugins.file_name(name)


def _factory(name: str) -> Callable[..., Any]:
    """A plug-in's class or factory (entry point first, then ``module:Name``)."""
    entry = plugins.entry_points().get(name)
    if entry is None and not plugins.is_spec(name):
        raise _unknown(name)
    if (clash := plugins.clash_problem(name)) is not None:
        raise plugins.PluginError(clash)
    return plugins.load_factory(name, entry)


def options_of(name: str) -> type | None:
    """The options dataclass of planner ``name`` (a plug-in's ``Options``; importing it),
    or None for a plug-in without one."""
    entry = REGISTRY.get(name.strip().lower())
    if entry is not None:
        return entry.options
    return plugins.options_class(_factory(name))


def effective_options(name: str, given: Mapping[str, Any]) -> dict[str, Any]:
    """``given`` options of planner ``name`` as it takes them (each value parsed as ``-O``
    text is), those at the planner's default left out: ``-O scout.delta=0.10`` runs as no
    option at all. As given when the planner cannot be asked here (a plug-in that does not
    import in this process)."""
    try:
        cls = options_of(name)
    except Exception:  # noqa: BLE001 - a plug-in that fails here: compare as -O text
        return {k: _option_text(v) for k, v in sorted(given.items())}
    defaults = {"timed": True, **({} if cls is None else
                                  {i.name: i.default for i in option_infos(cls)})}
    if cls is None and name.strip().lower() not in REGISTRY:  # a plug-in's own defaults
        defaults |= _signature_defaults(_factory(name))
    values = typed_options(name, given)
    source = ANSWER_SOURCE if is_llm_planner(name) else frozenset()
    return {k: v for k, v in sorted(values.items())
            if k not in source and (k not in defaults or v != defaults[k])}


# the options of the built-in LLM planners that say where their answers come from and where
# they are written, not which answers: a live run, the same run on another port and its
# offline replay from the transcript decide alike
ANSWER_SOURCE = frozenset({"base_url", "replay", "transcript"})


def _option_text(value: Any) -> Any:
    """A plain value as ``-O`` text of one meaning (a list comma-separated, a bool
    ``true``/``false`` however written, a number by its value: ``1``, ``1.0`` and
    ``"1.0"`` alike), so that a log's typed value and the text of a command compare
    alike; anything else as given."""
    if isinstance(value, list | tuple) and all(
            isinstance(x, int | float | str) and not isinstance(x, bool) for x in value):
        return ",".join(_plain_text(x) for x in value)
    if isinstance(value, str):  # a list as -O text: item by item
        return ",".join(_plain_text(x) for x in value.split(","))
    return _plain_text(value) if isinstance(value, int | float) else value


def _plain_text(value: int | float | str) -> str:
    """One text per meaning of a bool, number or word (:func:`_option_text`)."""
    if isinstance(value, bool):
        return "true" if value else "false"
    text = str(value).strip()
    if text.lower() in ("true", "yes", "on", "false", "no", "off"):
        return "true" if text.lower() in ("true", "yes", "on") else "false"
    try:
        number = float(text)
    except ValueError:
        return text
    if not math.isfinite(number):
        return text
    return str(int(number)) if number.is_integer() else repr(number)


def typed_options(name: str, given: Mapping[str, Any]) -> dict[str, Any]:
    """``given`` options of planner ``name`` with each value as the planner takes it (parsed
    as ``-O`` text is: ``2`` given from Python for a float option is ``2.0``, as from the
    command line), so that a run records them alike however they were given; a value that
    does not parse (a Python object, a key the planner does not take, a plug-in that does
    not import here) as given."""
    out = {}
    for k, v in given.items():
        try:
            out[k] = _as_list_option(name, k, v) if isinstance(v, list | tuple) else \
                parse_option(name, k, str(v)) if isinstance(
                    v, str | int | float | bool | os.PathLike) else v
        except Exception:  # noqa: BLE001 - as given (see above)
            out[k] = v
    return out


def _as_list_option(name: str, key: str, value: list[Any] | tuple[Any, ...]) -> Any:
    """A list or tuple given for a ``list`` option as ``-O`` gives it (a log records a
    list; Python may give a tuple); as given for any other option."""
    meta = _option_meta(name, key)
    if meta is None or meta.kind != "list" or not all(
            isinstance(x, str | int | float) and not isinstance(x, bool) for x in value):
        return value
    # item by item, not joined and split again: a text item may hold a comma or spaces
    return convert_value(name, key, meta, list(value))


def _option_meta(name: str, key: str) -> OptionMeta | None:
    """The metadata of option ``key`` of planner ``name`` (None: not a typed option)."""
    cls = options_of(name)
    if cls is None:
        return plugins.signature_metas(_factory(name)).get(key)
    return next((i.meta for i in option_infos(cls) if i.name == key), None)


def _unannotated_parameters(factory: Any) -> list[str]:
    """The parameters without an annotation of a plug-in without an ``Options`` class, in
    order (its ``__init__``'s, for a class; not ``*args``/``**kwargs``): ``-O`` passes
    them as int, float, true/false or text; none when Python cannot tell."""
    import inspect

    try:
        params = inspect.signature(factory).parameters.values()
    except (TypeError, ValueError):
        return []
    return [p.name for p in params if p.annotation is p.empty
            and p.kind in (p.POSITIONAL_OR_KEYWORD, p.KEYWORD_ONLY)]


def _signature_defaults(factory: Any) -> dict[str, Any]:
    """The keyword defaults of a plug-in without an ``Options`` class: its factory's (its
    ``__init__``'s, for a class); none when Python cannot tell."""
    import inspect

    try:
        params = inspect.signature(factory).parameters.values()
    except (TypeError, ValueError):
        return {}
    return {p.name: p.default for p in params if p.default is not inspect.Parameter.empty}


def parse_option(name: str, key: str, text: str) -> Any:
    """The value of ``-O NAME.KEY=TEXT``: checked against the planner's field (built-in,
    or a plug-in's ``Options``), else the text parsed as int, float, true/false or text."""
    if key == "timed":
        return convert_value(name, key, TIMED, text, from_cli=True)
    entry = REGISTRY.get(name.strip().lower())
    if entry is not None and key in entry.fixed:
        raise _fixed(name, key, entry.fixed[key])
    cls = options_of(name)
    if cls is None:  # a plug-in without Options: typed by its factory's annotations
        meta = plugins.signature_metas(_factory(name)).get(key)
        return parse_text(text) if meta is None else \
            convert_value(name, key, meta, text, from_cli=True)
    return convert_options(name, cls, {key: text}, from_cli=True)[key]


def _fixed(name: str, key: str, value: Any) -> PlannerOptionError:
    return PlannerOptionError(f"planner {name!r}: option {key} is fixed at {value} by the "
                              "name (set it on the family's main planner instead)")


def make_planner(name: str, **options: Any) -> Planner:
    """A fresh planner by name (a built-in of :data:`REGISTRY` or a plug-in), built from
    ``options`` (checked against its options dataclass: one line for an unknown key, a
    value of the wrong type or out of range), wrapped in
    :class:`~sgtool.planning.timing.TimedPlanner` unless ``timed=False`` (a plug-in is
    wrapped either way, its decision time measured only when timed). A plug-in's wrapper
    checks its contract and carries ``name`` as its name, so tables and logs list it as it
    was named."""
    of_type("planner name", name, str, "a planner's name (--list-planners) or module:Name")
    timed = convert_value(name, "timed", TIMED, options.pop("timed", True))
    key = name.strip().lower()
    entry = REGISTRY.get(key)
    given = dict(options)  # as given: what a log of its episodes records (run_episode)
    if entry is None:
        planner = plugins.build_plugin(name, _factory(name), options)
    else:
        planner = _build(key, entry, options)
        # recorded as converted, so "2" from Python is recorded as -O's 2.0 is
        given = convert_options(key, entry.options, given)
    if not timed and entry is not None:
        # the options it was built with, which a closed-loop log records (run_episode)
        planner.given_options = given  # type: ignore[attr-defined]
        return planner
    from sgtool.planning.timing import TimedPlanner

    # a plug-in is always wrapped: its contract is checked and its name is the one given
    wrapped = TimedPlanner(planner, plugin=entry is None, measure=timed)
    wrapped.given_options = given
    if entry is None:
        wrapped.name = name
    return wrapped


def _build(name: str, entry: Entry, options: dict[str, Any]) -> Planner:
    """A built-in planner; a value that passes its field's check but fails in the planner
    (a weights folder, a table) is one line naming the options given."""
    for k in options:
        if k in entry.fixed:
            raise _fixed(name, k, entry.fixed[k])
    opts = build_options(name, entry.options, options)
    try:
        return entry.factory(name, opts)
    except SgtoolError:
        raise
    except (ValueError, TypeError, AttributeError, OSError, KeyError) as e:
        if not options:
            raise  # the defaults failed: a bug, not the user's input
        raise PlannerOptionError(
            f"planner {name!r}: a value of its option(s) {', '.join(sorted(options))} does "
            f"not fit ({type(e).__name__}: {e})") from e


def _plugin_lines(name: str) -> list[str]:
    """A plug-in's line and its options' (from its ``Options`` dataclass), or why not."""
    try:
        cls = options_of(name)
    except SgtoolError as e:
        return [f"{name}: {e}"]
    if cls is None:
        factory = _factory(name)
        typed, defaults = plugins.signature_metas(factory), _signature_defaults(factory)
        untyped = [k for k in _unannotated_parameters(factory) if k not in typed]
        return [f"{name}: a plug-in without an Options dataclass (its -O values are "
                "converted to its parameters' annotated types, else passed as int, float, "
                "true/false or text)",
                *(f"    {OptionInfo(k, m.kind, defaults.get(k), m, k not in defaults).line()}"
                  for k, m in typed.items()),
                *(f"    {k} (int, float, true/false or text, "
                  + (f"default {defaults[k]!r})" if k in defaults else "required)")
                  for k in untyped)]
    return [f"{name}: a plug-in", *(f"    {info.line()}" for info in option_infos(cls))]


def plugin_problem(names: Sequence[str]) -> str | None:
    """Why the first plug-in of ``names`` (built-in names are skipped) cannot be used as a
    planner (it does not import, names nothing callable, its options class is broken);
    None when all can."""
    for name in names:
        if name.lower() in REGISTRY:
            continue
        try:
            options_of(name)
        except SgtoolError as e:
            return str(e)
    return None


def describe_planners(plugins_named: Sequence[str] = ()) -> str:
    """Every built-in planner with its summary and options (name, kind, default, help),
    the options every planner takes, the plug-ins installed packages register, and the
    options of the plug-ins in ``plugins_named`` (``module:Name``, imported here)."""
    lines = ["Planners (-O PLANNER.KEY=VALUE sets an option; '(Python only)' options are "
             "for make_planner):", ""]
    for name, entry in REGISTRY.items():
        lines.append(f"{name}: {entry.summary}")
        for info in option_infos(entry.options):
            if info.name in entry.fixed:
                lines.append(f"    {info.name}: fixed at {entry.fixed[info.name]}")
            else:
                lines.append(f"    {info.line()}")
        lines.append("")
    lines.append("Every planner: timed (bool, default true): " + TIMED.help + ".")
    lines.append("")
    found = plugins.entry_points()
    lines.append(f"Plug-ins registered in the entry-point group {plugins.GROUP}: "
                 + ("none" if not found else ""))
    for ep_name, eps in sorted(plugins.registered().items()):
        shadow = " (shadowed by the built-in planner)" if ep_name.lower() in REGISTRY else \
            " (registered by two packages: name one as module:Name)" if len(eps) > 1 else ""
        lines.append(f"    {ep_name} = {' | '.join(e.value for e in eps)}{shadow}")
    for name in dict.fromkeys(n for n in plugins_named if n.lower() not in REGISTRY):
        lines += ["", *_plugin_lines(name)]
    lines.append("")
    lines.append("module:Name (e.g. mypkg.planners:MyPlanner): a class or factory importable "
                 "here (PYTHONPATH; with Ray, on every machine of the cluster), called with "
                 "its -O options as keyword arguments; an 'Options' dataclass attribute "
                 "checks them as for the built-ins.")
    return "\n".join(lines)
