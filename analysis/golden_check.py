"""Golden-log regression for any logs: pin their replay, check it after a change, update.

:func:`pin_logs` replays each log (on an executor: ``-w N`` or Ray) and writes its pin
into a folder (:mod:`sgtool.replayers.golden_pins` is the format): the canonical scene
graph of every refresh, the refresh times and map-layer summaries, the quality figures
when the log carries its house, and for an episode log the planner's decisions at its
decision points. :func:`check_pins` replays every pinned log with the current code (options
given override the pinned ones) and compares: a :class:`LogCheck` per log says whether it
is unchanged, changed (the first refresh that differs, layer by layer, the quality figures
before and after, the first decision that differs) or could not be checked (an error, one
line). :func:`update_pins` writes the changed logs' new pins.

**Planner decisions** (episode logs, :mod:`sgtool.analysis.golden_decisions`): the
planner is asked again at every logged decision point on the replayed graph and its
choices are pinned. So a change of the mapping that changes a graph a planner decides on,
or a change of the planner, shows as the first decision that differs. LLM planners and
planner objects of one's own are not asked again; their logs pin graphs and figures only.
"""

from __future__ import annotations

import contextlib
import dataclasses
import os
import shutil
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal

from sgtool.analysis.executor import Executor, LocalExecutor, Task
from sgtool.analysis.golden_decisions import planner_decisions
from sgtool.analysis.pin_lock import pins_locked
from sgtool.arg_checks import of_type
from sgtool.errors import SgtoolError
from sgtool.files import (
    atomic_output,
    deferred_interrupts,
    output_error,
    output_folder,
    quoted,
    read_manifest,
    sha256_file,
)
from sgtool.log.inspect import foreign_log_problem
from sgtool.replayers.derived_log import ReplayOptions
from sgtool.replayers.golden import describe_mismatch, quality_lines
from sgtool.replayers.golden_diff import paired_refreshes
from sgtool.replayers.golden_pins import (
    INDEX,
    Capture,
    Decision,
    PinError,
    Pinned,
    PinSet,
    RefreshMeta,
    capture,
    load_expected,
    options_dict,
    overridden,
    pinned_entry,
    read_pins,
    stored_path,
    valid_name,
    write_capture,
    write_index,
)
from sgtool.version import __version__

Status = Literal["unchanged", "changed", "error"]


def capture_log(log: str | Path, options: ReplayOptions) -> Capture:
    """:func:`~sgtool.replayers.golden_pins.capture` plus the planner decisions."""
    cap = capture(log, options)
    planner, decisions = planner_decisions(log, cap.graphs, cap.refreshes)
    return dataclasses.replace(cap, planner=planner, decisions=decisions)


# ----- pin ----------------------------------------------------------------------------------
@dataclass(frozen=True)
class _PinTask:
    log: str
    options: ReplayOptions


def _pin_task(t: _PinTask) -> Capture:
    return capture_log(t.log, t.options)


def pin_name(log: Path) -> str:
    """A pinned log's name: its file name without ``.mcap``."""
    return log.name[:-5] if log.name.endswith(".mcap") else log.name


def _run(executor: Executor | None, fn: Callable[[Any], Any], tasks: list[Task],
         desc: str, progress: bool) -> list[Any]:
    runner = executor or LocalExecutor(1)
    return runner.run(fn, tasks, progress=progress, desc=desc)


PIN_COMMAND = "sgtool golden"
# the replay options `sgtool golden pin` takes as flags (the others are set from Python)
PIN_CLI_OPTIONS = ("every", "classifier", "min_points", "voxel_size", "max_frames")
PIN_FILES = (INDEX, "*.graphs.jsonl.gz", "*.refreshes.jsonl.gz", "*.mcap")


@contextlib.contextmanager
def pin_folder(root: Path, logs: Sequence[Path] = ()) -> Iterator[Path]:
    """The folder to write pins of ``root`` into (:func:`sgtool.files.output_folder`): a
    new or empty ``root`` is built beside and moved in complete (a non-empty folder that
    holds no pins is refused, unless it holds only ``logs``, the logs pinned now: then in
    place); a pin folder sgtool made is written in place, file by file atomically, the
    index last; a pin folder without sgtool's manifest (one kept with a project's tests)
    likewise, as it is. The block holds :func:`pins_locked`: read the index inside it, so
    that writers in several processes (``pytest -n``) keep each other's pins."""
    with pins_locked(root):
        if ((root / INDEX).is_file() and read_manifest(root)[0] != PIN_COMMAND) or (
                root.is_dir() and not (root / INDEX).is_file() and any(root.iterdir())
                and _only_these_logs(root, logs)):
            yield root
            return
        with output_folder(root, force=False, command=PIN_COMMAND, option="--dir",
                           known=PIN_FILES, resume=(root / INDEX).is_file()) as out:
            yield out


def _same_place(out: Path, root: Path) -> bool:
    """Whether :func:`pin_folder` gave ``root`` itself (in place), however it is spelt."""
    return out.resolve() == root.resolve()


def pin_logs(logs: Sequence[str | Path] | str | Path, folder: str | Path,
             options: ReplayOptions | None = None, *, copy: bool = False,
             executor: Executor | None = None, progress: bool = False,
             why: str | None = None) -> PinSet:
    """Pin ``logs`` into ``folder`` (:func:`pin_folder`; logs pinned there before under
    other names are kept, the same name is replaced): replay each with ``options``, write
    its graphs and refresh files and the index. ``copy``: copy each log into the folder
    (the pin then refers to the copy)."""
    if not os.fspath(folder):
        raise SgtoolError("--dir (folder=) '': an empty path; give a folder")
    root = Path(folder)
    opts = options or ReplayOptions()
    paths = [Path(logs)] if isinstance(logs, (str, os.PathLike)) else [Path(p) for p in logs]
    names = [pin_name(p) for p in paths]
    if not paths:
        raise SgtoolError("logs: give at least one log to pin")
    for p in paths:
        if not p.is_file():
            raise SgtoolError(f"{p}: no such log")
        if (foreign := foreign_log_problem(p)) is not None:  # a bag: say so, and its import
            raise SgtoolError(foreign)
    dup = sorted({n for n in names if names.count(n) > 1})
    if dup:
        raise SgtoolError(f"two logs are named {dup[0]}.mcap; pin them into separate folders")
    for p, n in zip(paths, names, strict=True):
        if not valid_name(n):
            raise SgtoolError(f"{p}: a pin is named after its log's file name, and {n!r} "
                              "cannot name one (its files would leave the folder); rename "
                              "the log")
    if root.exists() and not root.is_dir():
        raise SgtoolError(f"--dir (folder=) {root} is a file; give a folder")
    if root.is_dir() and not (root / INDEX).is_file() and not _only_these_logs(root, paths):
        raise SgtoolError(f"--dir (folder=) {root}: the folder holds files but no pins "
                          f"({INDEX}); pin into a new or empty folder (or one holding only "
                          "the logs pinned now)")
    outcomes = _run(executor, _pin_task,
                    [Task(str(p), _PinTask(str(p), opts)) for p in paths], "pin", progress)
    failed = [o for o in outcomes if not o.ok]
    if failed:
        raise SgtoolError(f"{failed[0].id}: could not be replayed: {failed[0].error}")
    empty = [p for p, o in zip(paths, outcomes, strict=True)
             if not o.value.refreshes or o.value.refreshes[-1].frames == 0]
    if empty:
        raise SgtoolError(f"{empty[0]}: its replay mapped no camera frame (no depth "
                          "image?): a pin of it would check nothing")
    with pin_folder(root, paths) as out, \
            deferred_interrupts() if _same_place(out, root) else contextlib.nullcontext():
        old = read_pins(root).logs if (root / INDEX).is_file() else {}  # (under the lock)
        copies = {name: _copy_action(p, root / f"{name}.mcap", old.get(name))
                  for p, name in zip(paths, names, strict=True)} if copy else {}
        logs_now = dict(old)
        staged = PinSet(out, logs_now, sgtool_version=__version__)
        for p, name, o in zip(paths, names, outcomes, strict=True):
            stored = f"{name}.mcap" if copy else stored_path(p, root)
            if copies.get(name) == "copy":
                with atomic_output(out / stored) as tmp:
                    try:
                        shutil.copyfile(p, tmp)
                    except OSError as e:  # it names the file read; the copy is what failed
                        if isinstance(e, (FileNotFoundError, PermissionError)) and \
                                e.filename == str(p):
                            raise
                        raise output_error(e, root / stored) from None
            was = old.get(name)
            ours = copies.get(name) == "copy" or (copies.get(name) == "keep" and
                                                   was is not None and bool(was.copied))
            pin = pinned_entry(name, p, stored, opts, o.value, why, copied=ours)
            write_capture(staged, pin, o.value)
            copied = out / f"{name}.mcap"  # a copy sgtool made before, not the log pinned now
            if was is not None and was.copied and was.log == copied.name and \
                    stored != copied.name and copied.is_file() and copied.resolve() != p.resolve():
                copied.unlink()
            logs_now[name] = pin
        write_index(staged)
    return PinSet(root, logs_now, sgtool_version=__version__)


def _graph_times(graphs: Sequence[str]) -> list[int]:
    """The ``time_ns`` of each graph's JSON (0 where it is missing)."""
    import json

    return [int(json.loads(g).get("time_ns") or 0) for g in graphs]


def _not_a_whole_log(log: Path) -> str | None:
    """What ``log`` is when it is no whole MCAP file (a Git LFS pointer never fetched,
    another file, one cut short), with what to do; None for a whole one."""
    from sgtool.log.mcap_records import MAGIC

    with open(log, "rb") as f:
        head = f.read(64)
        f.seek(max(0, log.stat().st_size - len(MAGIC)))
        tail = f.read()
    if head.startswith(b"version https://git-lfs"):
        return "it is a Git LFS pointer, not the log: fetch it (`git lfs pull`)"
    if not head.startswith(MAGIC):
        return "it is not an MCAP file; put the pinned log back"
    if tail != MAGIC:
        return ("it ends without the MCAP footer (cut short, or still being written); put "
                "the pinned log back")
    return None


def _only_these_logs(root: Path, logs: Sequence[Path]) -> bool:
    """Whether every entry of ``root`` is one of ``logs`` (a folder of logs pinned in
    place on the first run, as a project's test folder is laid out)."""
    mine = {p.resolve() for p in logs}
    return all(e.resolve() in mine for e in root.iterdir())


def _copy_action(log: Path, dest: Path, was: Pinned | None) -> str:
    """What ``--copy`` does at ``dest``: "copy" (nothing there, or sgtool's own earlier
    copy), "keep" (the log itself, or the same bytes already there); a file of the user's
    with other bytes is refused, never replaced, and so is one an older index pinned
    without saying whether sgtool copied it."""
    if not dest.exists():
        return "copy"
    if dest.resolve() == log.resolve() or (dest.is_file()
                                           and sha256_file(dest) == sha256_file(log)):
        return "keep"
    if was is not None and was.log == dest.name and was.copied:
        return "copy"  # sgtool's own copy
    if was is not None and was.log == dest.name and was.copied is None:
        raise SgtoolError(f"--copy: {dest} was pinned by an sgtool that did not record "
                          "whether it copied the log there or found it there; not replacing "
                          "it: move it away (a copy of its own is made), or pin without "
                          "--copy")
    raise SgtoolError(f"--copy: {dest} is a file sgtool did not copy there; not replacing it "
                      "(move it away, or pin without --copy)")


# ----- check --------------------------------------------------------------------------------
@dataclass(frozen=True)
class LogCheck:
    """What checking one pinned log found (module doc). ``lines``: the layer-by-layer
    report of the first refresh that differs (its first line names the refresh);
    ``layers``: lines per layer in it; ``quality``: the pinned and the current figures
    (``{"strict"|"merged": {figure: value}}``, None without a house); ``decision``: the
    first planner decision that differs; ``capture``: the new replay, kept for
    :func:`update_pins` when asked."""

    name: str
    status: Status
    log: str
    options: dict[str, Any] = field(default_factory=dict)
    refreshes: tuple[int, int] = (0, 0)  # pinned, now
    first: str | None = None
    lines: tuple[str, ...] = ()
    layers: dict[str, int] = field(default_factory=dict)
    quality: tuple[dict[str, Any] | None, dict[str, Any] | None] = (None, None)
    decision: str | None = None
    error: str | None = None
    capture: Capture | None = None
    differing: int = 0  # refreshes whose graph is not byte-identical (or missing)
    compared: int | None = None  # refreshes paired, when replayed at other times

    def report(self) -> list[str]:
        """The per-log report (text lines)."""
        head = f"{self.name}: {self.status}"
        if self.status == "error":
            return [f"{head}: {self.error}"]
        opts = ", ".join(f"{k} {v}" for k, v in sorted(self.options.items()))
        out = [head + f" ({self.log}, {self.refreshes[1]} refreshes"
               + (f"; replayed with {opts})" if opts else ")")]
        if self.status == "unchanged":
            return out
        out += ["  " + x for x in self.lines]
        if self.lines and self.compared is not None:
            out.append(f"  {self.differing} of the {self.compared} refreshes compared are not "
                       "byte-identical")
        elif self.lines:
            out.append(f"  {self.differing} of {max(self.refreshes)} refreshes are not "
                       "byte-identical")
        out += ["  " + x for x in quality_lines(*self.quality)]
        if self.decision:
            out.append("  " + self.decision)
        return out


@dataclass(frozen=True)
class _CheckTask:
    folder: str
    pin: Pinned
    options: ReplayOptions
    tolerance: float
    keep: bool  # return the capture of a changed log (for --update)


def _layer_counts(lines: Sequence[str]) -> dict[str, int]:
    out: dict[str, int] = {}
    for x in lines[1:]:
        layer = x.strip().split(":", 1)[0]
        if layer.startswith(("...", "(")):  # "... and 5 more", a note
            continue
        out[layer] = out.get(layer, 0) + 1
    return out


def first_decision_change(pinned: Sequence[Decision] | None, now: Sequence[Decision] | None,
                          planner: str | None) -> str | None:
    """``decisions: scout at episode 0, step 3: navigate(room:2) -> explore(frontier:4)``."""
    if pinned is None and now is None:
        return None
    if pinned is None or now is None:
        return (f"decisions: {'now' if pinned is None else 'no longer'} an episode log with "
                f"planner decisions")
    for a, b in zip(pinned, now, strict=False):
        if a != b:
            where = f"episode {a.episode}, step {a.step}"
            if (a.episode, a.step) != (b.episode, b.step):
                where += f" (now episode {b.episode}, step {b.step})"
            return f"decisions: {planner} at {where}: {a.text()} -> {b.text()}"
    if len(pinned) != len(now):
        return (f"decisions: {len(now)} where {len(pinned)} were pinned; the first "
                f"{min(len(pinned), len(now))} agree")
    return None


def pin_command(pin: Pinned, log: Path, folder: Path) -> str:
    """The ``sgtool golden pin`` command that pins ``log`` again as ``pin`` was pinned:
    its replay options and its note (a bare command would reset them); options the
    command does not take (set from Python) are named after it."""
    import shlex

    words = ["sgtool", "golden", "pin", str(log), "--dir", str(folder)]
    others = []
    for k, v in sorted(options_dict(pin.options).items()):
        if k in PIN_CLI_OPTIONS:
            words += ["--" + k.replace("_", "-"), str(v)]
        else:
            others.append(f"{k}={v!r}")
    if pin.why:
        words += ["--why", pin.why]
    return shlex.join(words) + (f" (and from Python: {', '.join(others)})" if others else "")


def _check_task(t: _CheckTask) -> LogCheck:
    folder = Path(t.folder)
    with pins_locked(folder, shared=True):  # the index and its graphs of one moment
        pin = read_pins(folder).logs.get(t.pin.name, t.pin) if (folder / INDEX).is_file() \
            else t.pin  # (re-pinned since the index was read: the new pin)
        pins = PinSet(folder, {pin.name: pin})
        try:
            loaded: tuple[list[str], list[RefreshMeta] | None] | SgtoolError = \
                load_expected(pins, pin.name)
        except SgtoolError as e:
            loaded = e
    log = pin.log_path(folder)
    base = LogCheck(pin.name, "error", str(log), options_dict(t.options))
    try:
        if not log.is_file():
            raise PinError(f"pinned log {log} is missing (moved or deleted? put it back, or "
                           f"pin it again with `{pin_command(pin, log, folder)}`)")
        size = log.stat().st_size
        if (pin.log_bytes is not None and size != pin.log_bytes) or \
                sha256_file(log) != pin.log_sha256:
            what = (f"{size} bytes, {pin.log_bytes} pinned" if pin.log_bytes not in (None, size)
                    else "its sha256 differs")
            if (damage := _not_a_whole_log(log)) is not None:
                raise PinError(f"{log} is not the pinned log ({what}): {damage}")
            raise PinError(f"{log} is not the pinned log ({what}); if it was "
                           "re-recorded on purpose, pin it again with its settings: "
                           f"`{pin_command(pin, log, folder)}`")
        if isinstance(loaded, SgtoolError):
            raise loaded
        expected, metas = loaded
        cap = capture_log(log, t.options)
    except SgtoolError as e:
        return dataclasses.replace(base, error=str(e).splitlines()[0])
    exact = t.tolerance <= 0
    actual = list(zip(cap.refreshes, cap.graphs, strict=True))
    pinned, numbers, note = expected, list(range(len(actual))), None
    if metas is not None:  # replayed at other times (--every): compared at the same times
        ia, numbers, note = paired_refreshes([m.time_ns for m in metas],
                                             [r.time_ns for r in cap.refreshes])
        pinned, metas, actual = ([expected[i] for i in ia], [metas[i] for i in ia],
                                 [actual[j] for j in numbers])
    elif (times := _graph_times(expected)) != [r.time_ns for r in cap.refreshes] and \
            len(set(times)) == len(times) == len(expected):
        # no refresh file (an older pin): the graphs' own distinct times pair them
        ia, numbers, note = paired_refreshes(times, [r.time_ns for r in cap.refreshes])
        pinned, actual = [expected[i] for i in ia], [actual[j] for j in numbers]
    layers = ([(m.layers, c.layers) for m, (c, _) in zip(metas, actual, strict=False)]
              if metas is not None else [])
    lines = describe_mismatch(pinned, actual, tol=t.tolerance, exact=exact, layers=layers,
                              numbers=numbers)
    if note is not None:
        lines = (lines or [f"{len(cap.graphs)} refreshes where {len(expected)} were pinned; "
                           "the graphs agree where both refresh"]) + [f"  ({note})"]
    decision = first_decision_change(pin.decisions, cap.decisions, cap.planner or pin.planner)
    quality = (pin.quality, cap.quality)
    q_changed = bool(quality_lines(*quality, changed_only=True)) and (exact or bool(lines))
    changed = bool(lines) or decision is not None or q_changed
    first = lines[0].removesuffix(" differs:") if lines else None
    differing = sum(e != g for e, (_, g) in zip(pinned, actual, strict=False))
    if note is None:  # every refresh paired: one missing differs too
        differing += max(len(expected), len(cap.graphs)) - min(len(pinned), len(actual))
    return dataclasses.replace(
        base, status="changed" if changed else "unchanged",
        refreshes=(pin.refreshes, len(cap.graphs)), first=first, lines=tuple(lines),
        layers=_layer_counts(lines), quality=quality, decision=decision,
        capture=cap if changed and t.keep else None, differing=differing,
        compared=None if note is None else min(len(pinned), len(actual)))


@dataclass(frozen=True)
class CheckReport:
    """Every pinned log's :class:`LogCheck`, in name order; the ``pins`` checked and the
    ``options`` that overrode the pinned ones."""

    pins: PinSet
    logs: tuple[LogCheck, ...]
    options: ReplayOptions = field(default_factory=ReplayOptions)
    tolerance: float = 0.0

    @property
    def exit_code(self) -> int:
        """0 unchanged, 1 changed, 2 an error (before changes)."""
        if any(c.status == "error" for c in self.logs):
            return 2
        return 1 if any(c.status == "changed" for c in self.logs) else 0

    def counts(self) -> dict[str, int]:
        out = {"unchanged": 0, "changed": 0, "error": 0}
        for c in self.logs:
            out[c.status] += 1
        return out


def check_pins(folder: str | Path, options: ReplayOptions | None = None, *,
               tolerance: float = 0.0, executor: Executor | None = None,
               names: Sequence[str] | None = None, keep: bool = False,
               progress: bool = False) -> CheckReport:
    """Check every pinned log of ``folder`` (or those in ``names``) against the current
    code (module doc). ``options``: set fields override the pinned options; ``tolerance``
    (m, m², scores): differences up to it pass (0: byte-exact graphs); ``keep``: keep the
    new replay of changed logs for :func:`update_pins`."""
    from sgtool.arg_checks import number

    number("tolerance", tolerance, 0.0)
    pins = read_pins(folder)
    if not pins.logs:  # a check of nothing would pass a CI job whose pins were lost
        raise PinError(f"{pins.folder}: its index pins no log; pin some with `sgtool golden "
                       f"pin LOG --dir {quoted(pins.folder)}`")
    chosen = sorted(pins.logs) if names is None else list(dict.fromkeys(names))  # each once
    for n in chosen:
        if n not in pins.logs:
            raise PinError(f"{pins.folder}: no pinned log named {n!r} (pinned: "
                           f"{', '.join(sorted(pins.logs)) or 'none'})")
    tasks = [Task(n, _CheckTask(str(pins.folder), pins.logs[n],
                                overridden(pins.logs[n].options, options), tolerance, keep))
             for n in chosen]
    outcomes = _run(executor, _check_task, tasks, "check", progress)
    logs = tuple(o.value if o.ok else LogCheck(o.id, "error", pins.logs[o.id].log,
                                               error=o.error) for o in outcomes)
    return CheckReport(pins, logs, options or ReplayOptions(), tolerance)


def update_pins(report: CheckReport) -> list[str]:
    """Re-pin the changed logs of ``report`` (checked with ``keep``) with the options they
    were checked with (in place: :func:`pin_folder`); what was accepted, one line per
    log."""
    of_type("report", report, CheckReport, "a CheckReport (of check_pins(..., keep=True))")
    pins = report.pins
    accepted = []
    if any(c.status == "changed" and c.capture is None for c in report.logs):
        raise SgtoolError("report: its changed logs kept no replay to pin; check with "
                          "check_pins(..., keep=True) to update them")
    changed = [c for c in report.logs if c.status == "changed" and c.capture is not None]
    if not changed:
        return []
    with pin_folder(pins.folder) as out, \
            deferred_interrupts() if _same_place(out, pins.folder) else contextlib.nullcontext():
        now = read_pins(pins.folder).logs  # as other writers left it (under the lock)
        staged = PinSet(out, now, sgtool_version=__version__)
        for c in changed:
            assert c.capture is not None
            old = pins.logs[c.name]
            opts = overridden(old.options, report.options)
            pin = pinned_entry(c.name, old.log_path(pins.folder), old.log, opts, c.capture,
                               old.why, copied=old.copied)  # a copy stays sgtool's
            write_capture(staged, pin, c.capture)
            pins.logs[c.name] = now[c.name] = pin
            if c.first:
                what = f"{c.first} ({sum(c.layers.values())} differences in it)"
            elif c.decision:
                what = f"the planner's decisions ({c.decision.removeprefix('decisions: ')})"
            else:
                what = "the quality figures"
            accepted.append(f"updated {c.name}: accepted the change from {what}")
        write_index(staged)
    return accepted
