"""``sgtool golden pin|check``: pin the replay of your own logs, check it after a change.

The work is :mod:`sgtool.analysis.golden_check` (pin format:
:mod:`sgtool.replayers.golden_pins`, documented in ``docs/golden.md``); this module parses
options and prints or writes the reports (:mod:`sgtool.analysis.golden_report`).
"""

from __future__ import annotations

import contextlib
import shlex
import sys
from collections.abc import Callable, Iterator, Sequence
from pathlib import Path
from typing import Any, TypeVar

import click

from sgtool.commands.options import FiniteFloatRange, PathParam, executor_options, option_group
from sgtool.errors import SgtoolError
from sgtool.files import quoted
from sgtool.scenegraph.build_options import CLASSIFIERS

F = TypeVar("F", bound=Callable[..., Any])


def replay_options(what: str) -> Callable[[F], F]:
    """``--every``, ``--classifier``, ``--min-points``, ``--voxel-size``, ``--max-frames``
    (as ``sgtool replay``'s; unset: ``what``)."""
    return option_group([
        click.option("--every", type=click.IntRange(min=1), default=None,
                     help=f"Refresh the graph every K frames (and at every action) [{what}]."),
        click.option("--classifier", type=click.Choice([c for c in CLASSIFIERS if c != "llm"]),
                     default=None, help=f"Room classifier [{what}]."),
        click.option("--min-points", type=click.IntRange(min=1), default=None,
                     help=f"Points an instance needs in one frame to count as seen [{what}]."),
        click.option("--voxel-size", type=FiniteFloatRange(0.01, 0.5), default=None,
                     help=f"Voxel edge in metres [{what}]."),
        click.option("--max-frames", type=click.IntRange(min=1), default=None,
                     help=f"Stop after this many frames [{what}]."),
    ])


def make_options(every: int | None, classifier: str | None, min_points: int | None,
                 voxel_size: float | None, max_frames: int | None) -> Any:
    from sgtool.replayers.derived_log import ReplayOptions

    return ReplayOptions(every=every, classifier=classifier, min_points=min_points,
                         voxel_size=voxel_size, max_frames=max_frames)


def _show(progress: bool | None) -> bool:
    return progress if progress is not None else sys.stderr.isatty()


@click.group("golden")
def command() -> None:
    """Golden-log regression for your own logs: `pin` the replay of logs once, `check`
    it after changing code or a parameter (exit 0 unchanged, 1 changed, 2 an error), read
    what changed layer by layer, `check --update` to accept a change on purpose.

    \b
    sgtool golden pin runs/*.mcap --dir golden/
    sgtool golden check --dir golden/ -w 2
    sgtool golden check --dir golden/ --voxel-size 0.08   # what would this change?
    sgtool golden check --dir golden/ --update            # accept it

    The pin format is documented in docs/golden.md; `pytest --sgtool-golden=DIR DIR` runs one
    test per pinned log."""


@command.command("pin")
@click.argument("logs", metavar="LOG...", nargs=-1, required=True, type=PathParam())
@click.option("--dir", "folder", required=True, type=PathParam(file_okay=False),
              help="Pin folder (created when missing; logs pinned there before under other "
              "names are kept).")
@click.option("--copy", is_flag=True,
              help="Copy each log into the folder and pin the copy (for small logs kept "
              "with the tests).")
@click.option("--why", default=None, help="A note kept with each pin (what it covers).")
@replay_options("the log's, else the replay default")
@executor_options("replays (one per log)")
@click.option("--progress/--no-progress", default=None,
              help="Progress bar on stderr (default: when stderr is a terminal).")
def pin(logs: tuple[str, ...], folder: str, copy: bool, why: str | None, every: int | None,
        classifier: str | None, min_points: int | None, voxel_size: float | None,
        max_frames: int | None, executor: str, workers: int, ray_address: str | None,
        progress: bool | None) -> None:
    """Replay every LOG and pin what a check needs into DIR: the log's digest and place,
    the replay options, every refresh's canonical scene graph (compressed), the quality
    figures when the log carries its house, the planner's decisions for an episode log."""
    from sgtool.analysis.batch_inputs import expand_inputs
    from sgtool.analysis.executor import make_executor
    from sgtool.analysis.golden_check import pin_logs

    inputs = expand_inputs(logs, (".mcap",))
    runner = make_executor(executor, workers, ray_address)
    before = _pinned_logs(Path(folder))
    pins = pin_logs(inputs, Path(folder),
                    make_options(every, classifier, min_points, voxel_size, max_frames),
                    copy=copy, executor=runner, progress=_show(progress), why=why)
    from sgtool.analysis.golden_check import pin_name
    from sgtool.analysis.golden_decisions import decisions_left_out

    for p in inputs:
        e = pins.logs[pin_name(Path(p))]
        extra = ", quality figures" if e.quality else ""
        extra += f", {len(e.decisions)} {e.planner} decisions" if e.decisions else ""
        left = None if e.decisions is not None else decisions_left_out(p)
        extra += f"; its decisions are not pinned ({left})" if left else ""
        was = before.get(e.name)
        if was is not None and (was[0] != e.log or was[1] != e.log_sha256):
            extra += f"; replaces the pin of {was[0]}" + (
                f" (another log, sha256 {was[1][:12]})" if was[0] == e.log else "")
        click.echo(f"pinned {e.name}: {e.refreshes} refreshes{extra} ({e.log})")
    click.echo(f"wrote {Path(folder) / 'expected.json'}; check with: sgtool golden check "
               f"--dir {quoted(folder)}")


def _pinned_logs(folder: Path) -> dict[str, tuple[str, str]]:
    """Pin name -> the log it pins, of the pin folder ``folder`` (none when it holds no
    readable index): what a new pin of the same name replaces."""
    from sgtool.replayers.golden_pins import INDEX, read_pins

    if not (folder / INDEX).is_file():
        return {}
    try:
        return {name: (pin.log, pin.log_sha256)
                for name, pin in read_pins(folder).logs.items()}
    except SgtoolError:
        return {}  # pin_logs says what is wrong with it


class _ReportingCommand(click.Command):
    """A command whose refused arguments (click's usage errors: ``--every 0``) still
    replace ``--report``/``--junit`` with the error, so an earlier check's green report is
    never read as this one's."""

    def parse_args(self, ctx: click.Context, args: list[str]) -> list[str]:
        given = list(args)
        try:
            return super().parse_args(ctx, args)
        except click.UsageError as e:
            report_md, junit = (_given_value(given, o) for o in ("--report", "--junit"))
            if report_md or junit:
                with contextlib.suppress(Exception):  # the usage error is the one said
                    _write_report_files(None, report_md, junit, error=(
                        _given_value(given, "--dir") or "(no --dir)", e.format_message()))
            raise


def _given_value(args: Sequence[str], option: str) -> str | None:
    """The last value of ``option`` in raw command-line ``args`` (``--x V`` or
    ``--x=V``), or None."""
    found = None
    for i, a in enumerate(args):
        if a == option and i + 1 < len(args):
            found = args[i + 1]
        elif a.startswith(option + "="):
            found = a.split("=", 1)[1]
    return found


@command.command("check", cls=_ReportingCommand)
@click.option("--dir", "folder", required=True, type=PathParam(file_okay=False),
              help="Pin folder written by `sgtool golden pin`.")
@click.option("--log", "names", multiple=True, metavar="NAME",
              help="Check only this pinned log (repeatable).")
@replay_options("as pinned; given here it overrides the pinned option for every log")
@click.option("--tolerance", type=FiniteFloatRange(min=0.0), default=0.0, show_default=True,
              help="Let differences up to this pass: positions and distances (m), room "
              "areas (m²), category scores, the robot's yaw (rad) (0: the graphs must be "
              "byte-identical).")
@click.option("--update", is_flag=True,
              help="Re-pin the changed logs (with the options checked) and print what was "
              "accepted; exit 0 then.")
@click.option("--report", "report_md", type=PathParam(dir_okay=False), default=None,
              help="Also write the report as Markdown to this file.")
@click.option("--junit", type=PathParam(dir_okay=False), default=None,
              help="Also write a JUnit XML file (one test case per log) for CI.")
@executor_options("checks (one per log)")
@click.option("--progress/--no-progress", default=None,
              help="Progress bar on stderr (default: when stderr is a terminal).")
def check(folder: str, names: tuple[str, ...], every: int | None, classifier: str | None,
          min_points: int | None, voxel_size: float | None, max_frames: int | None,
          tolerance: float, update: bool, report_md: str | None, junit: str | None,
          executor: str, workers: int, ray_address: str | None,
          progress: bool | None) -> None:
    """Replay every pinned log with the current code and compare: per log the first
    refresh (frame, log time) that differs and what differs in it layer by layer (rooms
    added, removed, merged or split with their areas; categories; objects moved or
    re-assigned; doors; frontiers; the Voronoi graph size), the quality figures before and
    after, the first planner decision that differs; then a summary table. Exit 0 when
    nothing changed, 1 when something did, 2 when a log could not be checked."""
    from sgtool.analysis.executor import make_executor
    from sgtool.analysis.golden_check import check_pins
    from sgtool.analysis.golden_report import text_report

    _check_report_files(report_md, junit)
    runner = make_executor(executor, workers, ray_address)
    with _reported_error(folder, report_md, junit):
        report = check_pins(Path(folder),
                            make_options(every, classifier, min_points, voxel_size, max_frames),
                            tolerance=tolerance, executor=runner, names=names or None,
                            keep=update, progress=_show(progress))
    for line in text_report(report):
        click.echo(line)
    _reports_and_update(report, update, report_md, junit)
    code = 2 if report.exit_code == 2 else 0 if update else report.exit_code
    if code == 2:
        first = next(c for c in report.logs if c.status == "error")
        raise SgtoolError(f"{report.counts()['error']} pinned log(s) could not be checked; "
                          f"the first: {first.name}: {first.error}")
    if code:
        again = _same_check(folder, names, every=every, classifier=classifier,
                            min_points=min_points, voxel_size=voxel_size,
                            max_frames=max_frames, tolerance=tolerance or None)
        click.echo(f"changed on purpose? accept it with: sgtool golden check {again} "
                   "--update", err=True)
        raise click.exceptions.Exit(code)


def _same_check(folder: str, names: tuple[str, ...], **given: Any) -> str:
    """The options of this check as shell words: the folder, the logs, the options set."""
    return shlex.join(["--dir", folder, *(a for n in names for a in ("--log", n)),
                       *(a for k, v in given.items() if v is not None
                         for a in ("--" + k.replace("_", "-"), str(v)))])


def _check_report_files(report_md: str | None, junit: str | None) -> None:
    """``--report`` and ``--junit`` through the one output check before any replay (each
    is replaced when it is a report of an earlier check, any other file refused)."""
    from sgtool.commands.options import check_output

    if report_md and junit and Path(report_md).resolve() == Path(junit).resolve():
        raise SgtoolError(f"--report {report_md} and --junit {junit}: one file; give two "
                          "(the second would replace the first)")
    for path, option in ((report_md, "--report"), (junit, "--junit")):
        if path:
            check_output(path, force=True, option=option)
            _only_a_report(path, option)


_REPORT_HEADS = {"--report": b"# Golden check of ", "--junit": b'<testsuite name="sgtool golden"'}


def _only_a_report(path: str, option: str) -> None:
    """A report replaces only an earlier report of its kind (or an empty file): never a
    pinned log, a pin file or any other file (one line)."""
    with contextlib.suppress(OSError):
        if not Path(path).is_file():  # (none yet; a device the output check refuses)
            return
        with open(path, "rb") as fh:
            head = fh.read(256).lstrip()
        if head.startswith(b"<?xml"):  # the declaration, then the root element
            head = head.split(b"?>", 1)[-1].lstrip()
        if head and not head.startswith(_REPORT_HEADS[option]):
            raise SgtoolError(f"{option} {path}: exists and is not a golden check report; "
                              "not writing over it")


def _reports_and_update(report: Any, update: bool, report_md: str | None,
                        junit: str | None) -> None:
    """Write the check's report files, then with ``update`` re-pin the changed logs, say
    what was accepted and write the files again with it (they keep the check's if the
    update fails)."""
    from sgtool.analysis.golden_check import update_pins

    _write_report_files(report, report_md, junit)
    if not update:
        return
    accepted = update_pins(report)
    if accepted:
        _write_report_files(report, report_md, junit, accepted)
    for line in accepted or ["nothing to accept: no pinned log changed"]:
        click.echo(line)


@contextlib.contextmanager
def _reported_error(folder: str, report_md: str | None, junit: str | None) -> Iterator[None]:
    """A check that cannot start (a damaged pin folder): the report files say so, so one
    left by an earlier check is never read as this one's."""
    try:
        yield
    except SgtoolError as e:
        _write_report_files(None, report_md, junit, error=(folder, str(e)))
        raise


def _write_report_files(report: Any, report_md: str | None, junit: str | None,
                        accepted: Sequence[str] = (),
                        error: tuple[str, str] | None = None) -> None:
    """The Markdown report and the JUnit XML of a check (with what ``--update``
    ``accepted``), or of the ``error`` (folder, message) that stopped it, each written
    atomically."""
    from sgtool.analysis.golden_report import error_reports, junit_report, markdown_report
    from sgtool.files import atomic_write

    names = [c.name for c in report.logs if c.status == "changed"] if accepted else []
    md, xml = error_reports(*error) if error is not None else (
        markdown_report(report, accepted), junit_report(report, names))
    for path, option in ((report_md, "--report"), (junit, "--junit")):
        if path:
            _only_a_report(path, option)
    if report_md:
        atomic_write(report_md, md)
    if junit:
        atomic_write(junit, xml)
