"""The pin format of golden logs: what ``sgtool golden pin`` writes and ``check`` reads.

A pin folder holds ``expected.json`` (the index, :data:`INDEX`) and per pinned log ``NAME``:

- ``NAME.graphs.jsonl.gz``: the canonical JSON of every scene graph of the log's replay, one
  per line, gzip'd byte-stably (:func:`~sgtool.replayers.golden.write_graphs`);
- ``NAME.refreshes.jsonl.gz`` (optional): per refresh its log time, frames and reason and
  the :class:`~sgtool.replayers.golden_layers.LayerSummary` of its map layers;
- ``NAME.mcap`` when the log was copied in (``--copy``).

The index is ``{"format": 2, "sgtool_version": ..., "cases": {NAME: entry}}``; an entry
holds the log's path (relative to the folder when it lies below it), sha256 and size, the
replay options given (unset ones resolve as a replay resolves them) and what they resolved
to, the number of refreshes and the sha256 of the final graph and of the whole sequence
(:func:`~sgtool.replayers.golden.sequence_digest`), and when the log has them the quality
figures of the final graph (:func:`sgtool.replayers.score.score_dict`) and the planner's
decisions. ``docs/golden.md`` documents every field. Format 1 (one ``replay`` option set
for all cases, logs beside the index) is still read; a newer format is refused in one line
naming both versions, and a damaged index or graphs file in one line naming the file.
"""

from __future__ import annotations

import hashlib
import json
import os
import re
import typing
import zlib
from collections.abc import Mapping
from dataclasses import asdict, dataclass, field, fields
from pathlib import Path
from typing import Any

from sgtool.canonical import canonical_float
from sgtool.errors import SgtoolError
from sgtool.files import atomic_write, quoted, sha256_file
from sgtool.replayers.derived_log import ReplayOptions, replay
from sgtool.replayers.golden import (
    EXPECTED,
    read_graphs,
    sequence_digest,
    write_graphs,
)
from sgtool.replayers.golden_layers import LayerSummary, layer_summary
from sgtool.scenegraph.stream import Refresh, SceneGraphStream
from sgtool.version import __version__

INDEX = EXPECTED
PIN_FORMAT = 2


class PinError(SgtoolError):
    """A pin folder that cannot be used: missing, damaged, newer than this sgtool, or a
    pinned log that moved or changed."""


@dataclass(frozen=True)
class RefreshMeta:
    """When a refresh happened (log time in ns, frames integrated, why) and its layers."""

    time_ns: int
    frames: int
    reason: str
    layers: LayerSummary | None = None

    def to_dict(self) -> dict[str, Any]:
        d: dict[str, Any] = {"time_ns": self.time_ns, "frames": self.frames,
                             "reason": self.reason}
        if self.layers is not None:
            d.update(self.layers.to_dict())
        return d

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> RefreshMeta:
        layers = LayerSummary.from_dict(d) if "voronoi" in d else None
        return cls(int(d["time_ns"]), int(d["frames"]), str(d["reason"]), layers)


@dataclass(frozen=True)
class Decision:
    """One planner decision at a logged decision point: episode and step of the log, the
    chosen skill and target."""

    episode: int
    step: int
    skill: str
    target: str | None

    def text(self) -> str:
        return f"{self.skill}({self.target or ''})"


@dataclass(frozen=True)
class Capture:
    """A replay as a pin keeps it: every graph's canonical JSON, every refresh's metadata,
    the resolved options, the final graph's quality figures (None without a house), and the
    planner's decisions (None for a log that is no episode log)."""

    graphs: list[str]
    refreshes: list[RefreshMeta]
    resolved: dict[str, Any]
    quality: dict[str, dict[str, float | int | None]] | None = None
    planner: str | None = None
    decisions: tuple[Decision, ...] | None = None


@dataclass(frozen=True)
class Pinned:
    """One pinned log (an entry of the index; module doc)."""

    name: str
    log: str  # as stored: relative to the folder when below it
    log_sha256: str
    refreshes: int
    final_sha256: str
    sequence_sha256: str
    options: ReplayOptions = field(default_factory=ReplayOptions)
    log_bytes: int | None = None
    resolved: dict[str, Any] | None = None
    quality: dict[str, dict[str, float | int | None]] | None = None
    planner: str | None = None
    decisions: tuple[Decision, ...] | None = None
    why: str | None = None
    sgtool_version: str | None = None
    copied: bool | None = None  # True: sgtool copied the log in (--copy), and may replace
    # it; False: the log is the user's; None: an index written before pins said

    def log_path(self, folder: Path) -> Path:
        """The log's path: as stored, or joined to ``folder``, resolved as
        :func:`stored_path` made it (``..`` through a symlinked folder goes to the link's
        target's parent)."""
        p = Path(self.log)
        return p if p.is_absolute() else Path(os.path.normpath(folder.resolve() / p))

    def to_dict(self) -> dict[str, Any]:
        d: dict[str, Any] = {
            "log": self.log, "log_sha256": self.log_sha256, "refreshes": self.refreshes,
            "final_sha256": self.final_sha256, "sequence_sha256": self.sequence_sha256,
            "options": options_dict(self.options)}
        for k, v in (("log_bytes", self.log_bytes), ("resolved", self.resolved),
                     ("quality", self.quality), ("planner", self.planner),
                     ("why", self.why), ("sgtool_version", self.sgtool_version)):
            if v is not None:
                d[k] = v
        if self.copied is not None:  # (absent: an index written before pins said)
            d["copied"] = self.copied
        if self.decisions is not None:
            d["decisions"] = [[x.episode, x.step, x.skill, x.target] for x in self.decisions]
        return d


@dataclass(frozen=True)
class PinSet:
    """A pin folder's index: its format, the sgtool version that last wrote it, the logs."""

    folder: Path
    logs: dict[str, Pinned]
    format: int = PIN_FORMAT
    sgtool_version: str = __version__

    def graphs_path(self, name: str) -> Path:
        return self.folder / f"{name}.graphs.jsonl.gz"

    def refreshes_path(self, name: str) -> Path:
        return self.folder / f"{name}.refreshes.jsonl.gz"


def options_dict(o: ReplayOptions) -> dict[str, Any]:
    """The options that are set: those that differ from :class:`ReplayOptions`' defaults
    (an unset option is the log's recorded value, else the replay default)."""
    default = ReplayOptions()
    return {f.name: getattr(o, f.name) for f in fields(ReplayOptions)
            if getattr(o, f.name) != getattr(default, f.name)}


def _option_types() -> dict[str, tuple[type, ...]]:
    """ReplayOptions' field -> the JSON types its value may have (its annotation less
    None, which means unset; a float option takes an integer too)."""
    out: dict[str, tuple[type, ...]] = {}
    for name, hint in typing.get_type_hints(ReplayOptions).items():
        kinds = tuple(t for t in (typing.get_args(hint) or (hint,)) if t is not type(None))
        out[name] = (*kinds, int) if float in kinds else kinds
    return out


_OPTION_TYPES = _option_types()


def options_from(d: Mapping[str, Any], where: str) -> ReplayOptions:
    """The replay options of a pin entry; one-line :class:`PinError` for an option this
    sgtool does not know or a value of the wrong type."""
    if not isinstance(d, Mapping):
        raise PinError(f"{where}: replay options must be an object, not {_json_kind(d)}")
    known = {f.name for f in fields(ReplayOptions)}
    unknown = set(d) - known
    if unknown:
        raise PinError(f"{where}: replay option {sorted(unknown)[0]!r} is unknown to this "
                       f"sgtool ({__version__}); upgrade sgtool, or pin the logs again into "
                       "a new folder")
    for k, v in sorted(d.items()):
        kinds = _OPTION_TYPES.get(k, (object,))
        if v is not None and (isinstance(v, bool) or not isinstance(v, kinds)):
            raise PinError(f"{where}: replay option {k!r} is {_json_kind(v)} {v!r}; expected "
                           f"{' or '.join(t.__name__ for t in kinds)}")
    try:
        return ReplayOptions(**{k: v for k, v in d.items() if k in known})
    except SgtoolError as e:
        raise PinError(f"{where}: {e}") from None


def _json_kind(v: Any) -> str:
    """What a JSON value is, for a message: "a list", "a string", ..."""
    return {dict: "an object", list: "a list", str: "a string", bool: "a boolean",
            int: "a number", float: "a number", type(None): "null"}.get(type(v), type(v).__name__)


def overridden(pinned: ReplayOptions, given: ReplayOptions | None) -> ReplayOptions:
    """``pinned`` with every option that is set in ``given`` replaced."""
    if given is None:
        return pinned
    return ReplayOptions(**(asdict(pinned) | options_dict(given)))


# ----- capture ---------------------------------------------------------------------------
def capture(log: str | os.PathLike[str], options: ReplayOptions, *,
            quality: bool = True) -> Capture:
    """Replay ``log`` with ``options`` and keep what a pin needs (no planner decisions:
    those are :mod:`sgtool.analysis.golden_check`'s). ``quality``: score the final graph
    when the log carries its house."""
    from sgtool.log.reader import LogReader

    graphs: list[str] = []
    metas: list[RefreshMeta] = []
    last: dict[str, Any] = {}

    def keep(r: Refresh, s: SceneGraphStream) -> None:
        graphs.append(r.graph.to_json())
        metas.append(RefreshMeta(r.time_ns, r.frames, r.reason, layer_summary(r.layers)))
        last["refresh"], last["stream"] = r, s

    report = replay(log, None, options, on_refresh=keep)
    figures = None
    if quality:
        from sgtool.replayers.score import score, score_dict, truth_alignment

        with LogReader(log) as reader:
            house = reader.house_json()
            ref = last.get("refresh")
            align = truth_alignment(reader, None if ref is None else ref.time_ns) \
                if house is not None else None
        if house is not None and ref is not None and ref.layers is not None:
            from sgtool.house.io import load_house

            spec = load_house(json.loads(house))
            builder = last["stream"].builder
            figures = score_dict(score(spec, builder.instances, ref.layers, ref.graph,
                                       builder.trajectory, align))
            figures = {k: {f: canonical_float(v) if isinstance(v, float) else v
                           for f, v in q.items()} for k, q in figures.items()}
    return Capture(graphs, metas, asdict(report.options), figures)


# ----- reading and writing ------------------------------------------------------------------
def _damaged(path: Path, why: str) -> PinError:
    return PinError(f"{path}: damaged pin file ({why}); pin the log again with `sgtool golden "
                    "pin` or restore the file")


def read_pins(folder: str | os.PathLike[str]) -> PinSet:
    """The index of a pin folder (module doc). One-line :class:`PinError` when the folder
    or its index is missing or damaged, or the format is newer than :data:`PIN_FORMAT`."""
    root = Path(folder)
    path = root / INDEX
    if root.is_file():
        raise PinError(f"{root} is a file, not a pin folder (give the folder `sgtool golden "
                       "pin` wrote)")
    if not root.is_dir():
        raise PinError(f"{root}: no such pin folder (make one with `sgtool golden pin LOG "
                       f"--dir {quoted(root)}`)")
    if not path.is_file():
        raise PinError(f"{root}: no {INDEX}, so nothing is pinned there (pin logs with "
                       f"`sgtool golden pin LOG --dir {quoted(root)}`)")
    try:
        doc = json.loads(path.read_bytes())
    except (ValueError, UnicodeDecodeError) as e:
        raise _damaged(path, f"not JSON: {str(e).splitlines()[0]}") from None
    if not isinstance(doc, dict) or not isinstance(doc.get("cases"), dict):
        raise _damaged(path, "no 'cases' object")
    fmt = doc.get("format")
    if not isinstance(fmt, int) or isinstance(fmt, bool) or fmt < 1:
        raise _damaged(path, f"format {fmt!r} is no version number")
    if fmt > PIN_FORMAT:
        raise PinError(f"{path}: pin format {fmt} is newer than this sgtool reads (format "
                       f"{PIN_FORMAT}, sgtool {__version__}); upgrade sgtool, or pin the "
                       "logs again into a new folder (this one is left as it is)")
    common = doc.get("replay", {}) if fmt == 1 else {}
    logs: dict[str, Pinned] = {}
    for name, entry in sorted(doc["cases"].items()):
        if not valid_name(name):
            raise _damaged(path, f"entry {name!r}: a pin name is a file name (no path)")
        try:
            logs[name] = _entry(name, entry, common, fmt, path)
        except (KeyError, TypeError, ValueError) as err:
            raise _damaged(path, f"entry {name!r}: {err}") from None
    return PinSet(root, logs, fmt, str(doc.get("sgtool_version", "")))


def valid_name(name: str) -> bool:
    """Whether ``name`` can name a pin: a plain file name, so that its files stay in the
    pin folder."""
    return bool(name) and name not in (".", "..") and "/" not in name and "\\" not in name \
        and "\0" not in name


def _entry(name: str, e: Mapping[str, Any], common: Mapping[str, Any], fmt: int,
           path: Path) -> Pinned:
    if not isinstance(e, Mapping):
        raise TypeError(f"must be an object, not {_json_kind(e)}")
    for key, kinds in (("log", (str,)), ("quality", (dict,)), ("resolved", (dict,)),
                       ("planner", (str,)), ("why", (str,)), ("decisions", (list,)),
                       ("copied", (bool,))):
        if e.get(key) is not None and not isinstance(e[key], kinds):
            raise TypeError(f"{key!r} is {_json_kind(e[key])}, expected "
                            f"{' or '.join(_json_kind(t()) for t in kinds)}")
    for variant, figures in (e.get("quality") or {}).items():
        if not isinstance(figures, dict) or not all(
                v is None or (isinstance(v, int | float) and not isinstance(v, bool))
                for v in figures.values()):
            raise TypeError(f"'quality' {variant!r} must map figures to numbers or null")
    for key in ("log_sha256", "final_sha256", "sequence_sha256"):
        if key not in e:
            raise KeyError(f"{key!r} is missing")
        if not (isinstance(e[key], str) and re.fullmatch(r"[0-9a-f]{64}", e[key])):
            raise ValueError(f"{key!r} is {e[key]!r}, not a SHA-256 (64 hex digits)")
    for key, least in (("refreshes", 1), ("log_bytes", 0)):
        v = e.get(key)
        if (v is not None or key == "refreshes") and not (
                isinstance(v, int) and not isinstance(v, bool) and v >= least):
            raise ValueError(f"{key!r} is {v!r}, not a whole number >= {least}")
    options = options_from(common if fmt == 1 else e.get("options", {}), f"{path}: {name}")
    decisions = None
    if e.get("decisions") is not None:
        decisions = tuple(Decision(int(ep), int(st), str(sk), None if t is None else str(t))
                          for ep, st, sk, t in e["decisions"])
    return Pinned(
        name=name, log=str(e.get("log") or f"{name}.mcap"), log_sha256=str(e["log_sha256"]),
        refreshes=int(e["refreshes"]), final_sha256=str(e["final_sha256"]),
        sequence_sha256=str(e["sequence_sha256"]), options=options,
        log_bytes=None if e.get("log_bytes") is None else int(e["log_bytes"]),
        resolved=e.get("resolved"), quality=e.get("quality"), planner=e.get("planner"),
        decisions=decisions, why=e.get("why"), sgtool_version=e.get("sgtool_version"),
        copied=e.get("copied"))


def write_index(pins: PinSet) -> Path:
    """Write the index of ``pins`` (format :data:`PIN_FORMAT`) atomically."""
    doc = {"format": PIN_FORMAT, "sgtool_version": pins.sgtool_version,
           "cases": {k: v.to_dict() for k, v in sorted(pins.logs.items())}}
    return atomic_write(pins.folder / INDEX, json.dumps(doc, indent=2, sort_keys=True) + "\n")


def load_expected(pins: PinSet, name: str) -> tuple[list[str], list[RefreshMeta] | None]:
    """The pinned graphs of log ``name`` (checked against the sequence digest) and its
    refresh metadata (None when the pin has none); one-line :class:`PinError` when a file
    is damaged."""
    pin = pins.logs[name]
    gpath = pins.graphs_path(name)
    if not gpath.is_file():
        raise PinError(f"{gpath}: missing pin file of {name}; pin the log again with "
                       "`sgtool golden pin` or restore the file")
    try:
        graphs = read_graphs(gpath)
    except (OSError, EOFError, zlib.error, UnicodeDecodeError) as e:
        raise _damaged(gpath, f"{type(e).__name__}: {e}") from None
    if len(graphs) != pin.refreshes or sequence_digest(graphs) != pin.sequence_sha256:
        raise _damaged(gpath, "its graphs do not match the digest in the index")
    rpath = pins.refreshes_path(name)
    if not rpath.is_file():
        return graphs, None
    try:
        metas = [RefreshMeta.from_dict(json.loads(line)) for line in read_graphs(rpath)]
    except (OSError, EOFError, zlib.error, UnicodeDecodeError, ValueError, KeyError,
            TypeError) as e:
        raise _damaged(rpath, f"{type(e).__name__}: {e}") from None
    if len(metas) != len(graphs):
        raise _damaged(rpath, f"{len(metas)} refreshes where the graphs are {len(graphs)}")
    return graphs, metas


def stored_path(log: Path, folder: Path) -> str:
    """How the index names ``log``: relative to ``folder`` (``../../logs/run.mcap``) when
    the two share a directory other than the filesystem root, so that a repository
    holding both checks out anywhere; else absolute. The path as given is kept when it
    leads to the same file from ``folder`` (a symlinked data folder of the repository
    stays a link in the index, not its target's place on this machine)."""
    la, fa = os.path.abspath(log), os.path.abspath(folder)
    if os.path.commonpath([la, fa]) != os.path.abspath(os.sep):
        lexical = Path(os.path.relpath(la, fa))
        target = Path(os.path.normpath(folder.resolve() / lexical))
        if target.exists() and os.path.samefile(target, log):
            return lexical.as_posix()
    a, f = log.resolve(), folder.resolve()
    try:
        return a.relative_to(f).as_posix()
    except ValueError:
        pass
    common = Path(os.path.commonpath([a, f]))
    if common == Path(common.anchor):
        return str(a)
    return Path(os.path.relpath(a, f)).as_posix()


def pinned_entry(name: str, log: Path, stored: str, options: ReplayOptions, cap: Capture,
                 why: str | None = None, copied: bool | None = False) -> Pinned:
    """The index entry of ``cap``, a capture of ``log`` (its bytes are digested; the index
    names it ``stored``: :func:`stored_path`) with ``options``; ``copied``: ``stored`` is
    a copy sgtool made."""
    graphs = cap.graphs
    return Pinned(
        name=name, log=stored, log_sha256=sha256_file(log), refreshes=len(graphs),
        final_sha256=hashlib.sha256(graphs[-1].encode()).hexdigest() if graphs else "",
        sequence_sha256=sequence_digest(graphs), options=options,
        log_bytes=log.stat().st_size, resolved=cap.resolved, quality=cap.quality,
        planner=cap.planner, decisions=cap.decisions, why=why, sgtool_version=__version__,
        copied=copied)


def write_capture(pins: PinSet, pin: Pinned, cap: Capture) -> None:
    """Write the graphs and refresh files of ``pin`` (the index is :func:`write_index`'s)."""
    write_graphs(pins.graphs_path(pin.name), cap.graphs)
    lines = [json.dumps(m.to_dict(), sort_keys=True, separators=(",", ":"))
             for m in cap.refreshes]
    write_graphs(pins.refreshes_path(pin.name), lines)
