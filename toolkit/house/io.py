"""Reading and writing house specs: ``load_house`` (a path, JSON text or a parsed dict,
validated by :func:`sgtool.house.parse.parse_house`; a version-1 file loads as the
equivalent version-2 spec) and ``save_house`` (canonical JSON of the current version,
written atomically). A file over :data:`MAX_FILE_BYTES` is refused unread, and JSON
nested too deeply for the parser or holding an integer too long to convert is a one-line
:class:`SpecError`, not a traceback."""

from __future__ import annotations

import json
import os
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from sgtool.errors import SpecError
from sgtool.files import atomic_write
from sgtool.house.parse import parse_house
from sgtool.house.spec import LIMITS, HouseSpec, SpecLimits

MAX_FILE_BYTES = 64 * 1024 * 1024  # a house at every limit of SpecLimits is far smaller


def save_house(spec: HouseSpec, path: str | os.PathLike[str]) -> Path:
    """Write the canonical JSON atomically (temp file beside ``path``, then rename)."""
    return atomic_write(path, spec.to_json())


def load_house(source: str | os.PathLike[str] | Mapping[str, Any],
               limits: SpecLimits = LIMITS) -> HouseSpec:
    """Read and validate a house spec from a path, a JSON string or an already parsed dict.

    Raises :class:`sgtool.errors.SpecError` whose message starts with the offending field
    (``furniture[3].size: every side must be > 0``).
    """
    if isinstance(source, Mapping):
        data: Any = source
        where = "house spec"
    else:
        text_or_path = os.fspath(source)
        if isinstance(source, str) and text_or_path.lstrip().startswith("{"):
            raw, where = text_or_path, "house spec"
        else:
            p = Path(text_or_path)
            where = str(p)
            try:
                if p.is_file() and p.stat().st_size > MAX_FILE_BYTES:
                    raise SpecError(f"{p}: {p.stat().st_size} bytes, more than the limit of "
                                    f"{MAX_FILE_BYTES} for a house spec")
                raw = p.read_text(encoding="utf-8")
            except FileNotFoundError:
                raise SpecError(f"{p}: no such house spec file") from None
            except (OSError, UnicodeDecodeError) as e:
                raise SpecError(f"{p}: cannot read house spec: {e}") from None
        try:
            data = json.loads(raw)
        except json.JSONDecodeError as e:
            raise SpecError(f"{where}: not valid JSON ({e.msg} at line {e.lineno})") from None
        except RecursionError:
            raise SpecError(f"{where}: JSON nested too deeply to read") from None
        except ValueError as e:  # e.g. an integer of more than 4300 digits
            raise SpecError(f"{where}: not readable JSON ({str(e)[:80]})") from None
    try:
        return parse_house(data, limits)
    except SpecError as e:
        if where != "house spec":
            raise SpecError(f"{where}: {e}") from None
        raise

