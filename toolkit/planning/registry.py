"""Planners by name: ``make_planner(name, **options) -> Planner``.

==================  ====================================================================
name                what it is
==================  ====================================================================
``random``          uniform over actionable nodes (SCOUT's random agent)
``greedy``          nearest actionable node
``sbert``           SBERT cosine utilities with room influence (SCOUT Table VI defaults)
``sbert-noroom``    the same without room influence ("w/o RI")
``scout``           distilled containment/co-occurrence priors, Eqs. 1-4, 12-13
                    (Table II defaults: room 0.7, frontier 0.6, delta 0.1, w 0.3)
``scout-noroom``    SCOUT without room influence
``scout-delta0``    SCOUT with delta = 0 (greedy on utility, Eq. 13)
``godhs``           GODHS (SCOUT sec. VI, [12]): explore everything, then rooms by
                    relevance, then identified carriers (:mod:`sgtool.planning.godhs`)
``esc``             ESC-Interactive (MoMa-LLM's baseline): soft commonsense rules over
                    frontiers and carriers (:mod:`sgtool.planning.esc`)
``bayes-search``    search theory: Bayes belief over places, p/c ratio rule with a
                    look-ahead (:mod:`sgtool.planning.search_theory`)
``moma-llm``        MoMa-LLM over an OpenAI-compatible chat endpoint or a transcript
``unstructured-llm`` MoMa-LLM's ablation: the same, shown the raw JSON scene graph
                    (:mod:`sgtool.planning.moma.unstructured`)
``godhs-llm``       GODHS with an LLM ranking rooms and carriers
                    (:mod:`sgtool.planning.llm_ranker`; the priors when it fails)
==================  ====================================================================

Every planner comes wrapped in :class:`~sgtool.planning.timing.TimedPlanner`, so each
action carries its measured decision time. Options:

- all: ``timed`` (bool, default True), ``max_failures`` (node-selection planners: failed
  attempts before a node is dropped, default 2);
- ``sbert*``/``scout*``: ``default_room``, ``default_frontier``, ``delta``, ``room_weight``,
  ``frontier_radius`` override the table defaults; ``encoder`` (a SentenceEncoder),
  ``weights_dir`` (scout only: another set of distilled weights);
- ``godhs``, ``esc``, ``bayes-search``: ``encoder``, ``weights_dir`` as for scout;
  ``godhs``: ``carrier_threshold`` (default 0.1), ``ranker`` (any
  :class:`~sgtool.planning.godhs.Ranker`, e.g. an LLM ranker; default the priors);
  ``esc``: ``w_obj``, ``w_room``, ``w_dist``, ``radius``; ``bayes-search``: ``step_cost``,
  ``open_cost``, ``reveal_cost``, ``top_k``, ``horizon``, ``step_budget`` (0: none),
  ``room_floor``, ``object_floor``, ``sharpness``, ``object_sharpness``, ``beyond``,
  ``miss``, ``region_weight``, ``blend`` (false: learned scores only, no novelty blend),
  ``furniture_levels`` (name -> φ mapping or a table's path, default the shipped table;
  "none": no furniture-level prior; :mod:`sgtool.planning.furniture_prior`);
- ``moma-llm``: ``base_url``, ``model``, ``api_key`` (else from the environment, see
  :mod:`sgtool.llm.client`), ``timeout_s``, ``temperature``, ``replay`` (a JSONL transcript
  to serve instead of an endpoint), ``transcript`` (append exchanges to this JSONL),
  ``on_exchange`` (callback per exchange record), ``max_attempts``, ``stuck_repeats``,
  ``history_limit``, ``client`` (any object with ``model`` and ``complete(messages)``),
  ``constraint`` (``auto`` (default), ``grammar``, ``json_schema``, ``none``:
  :mod:`sgtool.llm.constraints`), ``reason_chars``, ``max_tokens``; ``unstructured-llm``:
  the same;
- ``godhs-llm``: the endpoint options of ``moma-llm`` (``base_url`` ... ``replay``,
  ``client``, ``transcript``), ``carrier_threshold``, ``encoder``, ``weights_dir`` (the
  fallback priors).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

from sgtool.errors import SgtoolError
from sgtool.planning.base import Planner

PLANNER_NAMES: tuple[str, ...] = (
    "random", "greedy", "sbert", "sbert-noroom", "scout", "scout-noroom", "scout-delta0",
    "godhs", "esc", "bayes-search", "moma-llm", "unstructured-llm", "godhs-llm",
)

_UTILITY_KEYS = ("default_room", "default_frontier", "delta", "room_weight", "frontier_radius")


class UnknownPlannerError(SgtoolError):
    """A planner name that is not registered, or an option it does not take."""


def _pop_params(name: str, options: dict[str, Any]) -> dict[str, Any]:
    out = {k: float(options.pop(k)) for k in _UTILITY_KEYS if k in options}
    bad = next((k for k, v in out.items() if not math.isfinite(v) or v < 0), None)
    if bad is not None:
        raise UnknownPlannerError(f"planner {name!r}: option {bad}={out[bad]}: must be a finite "
                                  "number >= 0")
    return out


def _utility(name: str, options: dict[str, Any]) -> Planner:
    from sgtool.planning.planners import UtilityPlanner
    from sgtool.planning.utility import UtilityParams
    from sgtool.semantics.priors import CosinePriors, LearnedPriors, default_priors

    encoder = options.pop("encoder", None)
    weights_dir = options.pop("weights_dir", None)
    max_failures = int(options.pop("max_failures", 2))
    params = _pop_params(name, options)
    family, _, variant = name.partition("-")
    if variant == "noroom":
        params["room_influence"] = False
    if variant == "delta0":
        params["delta"] = 0.0
    if family == "sbert":
        scorer: Any = CosinePriors(encoder)
        up = UtilityParams.sbert(**params)
    else:
        if encoder is None and weights_dir is None:
            scorer = default_priors()
        else:
            scorer = LearnedPriors(encoder, weights_dir)
        up = UtilityParams.scout(**params)
    return UtilityPlanner(name, scorer, up, max_failures=max_failures)


def _priors(options: dict[str, Any], blend: bool) -> Any:
    """The learned priors (``encoder``/``weights_dir`` options), optionally blended with the
    cosine by query novelty (:mod:`sgtool.planning.calibration`)."""
    from sgtool.semantics.encoder import default_encoder
    from sgtool.semantics.priors import CosinePriors, LearnedPriors, default_priors

    encoder = options.pop("encoder", None)
    weights_dir = options.pop("weights_dir", None)
    if encoder is None and weights_dir is None:
        learned = default_priors()
    else:
        learned = LearnedPriors(encoder, weights_dir)
    if not blend:
        return learned
    from sgtool.planning.calibration import BlendedPriors

    enc = encoder or default_encoder()
    return BlendedPriors(learned, CosinePriors(enc), learned.metadata.get("training_queries"),
                         enc)


def _furniture_levels(options: dict[str, Any]) -> Any:
    """The ``furniture_levels`` option: a mapping, a table's path, "none"/"off", or absent
    (the shipped table, :mod:`sgtool.planning.furniture_prior`)."""
    from sgtool.planning.furniture_prior import load_levels

    value = options.pop("furniture_levels", None)
    if value is None:
        return load_levels()
    if isinstance(value, str):
        if value.strip().lower() in ("none", "off", "false", "0", ""):
            return None
        return load_levels(value)
    return value


def _search(name: str, options: dict[str, Any]) -> Planner:
    max_failures = int(options.pop("max_failures", 2))
    if name == "bayes-search":
        from sgtool.planning.belief import BeliefParams
        from sgtool.planning.search_theory import SearchParams, SearchTheoryPlanner

        keys = ("step_cost", "open_cost", "reveal_cost", "top_k", "horizon", "step_budget")
        kw = {k: type(getattr(SearchParams, k))(options.pop(k)) for k in keys if k in options}
        bkeys = ("room_floor", "object_floor", "sharpness", "object_sharpness", "beyond",
                 "miss", "region_weight")
        bkw = {k: float(options.pop(k)) for k in bkeys if k in options}
        kw["belief"] = BeliefParams(**bkw)
        blend = str(options.pop("blend", True)).strip().lower() not in ("false", "0", "no")
        scorer = _priors(options, blend=blend)
        return SearchTheoryPlanner(scorer, SearchParams(**kw), max_failures=max_failures,
                                   furniture_levels=_furniture_levels(options))
    if name == "esc":
        from sgtool.planning.esc import EscParams, EscPlanner

        keys = ("w_obj", "w_room", "w_dist", "radius")
        kw = {k: float(options.pop(k)) for k in keys if k in options}
        return EscPlanner(_priors(options, blend=False), EscParams(**kw),
                          max_failures=max_failures)
    from sgtool.planning.godhs import GodhsPlanner, PriorRanker

    ranker = options.pop("ranker", None) or PriorRanker(_priors(options, blend=False))
    return GodhsPlanner(ranker, float(options.pop("carrier_threshold", 0.1)),
                        max_failures=max_failures)


def _llm_client(options: dict[str, Any]) -> Any:
    """The chat client of an LLM planner: ``client``, else a ``replay`` transcript, else an
    endpoint from ``base_url``/``model``/``api_key``/... (:mod:`sgtool.llm.client`)."""
    from sgtool.llm.client import LlmSettings, OpenAIChatClient
    from sgtool.llm.recorded import ReplayChatClient

    client = options.pop("client", None)
    replay = options.pop("replay", None)
    settings_kw = {k: options.pop(k) for k in
                   ("base_url", "model", "api_key", "timeout_s", "temperature", "max_tokens")
                   if k in options}
    if client is not None:
        return client
    if replay:
        return ReplayChatClient(replay, model=settings_kw.get("model"))
    return OpenAIChatClient(LlmSettings.resolve(**settings_kw))


def _godhs_llm(options: dict[str, Any]) -> Planner:
    from sgtool.planning.godhs import GodhsPlanner, PriorRanker
    from sgtool.planning.llm_ranker import LlmRanker

    client = _llm_client(options)
    ranker = LlmRanker(client, fallback=PriorRanker(_priors(options, blend=False)),
                       transcript=options.pop("transcript", None))
    return GodhsPlanner(ranker, float(options.pop("carrier_threshold", 0.1)), name="godhs-llm",
                        max_failures=int(options.pop("max_failures", 2)))


def _moma(options: dict[str, Any], unstructured: bool = False) -> Planner:
    from sgtool.planning.moma.planner import MomaLlmPlanner
    from sgtool.planning.moma.unstructured import UnstructuredLlmPlanner

    client = _llm_client(options)
    kw = {k: options.pop(k) for k in
          ("max_attempts", "stuck_repeats", "history_limit", "on_exchange", "transcript",
           "decision_timeout_s", "reason_chars")
          if k in options}
    cls = UnstructuredLlmPlanner if unstructured else MomaLlmPlanner
    return cls(client, constraint=str(options.pop("constraint", "auto")), **kw)


def _simple(cls_name: str) -> Callable[[dict[str, Any]], Planner]:
    def make(options: dict[str, Any]) -> Planner:
        from sgtool.planning import planners

        return getattr(planners, cls_name)(max_failures=int(options.pop("max_failures", 2)))

    return make


def make_planner(name: str, **options: Any) -> Planner:
    """A fresh planner by name (see the module doc for names and options)."""
    timed = bool(options.pop("timed", True))
    given = sorted(options)
    try:
        planner = _build(name, options)
    except SgtoolError:
        raise
    except (ValueError, TypeError, AttributeError, OSError, KeyError) as e:
        if not given:
            raise  # the defaults failed: a bug, not the user's input
        raise UnknownPlannerError(
            f"planner {name!r}: a value of its option(s) {', '.join(given)} does not fit "
            f"({type(e).__name__}: {e})") from e
    if timed:
        from sgtool.planning.timing import TimedPlanner

        return TimedPlanner(planner)  # type: ignore[return-value]
    return planner


def _build(name: str, options: dict[str, Any]) -> Planner:
    """The planner ``name`` built from ``options`` (each taken out as it is used; any left
    is an error)."""
    key = name.strip().lower()
    if key == "random":
        planner = _simple("RandomPlanner")(options)
    elif key == "greedy":
        planner = _simple("GreedyPlanner")(options)
    elif key in ("sbert", "sbert-noroom", "scout", "scout-noroom", "scout-delta0"):
        planner = _utility(key, options)
    elif key in ("godhs", "esc", "bayes-search"):
        planner = _search(key, options)
    elif key in ("moma-llm", "unstructured-llm"):
        planner = _moma(options, unstructured=key == "unstructured-llm")
    elif key == "godhs-llm":
        planner = _godhs_llm(options)
    else:
        raise UnknownPlannerError(
            f"unknown planner {name!r}; choose one of: {', '.join(PLANNER_NAMES)}"
        )
    if options:
        raise UnknownPlannerError(
            f"planner {name!r} does not take option(s): {', '.join(sorted(options))}"
        )
    return planner
