"""Typed sgtool JSON log records: one frozen dataclass per JSON channel, checked both ways.

Every JSON channel of :data:`sgtool.log.schemas.RECORDS` has its record type here:

=================  =======================  =====================================
kind               record type              channel
=================  =======================  =====================================
``episode``        :class:`Episode`         ``/sgtool/episode`` (sgtool.Episode)
``instances``      :class:`Instances`       ``/sgtool/instances`` (sgtool.Instances)
``action``         :class:`Action`          ``/sgtool/action`` (sgtool.Action)
``scene_graph``    :class:`SceneGraphRecord` ``/sgtool/scene_graph`` (sgtool.SceneGraph)
``llm_exchange``   :class:`LlmExchange`     ``/sgtool/llm`` (sgtool.LlmExchange)
=================  =======================  =====================================

``to_json()`` gives the dict exactly as it is written (the writer dumps it with sorted keys
and no spaces), ``from_json(d)`` reads one back; ``from_json(r.to_json()) == r`` and
``from_json(d).to_json() == d`` for every valid ``d``. JSON distinguishes a field that is
absent from one that is null, and so do the records: a field not given is :data:`ABSENT`
and is left out of ``to_json()``; ``None`` is written as null (the Action field
``graph_time_ns`` means different things absent and null). The exception are the fields a
planner fills in an :class:`Action` (it is also what planners return): they have plain
defaults, and a record read without one remembers that in ``absent`` instead. Keys a
record type does not know (a newer minor schema version) are kept in ``unknown`` and
written back.

**Checked.** Both directions check the JSON form against the record's JSON schema, the
one registered with the channel (:mod:`sgtool.log.schemas`; an LlmExchange also has the
optional transcript fields ``prompt_sha256``, ``step``, ``query`` and ``source``, which the
registered schema leaves open): a missing required field, a wrong type or a value outside
an enumeration is a :class:`~sgtool.errors.LogFormatError` naming the channel, the record
(its index on the channel and log time) and the field, e.g. ``/sgtool/action record 3 at
2000000000 ns: field 'travelled_m' must be number, got string``.
"""

from __future__ import annotations

import enum
import json
from collections.abc import Mapping
from dataclasses import dataclass, field, fields, replace
from typing import TYPE_CHECKING, Any, ClassVar, Final, Literal, TypeVar, overload

from sgtool.canonical import canonical_float
from sgtool.errors import LogFormatError, SgtoolError
from sgtool.log import schemas as S
from sgtool.vocabulary import (
    EpisodeKind,
    EpisodeStatus,
    InstanceKind,
    OpenState,
    Outcome,
    RecordName,
    Relation,
)

if TYPE_CHECKING:
    from sgtool.scenegraph.graph import SceneGraph

T = TypeVar("T")
D = TypeVar("D")
R = TypeVar("R", bound="LogRecord")
J = TypeVar("J", bound="JsonRecord")


class Absent(enum.Enum):
    """The type of :data:`ABSENT`: a field the JSON record does not hold (not even null).

    A one-member enum, so a field typed ``str | Absent`` is not a ``str`` to mypy until
    ``is ABSENT`` (or :func:`given`) has taken the sentinel out. Falsy; ``repr`` is
    ``ABSENT``; copies and pickles are the same object."""

    ABSENT = "ABSENT"

    def __repr__(self) -> str:
        return "ABSENT"

    def __bool__(self) -> Literal[False]:
        return False


ABSENT: Final = Absent.ABSENT


@overload
def given(value: T | None | Absent) -> T | None: ...
@overload
def given(value: T | None | Absent, default: D) -> T | D: ...
def given(value: object, default: object = None) -> object:
    """``value``, or ``default`` (None when not given) when the field is absent or null."""
    return default if value is None or value is ABSENT else value


# ----------------------------------------------------------------------------------------
# checking the JSON form against a JSON schema (the subset the record schemas use)
# ----------------------------------------------------------------------------------------
_JSON_TYPES: dict[str, tuple[type, ...]] = {
    "string": (str,), "number": (int, float), "integer": (int,), "boolean": (bool,),
    "object": (dict,), "array": (list,), "null": (type(None),),
}


def _json_type(v: object) -> str:
    if isinstance(v, bool):
        return "boolean"
    for name in ("null", "string", "integer", "number", "object", "array"):
        if isinstance(v, _JSON_TYPES[name]):
            return name
    return type(v).__name__


def _is(v: object, t: str) -> bool:
    if isinstance(v, bool) and t in ("number", "integer"):
        return False
    return isinstance(v, _JSON_TYPES[t])


def schema_problem(value: object, schema: Mapping[str, Any], path: str = ""
                   ) -> tuple[str, str] | None:
    """The first (field path, problem) of ``value`` against ``schema``; None when it fits."""
    enum = schema.get("enum")
    if enum is not None and not any(value == e and type(value) is type(e) for e in enum):
        return path, f"must be one of {', '.join(map(repr, enum))}, got {value!r}"
    types = schema.get("type")
    if types is not None:
        allowed = [types] if isinstance(types, str) else list(types)
        if not any(_is(value, t) for t in allowed):
            return path, f"must be {' or '.join(allowed)}, got {_json_type(value)}"
    if isinstance(value, dict):
        for key in schema.get("required", ()):
            if key not in value:
                return (f"{path}.{key}" if path else key), "is missing"
        props = schema.get("properties", {})
        for key, sub in props.items():
            if key in value:
                p = schema_problem(value[key], sub, f"{path}.{key}" if path else key)
                if p is not None:
                    return p
        extra = schema.get("additionalProperties")
        if isinstance(extra, Mapping):
            for key, v in value.items():
                if key not in props:
                    p = schema_problem(v, extra, f"{path}.{key}" if path else key)
                    if p is not None:
                        return p
    if isinstance(value, list) and "items" in schema:
        for i, item in enumerate(value):
            p = schema_problem(item, schema["items"], f"{path}[{i}]")
            if p is not None:
                return p
    return None


# ----------------------------------------------------------------------------------------
# the records
# ----------------------------------------------------------------------------------------
@dataclass(frozen=True)
class JsonRecord:
    """A JSON object with typed fields (base of the records and their items)."""

    unknown: Mapping[str, Any] = field(default_factory=dict, kw_only=True, compare=True)
    CANONICAL: ClassVar[tuple[str, ...]] = ()  # float fields written canonically rounded
    NOT_LOGGED: ClassVar[tuple[str, ...]] = ()  # in-memory fields, neither written nor read

    def to_json(self) -> dict[str, Any]:
        """The JSON object as written: absent fields and the :data:`NOT_LOGGED` fields left
        out, tuples as lists, the :data:`CANONICAL` fields rounded by
        :func:`sgtool.canonical.canonical_float` (so every writer writes distances alike)."""
        out = dict(self.unknown)
        for name in _logged_names(type(self)):
            v = getattr(self, name)
            if isinstance(v, Absent):
                continue
            if isinstance(v, tuple):
                v = [x.to_json() if isinstance(x, JsonRecord) else x for x in v]
            elif name in self.CANONICAL and isinstance(v, float):
                v = canonical_float(v)
            out[name] = v
        return out

    @classmethod
    def _build(cls: type[J], d: Mapping[str, Any]) -> J:
        """The record of an already checked JSON object."""
        names = _logged_names(cls)
        kw: dict[str, Any] = {}
        for k in names:
            v = d.get(k, ABSENT)
            kw[k] = tuple(v) if isinstance(v, list) else v
        return cls(**kw, unknown={k: v for k, v in d.items() if k not in names})


_NAMES: dict[type, tuple[str, ...]] = {}  # record type -> its logged field names


def _logged_names(cls: type[JsonRecord]) -> tuple[str, ...]:
    """The names of the fields of ``cls`` that are written and read, in declaration order
    (``unknown`` and :data:`JsonRecord.NOT_LOGGED` left out)."""
    names = _NAMES.get(cls)
    if names is None:
        names = _NAMES[cls] = tuple(f.name for f in fields(cls)
                                    if f.name != "unknown" and f.name not in cls.NOT_LOGGED)
    return names


@dataclass(frozen=True)
class LogRecord(JsonRecord):
    """A record of one of sgtool's JSON channels."""

    KIND: ClassVar[RecordName]  # each record type names its channel

    @classmethod
    def channel(cls) -> S.RecordKind:
        return S.RECORDS[cls.KIND]

    @classmethod
    def json_schema(cls) -> Mapping[str, Any]:
        """The schema records of this type are checked against (module doc)."""
        return cls.channel().schema

    @classmethod
    def check(cls, d: object, where: str) -> None:
        """Raise :class:`LogFormatError` naming ``where`` and the field when ``d`` is not a
        valid JSON form of this record type."""
        p = schema_problem(d, cls.json_schema())
        if p is None:
            return
        path, problem = p
        what = f"field {path!r} {problem}" if path else f"the record {problem}"
        raise LogFormatError(f"{where}: {what}")

    @classmethod
    def describe(cls, index: int | None = None, t_ns: int | None = None) -> str:
        """``/sgtool/action record 3 at 2000 ns``: the channel and the record, for messages."""
        out = f"{cls.channel().topic} ({cls.channel().schema_name}) record"
        if index is not None:
            out += f" {index}"
        if t_ns is not None:
            out += f" at {t_ns} ns"
        return out

    @classmethod
    def from_json(cls: type[R], d: object, *, where: str = "") -> R:
        """The record of a JSON object; :class:`LogFormatError` when it is not valid."""
        cls.check(d, where or cls.describe())
        assert isinstance(d, Mapping)  # checked: every record schema is a JSON object
        return cls._build(d)

    def checked_json(self, where: str = "") -> dict[str, Any]:
        """:meth:`to_json`, checked (what the writer writes)."""
        d = self.to_json()
        self.check(d, where or self.describe())
        return d


@dataclass(frozen=True)
class Episode(LogRecord):
    """``sgtool.Episode``: a run starts ("started") or ends (its final figures)."""

    KIND: ClassVar[RecordName] = "episode"
    CANONICAL: ClassVar[tuple[str, ...]] = ("travelled_m", "shortest_m")

    kind: EpisodeKind
    status: EpisodeStatus
    source: str | Absent = ABSENT
    house_id: str | None | Absent = ABSENT
    query: str | None | Absent = ABSENT
    planner: str | None | Absent = ABSENT
    steps: int | Absent = ABSENT
    travelled_m: float | Absent = ABSENT
    shortest_m: float | None | Absent = ABSENT
    frames: int | Absent = ABSENT
    extra: Mapping[str, Any] | Absent = ABSENT

    @property
    def extras(self) -> Mapping[str, Any]:
        """``extra``, empty when absent."""
        return given(self.extra, {})

    def merged(self, later: Episode) -> Episode:
        """This record with the fields ``later`` holds replaced by its values (a closing
        record over its opening one); ``extra`` is merged the same way, key by key."""
        d = self.to_json()
        d.update(later.to_json())
        if self.extras and later.extras:
            d["extra"] = {**self.extras, **later.extras}
        return Episode._build(d)


# the reason of a closed-loop explore that goes on after a planner's (no step of its own)
WENT_ON = "went on: the last explore showed no new object, door or room"


@dataclass(frozen=True)
class Action(LogRecord):
    """``sgtool.Action``: a high-level action on a scene-graph node, as a planner decides it
    and as a log holds it once executed. One type serves both: a planner returns
    ``Action(skill, target, reason=..., scores=...)``; whoever executes it fills the
    outcome and the log fields (:meth:`executed`) and writes that record.

    The planner's part (positional in this order):

    - ``skill``: ``navigate`` (go to a room, region, frontier or object node), ``open`` (go
      to and open an object or a door: MoMa-LLM's go_to_and_open), ``close``, ``explore``
      (an unexplored room or a frontier), ``done`` (the target is observed; ``target`` is
      the found object's node id, or None when giving up). A planner returns one of
      :data:`sgtool.vocabulary.SKILLS`; sgtool's recorders log
      :data:`~sgtool.vocabulary.LOGGED_SKILLS`; the schema admits any string;
    - ``target``: the id of a node of the graph the planner was given (None for ``done``);
    - ``reason``: why, in words;
    - ``decision_time_s``: seconds the planner took to decide, filled by the caller
      (:class:`sgtool.planning.timing.TimedPlanner`), not by the planner;
    - ``scores``: the planner's scores per node id; kept in memory, never logged.

    The executor's part, :data:`ABSENT` until executed: ``outcome`` (the writer refuses a
    record without one), ``travelled_m`` (metres, rounded to 0.1 mm on write), ``planner``
    (its name), ``step`` (the index in the episode) and ``graph_time_ns`` (1.1): the log
    time of the scene graph it was decided on; null: decided on no graph; absent: the last
    graph at or before the action's log time; ``view_distances`` (1.2): the ``distances``
    of the graph as the planner was shown it, when they differ from the logged graph's (the
    closed loop's live navigation shows the robot's own geodesics and withholds the goals
    it cannot reach: a node missing here was not on offer); absent: the logged graph's.

    The planner's fields are never :data:`ABSENT` (a planner always has a target, maybe
    None, and a reason, maybe empty). A log record that lacks one reads as its default and
    names it in ``absent``; :meth:`to_json` leaves such a field out while it still holds its
    default, so a record read and written again is byte-identical.
    """

    KIND: ClassVar[RecordName] = "action"
    CANONICAL: ClassVar[tuple[str, ...]] = ("travelled_m",)
    NOT_LOGGED: ClassVar[tuple[str, ...]] = ("scores", "absent")
    PLANNER_DEFAULTS: ClassVar[Mapping[str, object]] = {
        "target": None, "reason": "", "decision_time_s": 0.0}

    skill: str
    target: str | None = None
    reason: str = ""
    decision_time_s: float = 0.0
    scores: dict[str, float] = field(default_factory=dict)
    outcome: Outcome | Absent = ABSENT
    travelled_m: float | Absent = ABSENT
    planner: str | None | Absent = ABSENT
    step: int | Absent = ABSENT
    graph_time_ns: int | None | Absent = ABSENT
    view_distances: Mapping[str, float] | Absent = ABSENT
    # planner fields the logged record did not hold (see the class doc)
    absent: frozenset[str] = field(default=frozenset(), kw_only=True)

    @classmethod
    def _build(cls, d: Mapping[str, Any]) -> Action:
        missing = frozenset(k for k in cls.PLANNER_DEFAULTS if k not in d)
        record = super()._build({**{k: cls.PLANNER_DEFAULTS[k] for k in missing}, **d})
        return replace(record, absent=missing) if missing else record

    def to_json(self) -> dict[str, Any]:
        out = super().to_json()
        if "view_distances" in out:
            out["view_distances"] = {  # numbers rounded; anything else is left to check()
                k: canonical_float(v) if isinstance(v, (int, float)) and
                not isinstance(v, bool) else v for k, v in sorted(out["view_distances"].items())}
        for name in self.absent:
            if getattr(self, name) == self.PLANNER_DEFAULTS[name]:
                del out[name]
        return out

    @property
    def decided(self) -> bool:
        """False for an action decided on no graph (``graph_time_ns`` null)."""
        return self.graph_time_ns is not None

    def shown(self, graph: SceneGraph) -> SceneGraph:
        """``graph`` (the logged graph this action was decided on) as the planner was shown
        it: with :attr:`view_distances` when the record holds them."""
        if isinstance(self.view_distances, Absent):
            return graph
        return replace(graph, distances=dict(self.view_distances))

    @property
    def result(self) -> Outcome:
        """The outcome of an executed action (every record read from a log has one);
        :class:`LogFormatError` for an action not executed yet."""
        if isinstance(self.outcome, Absent):
            raise LogFormatError(f"{self.describe()}: the action {self.skill!r} on "
                                 f"{self.target!r} has no outcome (not executed)")
        return self.outcome

    def executed(self, outcome: Outcome, travelled_m: float, *,
                 planner: str | None | Absent = ABSENT, step: int | Absent = ABSENT,
                 graph_time_ns: int | None | Absent = ABSENT,
                 decision_time_s: float | None = None,
                 unknown: Mapping[str, Any] | None = None) -> Action:
        """The record the executor writes: this action with its ``outcome``, the metres
        ``travelled_m`` and the log fields given (``decision_time_s`` and ``unknown`` stay
        the action's when None)."""
        return replace(
            self, outcome=outcome, travelled_m=travelled_m, planner=planner, step=step,
            graph_time_ns=graph_time_ns,
            decision_time_s=self.decision_time_s if decision_time_s is None else decision_time_s,
            unknown=self.unknown if unknown is None else unknown)


@dataclass(frozen=True)
class InstanceItem(JsonRecord):
    """One item of an ``sgtool.Instances`` table."""

    id: int
    category: str
    kind: InstanceKind
    synset: str | None | Absent = ABSENT
    state: OpenState | None | Absent = ABSENT
    affordances: tuple[str, ...] | Absent = ABSENT
    parent: int | None | Absent = ABSENT
    relation: Relation | None | Absent = ABSENT
    spec_id: str | None | Absent = ABSENT


@dataclass(frozen=True)
class Instances(LogRecord):
    """``sgtool.Instances``: the whole instance table (written again on every change)."""

    KIND: ClassVar[RecordName] = "instances"

    instances: tuple[InstanceItem, ...]

    @classmethod
    def _build(cls, d: Mapping[str, Any]) -> Instances:
        return cls(tuple(InstanceItem._build(x) for x in d["instances"]),
                   unknown={k: v for k, v in d.items() if k != "instances"})

    @classmethod
    def check(cls, d: object, where: str) -> None:
        """The schema check, then every entry in range: ``id`` in 1 ..
        :data:`INSTANCE_ID_MAX` and given once, ``parent`` null or in that range, a
        non-empty ``category`` (``kind``, ``state`` and ``relation`` are enumerations of the
        schema); :class:`LogFormatError` naming the entry and the field."""
        super().check(d, where)
        assert isinstance(d, Mapping)
        seen: set[int] = set()
        for i, item in enumerate(d["instances"]):
            problem = _instance_problem(item, seen)
            if problem is not None:
                key, why = problem
                raise LogFormatError(f"{where}: field 'instances[{i}].{key}' {why}")
            seen.add(item["id"])

    @classmethod
    def check_since(cls, d: object, where: str, checked: set[str]) -> None:
        """:meth:`check`, with the items whose JSON text (sorted keys, no spaces) is in
        ``checked`` taken as checked (they passed in an earlier table of the same writer:
        an item's check depends on the item alone, besides ids given once, which is checked
        over all items); the texts of the items that pass are added to ``checked``. A
        failure raises the error :meth:`check` of the whole table raises."""
        items = d.get("instances") if isinstance(d, dict) else None
        if not isinstance(d, dict) or not isinstance(items, list):
            cls.check(d, where)
            return
        try:
            texts = [json.dumps(x, sort_keys=True, separators=(",", ":")) for x in items]
        except (TypeError, ValueError):  # not JSON: the whole check names the field
            cls.check(d, where)
            raise
        new = [x for x, t in zip(items, texts, strict=True) if t not in checked]
        try:
            cls.check({**d, "instances": new}, where)
        except LogFormatError:
            cls.check(d, where)  # the error with the item's index in the whole table
            raise
        if len({x["id"] for x in items}) != len(items):
            cls.check(d, where)  # an id given twice: raises, naming the item
        if len(checked) > _CHECKED_KEPT:
            checked.clear()
        checked.update(texts)

    @classmethod
    def of(cls, items: list[dict[str, Any]]) -> Instances:
        """The record of a list of item dicts (checked when written)."""
        return cls(tuple(InstanceItem._build(x) for x in items))


INSTANCE_ID_MAX = 2**31 - 1  # ids are the int32 pixel values of the instance images
_CHECKED_KEPT = 100_000  # item texts a writer remembers as checked (then it starts over)


def short_number(v: float) -> str:
    """``v`` for a message: an integer of more than 15 digits or a float as ``%.6g``
    (``1e+300``), never a 300-digit number."""
    if isinstance(v, int) and not isinstance(v, bool) and abs(v) >= 10**15:
        return f"{float(v):.6g}" if abs(v) < 10**308 else f"an integer of {len(str(abs(v)))} digits"
    return f"{v:.6g}" if isinstance(v, float) else str(v)


def _instance_problem(item: Mapping[str, Any], seen: set[int]) -> tuple[str, str] | None:
    """(field, problem) of an instance table entry already checked against the schema."""
    ids = f"1 .. {INSTANCE_ID_MAX} (instance ids are the int32 pixel values of the instance " \
          "images; 0 means none)"
    iid = item["id"]
    if not 1 <= iid <= INSTANCE_ID_MAX:
        return "id", f"is {short_number(iid)}, outside {ids}"
    if iid in seen:
        return "id", f"{iid} is given twice"
    parent = item.get("parent")
    if parent is not None and not 1 <= parent <= INSTANCE_ID_MAX:
        return "parent", f"is {short_number(parent)}, outside {ids}"
    if not item["category"].strip():
        return "category", "is empty"
    return None


@dataclass(frozen=True)
class SceneGraphRecord(LogRecord):
    """``sgtool.SceneGraph``: the canonical JSON of a
    :class:`sgtool.scenegraph.graph.SceneGraph` (:meth:`graph` builds it back)."""

    KIND: ClassVar[RecordName] = "scene_graph"

    version: str
    time_ns: int | Absent = ABSENT
    robot: Mapping[str, Any] | Absent = ABSENT
    rooms: tuple[Any, ...] | Absent = ABSENT
    regions: tuple[Any, ...] | Absent = ABSENT
    objects: tuple[Any, ...] | Absent = ABSENT
    doors: tuple[Any, ...] | Absent = ABSENT
    distances: Mapping[str, float] | Absent = ABSENT

    @classmethod
    def of_graph(cls, graph: SceneGraph) -> SceneGraphRecord:
        return cls._build(graph.to_dict())

    def graph(self) -> SceneGraph:
        from sgtool.scenegraph.graph import SceneGraph

        return SceneGraph.from_dict(self.to_json())


# fields of an LLM exchange that transcripts carry and the registered schema leaves open
_LLM_TRANSCRIPT_FIELDS = {
    "prompt_sha256": {"type": ["string", "null"]},
    "step": {"type": ["integer", "null"]},
    "query": {"type": ["string", "null"]},
    "source": {"type": "string"},
    "verdict": {"type": ["string", "null"]},
}


@dataclass(frozen=True)
class LlmExchange(LogRecord):
    """``sgtool.LlmExchange``: one prompt and its answer (:mod:`sgtool.llm.exchange`)."""

    KIND: ClassVar[RecordName] = "llm_exchange"

    model: str
    messages: tuple[Mapping[str, str], ...]
    prompt_sha256: str | None | Absent = ABSENT
    response: str | None | Absent = ABSENT
    latency_s: float | Absent = ABSENT
    prompt_tokens: int | None | Absent = ABSENT
    completion_tokens: int | None | Absent = ABSENT
    error: str | None | Absent = ABSENT
    attempt: int | Absent = ABSENT
    step: int | None | Absent = ABSENT
    query: str | None | Absent = ABSENT
    source: str | Absent = ABSENT
    verdict: str | None | Absent = ABSENT  # the planner's: "ok" or "invalid: reason"

    @classmethod
    def json_schema(cls) -> Mapping[str, Any]:
        base = cls.channel().schema
        return {**base, "properties": {**base["properties"], **_LLM_TRANSCRIPT_FIELDS}}


RECORD_TYPES: dict[RecordName, type[LogRecord]] = {
    c.KIND: c for c in (Episode, Instances, Action, SceneGraphRecord, LlmExchange)
}


def record_type(kind: type[LogRecord] | str) -> type[LogRecord]:
    """The record type of ``kind`` (a type, or its channel's name: ``"episode"``); anything
    else is one :class:`~sgtool.errors.SgtoolError` line naming the kinds there are."""
    if isinstance(kind, str) and kind in RECORD_TYPES:
        return RECORD_TYPES[kind]
    if isinstance(kind, type) and issubclass(kind, LogRecord):
        return kind
    raise SgtoolError(f"record kind {kind!r}: one of {', '.join(sorted(RECORD_TYPES))} "
                      "(or its record type)")
