"""Errors a user can cause and fix. The CLI prints them as one clear message, no traceback
(with the environment variable ``SGTOOL_TRACEBACK=1``, the traceback too: :func:`traceback_text`,
for the author of a plug-in planner or classifier whose code raised)."""

from __future__ import annotations

import os
import signal
import threading
import traceback
from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any


class SgtoolError(Exception):
    """Base for every error caused by input a user gave (a file, an option, a log).

    ``details``: text that helps to mend the input (a file's table of contents), which
    the CLI prints before the one-line message; the message itself stands alone."""

    exit_code = 2
    details = ""  # (a subclass whose __init__ does not call this one's has none of its own)

    def __init__(self, *args: object, details: str = "") -> None:
        super().__init__(*args)
        self.details = details


class ArgumentError(SgtoolError, ValueError):
    """An API function given an argument it cannot take: an :class:`SgtoolError` (one
    line), and a ``ValueError`` as such mistakes are in Python."""


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


# the signals that stop a command as Ctrl-C does, turned into Terminated by the CLI: a
# kill and a closed terminal (or ssh session)
STOP_SIGNALS: tuple[signal.Signals, ...] = tuple(
    getattr(signal, name) for name in ("SIGTERM", "SIGHUP") if hasattr(signal, name))
_received: list[int] = []  # the stop signals the handler got during this command


def raise_terminated(signum: int, frame: object) -> None:
    """A SIGTERM (SIGHUP) handler: raise :class:`Terminated` in the main thread."""
    _received.append(int(signum))
    raise Terminated


def set_stop_handlers(handler: Any) -> None:
    """Every stop signal to ``handler`` (a function, ``signal.SIG_DFL``), but for one that
    is ignored (``nohup sgtool ...``: a hang-up must not stop it). Main thread only
    (``ValueError`` elsewhere, as :func:`signal.signal`)."""
    for sig in STOP_SIGNALS:
        if signal.getsignal(sig) is not signal.SIG_IGN:
            signal.signal(sig, handler)


def forget_stop_signals() -> None:
    """A command starts: no stop signal received yet."""
    _received.clear()


def stop_exit_code(e: BaseException) -> int:
    """The exit code of a command stopped by ``e``: 128 + the stop signal received (143 a
    kill, 129 a closed terminal), as a shell reports it; 130 for Ctrl-C. A library (Ray's
    wait) may raise a plain KeyboardInterrupt in place of the :class:`Terminated` the
    handler raised, so the signal received decides."""
    if _received:
        return 128 + _received[-1]
    return 143 if isinstance(e, Terminated) else 130


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


def a_or_an(word: str) -> str:
    """``word`` with its indefinite article by its first letter: "an int", "a TUM", "an
    Open3D" (messages name types and formats, whose spelling decides)."""
    return f"{'an' if word[:1].lower() in 'aeiou' else 'a'} {word}"


def returned_text(value: object) -> str:
    """What a user's code returned, for a message: "None", "an int", "a Half" (by its
    type's name)."""
    return "None" if value is None else a_or_an(type(value).__name__)


def traceback_text(e: BaseException) -> str | None:
    """The traceback of ``e`` with its causes (a plug-in's own frames: it is raised ``from``
    what the plug-in raised; from a worker process, the worker's traceback), when the
    environment variable ``SGTOOL_TRACEBACK`` is set (not empty, not ``0``); else None."""
    if os.environ.get("SGTOOL_TRACEBACK", "") in ("", "0"):
        return None
    return "".join(traceback.format_exception(e)).rstrip()


@contextmanager
def deferred_interrupts() -> Iterator[None]:
    """Ctrl-C (and SIGTERM, SIGHUP) during the block take effect when it ends: for a commit of
    files that must change together (a pin folder's graphs and its index), which an
    interrupt between two of them would leave out of step. Outside the main thread (no
    signal handlers there) the block runs as it is."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    got: list[int] = []
    old = {int(s): signal.getsignal(s) for s in (signal.SIGINT, *STOP_SIGNALS)}
    for s in old:
        signal.signal(s, lambda signum, _frame: got.append(signum))
    try:
        yield
    finally:
        for s, handler in old.items():
            signal.signal(s, handler)
    if not got:
        return
    handler = old[got[0]]
    if callable(handler):  # Python's Ctrl-C handler raises KeyboardInterrupt
        handler(got[0], None)
    elif handler == signal.SIG_DFL:  # the default action (SIGTERM: the process ends)
        signal.raise_signal(got[0])
