"""Keeping secrets out of every output: summaries, logs, metadata, transcripts, messages.

An option is a secret when its name looks like one: a part of it (split at ``_``, ``-``,
``.``; any case) is one of :data:`SECRET_PARTS` (``key``, ``token``, ``secret``,
``password``, ...), or it contains ``apikey``, ``secret`` or ``password`` (``api_key``,
``hf_token``, ``client_secret``, ``db.password``; not ``max_tokens``):
:func:`redact_options` replaces its value with :data:`REDACTED`, at any depth.
:func:`redact_text` removes known secret values (and the password of a URL) from free text,
such as an error message that quotes a request.
"""

from __future__ import annotations

import os
import re
from collections.abc import Iterable, Mapping
from typing import Any

REDACTED = "<redacted>"
SECRET_PARTS = frozenset({"key", "apikey", "token", "secret", "password", "passwd", "pwd",
                          "credential", "credentials", "auth", "bearer"})
_SECRET_INFIXES = ("apikey", "secret", "password")
_URL_PASSWORD = re.compile(r"(://[^/\s:@]+:)[^/\s@]+@")
# NAME=VALUE in free text; the placeholder VALUE of a usage message is left alone
_ASSIGNMENT = re.compile(r"([\w.\-]+=)(?!<redacted>|VALUE\b)[^\s'\"`,;)]+")
MIN_SECRET_LEN = 4  # shorter values are not searched for in text (they would match anywhere)


def is_secret_name(name: str) -> bool:
    low = str(name).lower()
    parts = set(re.split(r"[_\-.\s]+", low))
    return bool(parts & SECRET_PARTS) or any(s in low.replace("_", "") for s in _SECRET_INFIXES)


def redact_options(options: Any) -> Any:
    """A copy of ``options`` (mappings, lists, tuples of plain values) with the value of
    every key named like a secret replaced by :data:`REDACTED`, and the password of a URL
    in any text value (``http://user:PASS@host``) too."""
    if isinstance(options, Mapping):
        return {k: (REDACTED if is_secret_name(str(k)) and v is not None
                    else redact_options(v)) for k, v in options.items()}
    if isinstance(options, list | tuple):
        return type(options)(redact_options(v) for v in options)
    if isinstance(options, str):
        return redact_url(options)
    return options


def redact_url(text: str) -> str:
    """``text`` with the password of every URL in it (``user:PASS@host``) redacted."""
    return _URL_PASSWORD.sub(rf"\g<1>{REDACTED}@", text)


def secret_values(options: object) -> list[str]:
    """The values of the keys named like secrets in ``options``, at any depth."""
    out: list[str] = []
    if isinstance(options, Mapping):
        for k, v in options.items():
            if is_secret_name(str(k)) and isinstance(v, str):
                out.append(v)
            else:
                out.extend(secret_values(v))
    elif isinstance(options, list | tuple):
        for v in options:
            out.extend(secret_values(v))
    return out


def redact_text(text: str, secrets: Iterable[str | None] = ()) -> str:
    """``text`` without the given secret values, URL passwords (``user:PASS@host``) and
    the values of secret-named assignments (``moma-llm.api_key=VALUE``)."""
    for s in secrets:
        if s and len(s) >= MIN_SECRET_LEN:
            text = text.replace(s, REDACTED)
    text = _ASSIGNMENT.sub(
        lambda m: m.group(1) + REDACTED if is_secret_name(m.group(1).split(".")[-1][:-1])
        else m.group(0), text)
    return redact_url(text)


def options_as_text(planner_options: Mapping[str, Mapping[str, Any]]
                    ) -> dict[str, dict[str, str]]:
    """Planners' options as a run's settings record them: per planner (sorted) each value
    redacted (:func:`redact_options`) and as its text."""
    return {planner: {k: _as_text(v) for k, v in redact_options(opts).items()}
            for planner, opts in sorted(planner_options.items())}


def _as_text(value: Any) -> str:
    """An option value as ``-O`` text gives it: a list of plain values comma-separated
    (``0.3,0.7``, which parses back to the same value), anything else ``str``."""
    if isinstance(value, list | tuple) and all(
            isinstance(x, str | int | float) for x in value):
        return ",".join(str(x) for x in value)
    return str(value)


def recorded_options(options: Mapping[str, Any]) -> dict[str, Any]:
    """A planner's options as an episode record keeps them: JSON values only (a path as
    its text; a Python object set from Python, an encoder, is left out), keys named like
    secrets left out (:func:`sgtool.redact.is_secret_name`) and URL passwords redacted,
    sorted."""
    plain = (str, int, float, bool, type(None))
    options = {k: os.fspath(v) if isinstance(v, os.PathLike) else v
               for k, v in options.items()}
    return {k: redact_options(v) for k, v in sorted(options.items())
            if not is_secret_name(str(k)) and (isinstance(v, plain) or (
                isinstance(v, list | tuple) and all(isinstance(x, plain) for x in v)))}
