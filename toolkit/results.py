"""The per-episode record every metric is computed from, and its JSONL file.

One :class:`EpisodeResult` per episode, whatever ran it: the symbolic benchmark
(:mod:`sgtool.recorders.symbolic_environment`) writes them directly; a closed-loop log is
turned into one by :func:`result_from_log_records` from its typed ``sgtool.Episode`` and
``sgtool.Action`` records (:mod:`sgtool.log.records`; the mapping is documented there).

Determinism: everything in a record is derived data except the ``wall`` mapping (decision
and episode wall-clock seconds). Two runs of one command give the same JSONL bytes except
inside ``wall``; :func:`results_digest` hashes the records with ``wall`` (and the planners'
``options``) left out, so it is the figure to compare between runs.
"""

from __future__ import annotations

import hashlib
import json
import math
import os
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from sgtool.canonical import canonical_float
from sgtool.errors import SgtoolError
from sgtool.files import atomic_write
from sgtool.log.records import WENT_ON, Action, Episode, given

RESULT_VERSION = "1.0"


class ResultsFormatError(SgtoolError):
    """A results file is not a JSONL file of episode records, or a record lacks a field."""


@dataclass(frozen=True)
class Step:
    """One executed action: skill, target node id, outcome, metres travelled for it."""

    skill: str
    target: str | None
    outcome: str
    travelled_m: float = 0.0


@dataclass(frozen=True)
class EpisodeResult:
    """What happened in one episode.

    - ``success``: the query object was revealed within the step budget (SCOUT V.C);
    - ``steps``: high-level actions executed (invalid ones count: a step is spent);
    - ``travelled_m`` / ``shortest_m``: path length walked and the geodesic from the start
      to the nearest place the target can be seen from (SPL's p and l; ``shortest_m`` is
      None when unknown, e.g. a log without it: SPL is then undefined for the episode);
    - ``n_open``: successful open interactions (containers and doors), for the distance
      variant of AUC-E (MoMa-LLM: 30 low-level steps per open);
    - ``seen``: whether the query category occurs in the planners' training knowledge
      (SCOUT Table IX); None when not known;
    - ``end``: why it ended ("found", "max_steps", "gave_up", "wrong_done", "stuck", ...);
    - ``wall``: wall-clock figures (``decision_s`` summed over decisions, ``decisions``,
      ``episode_s``), the only non-deterministic part;
    - ``llm_answers``: an LLM planner's answer counts (:func:`sgtool.llm.stats.answer_counts`:
      requests, valid, invalid (rejected), faults, unknown); empty, and absent from the
      record, for other planners, so their records are as before;
    - ``noise``: the sensor noise profile of a closed-loop episode (its name: ``none``,
      ``strong``, ``mild,holes=0.05``, ...; empty, and absent from the record, when not
      known, as in the symbolic bench);
    - ``options``: the planner's options as the run recorded them
      (:func:`sgtool.redact.recorded_options`: JSON values, secrets left out); empty, and
      absent from the record, for a planner run with its defaults. Two runs of one planner
      name with other options are two planners to ``sgtool eval``.
    """

    planner: str
    seed: int
    house: str
    episode: int
    query: str
    success: bool
    steps: int
    travelled_m: float
    shortest_m: float | None
    n_open: int = 0
    n_invalid: int = 0
    n_failure: int = 0
    seen: bool | None = None
    end: str = ""
    source: str = "symbolic"
    trace: tuple[Step, ...] = ()
    wall: Mapping[str, float] = field(default_factory=dict)
    llm_answers: Mapping[str, int] = field(default_factory=dict)
    noise: str = ""
    options: Mapping[str, Any] = field(default_factory=dict)

    @property
    def decision_s(self) -> float:
        return float(self.wall.get("decision_s", 0.0))

    @property
    def decisions(self) -> int:
        return int(self.wall.get("decisions", self.steps))

    def key(self) -> tuple[str, int, str, int]:
        return (self.planner, self.seed, self.house, self.episode)

    # ----- JSON -----------------------------------------------------------------------
    def to_dict(self) -> dict[str, Any]:
        return {
            "version": RESULT_VERSION,
            "planner": self.planner,
            "seed": int(self.seed),
            "house": self.house,
            "episode": int(self.episode),
            "query": self.query,
            "seen": self.seen,
            "success": bool(self.success),
            "steps": int(self.steps),
            "travelled_m": canonical_float(self.travelled_m),
            "shortest_m": None if self.shortest_m is None else canonical_float(self.shortest_m),
            "n_open": int(self.n_open),
            "n_invalid": int(self.n_invalid),
            "n_failure": int(self.n_failure),
            "end": self.end,
            "source": self.source,
            "trace": [[s.skill, s.target, s.outcome, canonical_float(s.travelled_m)]
                      for s in self.trace],
            "wall": {k: round(float(v), 6) for k, v in sorted(self.wall.items())},
            **({"llm_answers": {k: int(v) for k, v in sorted(self.llm_answers.items())}}
               if self.llm_answers else {}),
            **({"noise": self.noise} if self.noise else {}),
            **({"options": dict(sorted(self.options.items()))} if self.options else {}),
        }

    def to_json(self) -> str:
        return json.dumps(self.to_dict(), sort_keys=True, separators=(",", ":"))

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> EpisodeResult:
        missing = [k for k in ("planner", "success", "steps", "travelled_m") if k not in d]
        if missing:
            raise ResultsFormatError(f"episode record lacks field(s): {', '.join(missing)}")
        major = str(d.get("version", RESULT_VERSION)).split(".")[0]
        if major != RESULT_VERSION.split(".")[0]:
            raise ResultsFormatError(
                f"episode record version {d.get('version')} is not readable by this sgtool "
                f"(reads {RESULT_VERSION.split('.')[0]}.x)"
            )
        shortest = d.get("shortest_m")
        trace = d.get("trace", [])
        if not isinstance(trace, list):
            raise ResultsFormatError("trace: expected a list")
        return cls(
            planner=_text(d, "planner"),
            seed=_whole(d, "seed", 0),
            house=_text(d, "house", ""),
            episode=_whole(d, "episode", 0),
            query=_text(d, "query", ""),
            seen=None if d.get("seen") is None else _flag(d, "seen"),
            success=_flag(d, "success"),
            steps=_whole(d, "steps"),
            travelled_m=_number(d, "travelled_m"),
            shortest_m=None if shortest is None else _number(d, "shortest_m"),
            n_open=_whole(d, "n_open", 0),
            n_invalid=_whole(d, "n_invalid", 0),
            n_failure=_whole(d, "n_failure", 0),
            end=_text(d, "end", ""),
            source=_text(d, "source", "symbolic"),
            trace=tuple(Step(str(s[0]), s[1], str(s[2]), float(s[3])) for s in trace),
            wall=dict(d.get("wall", {})),
            llm_answers={str(k): int(v) for k, v in (d.get("llm_answers") or {}).items()},
            noise=str(d.get("noise") or ""),
            options=_options(d),
        )


_ABSENT = object()


def _options(d: Mapping[str, Any]) -> dict[str, Any]:
    """A record's ``options``: a JSON object (absent or null: none)."""
    value = d.get("options") or {}
    if not isinstance(value, dict):
        raise ResultsFormatError(f"options: expected an object, got {json.dumps(value)}")
    return {str(k): v for k, v in value.items()}


def _field(d: Mapping[str, Any], key: str, default: Any) -> Any:
    value = d.get(key, default)
    if value is _ABSENT:
        raise ResultsFormatError(f"episode record lacks field(s): {key}")
    return value


def _flag(d: Mapping[str, Any], key: str, default: Any = _ABSENT) -> bool:
    """A JSON true/false (not "false", not 0)."""
    value = _field(d, key, default)
    if not isinstance(value, bool):
        raise ResultsFormatError(f"{key}: expected true or false, got {json.dumps(value)}")
    return value


def _whole(d: Mapping[str, Any], key: str, default: Any = _ABSENT) -> int:
    """A JSON integer (not 3.5, not a string, not a boolean)."""
    value = _field(d, key, default)
    if isinstance(value, bool) or not isinstance(value, int):
        raise ResultsFormatError(f"{key}: expected a whole number, got {json.dumps(value)}")
    return value


def _number(d: Mapping[str, Any], key: str, default: Any = _ABSENT) -> float:
    """A JSON number (a non-finite one is read: the validity rules refuse that record
    alone, with a note, :mod:`sgtool.analysis.validity`)."""
    value = _field(d, key, default)
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise ResultsFormatError(f"{key}: expected a number, got {json.dumps(value)}")
    return float(value)


def _text(d: Mapping[str, Any], key: str, default: Any = _ABSENT) -> str:
    value = _field(d, key, default)
    if not isinstance(value, str):
        raise ResultsFormatError(f"{key}: expected text, got {json.dumps(value)}")
    return value


# ----------------------------------------------------------------------------------------
# files
# ----------------------------------------------------------------------------------------
def write_jsonl(results: Iterable[EpisodeResult], path: str | os.PathLike[str]) -> Path:
    """One record per line, written to a temp file beside ``path`` and renamed at the end."""
    from sgtool.arg_checks import of_type

    of_type("path", path, (str, os.PathLike), "a file's path (write_results(results, path))")
    if isinstance(results, str | bytes | os.PathLike):
        raise SgtoolError("results: give the EpisodeResults, then the path "
                          "(write_results(results, path))")
    rows = list(results)
    for r in rows:
        of_type("results", r, EpisodeResult, "EpisodeResults")
    return atomic_write(path, "".join(r.to_json() + "\n" for r in rows))




def read_jsonl(path: str | os.PathLike[str]) -> list[EpisodeResult]:
    """The episode records of a JSONL file (``episodes.jsonl`` of ``sgtool bench``: one
    :class:`EpisodeResult` per line, blank lines skipped); anything else is a
    :class:`ResultsFormatError` naming the file and the line."""
    p = Path(path)
    try:
        lines = p.read_text(encoding="utf-8").splitlines()
    except FileNotFoundError:
        raise ResultsFormatError(f"{p}: no such file") from None
    except (OSError, UnicodeDecodeError) as e:
        raise ResultsFormatError(f"{p}: cannot read: {e}") from None
    out = []
    for i, line in enumerate(lines, 1):
        if not line.strip():
            continue
        try:
            d = json.loads(line)
        except json.JSONDecodeError as e:
            raise ResultsFormatError(f"{p}:{i}: not a JSON line ({e.msg})") from None
        if not isinstance(d, dict):
            raise ResultsFormatError(f"{p}:{i}: expected a JSON object")
        try:
            out.append(EpisodeResult.from_dict(d))
        except ResultsFormatError as e:
            raise ResultsFormatError(f"{p}:{i}: {e}") from None
        except (TypeError, ValueError, IndexError) as e:
            raise ResultsFormatError(f"{p}:{i}: malformed episode record ({e})") from None
    return out


def source_log(result: EpisodeResult, table: str | os.PathLike[str]) -> Path | None:
    """The log a row of the table ``table`` (an ``episodes.jsonl``) names: its ``source``
    relative to the table's folder (run-bench names its logs so), else as it is; None when
    neither is a file (a symbolic episode, a log moved away)."""
    for p in (Path(table).parent / result.source, Path(result.source)):
        if p.is_file():
            return p
    return None


def results_digest(results: Sequence[EpisodeResult]) -> str:
    """SHA-256 over the canonical records without their ``wall`` figures and ``options``
    (what the planners did, not how they were set: a replay of an LLM planner's transcript
    digests as its live run)."""
    h = hashlib.sha256()
    for r in results:
        d = r.to_dict()
        d.pop("wall")
        d.pop("options", None)
        h.update(json.dumps(d, sort_keys=True, separators=(",", ":")).encode())
        h.update(b"\n")
    return h.hexdigest()


# ----------------------------------------------------------------------------------------
# from log records
# ----------------------------------------------------------------------------------------
def planner_steps(actions: Sequence[Action]) -> int:
    """The planner steps among ``actions``: those a planner decided (the closed loop's
    opening look-around and fallback explores name none), but explores that went on after
    one (reason :data:`~sgtool.log.records.WENT_ON`); every action when none names a
    planner (a log of its own kind)."""
    decided = [a for a in actions if given(a.planner)]
    if not decided:
        return len(actions)
    return sum(1 for a in decided if not str(a.reason or "").startswith(WENT_ON))


def decision_wall(actions: Sequence[Action]) -> dict[str, float]:
    """An episode's ``wall`` decision figures: the seconds the ``actions`` took to decide
    and how many said how long they took (an action without ``decision_time_s`` counts
    as no decision, not as an instant one)."""
    timed = [float(t) for a in actions if (t := given(a.decision_time_s)) is not None]
    return {"decision_s": sum(timed), "decisions": float(len(timed))}


def result_from_log_records(episode: Episode, actions: Sequence[Action],
                            source: str = "log") -> EpisodeResult:
    """An :class:`EpisodeResult` from the records of one episode of a log.

    Reads the final ``sgtool.Episode`` record (``status`` "success"/"failure"/"ended",
    ``steps``, ``travelled_m``, ``shortest_m``, ``query``, ``planner``, ``house_id``) and
    the episode's ``sgtool.Action`` records (``skill``, ``target``, ``outcome``,
    ``travelled_m``, ``decision_time_s``). From ``extra`` it reads, when present: ``seed``
    (int), ``episode`` (int), ``seen`` (bool), ``end`` (str), ``n_open`` (int),
    ``planner_options`` (an object: the result's ``options``).

    Derived when absent: ``n_open`` = actions with skill "open" and outcome "success";
    ``n_invalid`` / ``n_failure`` = actions with that outcome; ``steps`` = the actions a
    planner decided (:func:`planner_steps`: a closed-loop log cut short counts its steps as
    its closing record would); ``travelled_m`` = sum over actions.
    """
    extra = episode.extras
    trace = tuple(
        Step(a.skill, a.target, a.result, float(given(a.travelled_m, 0.0)))
        for a in actions
    )
    status = episode.status
    n_open = extra.get("n_open")
    if n_open is None:
        n_open = sum(1 for s in trace if s.skill == "open" and s.outcome == "success")
    seen = extra.get("seen")
    shortest = given(episode.shortest_m)
    options = extra.get("planner_options")
    return EpisodeResult(
        planner=str(given(episode.planner) or next(
            (a.planner for a in actions if given(a.planner)), "unknown")),
        seed=int(extra.get("seed", 0)),
        house=str(given(episode.house_id, "")),
        episode=int(extra.get("episode", 0)),
        query=str(given(episode.query, "")),
        seen=None if seen is None else bool(seen),
        success=status == "success",
        steps=int(given(episode.steps, planner_steps(actions))),
        travelled_m=float(given(episode.travelled_m, sum(s.travelled_m for s in trace))),
        shortest_m=None if shortest is None else float(shortest),
        n_open=int(n_open),
        n_invalid=sum(1 for s in trace if s.outcome == "invalid"),
        n_failure=sum(1 for s in trace if s.outcome == "failure"),
        end=str(extra.get("end", status or "")),
        source=source,
        trace=trace,
        wall=decision_wall(actions),
        options=dict(options) if isinstance(options, Mapping) else {},
    )


def episode_spl(success: bool, shortest: float | None, travelled: float) -> float:
    """S * l / max(l, p); NaN when l is unknown (None or NaN: the episode is left out of
    SPL). A ``travelled`` p that is no finite number >= 0, or a negative ``shortest`` l,
    raises ValueError: such figures would score SPL 1 (``sgtool eval`` refuses them first,
    :mod:`sgtool.analysis.validity`)."""
    if not (math.isfinite(travelled) and travelled >= 0.0):
        raise ValueError(f"SPL: travelled {travelled} m is not a finite number >= 0")
    if shortest is not None and shortest < 0.0:
        raise ValueError(f"SPL: shortest path {shortest} m is negative")
    if shortest is None or not math.isfinite(shortest):
        return math.nan  # failed or not: an episode whose l is unknown is left out
    if not success:
        return 0.0
    denom = max(float(shortest), float(travelled))
    if denom <= 0.0:
        return 1.0
    return float(shortest) / denom
