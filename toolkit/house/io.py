"""Reading and writing house specs: ``load_house`` (a path or a parsed dict, validated by
:func:`sgtool.house.parse.parse_house`; a version-1 file loads as the equivalent
version-2 spec), ``load_house_text`` (JSON text) and ``save_house`` (canonical JSON of the
current version, written atomically). A file over :data:`MAX_FILE_BYTES` is refused
unread; JSON nested too deeply for the parser, holding an integer too long to convert or
a key twice in one object is a one-line :class:`SpecError`, not a traceback."""

from __future__ import annotations

import json
import os
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from sgtool.arg_checks import of_type
from sgtool.errors import SpecError
from sgtool.files import atomic_write
from sgtool.house.parse import json_object_pairs, parse_house
from sgtool.house.spec import LIMITS, HouseSpec, SpecLimits

MAX_FILE_BYTES = 64 * 1024 * 1024  # a house at every limit of SpecLimits is far smaller


def save_house(spec: HouseSpec, path: str | os.PathLike[str]) -> Path:
    """Write the canonical JSON atomically (temp file beside ``path``, then rename)."""
    of_type("spec", spec, HouseSpec, "a HouseSpec (save_house(spec, path): the house first)")
    of_type("path", path, (str, os.PathLike), "a file's path")
    return atomic_write(path, spec.to_json())


def load_house(source: str | os.PathLike[str] | Mapping[str, Any],
               limits: SpecLimits = LIMITS) -> HouseSpec:
    """Read and validate a house spec from a file path or an already parsed dict.

    A ``Path`` is always a path (``{h1}.json`` loads). For compatibility a ``str`` that
    starts with ``{`` and names no file is read as JSON text; new code passes text to
    :func:`load_house_text`. Raises :class:`sgtool.errors.SpecError` whose message starts
    with the file and the offending field (``h.json: furniture[3].size: every side must
    be > 0``).
    """
    of_type("source", source, (str, os.PathLike, Mapping),
            "a house spec file's path or a parsed JSON object")
    if isinstance(source, Mapping):
        return parse_house(source, limits)
    if isinstance(source, str) and source.lstrip().startswith("{") \
            and not _is_file(source):
        return load_house_text(source, limits)
    if not os.fspath(source):  # ("" would be the folder ".")
        raise SpecError("an empty path: give a house spec file")
    p = Path(os.fspath(source))
    try:
        if p.is_file() and p.stat().st_size > MAX_FILE_BYTES:
            raise SpecError(f"{p}: {p.stat().st_size} bytes, more than the limit of "
                            f"{MAX_FILE_BYTES} for a house spec")
        raw = p.read_text(encoding="utf-8-sig")  # a byte-order mark (Windows editors) is no text
    except FileNotFoundError:
        raise SpecError(f"{p}: no such house spec file") from None
    except (OSError, UnicodeDecodeError) as e:
        raise SpecError(f"{p}: cannot read house spec: {e}") from None
    try:
        return load_house_text(raw, limits)
    except SpecError as e:
        raise SpecError(f"{p}: {e}") from None


def load_house_text(text: str, limits: SpecLimits = LIMITS) -> HouseSpec:
    """Validate a house spec given as JSON text (a key given twice in one object is
    refused, naming the field); :class:`SpecError` as :func:`load_house`."""
    try:
        data = json.loads(text, object_pairs_hook=json_object_pairs)
    except json.JSONDecodeError as e:
        raise SpecError(f"not valid JSON ({e.msg} at line {e.lineno})") from None
    except RecursionError:
        raise SpecError("JSON nested too deeply to read") from None
    except ValueError as e:  # e.g. an integer of more than 4300 digits
        raise SpecError(f"not readable JSON ({str(e)[:80]})") from None
    return parse_house(data, limits)


def house_file_id(path: str | os.PathLike[str]) -> str:
    """The id a house file goes by: its ``"id"`` (checked on load), else its file name
    without the suffix; ``sgtool bench``, ``record`` and ``run`` name logs and rows by it."""
    p = Path(path)
    try:
        raw: Any = json.loads(p.read_text(encoding="utf-8-sig"))
    except (OSError, ValueError):
        raw = None
    own = raw.get("id") if isinstance(raw, dict) else None
    return own if isinstance(own, str) and own.strip() else p.stem


def _is_file(name: str) -> bool:
    try:
        return len(name) < 4096 and "\0" not in name and Path(name).is_file()
    except (OSError, ValueError):
        return False

