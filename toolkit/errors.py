"""Errors a user can cause and fix. The CLI prints them as one clear message, no traceback."""

from __future__ import annotations


class SgtoolError(Exception):
    """Base for every error caused by input a user gave (a file, an option, a log)."""

    exit_code = 2


class LogFormatError(SgtoolError):
    """A file is not an sgtool/MCAP log, is truncated or corrupt where it must not be."""


class SchemaVersionError(LogFormatError):
    """A log was written with a log schema major version this sgtool cannot read."""


class MissingChannelError(LogFormatError):
    """A log lacks a channel that the requested operation needs."""


class SpecError(SgtoolError):
    """A house spec (or another JSON input) fails validation; the message names the field."""


class Terminated(KeyboardInterrupt):
    """SIGTERM (``kill``), turned into an interrupt so that it cleans up as Ctrl-C does:
    no half-written output is left, worker processes are stopped too."""


def raise_terminated(signum: int, frame: object) -> None:
    """A SIGTERM handler: raise :class:`Terminated` in the main thread."""
    raise Terminated


def raised_text(e: BaseException) -> str:
    """One line for what a user's code raised, for a message that names the code: ``Type:
    first line of the message`` (`` ...`` when it went on), ``exited (SystemExit: CODE)``
    for a ``sys.exit`` or an argument parser giving up."""
    code = e.code if isinstance(e, SystemExit) else e
    lines = str(code).strip().splitlines()
    text = (lines[0] if lines else "") + (" ..." if len(lines) > 1 else "")
    if isinstance(e, SystemExit):
        return f"exited (SystemExit: {text})"
    return f"{type(e).__name__}: {text}" if text else type(e).__name__
