"""The ``sgtool`` command: a click group whose subcommands load lazily.

Each subcommand lives in its own module ``sgtool.commands.<name>`` exposing ``command``
(a click command or group), so ``sgtool --help`` stays fast and a missing optional piece
never breaks the other commands. User errors (:class:`sgtool.errors.SgtoolError`) print as
one line on stderr with exit code 2; so do click's usage errors (a bad option value, a
missing argument: :class:`UsageLine`) and an :class:`OSError` that the user's environment
causes (a read-only, missing or full destination: ``sgtool.files``). Ctrl-C
prints one line (what was kept, if anything) with exit code 130; once a command has
finished, Ctrl-C no longer interrupts the exit (its outputs are complete). Anything else is
a bug and keeps its traceback.
"""

from __future__ import annotations

import importlib
import importlib.util
import logging
import os
import signal
import sys
from typing import Any

import click

from sgtool.commands.options import COMMAND_ARGS
from sgtool.errors import (
    SgtoolError,
    forget_stop_signals,
    raise_terminated,
    set_stop_handlers,
    stop_exit_code,
    traceback_text,
)
from sgtool.extras import missing_extra
from sgtool.files import is_environment_error
from sgtool.redact import redact_text
from sgtool.version import __version__

# command name -> module under sgtool.commands; order is the order of --help
COMMANDS: dict[str, tuple[str, str]] = {
    "demo": ("demo", "Record the demo house, replay it, benchmark planners, print the tables."),
    "info": ("info", "Summarise a log: channels, schemas, counts, time range, frames, episode."),
    "doctor": ("doctor", "Check a log for truncation or corruption and recover what is readable."),
    "scenes": ("scenes", "Generate, draw and summarise houses; list search episodes."),
    "record": ("record", "Simulate a robot in a house with PyBullet and log RGB-D + ids to MCAP."),
    "replay": ("replay", "Rebuild voxel map, occupancy, Voronoi graph, rooms, scene graph."),
    "view": ("view", "Write a Rerun recording (.rrd) of a log, or open the viewer."),
    "import": ("import_", "Import ROS 1/2 bags and RGB-D folders into sgtool logs."),
    "export": ("export", "Export a (derived) log as a ROS 1/2 bag: maps as ROS messages."),
    "distill": ("distill", "Train the relational priors (containment, co-occurrence) MLPs."),
    "bench": ("bench", "Run the symbolic object-search benchmark over planners."),
    "run": ("run", "Closed-loop search in PyBullet with a planner, logged to MCAP."),
    "run-bench": ("run_bench", "Closed-loop benchmark: episodes x planners, one log each."),
    "eval": ("eval", "Recompute metrics from episode logs; evaluate planners offline."),
    "golden": ("golden", "Pin the replay of your logs; check it after a change (exit 0/1/2)."),
    "diff": ("diff", "What differs, layer by layer, between the scene graphs of two logs."),
    "study": ("study", "Studies over many recordings: scene-graph quality vs sensor noise."),
    "llm": ("llm", "Serve a local GGUF chat model (llama.cpp) and check an LLM endpoint."),
}

CONTEXT_SETTINGS = {"help_option_names": ["-h", "--help"], "max_content_width": 100}


class UserError(click.ClickException):
    """A :class:`SgtoolError` on its way out: one line on stderr, exit code 2."""

    exit_code = 2

    def show(self, file: object = None) -> None:
        click.echo(f"sgtool: error: {redact_text(self.message)}", err=True)


class UsageLine(click.ClickException):
    """A click usage error (a bad option value, a missing argument, an unknown option or
    command) as one line on stderr, exit code 2: ``sgtool import rgbd: error: Invalid value
    for '--every': 'abc' is not a valid integer. (see --help)``, instead of click's usage,
    hint and error lines."""

    exit_code = 2

    def show(self, file: object = None) -> None:
        click.echo(self.message, err=True)


def usage_line(e: click.UsageError) -> click.ClickException:
    """``e`` as one line naming the command; a group called without a subcommand keeps
    click's help text (that is not an error message)."""
    if isinstance(e, click.exceptions.NoArgsIsHelpError):
        return e
    where = e.ctx.command_path if e.ctx is not None else "sgtool"
    text = " ".join(e.format_message().split())
    return UsageLine(f"{where}: error: {redact_text(text)} (see --help)")


class Interrupted(click.ClickException):
    """Ctrl-C during a command: one line on stderr (what was kept), exit code 130."""

    exit_code = 130

    def show(self, file: object = None) -> None:
        tail = f"; {self.message}" if self.message else ""
        click.echo(f"sgtool: interrupted{tail}", err=True)


class Killed(Interrupted):
    """SIGTERM during a command (:class:`~sgtool.errors.Terminated`): the same line as
    :class:`Interrupted`, exit code 143 (128 + SIGTERM, as a shell reports a killed
    command)."""

    exit_code = 143


class HungUp(Killed):
    """SIGHUP (the terminal or ssh session closed) during a command: as :class:`Killed`,
    exit code 129."""

    exit_code = 129


def os_error_text(e: OSError) -> str:
    """One line for an :class:`OSError`: ``Read-only file system: /data/out.mcap``."""
    reason = e.strerror or type(e).__name__
    return f"{reason}: {e.filename}" if e.filename is not None else reason


# commands whose exit code is their verdict (diff: 1 when the logs differ; golden check,
# doctor, llm check): a closed pipe ends them with 141 (as SIGPIPE would), never a false 0
VERDICT_COMMANDS = frozenset({"diff", "golden", "doctor", "llm"})


class LazyGroup(click.Group):
    def resolve_command(self, ctx: click.Context, args: list[str]
                        ) -> tuple[str | None, click.Command | None, list[str]]:
        name, cmd, rest = super().resolve_command(ctx, args)
        ctx.meta[COMMAND_ARGS] = tuple(rest)  # the subcommand's words, as given (eager options)
        return name, cmd, rest

    def invoke(self, ctx: click.Context) -> object:
        forget_stop_signals()  # this command's signals decide its exit code
        try:
            return super().invoke(ctx)
        except click.UsageError as e:  # a subcommand's arguments, or an unknown command
            raise usage_line(e) from e
        except SgtoolError as e:
            shown = traceback_text(e)
            if shown is not None:  # SGTOOL_TRACEBACK=1: what raised, before the line
                click.echo(shown, err=True)
            if e.details:  # what helps to mend the input, before the one line
                click.echo(e.details, err=True)
            raise UserError(str(e)) from e
        except BrokenPipeError:  # `sgtool ... | head`: the reader has what it wanted
            _quiet_stdout()
            # but a command whose exit code is its verdict has not given it: 128 + SIGPIPE
            verdict = ctx.invoked_subcommand in VERDICT_COMMANDS
            raise click.exceptions.Exit(141 if verdict else 0) from None
        except ModuleNotFoundError as e:  # an optional package (an extra) is not installed
            missing = missing_extra(f"sgtool {ctx.invoked_subcommand}", e)
            if missing is None:
                raise
            raise UserError(str(missing)) from e
        except OSError as e:
            if not is_environment_error(e):
                raise
            raise UserError(os_error_text(e)) from e
        except KeyboardInterrupt as e:
            # not click's Abort (a blank line and "Aborted!"): one line, what was kept
            note = getattr(e, "note", "") or "no output was left half-written"
            kind = {130: Interrupted, 129: HungUp}.get(stop_exit_code(e), Killed)
            raise kind(note) from e

    def make_context(self, info_name: str | None, args: list[str],
                     parent: click.Context | None = None, **extra: Any) -> click.Context:
        try:
            return super().make_context(info_name, args, parent, **extra)
        except click.UsageError as e:  # the group's own options (``sgtool --bogus``)
            raise usage_line(e) from e

    def _available(self) -> dict[str, tuple[str, str]]:
        out = {}
        for name, (module, summary) in COMMANDS.items():
            if importlib.util.find_spec(f"sgtool.commands.{module}") is not None:
                out[name] = (module, summary)
        return out

    def list_commands(self, ctx: click.Context) -> list[str]:
        return list(self._available())

    def get_command(self, ctx: click.Context, cmd_name: str) -> click.Command | None:
        avail = self._available()
        if cmd_name not in avail:
            return None
        try:
            mod = importlib.import_module(f"sgtool.commands.{avail[cmd_name][0]}")
        except ModuleNotFoundError as e:  # an optional package (an extra) is not installed
            missing = missing_extra(f"sgtool {cmd_name}", e)
            if missing is None:
                raise
            raise missing from e
        return mod.command

    def format_commands(self, ctx: click.Context, formatter: click.HelpFormatter) -> None:
        rows = [(name, summary) for name, (_, summary) in self._available().items()]
        if rows:
            with formatter.section("Commands"):
                formatter.write_dl(rows)


@click.group(cls=LazyGroup, context_settings=CONTEXT_SETTINGS)
@click.version_option(__version__, "--version", prog_name="sgtool")
@click.option("-v", "--verbose", count=True, help="More log output (-v info, -vv debug).")
def cli(verbose: int) -> None:
    """sgtool: language-grounded interactive object search on 3D scene graphs.

    Logs are MCAP files: record them in simulation or import them, replay them into scene
    graphs, look at them in Rerun, benchmark planners on them. Run `sgtool COMMAND -h` for
    the options of a command.
    """
    level = logging.WARNING - 10 * min(verbose, 2)
    logging.basicConfig(level=level, format="%(levelname)s %(name)s: %(message)s")


def main(argv: list[str] | None = None) -> None:
    _terminate_as_interrupt()
    try:
        rc = cli.main(args=argv, prog_name="sgtool", standalone_mode=False)
        _finished()
        if isinstance(rc, int) and rc != 0:
            sys.exit(rc)
    except SgtoolError as e:
        click.echo(f"sgtool: error: {redact_text(str(e))}", err=True)
        sys.exit(e.exit_code)
    except click.exceptions.Abort as e:  # click's form of a KeyboardInterrupt (a kill too)
        click.echo("sgtool: interrupted", err=True)
        _finished()  # a second Ctrl-C must not break the exit's clean-up with a traceback
        sys.exit(stop_exit_code(e.__cause__ or e))
    except click.ClickException as e:
        e.show()
        if isinstance(e, Interrupted):
            _finished()
        sys.exit(e.exit_code)
    except click.exceptions.Exit as e:
        sys.exit(e.exit_code)
    except KeyboardInterrupt as e:
        click.echo("sgtool: interrupted", err=True)
        _finished()
        sys.exit(stop_exit_code(e))
    except BrokenPipeError:  # the closed pipe found at the last flush
        _quiet_stdout()
        args = sys.argv[1:] if argv is None else argv
        command = next((a for a in args if not a.startswith("-")), None)
        sys.exit(141 if command in VERDICT_COMMANDS else 0)


def _quiet_stdout() -> None:
    """Point stdout at /dev/null, so that the flush at exit does not fail again on the
    closed pipe (Python's advice for SIGPIPE-free programs)."""
    try:
        fd = os.open(os.devnull, os.O_WRONLY)
        os.dup2(fd, sys.stdout.fileno())
        os.close(fd)
    except (OSError, ValueError):  # no real stdout (a test runner's buffer)
        pass


def _terminate_as_interrupt() -> None:
    """``kill`` (SIGTERM) and a closed terminal (SIGHUP) clean up as Ctrl-C does: partial
    outputs are removed and worker processes stopped, instead of the process vanishing
    mid-write."""
    forget_stop_signals()
    try:
        set_stop_handlers(raise_terminated)
    except ValueError:  # not the main thread (sgtool called from a thread of another tool)
        pass


def _finished() -> None:
    """The command is done and its outputs are in place (or, interrupted, cleaned up): a
    Ctrl-C during the exit (a library's shutdown hooks, a worker pool's) must not turn a
    complete run into a killed one, nor print a traceback."""
    try:
        signal.signal(signal.SIGINT, signal.SIG_IGN)
        set_stop_handlers(signal.SIG_DFL)
    except ValueError:  # not the main thread
        pass


if __name__ == "__main__":
    main()
