"""The options of each planner family: one frozen dataclass each, fields typed, defaults the
planners' own (``tests/toolkit/planning/test_planner_options.py`` checks them against the
planners' parameter classes), help text and ranges in the field metadata
(:func:`sgtool.planning.option_fields.option`). Fields of kind ``object`` (an encoder, a
chat client, a ranker, a callback) are accepted from Python only.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

from sgtool.planning.option_fields import option

_ENCODER = option("a SentenceEncoder to score with [default: the bundled all-MiniLM-L6-v2]",
                  "object")
_WEIGHTS = option("folder of distilled relational priors (`sgtool distill`) [default: the "
                  "shipped ones]", "path", optional=True)


@dataclass(frozen=True)
class NodeOptions:
    """random, greedy: planners that pick a node of the graph."""

    max_failures: int = field(default=2, metadata=option(
        "failed attempts on a node before it is dropped", "int", lo=1))


@dataclass(frozen=True)
class ScoutOptions(NodeOptions):
    """scout, scout-noroom, scout-delta0 (SCOUT Table II defaults)."""

    default_room: float = field(default=0.7, metadata=option(
        "exploration score of an unexplored room", "float", lo=0.0, hi=1.0))
    default_frontier: float = field(default=0.6, metadata=option(
        "exploration score of a frontier with no object near", "float", lo=0.0, hi=1.0))
    delta: float = field(default=0.1, metadata=option(
        "utility margin: the nearest node within delta of the best (Eq. 12)", "float", lo=0.0))
    room_weight: float = field(default=0.3, metadata=option(
        "room influence weight w (Eq. 4)", "float", lo=0.0, hi=1.0))
    frontier_radius: float = field(default=2.0, metadata=option(
        "metres: objects this close inform a frontier", "float", lo=0.0))
    encoder: Any = field(default=None, metadata=_ENCODER)
    weights_dir: str | None = field(default=None, metadata=_WEIGHTS)


@dataclass(frozen=True)
class SbertOptions(NodeOptions):
    """sbert, sbert-noroom: cosine similarity instead of the learned priors (SCOUT Table VI
    defaults)."""

    default_room: float = field(default=0.3, metadata=option(
        "exploration score of an unexplored room", "float", lo=0.0, hi=1.0))
    default_frontier: float = field(default=0.25, metadata=option(
        "exploration score of a frontier with no object near", "float", lo=0.0, hi=1.0))
    delta: float = field(default=0.05, metadata=option(
        "utility margin: the nearest node within delta of the best (Eq. 12)", "float", lo=0.0))
    room_weight: float = field(default=0.3, metadata=option(
        "room influence weight w (Eq. 4)", "float", lo=0.0, hi=1.0))
    frontier_radius: float = field(default=2.0, metadata=option(
        "metres: objects this close inform a frontier", "float", lo=0.0))
    encoder: Any = field(default=None, metadata=_ENCODER)


@dataclass(frozen=True)
class GodhsOptions(NodeOptions):
    """godhs: explore everything, then rooms by relevance, then carriers."""

    carrier_threshold: float = field(default=0.1, metadata=option(
        "carriers scoring below this are not searched", "float", lo=0.0, hi=1.0))
    ranker: Any = field(default=None, metadata=option(
        "a sgtool.planning.godhs.Ranker [default: the priors]", "object"))
    encoder: Any = field(default=None, metadata=_ENCODER)
    weights_dir: str | None = field(default=None, metadata=_WEIGHTS)


@dataclass(frozen=True)
class EscOptions(NodeOptions):
    """esc: weighted soft commonsense rules (ESC-Interactive)."""

    w_obj: float = field(default=1.0, metadata=option(
        "weight of rule R1 (related objects near)", "float", lo=0.0))
    w_room: float = field(default=1.0, metadata=option(
        "weight of rule R2 (room type)", "float", lo=0.0))
    w_dist: float = field(default=0.5, metadata=option(
        "weight of rule R3 (distance)", "float", lo=0.0))
    radius: float = field(default=2.0, metadata=option(
        "metres: 'near' of rule R1", "float", lo=0.0))
    encoder: Any = field(default=None, metadata=_ENCODER)
    weights_dir: str | None = field(default=None, metadata=_WEIGHTS)


@dataclass(frozen=True)
class BayesSearchOptions(NodeOptions):
    """bayes-search: a belief over places, probability per expected cost, look-ahead."""

    step_cost: float = field(default=3.0, metadata=option(
        "a of (S1): metres per action", "float", lo=0.0))
    open_cost: float = field(default=0.5, metadata=option(
        "b of (S1): extra cost of an open", "float", lo=0.0))
    reveal_cost: float = field(default=0.0, metadata=option(
        "e of (S1): extra cost of revealing a place", "float", lo=0.0))
    top_k: int = field(default=5, metadata=option(
        "places ranked by p/c that the look-ahead orders", "int", lo=1))
    horizon: int = field(default=3, metadata=option(
        "places per look-ahead sequence", "int", lo=1))
    step_budget: int = field(default=50, metadata=option(
        "actions per episode (N_max) the step price assumes; 0: none", "int", lo=0))
    room_floor: float = field(default=0.05, metadata=option(
        "(C1) floor of the room probability R", "float", lo=0.0, hi=1.0))
    object_floor: float = field(default=0.05, metadata=option(
        "(C1) floor of the carrier probability C", "float", lo=0.0, hi=1.0))
    sharpness: float = field(default=1.0, metadata=option(
        "(C1) exponent of R", "float", lo=0.0))
    object_sharpness: float = field(default=2.0, metadata=option(
        "(C1) exponent of C", "float", lo=0.0))
    beyond: float = field(default=1.0, metadata=option(
        "(B4) weight of the space behind a door or a leading-out frontier", "float", lo=0.0))
    miss: float = field(default=0.5, metadata=option(
        "mass factor per failed attempt on a node (1 - beta)", "float", lo=0.0, hi=1.0))
    region_weight: float = field(default=0.5, metadata=option(
        "omega of K = omega n C, the mass of an unseen region (B2)-(B3)", "float", lo=0.0))
    seen_type_weight: float = field(default=1.0, metadata=option(
        "eta of (B7): weight of a room type in an unexplored room's mean per explored room "
        "of that type; 1: off", "float", lo=0.0, hi=1.0))
    instance_exponent: float = field(default=1.0, metadata=option(
        "gamma of (B8): n carriers of one category in a room hold C n^gamma; 1: off",
        "float", lo=0.0, hi=1.0))
    leading_out_exponent: float = field(default=1.0, metadata=option(
        "delta of (B10): the L leading-out frontiers of one room hold one unknown room's "
        "mass times L^delta; 1: off", "float", lo=0.0, hi=1.0))
    blend: bool = field(default=True, metadata=option(
        "blend the learned scores with the cosine by query novelty", "bool"))
    furniture_levels: str | Mapping[str, float] | None = field(default=None, metadata=option(
        "furniture-level prior table (JSON) or 'none' [default: the shipped table]", "path",
        objects=True))
    encoder: Any = field(default=None, metadata=_ENCODER)
    weights_dir: str | None = field(default=None, metadata=_WEIGHTS)


@dataclass(frozen=True)
class VoiOptions(NodeOptions):
    """voi: the belief of bayes-rooms, actions valued by what they reveal per cost
    (sgtool.planning.voi)."""

    step_cost: float = field(default=3.0, metadata=option(
        "a of (V2): metres per action", "float", lo=0.0))
    open_cost: float = field(default=0.5, metadata=option(
        "b of (V2): extra cost of an open", "float", lo=0.0))
    follow_steps: float | None = field(default=None, metadata=option(
        "f of (V2): actions after a reveal before what it showed is checked [default: "
        "estimated from the revealed places by follow_rule]", "float", lo=0.0,
        optional=True))
    follow_rule: str = field(default="prefix", metadata=option(
        "how a reveal's follow-up is priced when follow_steps is unset: prefix (V4, the "
        "best initial segment of checks) or mean (V3, the expected number of checks)",
        "choice", choices=("prefix", "mean")))
    top_k: int = field(default=5, metadata=option(
        "places ranked by p/c that the look-ahead orders", "int", lo=1))
    horizon: int = field(default=3, metadata=option(
        "places per look-ahead sequence", "int", lo=1))
    step_budget: int = field(default=50, metadata=option(
        "actions per episode (N_max) the step price assumes; 0: none", "int", lo=0))
    step_rule: str = field(default="slack", metadata=option(
        "the price of an action: slack ((V5), lowered while every place could still be "
        "checked within the steps left) or floor ((S3), never below step_cost)",
        "choice", choices=("slack", "floor")))
    room_floor: float = field(default=0.05, metadata=option(
        "(C1) floor of the room probability R", "float", lo=0.0, hi=1.0))
    object_floor: float = field(default=0.05, metadata=option(
        "(C1) floor of the carrier probability C", "float", lo=0.0, hi=1.0))
    sharpness: float = field(default=1.0, metadata=option(
        "(C1) exponent of R", "float", lo=0.0))
    object_sharpness: float = field(default=2.0, metadata=option(
        "(C1) exponent of C", "float", lo=0.0))
    beyond: float = field(default=1.0, metadata=option(
        "(B4) weight of the space behind a door or a leading-out frontier", "float", lo=0.0))
    miss: float = field(default=0.5, metadata=option(
        "mass factor per failed attempt on a node (1 - beta)", "float", lo=0.0, hi=1.0))
    region_weight: float = field(default=1.0, metadata=option(
        "omega of K = omega n C, the mass of an unseen region (B2)-(B3)", "float", lo=0.0))
    seen_type_weight: float = field(default=0.3, metadata=option(
        "eta of (B7): weight of a room type in an unexplored room's mean per explored room "
        "of that type; 1: off", "float", lo=0.0, hi=1.0))
    instance_exponent: float = field(default=0.5, metadata=option(
        "gamma of (B8): n carriers of one category in a room hold C n^gamma; 1: off",
        "float", lo=0.0, hi=1.0))
    leading_out_exponent: float = field(default=1.0, metadata=option(
        "delta of (B10): the L leading-out frontiers of one room hold one unknown room's "
        "mass times L^delta; 1: off", "float", lo=0.0, hi=1.0))
    blend: bool = field(default=True, metadata=option(
        "blend the learned scores with the cosine by query novelty", "bool"))
    furniture_levels: str | Mapping[str, float] | None = field(default=None, metadata=option(
        "furniture-level prior table (JSON) or 'none' [default: the shipped table]", "path",
        objects=True))
    encoder: Any = field(default=None, metadata=_ENCODER)
    weights_dir: str | None = field(default=None, metadata=_WEIGHTS)


@dataclass(frozen=True)
class LlmEndpointOptions:
    """The chat endpoint of an LLM planner: ``client``, else a ``replay`` transcript, else
    ``base_url``/``model``/``api_key`` (unset: the ``SGTOOL_LLM_*`` environment variables,
    :mod:`sgtool.llm.client`); the LLM option group of the commands fills these."""

    base_url: str | None = field(default=None, metadata=option(
        "OpenAI-compatible endpoint [default: SGTOOL_LLM_BASE_URL, OPENAI_BASE_URL]", "str",
        optional=True))
    model: str | None = field(default=None, metadata=option(
        "model name [default: SGTOOL_LLM_MODEL, else gpt-5-mini]", "str", optional=True))
    api_key: str | None = field(default=None, metadata=option(
        "API key [default: SGTOOL_LLM_API_KEY, OPENAI_API_KEY]", "str", optional=True))
    timeout_s: float = field(default=30.0, metadata=option(
        "wall-clock seconds per request (connecting, headers and body together)", "float",
        lo=0.0, lo_open=True))
    temperature: float | None = field(default=None, metadata=option(
        "sampling temperature [default: not sent, the server's]", "float", lo=0.0, hi=2.0,
        optional=True))
    max_tokens: int | None = field(default=None, metadata=option(
        "longest answer in tokens [default: not sent]", "int", lo=1, optional=True))
    replay: str | None = field(default=None, metadata=option(
        "answer from this transcript (JSONL or an MCAP log's /sgtool/llm) instead of an "
        "endpoint", "path", objects=True))
    transcript: str | None = field(default=None, metadata=option(
        "write every exchange to this JSONL transcript (appended to; a command's run "
        "empties it first)", "path", optional=True))
    client: Any = field(default=None, metadata=option(
        "a chat client (``model``, ``complete(messages)``) instead of an endpoint", "object"))


@dataclass(frozen=True)
class MomaOptions(LlmEndpointOptions):
    """moma-llm, unstructured-llm (MoMa-LLM's defaults)."""

    max_attempts: int = field(default=5, metadata=option(
        "requests per decision before giving up", "int", lo=1))
    stuck_repeats: int = field(default=3, metadata=option(
        "repeated failing commands before the planner is told it is stuck; 0: never",
        "int", lo=0))
    history_limit: int = field(default=30, metadata=option(
        "past actions shown in the prompt", "int", lo=0))
    decision_timeout_s: float = field(default=60.0, metadata=option(
        "wall seconds for all the requests of one decision", "float", lo=0.0, lo_open=True))
    constraint: str = field(default="auto", metadata=option(
        "answers constrained to the valid commands (auto: detected per endpoint)", "choice",
        choices=("auto", "grammar", "json_schema", "none")))
    reason_chars: int = field(default=160, metadata=option(
        "length of the analysis/reasoning lines a constrained answer may write", "int",
        lo=1))
    on_exchange: Callable[[dict[str, Any]], None] | None = field(default=None, metadata=option(
        "a callback per exchange record", "object"))


@dataclass(frozen=True)
class GodhsLlmOptions(LlmEndpointOptions):
    """godhs-llm: GODHS with an LLM ranking rooms and carriers (the priors when it fails)."""

    max_failures: int = field(default=2, metadata=option(
        "failed attempts on a node before it is dropped", "int", lo=1))
    carrier_threshold: float = field(default=0.1, metadata=option(
        "carriers scoring below this are not searched", "float", lo=0.0, hi=1.0))
    encoder: Any = field(default=None, metadata=_ENCODER)
    weights_dir: str | None = field(default=None, metadata=_WEIGHTS)
